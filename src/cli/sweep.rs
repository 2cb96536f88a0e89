//! `sweeptrace sweep`: one sweep against a built-in scene, an OBJ mesh, or
//! the scene of a trace, explained.

use std::path::PathBuf;

use anyhow::Context;

use super::Exit;
use super::report;
use sweeptrace::core::{Options, Sweep};
use sweeptrace::replay::{
    FrameRange, ReplayEvent, ReplayOptions, SweepResult, explain_sweep, replay_events,
};
use sweeptrace::sim::load_obj;
use sweeptrace::sim::scenes::BuiltinScene;
use sweeptrace::suite::report::MarginFault;
use sweeptrace::suite::repro::find_sweep;
use sweeptrace::trace::{OutcomeMsg, TraceReader};

/// Arguments of `sweep`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  sweeptrace sweep --scene cube --radius 0.5 --from 0,3,0.2 --to 0.9,-3,0.2
  sweeptrace sweep --mesh tests/fixtures/scanned/bunny_res4.obj --radius 0.01 --from 0,0.1,0.2 --to 0,0.1,-0.2 --margin 0.001
  sweeptrace sweep --trace traces/record_mini_golf.mcap --frame 120 --ball 0   # that sweep, its scene, margin, facing

Why did my ball fall through? The report names a tunnel (the centre through a
triangle front to back, or a flipped one back to front) as `check` does, with
--trace also one since the ball's previous sweep; the mesh defect it went
through; every defect within ρ of the path (`sweeptrace mesh` lists them all);
and among the tests, each face the path passes through, with why it did not
count (back-facing, or a start within ρ of its plane).

Numbers may be written in hexadecimal floating point (0x1.8p+1), read exactly.")]
pub struct Args {
    /// Built-in scene: `cube` (the cube [-1,1]³, 12 outward triangles),
    /// `triangle` ((0,0,0), (4,0,0), (0,4,0), front +z), `mini_golf`, `bowl`,
    /// `box` (closed, faces inward) or `terrain` (100,352 triangles).
    /// Default `cube` when neither --mesh nor --trace is given.
    #[arg(long, value_enum, conflicts_with_all = ["mesh", "trace"])]
    pub scene: Option<BuiltinScene>,
    /// A Wavefront OBJ file (faces counter-clockwise seen from the front).
    #[arg(long, value_name = "FILE.obj", conflicts_with = "trace")]
    pub mesh: Option<PathBuf>,
    /// Take the sweep of --frame and --ball from this trace, with the
    /// trace's scene, margin and facing rule (--margin and --facing
    /// override them). Without it the margin is 0 and the facing rule
    /// non_strict unless --margin and --facing say otherwise.
    #[arg(long, value_name = "TRACE", requires = "frame")]
    pub trace: Option<PathBuf>,
    /// Frame of the sweep to take from --trace.
    #[arg(long, requires = "trace")]
    pub frame: Option<u64>,
    /// Ball of the sweep to take from --trace.
    #[arg(long, default_value_t = 0)]
    pub ball: u32,
    /// Radius r of the ball [default: 0.5].
    #[arg(long, allow_negative_numbers = true, value_parser = super::parse_number, conflicts_with = "trace")]
    pub radius: Option<f64>,
    /// Start of the ball's center, `x,y,z`.
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true,
          required_unless_present = "trace", conflicts_with = "trace")]
    pub from: Option<[f64; 3]>,
    /// End of the ball's center, `x,y,z`.
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true,
          required_unless_present = "trace", conflicts_with = "trace")]
    pub to: Option<[f64; 3]>,
    /// With --trace: where the `[engine]` table comes from (`check`'s
    /// files by default).
    #[command(flatten)]
    pub config: super::check_config::ConfigArgs,
    /// The engine's conventions: the answer is computed under them, as
    /// `check` judges (docs/ENGINES.md). With --trace, default: the
    /// `[engine]` table of the `sweeptrace.toml` beside or above it.
    #[command(flatten)]
    pub conventions: sweeptrace::conventions::PartialConventions,
    /// Explain every test, not only those that came close.
    #[arg(long)]
    pub all: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs the sweep and prints the outcome and explanations.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let mut source: Option<String> = None;
    let mut expected: Option<OutcomeMsg> = None;
    let mut replayed: Option<SweepResult> = None;
    let topology: Option<sweeptrace::Topology>;
    let settings: sweeptrace::suite::config::Settings;
    let (name, mesh, sweep, options) = if let Some(path) = &args.trace {
        let frame = args.frame.context("--trace needs --frame")?;
        let shown = path.display().to_string();
        let file = super::open_trace(path)?;
        let reader = TraceReader::new_indexed(std::io::BufReader::new(file), &shown);
        let found = find_sweep(reader, &shown, frame, args.ball)?;
        let mesh = sweeptrace::Mesh::new(found.scene.vertices.clone(), &found.scene.triangles)
            .with_context(|| format!("{shown}: building the scene of frame {frame}"))?;
        topology = sweeptrace::Topology::new(&found.scene.vertices, &found.scene.triangles).ok();
        let scene = found.options();
        settings = super::check_config::for_trace(path, &args.conventions, &args.config)?;
        let options = replay_options(&settings).core_options(scene.margin, scene.facing);
        // A margin given instead of the scene's that does not fit the
        // ball: the setting's fault, named where it was set.
        let radius = found.core_sweep().radius;
        if settings.engine.conventions().margin != sweeptrace::conventions::MarginRule::Scene
            && options.margin >= radius
        {
            let fault = MarginFault::new(options.margin, radius, frame, args.ball);
            anyhow::bail!(super::check_config::margin_fault(&settings, &shown, &fault));
        }
        source = Some(format!(
            "trace {shown}, frame {frame}, ball {} (the trace's margin {}, facing {})",
            args.ball, found.scene.margin, found.scene.facing
        ));
        expected = found.expected;
        replayed = replay_to(
            path,
            &shown,
            (frame, args.ball),
            &settings.engine.conventions(),
        )?;
        // The trace's text, shown on a terminal: its control characters
        // escaped.
        let name = found.scene.name.as_deref().map_or_else(
            || "(unnamed)".into(),
            |n| sweeptrace::error_text::escaped(n).into_owned(),
        );
        (name, mesh, found.core_sweep(), options)
    } else {
        // clap lets `requires` pass when the required flag conflicts with
        // another one present (here --from/--to): say it ourselves.
        if args.frame.is_some() {
            anyhow::bail!("--frame needs --trace (the trace to take the sweep from)");
        }
        let scene = match &args.mesh {
            Some(path) => load_obj(path)?,
            None => args.scene.unwrap_or(BuiltinScene::Cube).mesh(),
        };
        let mesh = scene
            .to_mesh()
            .with_context(|| format!("building scene `{}`", scene.name))?;
        topology = sweeptrace::Topology::new(&scene.vertices, &scene.triangles).ok();
        let (from, to) = args
            .from
            .zip(args.to)
            .context("--from and --to are required without --trace")?;
        settings = super::check_config::for_trace(
            std::path::Path::new(""),
            &args.conventions,
            &super::check_config::ConfigArgs {
                config: None,
                no_config: true,
            },
        )?;
        let rules = Options::default();
        let options = replay_options(&settings).core_options(rules.margin, rules.facing);
        (
            scene.name,
            mesh,
            Sweep::new(from, to, args.radius.unwrap_or(0.5)),
            options,
        )
    };
    if let Some(line) = super::check_config::conventions_line(&settings) {
        eprintln!("{line}");
    }
    // The tunnels, the defects within reach and the ghost contact, as
    // `check` and `replay` find them: from a trace, the trace replayed up
    // to this sweep (a tunnel between the ball's sweeps needs the one
    // before); otherwise the same function on this sweep alone.
    let story = explain_sweep(
        &mesh,
        topology.as_ref(),
        &sweep,
        &options,
        settings.engine.conventions().normal,
        replayed.as_ref(),
    )
    .context("invalid sweep")?;
    let explained = report::SweepReport {
        scene: &name,
        triangles: mesh.triangles().len(),
        source: source.as_deref(),
        expected: expected.as_ref(),
        sweep: &sweep,
        options: &options,
        story: &story,
        all: args.all,
        at: args.trace.as_ref().and(args.frame).map(|f| (f, args.ball)),
        conventions: &settings.engine.conventions(),
    };
    if args.json {
        println!("{}", report::sweep_json(&explained));
    } else {
        print!("{}", report::sweep_text(&explained));
    }
    Ok(Exit::Success)
}

/// The replay's options of this command: the engine's conventions, from
/// its flags (`--margin`, `--facing`, ...) over the `[engine]` table.
fn replay_options(settings: &sweeptrace::suite::config::Settings) -> ReplayOptions {
    ReplayOptions {
        conventions: settings.engine.conventions(),
        ..ReplayOptions::default()
    }
}

/// The sweep of `frame` and `ball` replayed as `check` and `replay` replay
/// it: the trace from its start up to that frame (the ball's earlier
/// sweeps give the tunnels between them), under the engine's
/// `conventions` (with the command's margin and facing flags). `None` when the
/// replay does not reach it (an invalid sweep; the core's own error says
/// why).
fn replay_to(
    path: &std::path::Path,
    shown: &str,
    (frame, ball): (u64, u32),
    conventions: &sweeptrace::conventions::EngineConventions,
) -> anyhow::Result<Option<SweepResult>> {
    let file = super::open_trace(path)?;
    let reader = TraceReader::new_indexed(std::io::BufReader::new(file), shown);
    let options = ReplayOptions {
        frames: FrameRange {
            start: None,
            end: Some(frame.saturating_add(1)),
        },
        ball: Some(ball),
        conventions: *conventions,
        ..ReplayOptions::default()
    };
    for event in replay_events(reader, options) {
        if let Ok(ReplayEvent::Sweep(r)) = event
            && r.frame == frame
            && r.ball == ball
        {
            return Ok(Some(*r));
        }
    }
    Ok(None)
}
