//! Where a replay writes: the recording's target (`--rrd`, `--spawn`,
//! `--connect`, or `<trace stem>.rrd`), the outcome lines and the Foxglove
//! file, from their opening to their finish.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use anyhow::Context;

use super::Args;
use super::progress::{progress_bar, read_with_progress};
use crate::cli::viewer::{FinishedRecording, Recording, RecordingTarget};
#[cfg(feature = "viewer")]
use crate::cli::viewer::{RrdFileOptions, Viewer};
use sweeptrace::atomic::{self, PendingFile};
use sweeptrace::foxglove::{FoxgloveFile, FoxgloveOptions};
use sweeptrace::judge::Tolerances;
use sweeptrace::judge::contact_marks::ContactsDrawn;
use sweeptrace::numbers::plural;
use sweeptrace::replay::{ReplayEvent, ReplayOptions};

/// Where the recording goes, if anywhere: `--rrd`, `--spawn`,
/// `--connect`; with no output named at all, `<trace stem>.rrd`.
#[cfg(feature = "viewer")]
pub(super) fn recording_target(args: &Args) -> anyhow::Result<Option<RecordingTarget>> {
    let viewer = match (&args.connect, args.spawn) {
        (Some(url), _) => Viewer::Connect(url.clone()),
        (None, true) => Viewer::Spawn,
        (None, false) => Viewer::None,
    };
    let file = match (&args.rrd, names_no_output(args)) {
        (Some(p), _) => Some(p.clone()),
        (None, true) => {
            let stem = args
                .trace
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or("replay".into());
            Some(PathBuf::from(format!("{stem}.rrd")))
        }
        (None, false) => None,
    };
    Ok(
        (file.is_some() || viewer.is_some()).then_some(RecordingTarget {
            file,
            file_options: RrdFileOptions {
                footer: !args.no_rrd_footer,
            },
            viewer,
        }),
    )
}

/// In a build without the viewer: the error of the first option that asks
/// for a recording (a replay that names no output asks for `<trace
/// stem>.rrd`); otherwise no recording.
#[cfg(not(feature = "viewer"))]
pub(super) fn recording_target(args: &Args) -> anyhow::Result<Option<RecordingTarget>> {
    let instead = "its outcomes and explanations need no viewer: \
                   --outcomes FILE (or -), --foxglove FILE (for Foxglove), --json";
    let asked = if args.rrd.is_some() {
        Some("--rrd")
    } else if args.spawn {
        Some("--spawn")
    } else if args.connect.is_some() {
        Some("--connect")
    } else if names_no_output(args) {
        Some("a replay without --outcomes or --foxglove (it writes <trace stem>.rrd)")
    } else {
        None
    };
    match asked {
        Some(option) => Err(crate::cli::viewer::needs_viewer(option, instead)),
        None => Ok(None),
    }
}

/// Whether the command line names no output at all (then the recording
/// goes to `<trace stem>.rrd`).
fn names_no_output(args: &Args) -> bool {
    args.outcomes.is_none()
        && args.rrd.is_none()
        && args.foxglove.is_none()
        && !args.spawn
        && args.connect.is_none()
}

/// Where the outcomes go.
pub(super) enum OutcomeSink {
    Stdout(BufWriter<std::io::Stdout>),
    /// The file, its pending name, and the bytes written since the
    /// kernel was last asked to start writing them out.
    File(BufWriter<File>, PendingFile, u64),
}

/// The outputs besides the recording, which take each event in trace
/// order: the outcome lines and the Foxglove file.
pub(super) struct Sinks {
    pub(super) outcomes: Option<OutcomeSink>,
    /// "writing the outcomes to FILE", for the errors.
    writing_outcomes: String,
    foxglove: Option<FoxgloveFile>,
}

impl Sinks {
    pub(super) fn event(
        &mut self,
        event: &ReplayEvent,
        line: Option<String>,
    ) -> anyhow::Result<()> {
        if let Some(file) = self.foxglove.as_mut() {
            file.writer().event(event)?;
        }
        if let (Some(o), ReplayEvent::Sweep(result)) = (self.outcomes.as_mut(), event) {
            let line = match line {
                Some(line) => line,
                None => result.outcome_line().context("serializing an outcome")?,
            };
            let w: &mut dyn Write = match o {
                OutcomeSink::Stdout(w) => w,
                OutcomeSink::File(w, _, unsynced) => {
                    // The data goes to the disk as it is written, so that
                    // the sync at the end has little left to wait for.
                    *unsynced += line.len() as u64 + 1;
                    if *unsynced >= atomic::WRITEBACK_BYTES {
                        atomic::start_writeback(w.get_ref());
                        *unsynced = 0;
                    }
                    w
                }
            };
            writeln!(w, "{line}").with_context(|| self.writing_outcomes.clone())?;
        }
        Ok(())
    }
}

/// Every output of one replay, from their opening to their finish.
pub(super) struct Outputs {
    recording: Option<Recording>,
    pub(super) sinks: Sinks,
    foxglove_target: Option<PathBuf>,
    /// The replay's options and tolerances, for the contacts drawn.
    options: ReplayOptions,
    tolerances: Tolerances,
}

impl Outputs {
    /// Opens the recording (when `target` asks for one), the outcomes and
    /// the Foxglove file.
    pub(super) fn open(
        args: &Args,
        target: Option<RecordingTarget>,
        options: &ReplayOptions,
        tolerances: Tolerances,
    ) -> anyhow::Result<Outputs> {
        let trace_path = &args.trace;
        let recording = match target {
            None => None,
            Some(target) => Some(crate::cli::viewer::open_replay_recording(
                trace_path,
                target,
                options,
                tolerances,
                !args.no_blueprint,
                args.ball.unwrap_or(0),
            )?),
        };
        let writing_outcomes = match &args.outcomes {
            Some(p) if p.as_os_str() != "-" => format!("writing the outcomes to {}", p.display()),
            _ => "writing the outcomes to stdout".to_string(),
        };
        let outcomes = match &args.outcomes {
            None => None,
            Some(p) if p.as_os_str() == "-" => {
                Some(OutcomeSink::Stdout(BufWriter::new(std::io::stdout())))
            }
            Some(p) => {
                crate::cli::warn_unfinished(p);
                let (pending, f) = PendingFile::create(p).with_context(|| {
                    format!("creating a temporary file next to {}", p.display())
                })?;
                Some(OutcomeSink::File(
                    BufWriter::with_capacity(1 << 20, f),
                    pending,
                    0,
                ))
            }
        };
        let foxglove = match &args.foxglove {
            None => None,
            Some(p) => {
                crate::cli::warn_unfinished(p);
                let options = FoxgloveOptions {
                    trace_name: trace_path
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default(),
                    tolerances,
                };
                Some(FoxgloveFile::create(p, options)?)
            }
        };
        Ok(Outputs {
            recording,
            sinks: Sinks {
                outcomes,
                writing_outcomes,
                foxglove,
            },
            foxglove_target: args.foxglove.clone(),
            options: *options,
            tolerances,
        })
    }

    /// Draws the trace's `queries` contact queries into the recording and
    /// the Foxglove file (those there are, when they are some), judged as
    /// `check` judges them, at their frames: a second read of the trace,
    /// one for both. Returns what was drawn (none without such an output).
    pub(super) fn draw_contacts(
        &mut self,
        trace_path: &Path,
        source_name: &str,
        queries: u64,
        pool: &rayon::ThreadPool,
    ) -> anyhow::Result<Option<ContactsDrawn>> {
        if queries == 0 {
            return Ok(None);
        }
        let (options, tolerances) = (self.options, self.tolerances);
        let how = sweeptrace::judge::contact_marks::ContactDrawing {
            tolerances: &tolerances,
            conventions: &options.conventions,
            ghost_degrees: sweeptrace::replay::ghost::GHOST_DEGREES,
            frames: options.frames,
            ball: options.ball,
            pool: Some(pool),
        };
        // Decoded on a thread of its own while the queries are judged, in
        // log-time order as the replay read it (through the chunk indexes
        // when the trace has them: a recorder's chunks may overlap in
        // time), with a progress bar.
        let read_again = |what: &str| -> anyhow::Result<_> {
            let file = std::fs::File::open(trace_path)
                .with_context(|| format!("reading {source_name} again for its contacts"))?;
            let total = file.metadata().map_or(0, |m| m.len());
            let (events, bar, count) = read_with_progress(file, total, source_name, what)?;
            let mut seen = 0u32;
            let moving = bar.clone();
            let events = events.inspect(move |_| {
                seen = seen.wrapping_add(1);
                if seen.is_multiple_of(1024) {
                    moving.set_position(count.load(Ordering::Relaxed));
                }
            });
            Ok((events, bar))
        };
        let foxglove = self.sinks.foxglove.as_mut();
        // With a recording, its drawing writes the Foxglove file's too: the
        // trace is read and the queries judged once for both.
        #[cfg(feature = "viewer")]
        if let Some(recording) = self.recording.as_mut() {
            let with_file = foxglove.is_some();
            let (events, bar) = read_again(if with_file {
                "drawing and writing the contact queries"
            } else {
                "drawing the contact queries"
            })?;
            let drawn = sweeptrace::viz::draw_contacts(
                recording.logger(),
                foxglove.map(|file| file.writer()),
                events,
                &how,
            );
            bar.finish_and_clear();
            let drawn = drawn?;
            eprintln!("contacts: {}", drawn_words(&drawn));
            if with_file {
                eprintln!("contacts in the Foxglove file: {}", drawn_words(&drawn));
            }
            return Ok(Some(drawn));
        }
        let Some(file) = foxglove else {
            return Ok(None);
        };
        let (events, bar) = read_again("writing the contact queries")?;
        let drawn = file
            .writer()
            .contact_queries(events, &how)
            .context("writing the contact queries to the Foxglove file");
        bar.finish_and_clear();
        let drawn = drawn?;
        eprintln!("contacts in the Foxglove file: {}", drawn_words(&drawn));
        Ok(Some(drawn))
    }

    /// The recording and the other outputs, apart, for the pipeline.
    pub(super) fn split(&mut self) -> (Option<&mut Recording>, &mut Sinks) {
        (self.recording.as_mut(), &mut self.sinks)
    }

    pub(super) fn streams_to_viewer(&self) -> bool {
        self.recording
            .as_ref()
            .is_some_and(Recording::streams_to_viewer)
    }

    /// Drops every output unfinished: their temporary files are removed.
    pub(super) fn abandon(self) {
        if let Some(r) = self.recording {
            r.abandon();
        }
    }

    /// Finishes every output, then renames them into place (so that an
    /// error finishing one leaves none of them); returns what it wrote, a
    /// line each.
    pub(super) fn finish(self) -> anyhow::Result<Vec<String>> {
        let recording = match self.recording {
            Some(r) => {
                let writing = progress_bar(0, "writing the recording");
                let done = r.finish(|done, total| {
                    writing.set_length(total);
                    writing.set_position(done);
                });
                writing.finish_and_clear();
                Some(done?)
            }
            None => None,
        };
        let Sinks {
            outcomes,
            writing_outcomes,
            foxglove,
        } = self.sinks;
        let outcomes = match outcomes {
            Some(OutcomeSink::Stdout(mut w)) => {
                w.flush().context(writing_outcomes.clone())?;
                None
            }
            Some(OutcomeSink::File(w, pending, _)) => {
                pending
                    .seal(w)
                    .map_err(|e| anyhow::Error::new(e.cause))
                    .context(writing_outcomes.clone())?;
                Some(pending)
            }
            None => None,
        };
        let mut wrote = Vec::new();
        if let Some(file) = foxglove {
            let target = self.foxglove_target.as_deref().unwrap_or(Path::new(""));
            let counts = file.commit()?;
            wrote.push(format!(
                "wrote the Foxglove file {} ({} {}, {} {}, {} {})",
                target.display(),
                counts.scenes,
                plural(counts.scenes, "scene"),
                counts.sweeps,
                plural(counts.sweeps, "sweep"),
                counts.messages,
                plural(counts.messages, "message"),
            ));
        }
        if let Some(path) = recording
            .map(FinishedRecording::commit)
            .transpose()?
            .flatten()
        {
            wrote.push(format!("wrote the recording to {}", path.display()));
        }
        if let Some(pending) = outcomes {
            let target = pending.target().to_path_buf();
            pending
                .commit()
                .with_context(|| format!("renaming the finished file to {}", target.display()))?;
            wrote.push(format!("wrote the outcomes to {}", target.display()));
        }
        Ok(wrote)
    }
}

/// What was drawn of the contact queries, in words.
fn drawn_words(drawn: &ContactsDrawn) -> String {
    format!(
        "{} drawn ({} contacts, {} diverging from the core's, {})",
        sweeptrace::numbers::counted(drawn.queries, "query", "queries"),
        drawn.contacts,
        drawn.divergent,
        sweeptrace::numbers::counted(drawn.ghosts, "ghost contact", "ghost contacts")
    )
}
