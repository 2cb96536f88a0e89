//! `sweeptrace record`: simulate balls through a scene and write a trace.

use super::NameFileOnce;
use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::Exit;
use sweeptrace::core::Facing;
use sweeptrace::sim::scenes::{self, BuiltinScene, SceneMesh};
use sweeptrace::sim::{self, SimOptions, SimSummary, StopReason};
use sweeptrace::trace::source::sweeptrace_source;
use sweeptrace::trace::{Encoding, write_trace_file_with_encoding};

/// Arguments of `record`. Every simulation option defaults to the scene's
/// own choice (`sweeptrace::sim::scenes::BuiltinScene::sim_options`).
#[derive(Debug, clap::Args)]
#[command(after_help = after_help())]
pub struct Args {
    /// Built-in scene: `mini_golf` (green, walls, ramp, cup), `bowl`, `box`
    /// (closed, ball inside), `terrain` (height field, 100,352 triangles by
    /// default), `cube` or `triangle`.
    #[arg(long, value_enum, default_value_t = BuiltinScene::MiniGolf, conflicts_with = "mesh")]
    pub scene: BuiltinScene,
    /// Record against a Wavefront OBJ file instead of a built-in scene
    /// (faces counter-clockwise seen from the front; the scene is named
    /// after the file).
    #[arg(long, value_name = "FILE")]
    pub mesh: Option<PathBuf>,
    /// Cells per side of the `terrain` scene (two triangles per cell;
    /// 1 to 4096).
    #[arg(long, default_value_t = scenes::TERRAIN_DEFAULT_CELLS, value_name = "N")]
    pub terrain_cells: usize,
    /// Output trace file [default: <scene>.mcap]. Written atomically: a
    /// failed run leaves no file behind.
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
    /// Number of simulation frames (a frame whose balls collide records
    /// extra sub-step frames).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Seed of the per-ball jitter: the same seed gives the same trace, byte
    /// for byte.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Number of balls. Ball 0 starts exactly at --position with
    /// --velocity; the others are jittered from the seed.
    #[arg(long)]
    pub balls: Option<u32>,
    /// Radius of every ball.
    #[arg(long)]
    pub radius: Option<f64>,
    /// Initial position of ball 0's centre, `x,y,z`.
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    pub position: Option<[f64; 3]>,
    /// Initial velocity of ball 0, `x,y,z` (units per second).
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    pub velocity: Option<[f64; 3]>,
    /// Largest offset added to the other balls' x and y start coordinates.
    #[arg(long)]
    pub position_jitter: Option<f64>,
    /// Largest offset added to each component of the other balls' velocity.
    #[arg(long)]
    pub velocity_jitter: Option<f64>,
    /// Duration of a frame in seconds (1e-6 to 10).
    #[arg(long)]
    pub time_step: Option<f64>,
    /// Gravity, `x,y,z` (units per second squared; scenes are `+z` up).
    #[arg(long, value_parser = super::parse_point, allow_hyphen_values = true)]
    pub gravity: Option<[f64; 3]>,
    /// Fraction of the normal speed kept at each bounce, 0 to 1.
    #[arg(long)]
    pub restitution: Option<f64>,
    /// Margin ε (0 ≤ ε < radius): sweeps detect at ρ = r - ε and the ball is
    /// pushed out by ε after each collision. Written into the scene.
    #[arg(long)]
    pub margin: Option<f64>,
    /// Facing rule of the sweeps: `non_strict` (n·d ≤ 0) or `strict`
    /// (n·d < 0). Written into the scene.
    #[arg(long)]
    pub facing: Option<Facing>,
    /// Largest number of sweeps per ball and frame (1 to 64); time left after
    /// the last one is dropped.
    #[arg(long)]
    pub max_substeps: Option<u32>,
    /// Message encoding of the trace: `json` (text) or `cbor` (binary, the
    /// same messages with every number an 8-byte double, read without
    /// parsing). See docs/TRACE_FORMAT.md.
    #[arg(long, value_enum, default_value_t = Encoding::Json, value_name = "ENCODING")]
    pub encoding: Encoding,
    /// Also record a contact query after every sweep (`/contact`, the ball
    /// where the sweep leaves it), with the core's contacts there as the
    /// expectation (`/expected_contacts`; face normals, as the rules
    /// report). See docs/SEMANTICS.md, "Contacts".
    #[arg(long)]
    pub contacts: bool,
    /// The contact distance of the queries `--contacts` records: a triangle
    /// this far from the ball is still in contact (an engine's speculative
    /// contact distance) [default: a tenth of the radius, so that a ball
    /// resting on the mesh is in contact beyond rounding].
    #[arg(long, value_name = "DISTANCE", requires = "contacts", value_parser = super::parse_non_negative)]
    pub contact_distance: Option<f64>,
}

impl Args {
    /// The simulation options: the scene's defaults, overridden by the
    /// options given.
    fn sim_options(&self, defaults: SimOptions) -> SimOptions {
        SimOptions {
            frames: self.frames.unwrap_or(defaults.frames),
            seed: self.seed.unwrap_or(defaults.seed),
            balls: self.balls.unwrap_or(defaults.balls),
            radius: self.radius.unwrap_or(defaults.radius),
            position: self.position.unwrap_or(defaults.position),
            velocity: self.velocity.unwrap_or(defaults.velocity),
            position_jitter: self.position_jitter.unwrap_or(defaults.position_jitter),
            velocity_jitter: self.velocity_jitter.unwrap_or(defaults.velocity_jitter),
            time_step: self.time_step.unwrap_or(defaults.time_step),
            gravity: self.gravity.unwrap_or(defaults.gravity),
            restitution: self.restitution.unwrap_or(defaults.restitution),
            margin: self.margin.unwrap_or(defaults.margin),
            facing: self.facing.unwrap_or(defaults.facing),
            max_substeps: self.max_substeps.unwrap_or(defaults.max_substeps),
            separation: defaults.separation,
        }
    }
}

/// The examples, then the defaults of each scene (from
/// [`BuiltinScene::sim_options`], so they cannot drift), where the ball
/// starts with `--mesh`, and what "left the play volume" means.
fn after_help() -> String {
    let examples = "Examples:
  sweeptrace record --scene mini_golf -o mini_golf.mcap
  sweeptrace record --scene terrain --terrain-cells 64 --balls 4 --seed 7 --frames 600 -o hills.mcap
  sweeptrace record --scene bowl --encoding cbor -o bowl.mcap
  sweeptrace record --mesh tests/fixtures/scanned/bunny_res4.obj --radius 0.005 --position 0,0.1,0.3 --margin 0.001 --frames 200 -o bunny.mcap";
    format!(
        "{examples}\n\n{}\n\n\
         With --mesh, ball 0 starts above the middle of the mesh: at the centre of \
         its bounding box in x and y, two radii above its top (--position \
         overrides that).\n\n\
         The play volume is the mesh's bounding box grown on every side by half its \
         diagonal plus four radii. A ball whose centre leaves it (it fell off the \
         scene, or was thrown out) \"left the play volume\": it records no further \
         sweep, and the summary counts it.",
        defaults_text()
    )
}

/// The options' defaults: those every scene shares on one line, then
/// those that differ, scene by scene (`--mesh` last).
fn defaults_text() -> String {
    type Show = fn(&SimOptions) -> String;
    let fields: [(&str, Show); 13] = [
        ("--frames", |o| o.frames.to_string()),
        ("--balls", |o| o.balls.to_string()),
        ("--radius", |o| o.radius.to_string()),
        ("--position", |o| {
            format!("{},{},{}", o.position[0], o.position[1], o.position[2])
        }),
        ("--velocity", |o| {
            format!("{},{},{}", o.velocity[0], o.velocity[1], o.velocity[2])
        }),
        ("--position-jitter", |o| o.position_jitter.to_string()),
        ("--velocity-jitter", |o| o.velocity_jitter.to_string()),
        ("--restitution", |o| o.restitution.to_string()),
        ("--seed", |o| o.seed.to_string()),
        ("--time-step", |o| o.time_step.to_string()),
        ("--gravity", |o| {
            format!("{},{},{}", o.gravity[0], o.gravity[1], o.gravity[2])
        }),
        ("--margin", |o| o.margin.to_string()),
        ("--max-substeps", |o| o.max_substeps.to_string()),
    ];
    let mut scenes: Vec<(String, SimOptions)> = BuiltinScene::all()
        .map(|s| (format!("--scene {s}"), s.sim_options()))
        .collect();
    scenes.push(("--mesh FILE".to_string(), SimOptions::default()));
    let shared = |show: Show| {
        let first = show(&scenes[0].1);
        scenes
            .iter()
            .all(|(_, o)| show(o) == first)
            .then_some(first)
    };
    let common: Vec<String> = fields
        .iter()
        .filter_map(|(name, show)| shared(*show).map(|v| format!("{name} {v}")))
        .collect();
    let mut text = format!(
        "Defaults (an option not given takes its scene's value); every scene: {}, --facing {}.",
        common.join(", "),
        SimOptions::default().facing
    );
    for (scene, options) in &scenes {
        let mesh = scene.starts_with("--mesh");
        let own: Vec<String> = fields
            .iter()
            .filter(|(_, show)| shared(*show).is_none())
            .map(|(name, show)| match *name {
                "--position" if mesh => format!("{name} above the middle of the mesh (below)"),
                _ => format!("{name} {}", show(options)),
            })
            .collect();
        text.push_str(&format!("\n  {scene}: {}", own.join(", ")));
    }
    text
}

/// Simulates, writes the trace and prints a summary.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let scene: SceneMesh = match &args.mesh {
        Some(path) => sim::load_obj(path)?,
        None => args.scene.mesh_with_terrain_cells(args.terrain_cells),
    };
    let mesh = scene
        .to_mesh()
        .with_context(|| format!("building scene `{}`", scene.name))?;
    if !mesh.degenerate().is_empty() {
        let first: Vec<String> = mesh
            .degenerate()
            .iter()
            .take(5)
            .map(|d| d.index.to_string())
            .collect();
        eprintln!(
            "warning: scene `{}`: {} left out (first: {})",
            scene.name,
            sweeptrace::numbers::counted(
                mesh.degenerate().len() as u64,
                "degenerate triangle",
                "degenerate triangles"
            ),
            first.join(", ")
        );
    }
    let mut defaults = match args.mesh {
        Some(_) => SimOptions::default(),
        None => args.scene.sim_options(),
    };
    if args.mesh.is_some() {
        // A ball above the middle of an unknown mesh.
        let (lo, hi) = mesh.bounds();
        let radius = args.radius.unwrap_or(defaults.radius);
        defaults.position = [
            0.5 * (lo.x + hi.x),
            0.5 * (lo.y + hi.y),
            hi.z + 2.0 * radius,
        ];
    }
    let options = args.sim_options(defaults);
    options.validate()?;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.mcap", scene.name)));
    let scene_msg = sim::scene_message(&scene, &options);

    let contact_distance = args.contact_distance.unwrap_or(options.radius / 10.0);
    // Queries, queries with a contact, contacts.
    let mut contacts = (0u64, 0u64, 0u64);
    let bar = progress_bar(options.frames);
    super::warn_unfinished(&output);
    let summary = write_trace_file_with_encoding(
        &output,
        args.encoding,
        |writer| -> anyhow::Result<SimSummary> {
            // The expectations are the core's, with the recording's margin and facing.
            writer.expected_source(&sweeptrace_source(
                &options.margin.to_string(),
                options.facing.as_str(),
            ))?;
            writer.scene(0, &scene_msg)?;
            let mut shown = 0;
            let summary = sim::simulate(&mesh, &options, |event| -> anyhow::Result<()> {
                writer.sweep(event.log_time_nanos, &event.sweep)?;
                writer.expected(event.log_time_nanos, &event.outcome)?;
                if args.contacts {
                    let (query, answer) = event.contacts(&mesh, contact_distance);
                    contacts.0 += 1;
                    contacts.1 += u64::from(!answer.contacts.is_empty());
                    contacts.2 += answer.contacts.len() as u64;
                    writer.contact(event.log_time_nanos, &query)?;
                    writer.expected_contacts(event.log_time_nanos, &answer)?;
                }
                if event.sim_frame >= shown + 256 {
                    shown = event.sim_frame;
                    bar.set_position(shown);
                }
                Ok(())
            })?;
            Ok(summary)
        },
    )
    .name_file_once("recording", output.display())?;
    bar.finish_and_clear();
    println!(
        "{}",
        summary_paragraph(
            &scene.name,
            mesh.triangles().len(),
            &options,
            &summary,
            &output.display().to_string()
        )
    );
    if args.contacts {
        println!(
            "Contact queries: {} (one after each sweep, contact distance {}), {} of them with a contact, {} in all.",
            contacts.0,
            sweeptrace::numbers::Shortest(contact_distance),
            contacts.1,
            sweeptrace::numbers::counted(contacts.2, "contact", "contacts")
        );
    }
    Ok(Exit::Success)
}

/// The closing summary of a recording, one paragraph.
pub fn summary_paragraph(
    scene: &str,
    triangles: usize,
    options: &SimOptions,
    s: &SimSummary,
    file: &str,
) -> String {
    use sweeptrace::numbers::counted;
    let mut text = format!(
        "Recorded {} of {} of radius {} over {} ({} with sub-steps) in scene `{scene}` \
         ({}, margin {}, facing {}, seed {}): {} ({} face, {} edge, {} vertex) and {}.",
        counted(s.sweeps, "sweep", "sweeps"),
        counted(u64::from(options.balls), "ball", "balls"),
        options.radius,
        counted(s.sim_frames, "frame", "frames"),
        counted(s.trace_frames, "trace frame", "trace frames"),
        counted(triangles as u64, "triangle", "triangles"),
        options.margin,
        options.facing,
        options.seed,
        counted(s.collisions(), "collision", "collisions"),
        s.face,
        s.edge,
        s.vertex,
        counted(s.none, "miss", "misses"),
    );
    if s.truncated > 0 {
        text.push_str(&format!(
            " {} ran out of sub-steps.",
            counted(s.truncated, "ball-frame", "ball-frames")
        ));
    }
    if !s.stopped.is_empty() {
        let left = s
            .stopped
            .iter()
            .filter(|b| b.reason == StopReason::LeftBounds)
            .count();
        let bad = s.stopped.len() - left;
        text.push_str(&format!(
            " {} left the play volume and stopped recording",
            counted(left as u64, "ball", "balls")
        ));
        if bad > 0 {
            text.push_str(&format!(", {bad} stopped on a non-finite value"));
        }
        text.push('.');
    }
    text.push_str(&format!(" Wrote {file}."));
    text
}

fn progress_bar(frames: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(frames), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} recording [{bar:40}] {pos}/{len} frames ({eta})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}
