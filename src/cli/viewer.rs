//! The commands' Rerun outputs (`replay --rrd`, `--spawn`, `--connect`,
//! a replay that names no output; `check --rrd-on-failure`). With the
//! `viewer` feature: the recordings, through `sweeptrace::viz`. In a build
//! without it (`--no-default-features --features cli`): the error that
//! names the option and the command installing the build with the viewer
//! (exit 2), and stand-ins of the recording types of which no value can be
//! made, so the commands' code is the same in both builds and the help
//! lists the same options.

use std::path::Path;

use sweeptrace::replay::ReplayOptions;

#[cfg(feature = "viewer")]
pub(crate) use sweeptrace::viz::rrd_file::RrdFileOptions;
#[cfg(feature = "viewer")]
pub(crate) use sweeptrace::viz::{
    FinishedRecording, LoggerOptions, PrepareOptions, Recording, RecordingError, RecordingTarget,
    Viewer,
};
#[cfg(not(feature = "viewer"))]
pub(crate) use without::{FinishedRecording, Recording, RecordingTarget};

/// The command that installs the build with the Rerun viewer (the default
/// features), from the repository's checkout.
#[cfg(not(feature = "viewer"))]
pub const VIEWER_BUILD: &str = "cargo install --locked --path .";

/// The error of `option`, which needs a Rerun recording, in a build
/// without the viewer: what is missing and how to get it.
#[cfg(not(feature = "viewer"))]
pub fn needs_viewer(option: &str, instead: &str) -> anyhow::Error {
    anyhow::anyhow!(
        "{option} needs the Rerun viewer, and this sweeptrace was built without it \
         (no `viewer` feature).\n  \
         {instead}\n  \
         for Rerun recordings, install the build with the viewer from the repository's \
         checkout (the Rerun SDK makes it a longer build): {VIEWER_BUILD}"
    )
}

/// The recording id of a replay of `trace` for `purpose` (`replay`,
/// `check`) with `options`: a hash of the trace's bytes, the purpose and the
/// options' [stable encoding](ReplayOptions::stable_encoding), so the same
/// trace replayed the same way gets the same id (and the same blueprint).
#[cfg(feature = "viewer")]
pub fn recording_id(
    mut trace: impl std::io::Read,
    purpose: &str,
    options: &ReplayOptions,
) -> std::io::Result<String> {
    let mut hasher = sweeptrace::viz::IdHasher::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = trace.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    for part in [purpose, &options.stable_encoding()] {
        hasher.update(&(part.len() as u64).to_le_bytes());
        hasher.update(part.as_bytes());
    }
    Ok(hasher.finish())
}

/// Opens `replay`'s recording of `trace` to `target`: its id from the
/// trace's bytes and the options, the divergence marks judged with
/// `tolerances` (the engine's declared conventions), the viewer layout
/// unless `blueprint` is false, the camera following ball `follow_ball`.
#[cfg(feature = "viewer")]
pub fn open_replay_recording(
    trace: &Path,
    target: RecordingTarget,
    options: &ReplayOptions,
    tolerances: sweeptrace::judge::Tolerances,
    blueprint: bool,
    follow_ball: u32,
) -> anyhow::Result<Recording> {
    use anyhow::Context as _;
    let file = super::open_trace(trace)?;
    let id = recording_id(std::io::BufReader::new(file), "replay", options)
        .with_context(|| format!("reading {}", trace.display()))?;
    if let Some(path) = &target.file {
        super::warn_unfinished(path);
    }
    let name = trace
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let logger_options = LoggerOptions {
        blueprint,
        prepare: PrepareOptions {
            follow_ball,
            tolerances,
            ..PrepareOptions::default()
        },
        ..LoggerOptions::default()
    };
    Recording::open(&id, &name, target, logger_options).map_err(|e| match e {
        RecordingError::Address { url, reason } => anyhow::anyhow!("--connect `{url}`: {reason}"),
        e => anyhow::Error::new(e),
    })
}

/// In a build without the viewer no recording target is ever made (the
/// options asking for one are refused first), so there is nothing to open.
#[cfg(not(feature = "viewer"))]
pub fn open_replay_recording(
    _trace: &Path,
    target: RecordingTarget,
    _options: &ReplayOptions,
    _tolerances: sweeptrace::judge::Tolerances,
    _blueprint: bool,
    _follow_ball: u32,
) -> anyhow::Result<Recording> {
    match target {}
}

/// Replays the frames `options` select of `trace` (its bytes) into a new
/// recording file `target`, named `name` in the viewer: `check
/// --rrd-on-failure`'s recording of a failing trace.
#[cfg(feature = "viewer")]
pub fn write_check_recording(
    trace: &[u8],
    name: &str,
    title: &str,
    target: &Path,
    options: ReplayOptions,
    tolerances: sweeptrace::judge::Tolerances,
) -> anyhow::Result<()> {
    use super::NameFileOnce as _;
    use anyhow::Context as _;
    use sweeptrace::replay::{ReplayError, ReplayEvent, replay_events};
    use sweeptrace::trace::TraceReader;

    let id = recording_id(trace, "check", &options).with_context(|| format!("reading {name}"))?;
    let mut recording = Recording::open(
        &id,
        title,
        RecordingTarget {
            file: Some(target.to_path_buf()),
            ..RecordingTarget::default()
        },
        LoggerOptions {
            prepare: PrepareOptions {
                tolerances,
                ..PrepareOptions::default()
            },
            ..LoggerOptions::default()
        },
    )?;
    let logger = recording.logger();
    for event in replay_events(
        TraceReader::new_indexed(std::io::Cursor::new(trace), name),
        options,
    ) {
        match event {
            Ok(ReplayEvent::Scene(scene)) => {
                logger.log_scene(&scene).context("logging the scene")?
            }
            Ok(ReplayEvent::Sweep(r)) => logger
                .log_sweep(&r)
                .with_context(|| format!("logging frame {}", r.frame))?,
            // The check already reported read errors; record what was read.
            Err(ReplayError::Trace(_)) => break,
            Err(err) => return Err(err).name_file_once("replaying", name),
        }
    }
    recording.finish(|_, _| {})?.commit()?;
    Ok(())
}

/// In a build without the viewer: the error of `--rrd-on-failure` (which
/// `check` gives before checking anything).
#[cfg(not(feature = "viewer"))]
pub fn write_check_recording(
    _trace: &[u8],
    _name: &str,
    _title: &str,
    _target: &Path,
    _options: ReplayOptions,
    _tolerances: sweeptrace::judge::Tolerances,
) -> anyhow::Result<()> {
    Err(needs_viewer(
        "--rrd-on-failure",
        "the check needs no viewer",
    ))
}

/// The stand-ins of a build without the viewer: types without values (no
/// recording can be opened), whose methods therefore never run.
#[cfg(not(feature = "viewer"))]
mod without {
    use std::path::PathBuf;

    use sweeptrace::replay::NoRecorder;

    /// Where a recording would go: never made in this build.
    pub enum RecordingTarget {}

    /// A recording being written: never opened in this build.
    pub enum Recording {}

    /// A finished recording: never made in this build.
    pub enum FinishedRecording {}

    impl Recording {
        pub fn logger(&mut self) -> &mut NoRecorder {
            match *self {}
        }

        pub fn streams_to_viewer(&self) -> bool {
            match *self {}
        }

        pub fn abandon(self) {
            match self {}
        }

        pub fn finish(self, _progress: impl FnMut(u64, u64)) -> anyhow::Result<FinishedRecording> {
            match self {}
        }
    }

    impl FinishedRecording {
        pub fn commit(self) -> anyhow::Result<Option<PathBuf>> {
            match self {}
        }
    }
}
