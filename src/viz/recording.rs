//! A recording from its opening to its end, in one piece: where it goes (an
//! `.rrd` file, a viewer spawned or connected to, or both), whether its rows
//! wait in a temporary file beside the recording (to a file only: a live
//! viewer would see nothing until the end), and the finish (the last rows,
//! the flush, the file's footer, the file made durable). `replay`,
//! `check --rrd-on-failure` and the replay benchmark all go through it, so
//! the benchmark measures what users run.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rerun::sink::{GrpcSink, LogSink, SinkFlushError};
use thiserror::Error;

use super::rrd_file::{self, RrdFileOptions, RrdFileWriter};
use super::{Logger, LoggerOptions, RecordError, RecordingStreamError, builder};
use crate::atomic::PendingFile;
use crate::error_text::full_text;

/// How long the end of a recording waits for a viewer to take the last
/// messages before saying it cannot be reached.
pub const VIEWER_FLUSH_TIMEOUT: Duration = Duration::from_secs(5);

/// The viewer a recording streams to, besides its file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Viewer {
    /// None: a file only.
    #[default]
    None,
    /// Start a viewer (the `rerun` executable on `PATH`) and stream to it.
    Spawn,
    /// Stream to a viewer already running at this address
    /// (`rerun+http://127.0.0.1:9876/proxy`).
    Connect(String),
}

impl Viewer {
    /// Whether the recording streams to a viewer.
    pub fn is_some(&self) -> bool {
        !matches!(self, Viewer::None)
    }
}

/// Where a recording goes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RecordingTarget {
    /// The `.rrd` file, written under a temporary name beside it and
    /// renamed by [`FinishedRecording::commit`].
    pub file: Option<PathBuf>,
    /// The file's options (its footer).
    pub file_options: RrdFileOptions,
    /// The viewer.
    pub viewer: Viewer,
}

/// Opening, writing or finishing a recording failed. Each message names
/// the recording's file or the viewer.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RecordingError {
    /// The temporary file beside the recording could not be created.
    #[error("creating a temporary file next to {}: {}", target.display(), full_text(.cause))]
    Temporary {
        /// The recording's file.
        target: PathBuf,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// Writing the recording's file failed (also at its finish).
    #[error("writing the recording {}: {reason}", target.display())]
    File {
        /// The recording's file.
        target: PathBuf,
        /// The first error, in words.
        reason: String,
    },
    /// The finished file could not be renamed into place.
    #[error("renaming the finished file to {}: {}", target.display(), full_text(.cause))]
    Renaming {
        /// The recording's file.
        target: PathBuf,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// The viewer could not be started.
    #[error("starting the Rerun viewer (is `rerun` on PATH?): {reason}")]
    Spawn {
        /// The SDK's error, in words.
        reason: String,
    },
    /// The viewer's address is not one.
    #[error("the viewer address `{url}`: {reason}")]
    Address {
        /// The address given.
        url: String,
        /// Why it is not one.
        reason: String,
    },
    /// The recording stream refused to start.
    #[error("{doing}: {}", full_text(.cause))]
    Stream {
        /// "creating the recording", "starting the recording".
        doing: &'static str,
        /// The SDK's error.
        cause: RecordingStreamError,
    },
    /// Logging or spilling rows failed.
    #[error("{doing}: {cause}")]
    Record {
        /// "starting the recording", "logging the last frames".
        doing: &'static str,
        /// What failed.
        cause: RecordError,
    },
    /// The viewer `--spawn` started exited before it listened (as it does
    /// without a display).
    #[error(
        "the Rerun viewer that --spawn started exited ({status}) before it could take the \
         recording, as it does without a display: see its messages above, or write a file \
         with --rrd and open it where there is one"
    )]
    ViewerExited {
        /// How it ended (`exit status 1`, `killed by signal 9`).
        status: String,
    },
    /// The viewer did not take the recording.
    #[error(
        "streaming to the viewer at {at}: {what}; is a Rerun viewer running there? \
         (start one with `rerun`, or write a file with --rrd)"
    )]
    Unreachable {
        /// The viewer's address (for `--spawn`, the one it was started on).
        at: String,
        /// What happened, with how long it was tried.
        what: String,
    },
    /// The stream could not be flushed to the file.
    #[error("flushing the recording: {}", full_text(.cause))]
    Flush {
        /// The SDK's error.
        cause: SinkFlushError,
    },
}

/// A recording being written ([`Recording::open`]); log through
/// [`Recording::logger`], end with [`Recording::finish`] (or
/// [`Recording::abandon`]).
pub struct Recording {
    logger: Logger,
    file: Option<(PendingFile, RrdFileWriter)>,
    viewer: Viewer,
    /// The address of the viewer `--spawn` started.
    spawned_url: Option<String>,
    since: Instant,
}

/// A recording whose file is complete and durable under its temporary name
/// ([`Recording::finish`]); [`FinishedRecording::commit`] renames it into
/// place. Dropped instead, the temporary file is removed.
#[must_use = "the file is removed unless committed"]
pub struct FinishedRecording {
    file: Option<PendingFile>,
}

impl FinishedRecording {
    /// The recording's file, if it has one.
    pub fn target(&self) -> Option<&Path> {
        self.file.as_ref().map(PendingFile::target)
    }

    /// Renames the file into place; returns its path (`None` for a
    /// recording streamed to a viewer only).
    pub fn commit(self) -> Result<Option<PathBuf>, RecordingError> {
        let Some(pending) = self.file else {
            return Ok(None);
        };
        let target = pending.target().to_path_buf();
        match pending.commit() {
            Ok(()) => Ok(Some(target)),
            Err(cause) => Err(RecordingError::Renaming { target, cause }),
        }
    }
}

impl Recording {
    /// Opens the recording `id` (named `name` in the viewer) to `target`,
    /// with the logger's `options` (their `flush_timeout` is
    /// [`VIEWER_FLUSH_TIMEOUT`] when streaming to a viewer). To a file
    /// only, the rows wait in a temporary file beside it
    /// ([`Logger::with_spill`]). A target with neither a file nor a viewer
    /// records into nothing (a recording whose cost alone is wanted).
    pub fn open(
        id: &str,
        name: &str,
        target: RecordingTarget,
        options: LoggerOptions,
    ) -> Result<Recording, RecordingError> {
        let since = Instant::now();
        let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
        let mut file = None;
        let mut spawned_url = None;
        if let Some(path) = &target.file {
            let pending = PendingFile::new(path).map_err(|cause| RecordingError::Temporary {
                target: path.clone(),
                cause,
            })?;
            let (sink, writer) = rrd_file::create_rrd_file(pending.path(), target.file_options)
                .map_err(|e| RecordingError::File {
                    target: path.clone(),
                    reason: e.reason,
                })?;
            sinks.push(Box::new(sink));
            file = Some((pending, writer));
        }
        match &target.viewer {
            Viewer::None => {}
            Viewer::Spawn => {
                let info = rerun::spawn(&rerun::SpawnOptions::default()).map_err(|e| {
                    RecordingError::Spawn {
                        reason: full_text(&e),
                    }
                })?;
                let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
                // Before any stream to it exists (dropping one to a viewer
                // that is gone would wait forever).
                if let Some(pid) = info.child_pid {
                    wait_for_spawned_viewer(pid, info.port, VIEWER_FLUSH_TIMEOUT)?;
                }
                sinks.push(Box::new(GrpcSink::new(parse_address(&url)?)));
                spawned_url = Some(url);
            }
            Viewer::Connect(url) => sinks.push(Box::new(GrpcSink::new(parse_address(url)?))),
        }
        let rec = builder(id, name)
            .set_sinks(sinks)
            .map_err(|cause| RecordingError::Stream {
                doing: "creating the recording",
                cause,
            })?;
        let options = LoggerOptions {
            flush_timeout: target.viewer.is_some().then_some(VIEWER_FLUSH_TIMEOUT),
            ..options
        };
        let mut logger =
            Logger::with_options(rec, options).map_err(|cause| RecordingError::Stream {
                doing: "starting the recording",
                cause,
            })?;
        if let (Some((pending, _)), Viewer::None) = (&file, &target.viewer) {
            let dir = match pending.path().parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => PathBuf::from("."),
            };
            logger = logger.with_spill(&dir, pending.target()).map_err(|cause| {
                RecordingError::Record {
                    doing: "starting the recording",
                    cause,
                }
            })?;
        }
        Ok(Recording {
            logger,
            file,
            viewer: target.viewer,
            spawned_url,
            since,
        })
    }

    /// Whether the recording streams to a viewer.
    pub fn streams_to_viewer(&self) -> bool {
        self.viewer.is_some()
    }

    /// The logger, to log the replay's events.
    pub fn logger(&mut self) -> &mut Logger {
        &mut self.logger
    }

    /// Sends the last rows (`progress(done, total)` as they go out),
    /// flushes the stream (to a viewer within [`VIEWER_FLUSH_TIMEOUT`]),
    /// and finishes the file: its footer written, flushed and synced. The
    /// file keeps its temporary name until [`FinishedRecording::commit`].
    pub fn finish(
        mut self,
        progress: impl FnMut(u64, u64),
    ) -> Result<FinishedRecording, RecordingError> {
        self.logger
            .send_all_with(progress)
            .map_err(|cause| RecordingError::Record {
                doing: "logging the last frames",
                cause,
            })?;
        let rec = self.logger.finish();
        match &self.viewer {
            Viewer::None => rec
                .flush_blocking()
                .map_err(|cause| RecordingError::Flush { cause })?,
            viewer => {
                // A viewer that cannot be reached would make a blocking
                // flush (and dropping the stream) wait forever.
                if let Err(err) = rec.flush_with_timeout(VIEWER_FLUSH_TIMEOUT) {
                    std::mem::forget(rec);
                    let at = match viewer {
                        Viewer::Connect(url) => url.clone(),
                        _ => format!(
                            "{} (started by --spawn)",
                            self.spawned_url.as_deref().unwrap_or("an unknown address")
                        ),
                    };
                    // One figure: how long the stream tried, from its start.
                    let tried = self.since.elapsed().as_secs_f64();
                    let what = match err {
                        SinkFlushError::Timeout => {
                            format!("no viewer took the recording (waited {tried:.0} s in all)")
                        }
                        SinkFlushError::Failed { .. } => {
                            format!("could not connect (tried for {tried:.0} s)")
                        }
                    };
                    return Err(RecordingError::Unreachable { at, what });
                }
            }
        }
        // The file's footer is written once every clone of the stream is
        // dropped.
        drop(rec);
        let file = match self.file {
            Some((pending, writer)) => {
                writer.finish().map_err(|e| RecordingError::File {
                    target: pending.target().to_path_buf(),
                    reason: e.reason,
                })?;
                Some(pending)
            }
            None => None,
        };
        Ok(FinishedRecording { file })
    }

    /// Drops a recording that will not be finished: its file is removed. A
    /// stream to a viewer is leaked instead: dropping it flushes, which
    /// waits forever for a viewer that cannot be reached (the process ends
    /// soon after).
    pub fn abandon(self) {
        if self.viewer.is_some() {
            std::mem::forget(self.logger);
        }
    }
}

/// How often [`wait_for_spawned_viewer`] looks.
const VIEWER_POLL: Duration = Duration::from_millis(50);

/// How long a launcher that exited successfully is given for the viewer it
/// started to listen (a launcher may start the viewer and exit).
const VIEWER_EXIT_GRACE: Duration = Duration::from_millis(1500);

/// Waits, up to `limit`, for the viewer `--spawn` started (process `pid`)
/// to listen on `port`, noticing when it exits first: that is
/// [`RecordingError::ViewerExited`] at once (a failure status) or when it
/// still does not listen [`VIEWER_EXIT_GRACE`] after its exit. A viewer
/// that neither listens nor exits within `limit` is left to the stream's
/// own timeout.
fn wait_for_spawned_viewer(pid: u32, port: u16, limit: Duration) -> Result<(), RecordingError> {
    let address = std::net::SocketAddr::from(([127, 0, 0, 1], port));
    let start = Instant::now();
    let mut exited: Option<(Instant, String)> = None;
    loop {
        if std::net::TcpStream::connect_timeout(&address, VIEWER_POLL).is_ok() {
            return Ok(());
        }
        if exited.is_none()
            && let Some((success, status)) = reap(pid)
        {
            if !success {
                return Err(RecordingError::ViewerExited { status });
            }
            exited = Some((Instant::now(), status));
        }
        if let Some((at, status)) = &exited
            && at.elapsed() >= VIEWER_EXIT_GRACE
        {
            return Err(RecordingError::ViewerExited {
                status: status.clone(),
            });
        }
        if start.elapsed() >= limit {
            return Ok(());
        }
        std::thread::sleep(VIEWER_POLL);
    }
}

/// Whether the child process `pid` has exited, without waiting: whether it
/// succeeded and its status in words (`exit status 1`).
#[cfg(unix)]
fn reap(pid: u32) -> Option<(bool, String)> {
    let pid = libc::pid_t::try_from(pid).ok()?;
    let mut status: libc::c_int = 0;
    // SAFETY: `status` is a valid out pointer; WNOHANG never blocks, and
    // `pid` is a child this process started (the SDK's spawn).
    let reaped = unsafe { libc::waitpid(pid, &mut status, libc::WNOHANG) };
    if reaped != pid {
        return None;
    }
    if libc::WIFEXITED(status) {
        let code = libc::WEXITSTATUS(status);
        Some((code == 0, format!("exit status {code}")))
    } else if libc::WIFSIGNALED(status) {
        Some((
            false,
            format!("killed by signal {}", libc::WTERMSIG(status)),
        ))
    } else {
        Some((false, "ended".to_string()))
    }
}

/// Elsewhere the exit is not looked for: the stream's timeout applies.
#[cfg(not(unix))]
fn reap(_pid: u32) -> Option<(bool, String)> {
    None
}

fn parse_address(url: &str) -> Result<rerun::external::re_uri::ProxyUri, RecordingError> {
    url.parse::<rerun::external::re_uri::ProxyUri>()
        .map_err(|e| RecordingError::Address {
            url: url.to_string(),
            reason: e.to_string(),
        })
}
