//! `sweeptrace sweep`: one sweep against a built-in scene, explained.

use anyhow::Context;

use super::report;
use sweeptrace::core::{Broadphase, CollectRecords, Facing, Options, Sweep, sweep_mesh_with};
use sweeptrace::run::RunOutcome;
use sweeptrace::sim::BuiltinScene;

/// Arguments of `sweep`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Example:\n  sweeptrace sweep --scene cube --radius 0.5 --from 0,3,0.2 --to 0.9,-3,0.2"
)]
pub struct Args {
    /// Built-in scene: `cube` (the cube [-1,1]³, 12 outward triangles),
    /// `triangle` ((0,0,0), (4,0,0), (0,4,0), front +z), `mini_golf`, `bowl`,
    /// `box` (closed, faces inward) or `terrain` (100,352 triangles).
    #[arg(long, value_enum, default_value_t = BuiltinScene::Cube)]
    pub scene: BuiltinScene,
    /// Radius r of the ball.
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub radius: f64,
    /// Start of the ball's center, `x,y,z`.
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    pub from: [f64; 3],
    /// End of the ball's center, `x,y,z`.
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    pub to: [f64; 3],
    /// Margin ε: tests use the detection radius ρ = r - ε (0 ≤ ε < r).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub margin: f64,
    /// Facing rule: `non_strict` (n·d ≤ 0) or `strict` (n·d < 0).
    #[arg(long, default_value = "non_strict")]
    pub facing: Facing,
    /// Explain every test, not only those that came close.
    #[arg(long)]
    pub all: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs the sweep and prints the outcome and explanations.
pub fn run(args: Args) -> anyhow::Result<RunOutcome> {
    let scene = args.scene.mesh();
    let mesh = scene
        .to_mesh()
        .with_context(|| format!("building scene `{}`", scene.name))?;
    let options = Options {
        margin: args.margin,
        facing: args.facing,
    };
    let sweep = Sweep::new(args.from, args.to, args.radius);
    let mut records = CollectRecords::default();
    let outcome = sweep_mesh_with(
        &mesh,
        &sweep,
        &options,
        Broadphase::Exhaustive,
        &mut records,
    )
    .context("invalid sweep")?;
    let explained = report::SweepReport {
        scene: &scene.name,
        triangles: mesh.triangles().len(),
        sweep: &sweep,
        options: &options,
        outcome: &outcome,
        records: &records.records,
        all: args.all,
    };
    if args.json {
        println!("{}", report::sweep_json(&explained));
    } else {
        print!("{}", report::sweep_text(&explained));
    }
    Ok(RunOutcome::Success)
}
