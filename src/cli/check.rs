//! `sweeptrace check`: replay traces and compare every sweep's outcome with
//! the trace's `/expected` channel (the library's [`sweeptrace::regress`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::Exit;
use sweeptrace::engine::{EngineCommand, EngineOptions};
use sweeptrace::replay::{Detail, ReplayOptions};
use sweeptrace::suite::discovery::discover;
use sweeptrace::suite::engine_check::check_file_with_engine;
use sweeptrace::suite::report::Against;
use sweeptrace::suite::{
    CheckOptions, DEFAULT_MAX_DETAILS, Status, TraceReport, check_file, frames_around, render_json,
    render_text,
};

/// Frames of context logged before and after the divergences by `--rrd-on-failure`.
const RRD_CONTEXT_FRAMES: u64 = 10;

/// Arguments of `check`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace check traces/                     # every *.mcap under traces/
  sweeptrace check traces/record_mini_golf.mcap --tolerance 1e-4 --normal-tolerance 0.5
  sweeptrace check tests/fixtures/wrong_engine_config.mcap --json --rrd-on-failure failures
  sweeptrace check traces/record_cube_corner_margin.mcap --engine 'python3 examples/engines/sweep_engine.py'
  sweeptrace check examples/rapier/rapier_mini_golf.mcap --fields kind,alpha --tolerance 1e-5 --no-config
  sweeptrace check traces/ --junit report.xml   # a test report for CI
  sweeptrace check traces/record_mini_golf.mcap --frames 100..200 --ball 1

Under `git bisect run sweeptrace check traces/ --engine ./build/engine`,
an engine that cannot be started skips the commit (exit 125).

With --engine, the engine runs as a child process and answers every sweep
over stdin/stdout (docs/ENGINE_PROTOCOL.md); its answers are compared with
the core's outcomes, as the expectations would be (in the report,
`engine` is its answer and `core` the core's); the traces' /expected
channels are not used. With --against expected they are compared with the
traces' /expected channels instead (`expected`, `engine`). A fault of the
engine (it crashes, prints something that is not an outcome, answers
another sweep, does not answer within --engine-timeout) is an error naming
the sweep, with its last stderr lines.

Per trace: `ok`, `FAIL` (with the first divergences explained, and every
tunnel: a ball's centre that went through a triangle from its front to its
back, named by frame, ball, triangle and point; and every ghost contact: an
expected edge or vertex contact on an internal flat or concave edge whose
normal leans more than --ghost-degrees off the faces', named by frame,
ball, edge and angle), `NO EXPECTATIONS` (no
/expected channel, or none matches a sweep: never a pass) or `ERROR`. Each
divergence gives the sweep's inputs exactly (--hex: also as hex floats).
When expectations fail, the recording engine's margin and facing rule are
inferred from them, with how many expectations match when replayed with
them. A divergence on a fragile decision is excused only when rounding
explains it: a perturbation of the sweep's inputs within the rounding
budget (a few units of p0, p1 or the radius) makes the core give the
expected answer; the report names that perturbation. Exit status: 0 every
trace matches (ties and divergences rounding explains included, unless
--strict), 1 a divergence, a tunnel or a ghost contact was found, 2
something could not be checked (bad input, I/O error, no expectations, a
fault of the engine), 3 a trace ends early, 125 the engine cannot be
started (git bisect run skips that commit). In GitHub Actions
(GITHUB_ACTIONS=true) the first divergences and tunnels of each failing
trace, and why a trace could not be checked, are also printed as ::error
annotations (not with --json).

Settings file: a sweeptrace.toml in a trace's folder or in any parent, up to
the repository root (the first folder holding .git), sets the tolerances,
fields, strict and allow_tunnels of the traces below it; a nearer file
overrides a farther one key by key, and its [[traces]] blocks apply to the
traces their match glob selects (relative to the file's folder), the last
matching block winning. For example:

  fields = [\"kind\", \"alpha\"]
  [tolerances]
  alpha = 1e-5
  [[traces]]
  match = \"rapier/*.mcap\"
  tolerances = { contact = 1e-5 }

A search of a folder leaves out the Foxglove files `replay --foxglove`
writes (told by content, whatever their name) and the files the
`exclude` globs of a settings file match (`exclude = [\"scratch/**\"]`,
relative to the file's folder; a file named on the command line is checked
all the same), and says so once on stderr.

The command line overrides the files (--strict=false undoes strict = true);
--print-config shows each trace's settings and where each came from;
--no-config ignores the files (docs/REGRESSION.md).")]
pub struct Args {
    /// Trace files, or directories searched recursively for `*.mcap`.
    #[arg(value_name = "TRACE|DIR", required = true)]
    pub paths: Vec<PathBuf>,
    #[command(flatten)]
    pub tolerances: super::ToleranceArgs,
    /// Print one JSON document instead of text.
    #[arg(long)]
    pub json: bool,
    /// Fail on divergences that rounding explains too. On a fragile
    /// decision (ties across kinds or triangles, near-tangent paths,
    /// contacts at a feature's boundary, ...: see docs/SEMANTICS.md) a
    /// divergence whose expected answer the core gives under a small
    /// perturbation of the inputs is counted and shown apart and, without
    /// --strict, does not fail the check; any other divergence fails.
    /// `--strict=false` overrides a settings file's `strict = true`.
    #[arg(long, value_name = "BOOL", num_args = 0..=1, require_equals = true, default_missing_value = "true")]
    pub strict: Option<bool>,
    /// Count and list tunnels (a ball's centre through a triangle, front to
    /// back, during a sweep or between two sweeps of a ball) without failing
    /// the check. Without it a tunnel fails the check: it is a bug of the
    /// engine that recorded the trace, whatever its expectations say.
    /// `--allow-tunnels=false` overrides a settings file's `allow_tunnels = true`.
    #[arg(long, value_name = "BOOL", num_args = 0..=1, require_equals = true, default_missing_value = "true")]
    pub allow_tunnels: Option<bool>,
    /// Count and list ghost contacts without failing the check. A ghost
    /// contact is an expectation (or an engine's answer) that is an edge or
    /// vertex contact on an internal flat or concave edge (or a vertex whose
    /// every edge is flat or concave) with a normal more than
    /// --ghost-degrees from the faces' normals there: the normal that bumps
    /// a ball rolling across a seam. They are judged whatever --fields
    /// compares; without this flag one fails the check.
    #[arg(long)]
    pub allow_ghosts: bool,
    /// The angle, in degrees, between an edge or vertex contact's normal and
    /// the nearest adjacent face's normal above which it is a ghost contact
    /// (docs/SEMANTICS.md), e.g. `--ghost-degrees 5`.
    #[arg(long, value_name = "DEGREES", default_value_t = sweeptrace::replay::ghost::GHOST_DEGREES)]
    pub ghost_degrees: f64,
    /// Ignore the sweeptrace.toml files: the defaults and the command line only.
    #[arg(long)]
    pub no_config: bool,
    /// Settings from this `sweeptrace.toml` instead of the ones found beside
    /// and above each trace (an engine's `[engine]` table kept with the
    /// engine, say: `--config examples/engines/jolt/sweeptrace.toml`).
    #[arg(long, value_name = "FILE", conflicts_with = "no_config")]
    pub config: Option<PathBuf>,
    /// Print each trace's settings and where each came from (`default`,
    /// `FILE:LINE`, `command line`), and exit without checking (with
    /// --json, as JSON).
    #[arg(long)]
    pub print_config: bool,
    /// Also give each divergence's inputs as hexadecimal floating point
    /// (`0x1.5555555555555p-2`), besides the shortest round-trip decimals.
    #[arg(long)]
    pub hex: bool,
    /// How many divergences per trace are explained in detail.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_DETAILS)]
    pub max_details: usize,
    /// For each failing trace, write DIR/<trace stem>.rrd: a Rerun recording
    /// of the frames around its first divergences.
    #[arg(long, value_name = "DIR", conflicts_with = "engine")]
    pub rrd_on_failure: Option<PathBuf>,
    /// Check a running engine instead of the traces' /expected channels:
    /// the command that starts it, split like a shell's words (no shell
    /// runs it), e.g. `--engine "python3 engine.py --margin 0.01"` or
    /// `--engine ./build/engine`. One engine process per trace.
    #[arg(long, value_name = "COMMAND")]
    pub engine: Option<String>,
    /// With --engine: the longest wait, in seconds, for the engine's next
    /// answer (and for it to exit at the end), e.g. `--engine-timeout 2.5`.
    #[arg(long, value_name = "SECONDS", default_value_t = sweeptrace::engine::DEFAULT_TIMEOUT.as_secs_f64(), requires = "engine")]
    pub engine_timeout: f64,
    /// With --engine: what the engine's answers are compared with. `core`
    /// (the default): the core's outcomes. `expected`: the traces' /expected
    /// channels (does the engine still decide what it recorded?), e.g.
    /// `--engine ./build/engine --against expected`.
    #[arg(long, value_enum, default_value_t = AgainstArg::Core, requires = "engine")]
    pub against: AgainstArg,
    /// With --engine: the engine also answers contact queries (docs/
    /// ENGINE_PROTOCOL.md, `contact`): each trace's /contact queries are
    /// sent to it and its contacts judged against the core's contact set,
    /// in place of the trace's /expected_contacts. Without it, an engine is
    /// sent sweeps only and the queries are counted as not judged.
    #[arg(long, requires = "engine")]
    pub engine_contacts: bool,
    /// Only frames A..B (A included, B excluded; also `A..`, `..B`,
    /// `A..=B`, `A`), as `replay --frames`: the other sweeps are neither
    /// replayed nor compared, e.g. `--frames 100..200`.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<sweeptrace::replay::FrameRange>,
    /// Only ball N, as `replay --ball`, e.g. `--ball 0`.
    #[arg(long, value_name = "N")]
    pub ball: Option<u32>,
    #[command(flatten)]
    pub junit: super::junit::JunitArgs,
    #[command(flatten)]
    pub conventions: sweeptrace::conventions::PartialConventions,
    /// With --engine: run the engine, then print only a `sweeptrace.toml`
    /// whose `[engine]` table declares the conventions its answers imply,
    /// each with its evidence in a comment (`check TRACES --engine CMD
    /// --infer-config > suite/sweeptrace.toml`). Without --engine, infers
    /// from the traces' own /expected (traces recorded from an engine).
    /// Never makes a run pass by itself: check again with the file.
    #[arg(long)]
    pub infer_config: bool,
}

/// `--against`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AgainstArg {
    /// The core's outcomes.
    Core,
    /// The traces' /expected channels.
    Expected,
}

/// Checks every trace, prints the reports, returns the exit code.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    #[cfg(not(feature = "viewer"))]
    if args.rrd_on_failure.is_some() {
        return Err(super::viewer::needs_viewer(
            "--rrd-on-failure",
            "the check itself needs no viewer: run it without --rrd-on-failure \
             (--json and --junit report the divergences)",
        ));
    }
    let overrides = sweeptrace::suite::config::Overrides {
        strict: args.strict,
        allow_tunnels: args.allow_tunnels,
        engine: args.conventions.clone(),
        ..args.tolerances.to_overrides()?
    };
    let found = discover(&args.paths)?;
    if !found.dangling.is_empty() {
        let list: Vec<String> = found
            .dangling
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        eprintln!(
            "note: left out {} whose target does not exist: {}",
            sweeptrace::numbers::counted(
                found.dangling.len() as u64,
                "symbolic link",
                "symbolic links"
            ),
            listed(&list)
        );
    }
    let found = found.traces;
    let mut files =
        super::check_config::SettingsFiles::new(args.no_config, args.config.as_deref())?;
    let traces = leave_out(found, &args.paths, &mut files)?;
    if traces.is_empty() {
        bail!(
            "no trace found (directories are searched for *.mcap): {}",
            args.paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let settings = super::check_config::settings(&traces, &overrides, &mut files)?;
    if args.print_config {
        print!(
            "{}",
            super::check_config::render(&traces, &settings, args.json)
        );
        return Ok(Exit::Success);
    }
    if !(args.ghost_degrees.is_finite() && (0.0..=180.0).contains(&args.ghost_degrees)) {
        bail!(
            "--ghost-degrees must be an angle from 0 to 180, got {}",
            sweeptrace::numbers::Shortest(args.ghost_degrees)
        );
    }
    let options = CheckOptions {
        max_details: args.max_details,
        hex: args.hex,
        fail_on_ghost: !args.allow_ghosts,
        ghost_degrees: args.ghost_degrees,
        replay: ReplayOptions {
            frames: args.frames.unwrap_or_default(),
            ball: args.ball,
            ..ReplayOptions::default()
        },
        ..CheckOptions::default()
    };
    let engine = match &args.engine {
        None => None,
        Some(text) => Some((
            EngineCommand::parse(text)?,
            EngineOptions {
                contacts: args.engine_contacts,
                ..engine_options(args.engine_timeout)?
            },
        )),
    };
    if args.infer_config {
        let source = match &engine {
            Some((command, _)) => format!("the engine `{}`", command.text),
            None => "the traces' /expected".to_string(),
        };
        // The engine runs once per trace: its answers do not depend on
        // the conventions tried, so every trial judges the same answers
        // (a run that did not end cleanly is run again in the trial, whose
        // report says why).
        let mut recorded: Vec<Option<sweeptrace::suite::engine_check::RecordedAnswers>> =
            Vec::new();
        if let Some((command, engine_options)) = &engine {
            for path in &traces {
                match sweeptrace::suite::engine_check::record_engine_answers(
                    path,
                    command,
                    *engine_options,
                ) {
                    Ok(answers) => recorded.push(answers),
                    Err(err) => {
                        eprintln!(
                            "error: {}: {err}\nno configuration inferred",
                            path.display()
                        );
                        return Ok(Exit::EngineUnavailable);
                    }
                }
            }
        }
        // A trace that cannot be checked, or a fault of the engine, ends
        // the inference: its exit code and its message; no table.
        let inferred = sweeptrace::suite::infer_conventions::infer_conventions(|conventions| {
            let mut reports: Vec<TraceReport> = Vec::new();
            for (i, (path, settings)) in traces.iter().zip(&settings).enumerate() {
                let base = settings.check_options(options);
                let options = CheckOptions {
                    replay: ReplayOptions {
                        conventions: *conventions,
                        ..options.replay
                    },
                    ..base
                };
                let report = match (&engine, recorded.get(i).and_then(Option::as_ref)) {
                    (None, _) => check_file(path, &options),
                    (Some(_), Some(answers)) => {
                        sweeptrace::suite::engine_check::check_recorded_answers(
                            answers,
                            &path.display().to_string(),
                            &options,
                        )
                    }
                    (Some((command, engine_options)), None) => check_file_with_engine(
                        path,
                        command,
                        *engine_options,
                        Against::Core,
                        &options,
                    )
                    .map_err(|err| {
                        (
                            Exit::EngineUnavailable,
                            format!("{}: {err}", path.display()),
                        )
                    })?,
                };
                if let Some(fault) = report.margin_fault {
                    let text = super::check_config::margin_fault(
                        settings,
                        &path.display().to_string(),
                        &fault,
                    );
                    return Err((Exit::Error, text));
                }
                if report.status() == Status::Error {
                    let errors: Vec<String> = report
                        .errors
                        .iter()
                        .map(|e| format!("{}: {e}", path.display()))
                        .collect();
                    return Err((outcome_of(&report), errors.join("\nerror: ")));
                }
                reports.push(report);
            }
            let trial = sweeptrace::suite::infer_conventions::Trial::of(&reports);
            eprintln!("tried {}: {}", conventions.summary(), trial.counts());
            Ok(trial)
        });
        return match inferred {
            Ok(inferred) => {
                print!("{}", inferred.to_toml(&source));
                Ok(Exit::Success)
            }
            Err((exit, message)) => {
                eprintln!("error: {message}\nno configuration inferred");
                Ok(exit)
            }
        };
    }
    let junit = args.junit.start()?;
    let (mut reports, mut times): (Vec<TraceReport>, Vec<_>) = (Vec::new(), Vec::new());
    let mut rrd_error = false;
    for (path, settings) in traces.iter().zip(&settings) {
        let started = std::time::Instant::now();
        let options = settings.check_options(options);
        let mut report = match &engine {
            None => check_file(path, &options),
            Some((command, engine_options)) => {
                let against = match args.against {
                    AgainstArg::Core => Against::Core,
                    AgainstArg::Expected => Against::Expected,
                };
                match check_file_with_engine(path, command, *engine_options, against, &options) {
                    Ok(report) => report,
                    Err(err) => {
                        eprintln!("error: {}: {err}", path.display());
                        return Ok(Exit::EngineUnavailable);
                    }
                }
            }
        };
        times.push(started.elapsed());
        // A margin that does not fit the balls is the setting's fault: one
        // error naming where it was set, and the run stops (exit 2; with
        // --json, the report of the trace holds the error).
        let margin_fault = report.margin_fault;
        if let Some(fault) = &margin_fault {
            let text =
                super::check_config::margin_fault(settings, &path.display().to_string(), fault);
            if !args.json {
                eprintln!("error: {text}");
                return Ok(Exit::Error);
            }
            report.errors = vec![text];
        }
        if !args.json {
            print!("{}", render_text(&report));
            super::junit::print_github_annotations(&report);
        }
        if report.status() == Status::Fail
            && let Some(dir) = &args.rrd_on_failure
        {
            match write_failure_rrd(path, dir, &report) {
                Ok(out) => eprintln!("wrote {}", out.display()),
                Err(err) => {
                    eprintln!("error: {}: writing the recording: {err:#}", path.display());
                    rrd_error = true;
                }
            }
        }
        reports.push(report);
        if margin_fault.is_some() {
            break;
        }
    }
    let outcome = Exit::worst(reports.iter().map(outcome_of));
    if args.json {
        print!("{}", render_json(&reports, outcome.exit_code()));
    } else if traces.len() > 1 {
        let count = |s: Status| reports.iter().filter(|r| r.status() == s).count();
        println!(
            "{} traces: {} ok, {} FAIL, {} NO EXPECTATIONS, {} ERROR",
            reports.len(),
            count(Status::Ok),
            count(Status::Fail),
            count(Status::NoExpectations),
            count(Status::Error)
        );
    }
    super::junit::finish_check(junit, &reports, &times)?;
    Ok(if rrd_error { Exit::Error } else { outcome })
}

/// The traces of `found` to check: without the Foxglove files that
/// `replay --foxglove` writes (MCAP files, but not traces) and, among the
/// files found by searching a folder (not those named on the command
/// line), those the `exclude` globs of the run's settings `files` leave
/// out. Says once on stderr what it left out, and why.
fn leave_out(
    found: Vec<PathBuf>,
    named: &[PathBuf],
    files: &mut super::check_config::SettingsFiles,
) -> anyhow::Result<Vec<PathBuf>> {
    let (mut traces, mut foxglove, mut excluded) = (Vec::new(), Vec::new(), Vec::new());
    for path in found {
        if let Some(trace) = sweeptrace::trace::sniff::foxglove_output(&path) {
            foxglove.push((path, trace));
            continue;
        }
        if !named.contains(&path) {
            let by = files.excluded_by(&path)?;
            if let Some((file, pattern)) = by {
                excluded.push((path, file, pattern));
                continue;
            }
        }
        traces.push(path);
    }
    if !foxglove.is_empty() {
        let list: Vec<String> = foxglove
            .iter()
            .map(|(path, trace)| match trace.as_str() {
                "" => path.display().to_string(),
                trace => format!("{} (from {trace})", path.display()),
            })
            .collect();
        let (files, what) = match foxglove.len() {
            1 => ("1 Foxglove file".to_string(), "not a trace"),
            n => (format!("{n} Foxglove files"), "not traces"),
        };
        eprintln!(
            "note: left out {files} that `sweeptrace replay --foxglove` wrote ({what}): {}",
            listed(&list)
        );
    }
    if !excluded.is_empty() {
        let list: Vec<String> = excluded
            .iter()
            .map(|(path, file, pattern)| format!("{} (`{pattern}` in {file})", path.display()))
            .collect();
        eprintln!(
            "note: left out {} excluded by `exclude` in sweeptrace.toml: {}",
            sweeptrace::numbers::counted(excluded.len() as u64, "file", "files"),
            listed(&list)
        );
    }
    Ok(traces)
}

/// The first few of `items`, comma-separated, then how many more.
fn listed(items: &[String]) -> String {
    const LISTED: usize = 5;
    let mut text = items
        .iter()
        .take(LISTED)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > LISTED {
        text.push_str(&format!(" and {} more", items.len() - LISTED));
    }
    text
}

/// What the check of one trace came to: a divergence is
/// [`Exit::Differences`]; a trace that ends early (its only error)
/// [`Exit::IncompleteInput`]; any other error, or nothing to
/// compare, [`Exit::Error`].
fn outcome_of(report: &TraceReport) -> Exit {
    match report.status() {
        Status::Ok => Exit::Success,
        Status::Fail => Exit::Differences,
        Status::Error if report.incomplete && report.errors.len() == 1 => Exit::IncompleteInput,
        Status::NoExpectations | Status::Error => Exit::Error,
    }
}

/// The engine's options from `--engine-timeout`.
pub fn engine_options(timeout_seconds: f64) -> anyhow::Result<EngineOptions> {
    if !(timeout_seconds.is_finite() && timeout_seconds > 0.0 && timeout_seconds <= 1e6) {
        bail!(
            "--engine-timeout must be a number of seconds in (0, 1e6], got {}",
            sweeptrace::numbers::Shortest(timeout_seconds)
        );
    }
    Ok(EngineOptions {
        timeout: std::time::Duration::from_secs_f64(timeout_seconds),
        ..EngineOptions::default()
    })
}

/// Replays the frames around the report's first divergences into
/// `dir/<stem>.rrd` (written under a temporary name and renamed).
fn write_failure_rrd(trace: &Path, dir: &Path, report: &TraceReport) -> anyhow::Result<PathBuf> {
    let frames = frames_around(report, RRD_CONTEXT_FRAMES, RRD_CONTEXT_FRAMES)
        .context("no divergence or tunnel to record")?;
    let stem = trace
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "trace".to_string());
    let target = dir.join(format!("{stem}.rrd"));
    // Created with the first recording: a check that writes none leaves
    // no directory behind.
    std::fs::create_dir_all(dir)
        .with_context(|| format!("creating the directory {}", dir.display()))?;
    super::warn_unfinished(&target);
    // Replayed and judged as the check was: under the engine's declared
    // conventions and the run's tolerances.
    let options = ReplayOptions {
        frames,
        explain: Some(Detail::Candidates),
        conventions: report.conventions,
        ..ReplayOptions::default()
    };
    let name = trace.display().to_string();
    let bytes = std::fs::read(trace).with_context(|| format!("reading {name}"))?;
    super::viewer::write_check_recording(
        &bytes,
        &name,
        &format!("{name} (check, frames {frames})"),
        &target,
        options,
        report.tolerances,
    )?;
    Ok(target)
}
