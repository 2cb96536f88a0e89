//! `sweeptrace repro`: one sweep of a trace as a minimal trace and a
//! ready-to-paste Rust test (the library's [`sweeptrace::suite::repro::ReproCase`]).

use super::NameFileOnce;
use std::path::PathBuf;

use super::Exit;
use sweeptrace::suite::repro::{ReproCase, find_sweep};
use sweeptrace::trace::{TraceReader, write_trace_file};

/// Arguments of `repro`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Example:
  sweeptrace repro traces/record_mini_golf.mcap --frame 120 --ball 0 -o case.mcap > repro_test.rs

Writes OUT: the sweep, the triangles within its reach (renumbered in their
order; the scene's name and a `sweeptrace.repro` metadata record give each
one's index in the trace), the scene's margin and facing, the expectation.
`sweeptrace check OUT` gives the same verdict for that sweep as the whole
trace. Prints on stdout a Rust test asserting the expected outcome (or the
replayed one, when the trace has no expectation) against the core, every
number bit-exact; on stderr what was written. Exit status 0, or 2 when the
reduced case does not make the same decision (please report it).")]
pub struct Args {
    /// The trace.
    #[arg(value_name = "TRACE")]
    pub trace: PathBuf,
    /// Frame of the sweep.
    #[arg(long)]
    pub frame: u64,
    /// Ball of the sweep.
    #[arg(long, default_value_t = 0)]
    pub ball: u32,
    /// The minimal trace to write (atomically).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    #[command(flatten)]
    pub tolerances: super::ToleranceArgs,
    /// Where the `[engine]` table and the tolerances come from (`check`'s
    /// files by default).
    #[command(flatten)]
    pub config: super::check_config::ConfigArgs,
    /// The engine's conventions: the case is replayed and judged under
    /// them, as `check` judges (docs/ENGINES.md). Default: the `[engine]`
    /// table of the `sweeptrace.toml` beside or above the trace.
    #[command(flatten)]
    pub conventions: sweeptrace::conventions::PartialConventions,
}

/// Writes the case and prints the test.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let overrides = sweeptrace::suite::config::Overrides {
        engine: args.conventions.clone(),
        ..args.tolerances.to_overrides()?
    };
    let settings = super::check_config::SettingsFiles::new(
        args.config.no_config,
        args.config.config.as_deref(),
    )?
    .settings(&args.trace, &overrides)?;
    let tolerances = settings.tolerances();
    let conventions = settings.engine.conventions();
    if let Some(line) = super::check_config::conventions_line(&settings) {
        eprintln!("{line}");
    }
    let shown = args.trace.display().to_string();
    let file = super::open_trace(&args.trace)?;
    let reader = TraceReader::new_indexed(std::io::BufReader::new(file), &shown);
    let found = find_sweep(reader, &shown, args.frame, args.ball)?;
    let case = ReproCase::build(&shown, &found, &tolerances, &conventions)?;
    write_trace_file(&args.output, |w| case.write(w))
        .name_file_once("writing", args.output.display())?;
    eprint!("{}", case.summary());
    eprintln!("wrote {}", args.output.display());
    if !conventions.is_rules() {
        // A trace holds no conventions: the command that judges the case
        // as this one was judged.
        eprintln!(
            "check it under the same conventions: sweeptrace check {} --no-config {}",
            args.output.display(),
            conventions.flags().join(" ")
        );
    }
    print!("{}", case.rust_test(&tolerances));
    Ok(if case.reproduces() {
        Exit::Success
    } else {
        Exit::Error
    })
}
