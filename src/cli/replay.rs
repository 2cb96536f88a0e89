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

use sweeptrace::atomic::PendingFile;
use sweeptrace::core::Facing;
use sweeptrace::foxglove::{FoxgloveFile, FoxgloveOptions};
use sweeptrace::numbers::{self, Rule, plural};
use sweeptrace::regress::Tolerances;
use sweeptrace::replay::{
    Detail, FrameRange, ReplayError, ReplayEvent, ReplayOptions, Selection, replay_events_parallel,
};
use sweeptrace::run::RunOutcome;
use sweeptrace::trace::TraceReader;
use sweeptrace::trace::prefetch::{self, prefetch};
use sweeptrace::viz;
use sweeptrace::viz::pipeline::{PipelineOptions, run_pipeline};

/// How long the end of a replay waits for a viewer (`--spawn`, `--connect`)
/// to take the last messages before saying it cannot be reached.
const VIEWER_FLUSH_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

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

A --frames or --ball filter that selects no sweep is an error naming the
trace's balls and frames, and writes nothing; one that selects part says how
many sweeps it kept. Without --outcomes, --rrd, --foxglove, --spawn or --connect the recording is
written to <trace stem>.rrd in the current directory. The outputs combine:
one replay can write outcomes, a Rerun recording and a Foxglove file. Files
are written under a temporary name next to the target and renamed once
complete: an error (or Ctrl-C, SIGTERM) leaves none of them, only a trace
that ends early (exit 3) keeps what was read before its end.")]
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
    /// Override every scene's margin ε (tests use ρ = r - ε).
    #[arg(long, value_name = "EPSILON")]
    pub margin: Option<f64>,
    /// Override every scene's facing rule: `non_strict` (n·d ≤ 0) or `strict` (n·d < 0).
    #[arg(long, value_name = "RULE")]
    pub facing: Option<Facing>,
    /// Do not embed the default viewer layout (blueprint) in the recording.
    #[arg(long)]
    pub no_blueprint: bool,
    /// Worker threads for the core queries and the logging [default: one
    /// per core]. The outputs do not depend on it.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
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

/// A temporary file next to `target`, with the error naming where.
fn pending_file(target: &Path) -> anyhow::Result<PendingFile> {
    super::warn_unfinished(target);
    PendingFile::new(target)
        .with_context(|| format!("creating a temporary file next to {}", target.display()))
}

/// Renames a finished file into place, with the error naming where.
fn complete(pending: PendingFile) -> anyhow::Result<()> {
    let target = pending.target().to_path_buf();
    pending
        .commit()
        .with_context(|| format!("renaming the finished file to {}", target.display()))
}

/// Where the outcomes go.
enum OutcomeSink {
    Stdout(BufWriter<std::io::Stdout>),
    File(BufWriter<File>, PendingFile),
}

impl OutcomeSink {
    fn writer(&mut self) -> &mut dyn Write {
        match self {
            OutcomeSink::Stdout(w) => w,
            OutcomeSink::File(w, _) => w,
        }
    }
}

/// Runs the replay.
pub fn run(args: Args) -> anyhow::Result<RunOutcome> {
    let started = Instant::now();
    let trace_path = &args.trace;
    let file =
        File::open(trace_path).with_context(|| format!("opening {}", trace_path.display()))?;
    let total_bytes = file.metadata().map(|m| m.len()).unwrap_or(0);
    let source_name = trace_path.display().to_string();

    let no_output = args.outcomes.is_none()
        && args.rrd.is_none()
        && args.foxglove.is_none()
        && !args.spawn
        && args.connect.is_none();
    let rrd_path = match (&args.rrd, no_output) {
        (Some(p), _) => Some(p.clone()),
        (None, true) => {
            let stem = trace_path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or("replay".into());
            Some(PathBuf::from(format!("{stem}.rrd")))
        }
        (None, false) => None,
    };
    let record = rrd_path.is_some() || args.spawn || args.connect.is_some();
    if let Some(m) = args.margin {
        numbers::check(m, Rule::NonNegative).map_err(|e| anyhow::anyhow!("--margin {e}"))?;
    }

    let options = ReplayOptions {
        frames: args.frames.unwrap_or_default(),
        ball: args.ball,
        detail: args.detail,
        // The decision lines of the recording and of the Foxglove file
        // describe the decisive test: keep the records.
        explain: record || args.foxglove.is_some(),
        margin: args.margin,
        facing: args.facing,
    };

    // The recording.
    let mut rrd_file = None;
    let mut logger = None;
    let mut viewer_since = None;
    if record {
        let trace =
            File::open(trace_path).with_context(|| format!("opening {}", trace_path.display()))?;
        let id = super::recording_id(BufReader::new(trace), "replay", &options)
            .with_context(|| format!("reading {}", trace_path.display()))?;
        let mut sinks: Vec<Box<dyn rerun::sink::LogSink>> = Vec::new();
        if let Some(path) = &rrd_path {
            let pending = pending_file(path)?;
            let file_options = viz::rrd_file::RrdFileOptions {
                footer: !args.no_rrd_footer,
            };
            let (sink, writer) =
                viz::rrd_file::create(pending.path(), file_options).map_err(|e| {
                    anyhow::anyhow!("writing the recording {}: {}", path.display(), e.reason)
                })?;
            sinks.push(Box::new(sink));
            rrd_file = Some((pending, writer));
        }
        if args.spawn || args.connect.is_some() {
            viewer_since = Some(Instant::now());
        }
        if args.spawn {
            let info = rerun::spawn(&rerun::SpawnOptions::default())
                .context("starting the Rerun viewer (is `rerun` on PATH?)")?;
            let uri = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
            sinks.push(Box::new(rerun::sink::GrpcSink::new(
                uri.parse().context("viewer address")?,
            )));
        }
        if let Some(url) = &args.connect {
            let uri = url
                .parse()
                .map_err(|e| anyhow::anyhow!("--connect `{url}`: {e}"))?;
            sinks.push(Box::new(rerun::sink::GrpcSink::new(uri)));
        }
        let name = trace_path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let rec = viz::builder(&id, &name)
            .set_sinks(sinks)
            .context("creating the recording")?;
        let logger_options = viz::LoggerOptions {
            blueprint: !args.no_blueprint,
            prepare: viz::PrepareOptions {
                follow_ball: args.ball.unwrap_or(0),
                ..viz::PrepareOptions::default()
            },
            flush_timeout: (args.spawn || args.connect.is_some()).then_some(VIEWER_FLUSH_TIMEOUT),
        };
        let mut l =
            viz::Logger::with_options(rec, logger_options).context("starting the recording")?;
        // To a file only: the rows wait in a temporary file beside it and
        // go out at the end in long chunks (a live viewer would see nothing
        // until then).
        if let Some((pending, _)) = &rrd_file
            && !args.spawn
            && args.connect.is_none()
        {
            let dir = match pending.path().parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => std::path::PathBuf::from("."),
            };
            l = l
                .with_spill(&dir, pending.target())
                .context("starting the recording")?;
        }
        logger = Some(l);
    }

    // The outcomes.
    let writing_outcomes = match &args.outcomes {
        Some(p) if p.as_os_str() != "-" => format!("writing the outcomes to {}", p.display()),
        _ => "writing the outcomes to stdout".to_string(),
    };
    let mut outcomes = match &args.outcomes {
        None => None,
        Some(p) if p.as_os_str() == "-" => {
            Some(OutcomeSink::Stdout(BufWriter::new(std::io::stdout())))
        }
        Some(p) => {
            super::warn_unfinished(p);
            let (pending, f) = PendingFile::create(p)
                .with_context(|| format!("creating a temporary file next to {}", p.display()))?;
            Some(OutcomeSink::File(BufWriter::new(f), pending))
        }
    };

    // The Foxglove file.
    let mut foxglove = match &args.foxglove {
        None => None,
        Some(p) => {
            super::warn_unfinished(p);
            let options = FoxgloveOptions {
                trace_name: trace_path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                tolerances: Tolerances::default(),
            };
            Some(FoxgloveFile::create(p, options)?)
        }
    };

    if args.threads == Some(0) {
        bail!("--threads must be at least 1");
    }
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(args.threads.unwrap_or(0))
            .build()
            .context("starting the worker threads")?,
    );

    let count = Arc::new(AtomicU64::new(0));
    let reader = CountingReader {
        inner: BufReader::with_capacity(1 << 16, file),
        count: count.clone(),
    };
    let progress = progress_bar(total_bytes, "replaying");
    // Decode on a thread of its own, so reading overlaps the core's work.
    let read_ahead = prefetch(
        TraceReader::new_indexed(reader, &source_name),
        prefetch::DEFAULT_CHUNK,
        prefetch::DEFAULT_DEPTH,
    )
    .context("starting the trace reader thread")?;
    let mut events = replay_events_parallel(
        read_ahead,
        options,
        options.detail.batch_events(),
        Some(pool.clone()),
    );
    let mut trace_error = None;
    let mut last_frame = None;
    let pipeline = PipelineOptions {
        outcome_lines: outcomes.is_some(),
        batch_events: options.detail.batch_events(),
    };
    let result = run_pipeline(
        &mut events,
        &pool,
        logger.as_mut(),
        pipeline,
        |event, line| -> anyhow::Result<()> {
            progress.set_position(count.load(Ordering::Relaxed));
            if let (Some(file), Ok(event)) = (foxglove.as_mut(), &event) {
                file.writer().event(event)?;
            }
            match event {
                Ok(ReplayEvent::Scene(scene)) => {
                    for d in scene.mesh.degenerate() {
                        progress.suspend(|| {
                            eprintln!("warning: scene {}: {d}, left out", scene.number)
                        });
                    }
                }
                Ok(ReplayEvent::Sweep(result)) => {
                    last_frame = Some(result.frame);
                    if let Some(o) = outcomes.as_mut() {
                        let line = match line {
                            Some(line) => line,
                            None => result.outcome_line().context("serializing an outcome")?,
                        };
                        writeln!(o.writer(), "{line}").with_context(|| writing_outcomes.clone())?;
                    }
                }
                Err(ReplayError::Trace(err)) => {
                    // The reader stops here; what was read is still replayed.
                    trace_error = Some(err);
                }
                Err(err) => {
                    return Err(err).name_file_once("replaying", &source_name);
                }
            }
            Ok(())
        },
    );
    if let Err(err) = result {
        progress.finish_and_clear();
        abandon(logger, args.spawn || args.connect.is_some());
        return Err(err);
    }
    progress.finish_and_clear();
    let summary = events.summary();

    // Nothing is written unless the run completed (or ended at a
    // truncation, whose outputs hold what was read): the pending files are
    // dropped here, which removes them.
    if let Some(err) = trace_error.take_if(|err| !err.is_truncation()) {
        abandon(logger, args.spawn || args.connect.is_some());
        return Err(err).name_file_once("replaying", &source_name);
    }
    let selection = summary.selection(&options);
    if selection.is_nothing() {
        abandon(logger, args.spawn || args.connect.is_some());
        bail!("{source_name}: {selection}; nothing written");
    }

    // Finish the files: the recording's footer is written when the last
    // clone of the stream is dropped.
    if let Some(mut l) = logger {
        let writing = progress_bar(0, "writing the recording");
        l.send_all_with(|done, total| {
            writing.set_length(total);
            writing.set_position(done);
        })
        .context("logging the last frames")?;
        writing.finish_and_clear();
        let rec = l.finish();
        if args.spawn || args.connect.is_some() {
            // A viewer that cannot be reached would make a blocking flush
            // (and dropping the stream) wait forever.
            if let Err(err) = rec.flush_with_timeout(VIEWER_FLUSH_TIMEOUT) {
                std::mem::forget(rec);
                let at = args.connect.as_deref().unwrap_or("the spawned viewer");
                // One figure: how long the stream tried, from its start.
                let tried = viewer_since.map_or(0.0, |t| t.elapsed().as_secs_f64());
                let what = match err {
                    rerun::sink::SinkFlushError::Timeout => {
                        format!("no viewer took the recording (waited {tried:.0} s in all)")
                    }
                    rerun::sink::SinkFlushError::Failed { .. } => {
                        format!("could not connect (tried for {tried:.0} s)")
                    }
                };
                bail!(
                    "streaming to the viewer at {at}: {what}; is a Rerun viewer running there? \
                     (start one with `rerun`, or write a file with --rrd)"
                );
            }
        } else {
            rec.flush_blocking().context("flushing the recording")?;
        }
        drop(rec);
    }
    // Every file finished before any is renamed into place, so that an
    // error finishing one leaves none of them.
    let rrd_done = match rrd_file {
        Some((pending, writer)) => {
            let target = pending.target().to_path_buf();
            writer.finish().map_err(|e| {
                anyhow::anyhow!("writing the recording {}: {}", target.display(), e.reason)
            })?;
            Some(pending)
        }
        None => None,
    };
    let outcomes_done = match outcomes {
        Some(OutcomeSink::Stdout(mut w)) => {
            w.flush().context(writing_outcomes.clone())?;
            None
        }
        Some(OutcomeSink::File(mut w, pending)) => {
            w.flush().context(writing_outcomes.clone())?;
            let file = w
                .into_inner()
                .map_err(|e| e.into_error())
                .context(writing_outcomes.clone())?;
            sweeptrace::atomic::sync(&file).context(writing_outcomes.clone())?;
            Some(pending)
        }
        None => None,
    };
    let mut wrote = Vec::new();
    if let Some(file) = foxglove {
        let target = args.foxglove.as_deref().unwrap_or(Path::new("")).display();
        let counts = file.commit()?;
        wrote.push(format!(
            "wrote the Foxglove file {target} ({} {}, {} {}, {} {})",
            counts.scenes,
            plural(counts.scenes, "scene"),
            counts.sweeps,
            plural(counts.sweeps, "sweep"),
            counts.messages,
            plural(counts.messages, "message"),
        ));
    }
    if let Some(pending) = rrd_done {
        let target = pending.target().to_path_buf();
        complete(pending)?;
        wrote.push(format!("wrote the recording to {}", target.display()));
    }
    if let Some(pending) = outcomes_done {
        let target = pending.target().to_path_buf();
        complete(pending)?;
        wrote.push(format!("wrote the outcomes to {}", target.display()));
    }
    for line in wrote {
        eprintln!("{line}");
    }
    if args.spawn || args.connect.is_some() {
        eprintln!("streamed the recording to the viewer");
    }
    eprint!("{}", summary.render_timed(Some(started.elapsed())));
    if let Selection::Part { .. } = selection {
        eprintln!("{selection}");
    }
    if let Some(err) = trace_error {
        eprintln!(
            "error: {err:#}\nthe outputs hold the {} read before it{}",
            numbers::counted(summary.sweeps, "sweep", "sweeps"),
            last_frame.map_or(String::new(), |f| format!(" (up to frame {f})"))
        );
        return Ok(RunOutcome::IncompleteInput);
    }
    Ok(RunOutcome::Success)
}

/// Drops a recording that will not be finished. A stream to a viewer is
/// leaked instead: dropping it flushes, which waits forever for a viewer
/// that cannot be reached (the process ends soon after).
fn abandon(logger: Option<viz::Logger>, to_viewer: bool) {
    match logger {
        Some(l) if to_viewer => std::mem::forget(l),
        other => drop(other),
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
