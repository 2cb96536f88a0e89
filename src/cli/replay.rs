//! `sweeptrace replay`: run every sweep of a trace through the core and
//! write the outcomes, a Rerun recording and/or a Foxglove file that
//! explain them.

mod outputs;
mod progress;
mod summary_json;

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

use anyhow::bail;

use super::check_config::replay_error;
use super::viewer::Recording;
use super::{Exit, NameFileOnce};
use outputs::{Outputs, recording_target};
use progress::{read_with_progress, worker_pool};
use summary_json::summary_json;
use sweeptrace::numbers;
use sweeptrace::replay::{
    Detail, FrameRange, PipelineOptions, ReplayError, ReplayEvent, ReplayOptions, Selection,
    replay_events_parallel, run_pipeline,
};

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

/// Runs the replay; with `--json` a failed one prints a JSON document with
/// the error too (as `check --json`).
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let json = args.json.then(|| args.trace.display().to_string());
    let result = run_replay(args);
    if let (Some(trace), Err(err)) = (json, &result) {
        println!("{}", summary_json::error_json(&trace, err));
    }
    result
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
    // The reference answers and divergence marks follow `check`'s conventions.
    let settings = super::check_config::for_trace(trace_path, &args.conventions, &args.config)?;
    let (conventions, tolerances) = (settings.engine.conventions(), settings.tolerances());
    let options = ReplayOptions {
        frames: args.frames.unwrap_or_default(),
        ball: args.ball,
        // The decision lines (recording, Foxglove) need the decisive test.
        explain: (target.is_some() || args.foxglove.is_some()).then_some(args.detail),
        conventions,
    };
    if let Some(line) = super::check_config::conventions_line(&settings) {
        eprintln!("{line}");
    }
    let mut outputs = Outputs::open(&args, target, &options, tolerances)?;
    let pool = worker_pool(args.threads)?;

    let (read_ahead, progress, count) =
        read_with_progress(file, total_bytes, &source_name, "replaying")?;
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
                Err(err) => return replay_error(err, &settings, &source_name),
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
                    None,
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
    let drawn = outputs.draw_contacts(trace_path, &source_name, summary.contact_queries, &pool)?;
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
                drawn.as_ref(),
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
