//! `sweeptrace diff`: compare the outcomes of two replays, sweep by sweep
//! (the library's [`sweeptrace::regress`]).

use super::NameFileOnce;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use anyhow::bail;

use super::Exit;
use sweeptrace::conventions::{EngineConventions, FacingRule, MarginRule};
use sweeptrace::core::Facing;
use sweeptrace::numbers::{self, Rule};
use sweeptrace::replay::{FrameRange, ReplayOptions, Selection};
use sweeptrace::suite::diff::{Side, diff, render_diff_json, render_diff_text};
use sweeptrace::trace::TraceReader;

/// Arguments of `diff`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace diff traces/record_box_strict.mcap traces/record_box_strict.mcap --facing-b non_strict
  sweeptrace diff traces/record_mini_golf.mcap traces/record_mini_golf.mcap --margin-b 0.01 --json
  sweeptrace diff traces/record_mini_golf.mcap tests/fixtures/wrong_engine_config.mcap --allow-different-scenes

The first shows what the non-strict rule changes in a trace recorded with the
strict one; before and after a change of the engine, `sweeptrace diff
before.mcap after.mcap`.

Sweeps are matched by (frame, ball), so the two traces must have the same
scenes (vertex and triangle counts, geometry, margin and facing rule, scene
by scene): when they differ that is an error naming the differences, unless
--allow-different-scenes. A --frames or --ball filter that selects no sweep
of a trace is an error. Exit status: 0 same outcomes, 1 different, 2 error.")]
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
    /// Compare the sweeps even when the two traces' scenes differ (vertex or
    /// triangle counts, geometry, margin, facing rule): without it that is
    /// an error, since the same (frame, ball) then means another sweep.
    #[arg(long)]
    pub allow_different_scenes: bool,
}

fn side(path: &Path, options: ReplayOptions) -> anyhow::Result<Side> {
    let name = path.display().to_string();
    let file = super::open_trace(path)?;
    let reader = TraceReader::new_indexed(BufReader::with_capacity(1 << 16, file), &name);
    Side::replay(reader, &name, options).name_file_once("replaying", &name)
}

/// Compares the two replays.
pub fn run(args: Args) -> anyhow::Result<Exit> {
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
            conventions: overrides(args.margin_a, args.facing_a),
            ..base
        },
    )?;
    let b = side(
        &args.b,
        ReplayOptions {
            conventions: overrides(args.margin_b, args.facing_b),
            ..base
        },
    )?;
    for side in [&a, &b] {
        let selection = side.summary.selection(&side.options);
        if selection.is_nothing() {
            bail!("{}: {selection}", side.name);
        }
    }
    let report = diff(&a, &b, &tolerances);
    if !report.scene_differences.is_empty() {
        let list = report.scene_differences.join("\n  ");
        if !args.allow_different_scenes {
            bail!(
                "the scenes of {} and {} differ, so the same (frame, ball) is not the same \
                 sweep:\n  {list}\ncompare them anyway with --allow-different-scenes",
                a.name,
                b.name
            );
        }
        eprintln!(
            "warning: the scenes differ (compared anyway, --allow-different-scenes):\n  {list}"
        );
    }
    let mut kept: Vec<String> = Vec::new();
    for side in [&a, &b] {
        if let part @ Selection::Part { .. } = side.summary.selection(&side.options) {
            let line = format!("{}: {part}", side.name);
            // `diff T T ...` replays one trace twice: say it once.
            if !kept.contains(&line) {
                kept.push(line);
            }
        }
    }
    for line in kept {
        eprintln!("{line}");
    }
    if args.json {
        print!("{}", render_diff_json(&report));
    } else {
        print!("{}", render_diff_text(&report));
    }
    Ok(if report.is_same() {
        Exit::Success
    } else {
        Exit::Differences
    })
}

/// The conventions of one side: its margin and facing overrides, the rules
/// otherwise.
fn overrides(margin: Option<f64>, facing: Option<Facing>) -> EngineConventions {
    EngineConventions {
        margin: margin.map_or(MarginRule::Scene, MarginRule::Fixed),
        facing: facing.map_or(FacingRule::Scene, FacingRule::from),
        ..EngineConventions::default()
    }
}
