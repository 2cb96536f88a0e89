//! `sweeptrace diff`: compare the outcomes of two replays, sweep by sweep
//! (the library's [`sweeptrace::regress`]).

use super::NameFileOnce;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use anyhow::Context;

use sweeptrace::core::Facing;
use sweeptrace::numbers::{self, Rule};
use sweeptrace::regress::diff::{render_json, render_text};
use sweeptrace::regress::{Side, diff};
use sweeptrace::replay::{FrameRange, ReplayOptions};
use sweeptrace::run::RunOutcome;
use sweeptrace::trace::TraceReader;

/// Arguments of `diff`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace diff old.mcap new.mcap
  sweeptrace diff run.mcap run.mcap --facing-b strict     # what the strict rule changes
  sweeptrace diff run.mcap run.mcap --margin-b 0.01 --json

Sweeps are matched by (frame, ball). Exit status: 0 same outcomes, 1
different, 2 error.")]
pub struct Args {
    /// Trace A.
    #[arg(value_name = "A")]
    pub a: PathBuf,
    /// Trace B (may be A itself, replayed with other options).
    #[arg(value_name = "B")]
    pub b: PathBuf,
    /// Override every scene's margin ε when replaying A.
    #[arg(long, value_name = "EPSILON")]
    pub margin_a: Option<f64>,
    /// Override every scene's margin ε when replaying B.
    #[arg(long, value_name = "EPSILON")]
    pub margin_b: Option<f64>,
    /// Override every scene's facing rule when replaying A: `non_strict` or `strict`.
    #[arg(long, value_name = "RULE")]
    pub facing_a: Option<Facing>,
    /// Override every scene's facing rule when replaying B: `non_strict` or `strict`.
    #[arg(long, value_name = "RULE")]
    pub facing_b: Option<Facing>,
    /// Only frames A..B (A included, B excluded; also `A..`, `..B`, `A..=B`, `A`).
    #[arg(long, value_name = "A..B")]
    pub frames: Option<FrameRange>,
    /// Only ball N.
    #[arg(long, value_name = "N")]
    pub ball: Option<u32>,
    #[command(flatten)]
    pub tolerances: super::ToleranceArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

fn side(path: &Path, options: ReplayOptions) -> anyhow::Result<Side> {
    let name = path.display().to_string();
    let file = File::open(path).with_context(|| format!("cannot open trace {name}"))?;
    let reader = TraceReader::new_indexed(BufReader::with_capacity(1 << 16, file), &name);
    Side::replay(reader, &name, options).name_file_once("replaying", &name)
}

/// Compares the two replays.
pub fn run(args: Args) -> anyhow::Result<RunOutcome> {
    let tolerances = args.tolerances.to_tolerances()?;
    for (flag, m) in [("--margin-a", args.margin_a), ("--margin-b", args.margin_b)] {
        if let Some(m) = m {
            numbers::check(m, Rule::NonNegative).map_err(|e| anyhow::anyhow!("{flag} {e}"))?;
        }
    }
    let base = ReplayOptions {
        frames: args.frames.unwrap_or_default(),
        ball: args.ball,
        ..ReplayOptions::default()
    };
    let a = side(
        &args.a,
        ReplayOptions {
            margin: args.margin_a,
            facing: args.facing_a,
            ..base
        },
    )?;
    let b = side(
        &args.b,
        ReplayOptions {
            margin: args.margin_b,
            facing: args.facing_b,
            ..base
        },
    )?;
    let report = diff(&a, &b, &tolerances);
    if args.json {
        print!("{}", render_json(&report));
    } else {
        print!("{}", render_text(&report));
    }
    Ok(if report.is_same() {
        RunOutcome::Success
    } else {
        RunOutcome::Differences
    })
}
