//! `sweeptrace replay`: run every sweep of a trace through the core and
//! write the outcomes, a Rerun recording and/or a Foxglove file that
//! explain them.

use super::NameFileOnce;
use std::fs::File;
use std::io::{BufReader, BufWriter, IsTerminal, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::Exit;
use super::viewer::{FinishedRecording, Recording, RecordingTarget};
#[cfg(feature = "viewer")]
use super::viewer::{RrdFileOptions, Viewer};
use sweeptrace::atomic::{self, PendingFile};

use sweeptrace::foxglove::{FoxgloveFile, FoxgloveOptions};
use sweeptrace::judge::Tolerances;
use sweeptrace::numbers::{self, plural};
use sweeptrace::replay::{
    Detail, FrameRange, PipelineOptions, ReplayError, ReplayEvent, ReplayOptions, Selection,
    replay_events_parallel, run_pipeline,
};
use sweeptrace::trace::{DEFAULT_PREFETCH_CHUNK, DEFAULT_PREFETCH_DEPTH, TraceReader, prefetch};

/// The viewer address `--connect` uses when given no URL.
pub const DEFAULT_CONNECT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

/// Arguments of `replay`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace replay traces/record_mini_golf.mcap          # writes ./record_mini_golf.rrd
  sweeptrace replay traces/record_mini_golf.mcap --frames 100..200 --detail candidates --rrd golf.rrd
  sweeptrace replay traces/record_mini_golf.mcap --outcomes - --rrd golf.rrd --ball 0
  sweeptrace replay traces/record_mini_golf.mcap --foxglove golf.foxglove.mcap   # open in Foxglove

To watch in a Rerun viewer, add --spawn (starts `rerun`, which must be on
PATH) or --connect (streams to a viewer already running).

--rrd, --spawn, --connect and a replay that names no output write a Rerun
recording: they need the build with the viewer (the default features). A
build without it (`--no-default-features --features cli`) refuses them with
exit 2 and the command that installs the viewer build; its --outcomes,
--foxglove and --json are the same.

A --frames or --ball filter that selects no sweep is an error naming the
trace's balls and frames, and writes nothing; one that selects part says how
many sweeps it kept. Without --outcomes, --rrd, --foxglove, --spawn or --connect the recording is
written to <trace stem>.rrd in the current directory. The outputs combine:
one replay can write outcomes, a Rerun recording and a Foxglove file. Files
are written under a temporary name next to the target and renamed once
complete: an error (or Ctrl-C, SIGTERM) leaves none of them, only a trace
that ends early (exit 3) keeps what was read before its end, unless that
is no sweep at all (\"0 sweeps read before the end\"): an empty outcome file
or a recording without a sweep would pass for a replay, so none is written.")]
pub struct Args {
    /// The trace (an MCAP file).
    #[arg(value_name = "TRACE")]
    pub trace: PathBuf,
    /// Write one JSON outcome per replayed sweep, in trace order (`-` for
    /// stdout): frame, ball, alpha, kind, triangle, feature, normal, contact.
    #[arg(long, value_name = "FILE")]
    pub outcomes: Option<PathBuf>,
    /// Write the Rerun recording to this `.rrd` file.
    #[arg(long, value_name = "FILE")]
    pub rrd: Option<PathBuf>,
    /// Leave out the `.rrd` file's footer, the index of every chunk that
    /// lets a reader find chunks without reading the whole file
    /// (`--rrd run.rrd --no-rrd-footer`). The index is built in memory
    /// until the end, a few kilobytes per chunk, so with it the memory of a
    /// replay grows slowly with the trace's length (BENCHMARKS.md has the
    /// figures); without it the memory stays bounded, but `rerun rrd
    /// verify` rejects the file.
    #[arg(long)]
    pub no_rrd_footer: bool,
    /// Write the replay as an MCAP file for Foxglove (`--foxglove run.fg.mcap`):
    /// the mesh, balls, sweeps, contacts and normals as 3D scene entities
    /// (`foxglove.SceneUpdate`, frame `world`), the decision per sweep as
    /// `foxglove.Log` on /decisions, α and the decisive test's numbers on
    /// /numbers for the Plot panel (`/numbers{ball==0}.alpha`).
    #[arg(long, value_name = "FILE")]
    pub foxglove: Option<PathBuf>,
    /// Start a Rerun viewer (the `rerun` executable on PATH) and stream to it.
    #[arg(long)]
    pub spawn: bool,
    /// Stream to a running Rerun viewer [default URL: rerun+http://127.0.0.1:9876/proxy].
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = DEFAULT_CONNECT_URL)]
    pub connect: Option<String>,
    /// Only frames A..B (A included, B excluded; also `A..`, `..B`, `A..=B`, `A`).
    #[arg(long, value_name = "A..B")]
    pub frames: Option<FrameRange>,
    /// Only ball N.
    #[arg(long, value_name = "N")]
    pub ball: Option<u32>,
    /// Which tests to log: `primary` (the tests reporting the collision, or
    /// the nearest miss), `candidates` (every test of the triangles the BVH
    /// visited) or `all` (every test of every triangle).
    #[arg(long, default_value = "primary", value_name = "LEVEL")]
    pub detail: Detail,
    /// Whether `--detail` was given on the command line (not its default):
    /// set by [`super::parse`].
    #[arg(skip)]
    pub detail_given: bool,
    /// Where the `[engine]` table comes from (`check`'s files by default).
    #[command(flatten)]
    pub config: super::check_config::ConfigArgs,
    /// The engine's conventions: the reference answers (outcome lines,
    /// recording, tunnels, ghost contacts) are computed under them, as
    /// `check` judges (docs/ENGINES.md). Default: the `[engine]` table of
    /// the `sweeptrace.toml` beside or above the trace, if any.
    #[command(flatten)]
    pub conventions: sweeptrace::conventions::PartialConventions,
    /// Do not embed the default viewer layout (blueprint) in the recording.
    #[arg(long)]
    pub no_blueprint: bool,
    /// Worker threads for the core queries and the logging [default: one
    /// per core]. The outputs do not depend on it.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print the summary as one JSON object on stdout instead of text on
    /// stderr (sweeps, outcomes by kind, verdicts, expectations, fragile
    /// decisions, tunnels, the files written, time), e.g. `--json
    /// --outcomes run.jsonl`. Not with `--outcomes -`, which has stdout. A
    /// replay that fails prints one JSON object with the error.
    #[arg(long)]
    pub json: bool,
}

/// Counts bytes read, for the progress bar.
struct CountingReader<R> {
    inner: R,
    count: Arc<AtomicU64>,
}

/// Seeking (to the summary, and to chunks when a trace is read through
/// its chunk indexes) counts nothing: only bytes read.
impl<R: std::io::Seek> std::io::Seek for CountingReader<R> {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        self.inner.seek(to)
    }
}

impl<R: Read> Read for CountingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
}

/// Runs the replay; with `--json`, a replay that fails still prints one
/// JSON document, with the error (`check --json` gives its report with
/// the errors too), and the error goes to stderr as without `--json`.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let json = args.json.then(|| args.trace.display().to_string());
    let result = run_replay(args);
    if let (Some(trace), Err(err)) = (json, &result) {
        println!("{}", error_json(&trace, err));
    }
    result
}

/// `--json`'s document for a replay that failed: the trace, the status,
/// the exit code and the error's text.
fn error_json(trace: &str, err: &anyhow::Error) -> String {
    let value = serde_json::json!({
        "trace": trace,
        "status": "error",
        "exit_code": Exit::Error.exit_code(),
        "error": format!("{err:#}"),
    });
    serde_json::to_string_pretty(&value)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}

/// The replay: the options in, the outputs opened, the pipeline, the
/// outputs finished, the summary printed.
fn run_replay(args: Args) -> anyhow::Result<Exit> {
    let started = Instant::now();
    let trace_path = &args.trace;
    let file = super::open_trace(trace_path)?;
    let total_bytes = file.metadata().map(|m| m.len()).unwrap_or(0);
    let source_name = trace_path.display().to_string();
    if args.json && args.outcomes.as_deref() == Some(Path::new("-")) {
        bail!("--json and --outcomes - both write to stdout: give --outcomes a file");
    }
    let target = recording_target(&args)?;
    if args.detail_given && target.is_none() && args.foxglove.is_none() {
        eprintln!(
            "warning: --detail only changes what the recording shows, and no recording \
             output was asked for (--rrd, --spawn, --connect or --foxglove give one)"
        );
    }
    // The engine's conventions, as `check` finds them: the reference
    // answers and the divergence marks follow them.
    let settings = super::check_config::for_trace(trace_path, &args.conventions, &args.config)?;
    let conventions = settings.engine.conventions();
    let tolerances = settings.tolerances();
    let options = ReplayOptions {
        frames: args.frames.unwrap_or_default(),
        ball: args.ball,
        // The decision lines of the recording and of the Foxglove file
        // describe the decisive test: keep the records.
        explain: (target.is_some() || args.foxglove.is_some()).then_some(args.detail),
        conventions,
    };
    if let Some(line) = super::check_config::conventions_line(&settings) {
        eprintln!("{line}");
    }
    let mut outputs = Outputs::open(&args, target, &options, tolerances)?;
    if args.threads == Some(0) {
        bail!("--threads must be at least 1");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("starting the worker threads")?;
    let pool = Arc::new(pool);

    let count = Arc::new(AtomicU64::new(0));
    let reader = CountingReader {
        inner: BufReader::with_capacity(1 << 16, file),
        count: count.clone(),
    };
    let progress = progress_bar(total_bytes, "replaying");
    // Decode on a thread of its own, so reading overlaps the core's work.
    let read_ahead = prefetch(
        TraceReader::new_indexed(reader, &source_name),
        DEFAULT_PREFETCH_CHUNK,
        DEFAULT_PREFETCH_DEPTH,
    )
    .context("starting the trace reader thread")?;
    let batch_events = options.batch_events();
    let mut events = replay_events_parallel(read_ahead, options, batch_events, Some(pool.clone()));
    let mut trace_error = None;
    let mut last_frame = None;
    let pipeline = PipelineOptions {
        outcome_lines: outputs.sinks.outcomes.is_some(),
        batch_events,
    };
    let (recording, sinks) = outputs.split();
    let result = run_pipeline(
        &mut events,
        &pool,
        recording.map(Recording::logger),
        pipeline,
        |event, line| -> anyhow::Result<()> {
            progress.set_position(count.load(Ordering::Relaxed));
            match event {
                Ok(event) => {
                    sinks.event(&event, line)?;
                    match &event {
                        ReplayEvent::Scene(scene) => {
                            for d in scene.mesh.degenerate() {
                                progress.suspend(|| {
                                    eprintln!("warning: scene {}: {d}, left out", scene.number)
                                });
                            }
                        }
                        ReplayEvent::Sweep(result) => last_frame = Some(result.frame),
                    }
                }
                // The reader stops here; what was read is still replayed.
                Err(ReplayError::Trace(err)) => trace_error = Some(err),
                Err(err) => match sweeptrace::suite::MarginFault::of(&err) {
                    Some(fault) => anyhow::bail!(super::check_config::margin_fault(
                        &settings,
                        &source_name,
                        &fault
                    )),
                    None => return Err(err).name_file_once("replaying", &source_name),
                },
            }
            Ok(())
        },
    );
    progress.finish_and_clear();
    if let Err(err) = result {
        outputs.abandon();
        return Err(err);
    }
    let summary = events.summary();

    // Nothing is written unless the run completed (or ended at a
    // truncation, whose outputs hold what was read): the pending files are
    // dropped here, which removes them.
    if let Some(err) = trace_error.take_if(|err| !err.is_truncation()) {
        outputs.abandon();
        return Err(err).name_file_once("replaying", &source_name);
    }
    // A trace that ends before its first sweep (a one-chunk trace cut
    // anywhere in its chunk) leaves nothing worth a file: an empty outcome
    // file or a recording without a sweep would pass for a replay.
    if let Some(err) = trace_error.take_if(|_| summary.sweeps == 0) {
        outputs.abandon();
        eprintln!("error: {err:#}\n0 sweeps read before the end: nothing written");
        if args.json {
            println!(
                "{}",
                summary_json(
                    &args,
                    &conventions,
                    &summary,
                    None,
                    &[],
                    Some(&err),
                    started
                )
            );
        }
        return Ok(Exit::IncompleteInput);
    }
    let selection = summary.selection(&options);
    if selection.is_nothing() {
        outputs.abandon();
        bail!("{source_name}: {selection}; nothing written");
    }
    let streamed = outputs.streams_to_viewer();
    let wrote = outputs.finish()?;
    for line in &wrote {
        eprintln!("{line}");
    }
    if streamed {
        eprintln!("streamed the recording to the viewer");
    }
    if !args.json {
        eprint!("{}", summary.render_timed(Some(started.elapsed())));
    }
    if let Selection::Part { .. } = selection {
        eprintln!("{selection}");
    }
    if let Some(err) = &trace_error {
        eprintln!(
            "error: {err:#}\n{} read before the end{}: the outputs hold them",
            numbers::counted(summary.sweeps, "sweep", "sweeps"),
            last_frame.map_or(String::new(), |f| format!(" (up to frame {f})"))
        );
    }
    if args.json {
        let selected = matches!(selection, Selection::Part { .. }).then(|| selection.to_string());
        println!(
            "{}",
            summary_json(
                &args,
                &conventions,
                &summary,
                selected,
                &wrote,
                trace_error.as_deref(),
                started
            )
        );
    }
    Ok(if trace_error.is_some() {
        Exit::IncompleteInput
    } else {
        Exit::Success
    })
}

/// `--json`'s summary: one object, the counts of [`ReplaySummary`]
/// (`sweeptrace::replay`) by name, the engine conventions the answers
/// were computed under (every key; the rules' values when none is
/// declared), the files written (each "wrote" line),
/// the selection of a filter that kept part of the trace, and `incomplete`
/// (the error of a trace that ends early, or `null`).
fn summary_json(
    args: &Args,
    conventions: &sweeptrace::conventions::EngineConventions,
    summary: &sweeptrace::replay::ReplaySummary,
    selection: Option<String>,
    wrote: &[String],
    truncation: Option<&sweeptrace::trace::TraceError>,
    started: Instant,
) -> String {
    use serde_json::{Map, Value, json};
    let counts = |pairs: Vec<(String, u64)>| -> Value {
        Value::Object(
            pairs
                .into_iter()
                .map(|(k, n)| (k, json!(n)))
                .collect::<Map<_, _>>(),
        )
    };
    let kinds = [
        sweeptrace::Kind::Face,
        sweeptrace::Kind::Edge,
        sweeptrace::Kind::Vertex,
        sweeptrace::Kind::None,
    ];
    let value = json!({
        "trace": args.trace.display().to_string(),
        "conventions": conventions,
        "sweeps": summary.sweeps,
        "filtered_out": summary.filtered_out,
        "selection": selection,
        "scenes": summary.scenes,
        "collisions": summary.collisions(),
        "outcomes": counts(kinds.iter().map(|k| (k.to_string(), summary.outcomes.get(k).copied().unwrap_or(0))).collect()),
        "verdicts": counts(summary.verdicts.iter().map(|(v, n)| (v.as_str().to_string(), n)).collect()),
        "skipped": counts(summary.skipped.iter().map(|(r, n)| (r.as_str().to_string(), n)).collect()),
        "expected": {
            "attached": summary.expected_matched,
            "unmatched": summary.expected_unmatched,
        },
        "fragile": {
            "count": summary.fragile,
            "by_reason": counts(summary.fragile_by_reason.iter().map(|(r, n)| (r.as_str().to_string(), *n)).collect()),
        },
        "tunnels": {
            "count": summary.tunnel_count(),
            "by_kind": counts(summary.tunnels.iter().map(|(k, n)| (k.to_string(), *n)).collect()),
            "first": summary.first_tunnels.iter().map(|t| json!({
                "frame": t.frame,
                "ball": t.ball,
                "text": t.to_string(),
            })).collect::<Vec<_>>(),
        },
        "degenerate_triangles": summary.degenerate_triangles,
        "wrote": wrote,
        "incomplete": truncation.map(|e| format!("{e:#}")),
        "seconds": {
            "total": started.elapsed().as_secs_f64(),
            "core": summary.elapsed.as_secs_f64(),
        },
    });
    serde_json::to_string_pretty(&value)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}

/// Where the recording goes, if anywhere: `--rrd`, `--spawn`,
/// `--connect`; with no output named at all, `<trace stem>.rrd`.
#[cfg(feature = "viewer")]
fn recording_target(args: &Args) -> anyhow::Result<Option<RecordingTarget>> {
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
fn recording_target(args: &Args) -> anyhow::Result<Option<RecordingTarget>> {
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
        Some(option) => Err(super::viewer::needs_viewer(option, instead)),
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
enum OutcomeSink {
    Stdout(BufWriter<std::io::Stdout>),
    /// The file, its pending name, and the bytes written since the
    /// kernel was last asked to start writing them out.
    File(BufWriter<File>, PendingFile, u64),
}

/// The outputs besides the recording, which take each event in trace
/// order: the outcome lines and the Foxglove file.
struct Sinks {
    outcomes: Option<OutcomeSink>,
    /// "writing the outcomes to FILE", for the errors.
    writing_outcomes: String,
    foxglove: Option<FoxgloveFile>,
}

impl Sinks {
    fn event(&mut self, event: &ReplayEvent, line: Option<String>) -> anyhow::Result<()> {
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
struct Outputs {
    recording: Option<Recording>,
    sinks: Sinks,
    foxglove_target: Option<PathBuf>,
}

impl Outputs {
    /// Opens the recording (when `target` asks for one), the outcomes and
    /// the Foxglove file.
    fn open(
        args: &Args,
        target: Option<RecordingTarget>,
        options: &ReplayOptions,
        tolerances: Tolerances,
    ) -> anyhow::Result<Outputs> {
        let trace_path = &args.trace;
        let recording = match target {
            None => None,
            Some(target) => Some(super::viewer::open_replay_recording(
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
                super::warn_unfinished(p);
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
                super::warn_unfinished(p);
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
        })
    }

    /// The recording and the other outputs, apart, for the pipeline.
    fn split(&mut self) -> (Option<&mut Recording>, &mut Sinks) {
        (self.recording.as_mut(), &mut self.sinks)
    }

    fn streams_to_viewer(&self) -> bool {
        self.recording
            .as_ref()
            .is_some_and(Recording::streams_to_viewer)
    }

    /// Drops every output unfinished: their temporary files are removed.
    fn abandon(self) {
        if let Some(r) = self.recording {
            r.abandon();
        }
    }

    /// Finishes every output, then renames them into place (so that an
    /// error finishing one leaves none of them); returns what it wrote, a
    /// line each.
    fn finish(self) -> anyhow::Result<Vec<String>> {
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

/// A progress bar on stderr (hidden when stderr is not a terminal): `what`,
/// then the bar, bytes and time left.
fn progress_bar(total_bytes: u64, what: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(total_bytes), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(&format!(
        "{{spinner}} {what} [{{bar:40}}] {{bytes}}/{{total_bytes}} ({{eta}})"
    )) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}
