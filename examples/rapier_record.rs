//! Records a trace from a real physics engine, Rapier (`rapier3d-f64`):
//! balls simulated by Rapier on a built-in scene or an OBJ mesh, and for
//! every ball and step the sweep Rapier's query pipeline tested and Rapier's
//! own answer for it, as the expected outcome.
//!
//! ```text
//! cargo run --example rapier_record -- --scene mini_golf -o rapier_mini_golf.mcap
//! cargo run --example rapier_record -- --mesh level.obj --radius 0.2 --position 0,0,5 -o level.mcap
//! sweeptrace check rapier_mini_golf.mcap --fields kind,alpha --tolerance 1e-5
//! ```
//!
//! Each step: the ball's centre before the step is `p0`, and `p1` is where
//! the step's motion would take it before contacts (Rapier's semi-implicit
//! Euler: `p0 + (v + g dt) dt`, what its CCD tests); the sweep `p0 → p1` is
//! written to `/sweep`, and Rapier's query pipeline casts the ball along it
//! (`QueryPipeline::cast_shape` against the fixed mesh, `max_time_of_impact`
//! 1, so the time of impact is `α`). Its answer goes to `/expected`: `α` (1
//! and kind `none` when nothing is hit), Rapier's normal (`normal1`, the
//! contact normal: from the witness on the mesh toward the ball), the
//! witness point on the mesh as the contact, the triangle that holds the
//! witness, and a kind read from that answer: `face` when Rapier's normal is
//! the triangle's own normal (within 1e-6 in its cosine), otherwise `vertex`
//! when the witness is at one of the triangle's corners and `edge` when it
//! is on one of its sides (within 1e-6 of the triangle's size), with that
//! corner or side as the feature. The balls do not collide with each other
//! (collision groups), like the balls of `sweeptrace record`. A ball is no
//! longer recorded once it leaves the scene's play volume.
//!
//! The trace names its expectations' source (the `sweeptrace.expected_source`
//! record): engine `rapier3d-f64`, the version linked, and the settings that
//! bear on its answers ([`rapier_source`]: the mesh's `fix_internal_edges`
//! flag, the contact skin, the time step and allowed linear error, the shape
//! cast's options and the kind's tolerance).
//!
//! The scene's starting positions, velocities, radius, time step, gravity
//! and restitution are those of `sweeptrace record --scene NAME` (the
//! built-in scene's defaults); `--mesh` uses `record`'s defaults with
//! `--radius` and `--position`. The output is written atomically (a
//! temporary file renamed when complete) and is deterministic for the same
//! options on the same machine. (The integration tests include this file
//! as a module and run [`run`].)

use std::path::PathBuf;
use std::process::ExitCode;

use rapier3d_f64::parry::query::{ShapeCastOptions, ShapeCastStatus};
use rapier3d_f64::parry::shape::{Ball, TriMeshFlags};
use rapier3d_f64::prelude::*;
use sweeptrace::core::Kind;
use sweeptrace::sim::obj::load_obj;
use sweeptrace::sim::scenes::SceneMesh;
use sweeptrace::sim::{BuiltinScene, SimOptions, initial_states, play_volume, scene_message};
use sweeptrace::trace::messages::{OutcomeMsg, SweepMsg};
use sweeptrace::trace::{ExpectedSource, write_trace_file};

/// Relative tolerance of the kind read from Rapier's answer (see the module
/// documentation).
const CLASSIFY_TOLERANCE: f64 = 1e-6;

const USAGE: &str = "\
usage: rapier_record (--scene NAME | --mesh FILE.obj) -o OUT.mcap [options]

  --scene NAME        a built-in scene (mini_golf, bowl, box, terrain, cube, triangle)
  --mesh FILE.obj     a Wavefront OBJ mesh instead
  -o, --output FILE   the trace to write
  --balls N           number of balls (default: the scene's)
  --frames N          simulation steps (default: the scene's)
  --seed N            seed of the balls' jitter (default 0)
  --radius R          radius of the balls (default: the scene's)
  --position X,Y,Z    ball 0's starting centre (default: the scene's)

example: rapier_record --scene mini_golf --balls 2 --frames 240 -o rapier_mini_golf.mcap";

/// The command line.
pub struct Args {
    /// The built-in scene, or
    pub scene: Option<BuiltinScene>,
    /// an OBJ mesh.
    pub mesh: Option<PathBuf>,
    /// The trace to write.
    pub output: PathBuf,
    /// Balls, frames, radius, time step, gravity, restitution.
    pub options: SimOptions,
}

fn parse_args() -> Result<Args, String> {
    let mut raw = std::env::args().skip(1);
    let (mut scene, mut mesh, mut output) = (None, None, None);
    let (mut balls, mut frames, mut seed, mut radius, mut position) =
        (None, None, None, None, None);
    while let Some(flag) = raw.next() {
        if flag == "-h" || flag == "--help" {
            println!("{USAGE}");
            std::process::exit(0);
        }
        let value = raw.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = |what: &str| -> Result<f64, String> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{what}: not a finite number: {value}"))
        };
        let count = |what: &str| -> Result<u64, String> {
            value
                .parse::<u64>()
                .map_err(|e| format!("{what}: {e}: {value}"))
        };
        match flag.as_str() {
            "--scene" => {
                scene = Some(BuiltinScene::from_name(&value).ok_or_else(|| {
                    format!("unknown scene {value}; built in: {}", BuiltinScene::names())
                })?)
            }
            "--mesh" => mesh = Some(PathBuf::from(&value)),
            "-o" | "--output" => output = Some(PathBuf::from(&value)),
            "--balls" => balls = Some(u32::try_from(count("--balls")?).map_err(|e| e.to_string())?),
            "--frames" => frames = Some(count("--frames")?),
            "--seed" => seed = Some(count("--seed")?),
            "--radius" => radius = Some(number("--radius")?),
            "--position" => {
                let parts: Vec<f64> = value
                    .split(',')
                    .map(|p| p.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
                    .collect::<Option<_>>()
                    .ok_or_else(|| format!("--position: expected X,Y,Z, got {value}"))?;
                let [x, y, z] = parts[..] else {
                    return Err(format!("--position: expected X,Y,Z, got {value}"));
                };
                position = Some([x, y, z]);
            }
            _ => return Err(format!("unknown option {flag}")),
        }
    }
    let output = output.ok_or("-o OUT.mcap is required")?;
    if scene.is_some() == mesh.is_some() {
        return Err("give one of --scene NAME or --mesh FILE.obj".to_string());
    }
    let mut options = scene.map(BuiltinScene::sim_options).unwrap_or_default();
    options.balls = balls.unwrap_or(options.balls);
    options.frames = frames.unwrap_or(options.frames);
    options.seed = seed.unwrap_or(options.seed);
    options.radius = radius.unwrap_or(options.radius);
    options.position = position.unwrap_or(options.position);
    // Rapier has no margin and no facing rule: the trace declares margin 0
    // and the default facing rule.
    options.margin = 0.0;
    options.validate().map_err(|e| e.to_string())?;
    Ok(Args {
        scene,
        mesh,
        output,
        options,
    })
}

fn vector(p: [f64; 3]) -> Vector {
    Vector::new(p[0], p[1], p[2])
}

fn array(v: Vector) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The kind and feature of a contact at `witness` on triangle `[a, b, c]`
/// whose contact normal is `normal` (see the module documentation).
fn classify(corners: [Vector; 3], witness: Vector, normal: Vector) -> (Kind, Option<u8>) {
    let [a, b, c] = corners;
    let face_normal = (b - a).cross(c - a).normalize();
    if normal.normalize().dot(face_normal).abs() >= 1.0 - CLASSIFY_TOLERANCE {
        return (Kind::Face, None);
    }
    let size = (b - a).length().max((c - b).length()).max((a - c).length());
    let near = CLASSIFY_TOLERANCE * size;
    if let Some(vertex) = corners
        .iter()
        .position(|&corner| (witness - corner).length() <= near)
    {
        return (Kind::Vertex, Some(vertex as u8));
    }
    // Edge i joins vertices i and i + 1 (docs/SEMANTICS.md): the side nearest
    // to the witness.
    let distance_to_side = |i: usize| {
        let (p, q) = (corners[i], corners[(i + 1) % 3]);
        let t = ((witness - p).dot(q - p) / (q - p).length_squared()).clamp(0.0, 1.0);
        (witness - (p + (q - p) * t)).length()
    };
    let edge = (0..3)
        .min_by(|&i, &j| distance_to_side(i).total_cmp(&distance_to_side(j)))
        .unwrap_or(0);
    (Kind::Edge, Some(edge as u8))
}

/// The expectations' source: Rapier, its version, and the settings of this
/// recording that bear on its answers.
pub fn rapier_source(
    world: &PhysicsWorld,
    mesh: ColliderHandle,
    cast: &ShapeCastOptions,
) -> ExpectedSource {
    let collider = &world.colliders[mesh];
    let fix_internal_edges = collider
        .shape()
        .as_trimesh()
        .is_some_and(|t| t.flags().contains(TriMeshFlags::FIX_INTERNAL_EDGES));
    let parameters = &world.integration_parameters;
    ExpectedSource::new("rapier3d-f64", rapier3d_f64::VERSION)
        .setting("fix_internal_edges", fix_internal_edges)
        .setting("contact_skin", collider.contact_skin())
        .setting("dt", parameters.dt)
        .setting("allowed_linear_error", parameters.allowed_linear_error())
        .setting("ccd", true)
        .setting("cast_target_distance", cast.target_distance)
        .setting("cast_stop_at_penetration", cast.stop_at_penetration)
        .setting("kind_tolerance", CLASSIFY_TOLERANCE)
}

/// Writes the trace; returns the sweeps, Rapier's hits, and the sweeps
/// that start in contact (written without an expectation).
pub fn run(args: Args) -> Result<(u64, u64, u64), String> {
    let scene: SceneMesh = match (&args.scene, &args.mesh) {
        (Some(builtin), _) => builtin.mesh(),
        (None, Some(path)) => load_obj(path).map_err(|e| e.to_string())?,
        (None, None) => unreachable!("checked by parse_args"),
    };
    let options = &args.options;
    let core_mesh = scene
        .to_mesh()
        .map_err(|e| format!("scene {}: {e}", scene.name))?;
    let (volume_min, volume_max) = play_volume(&core_mesh, options.radius);
    let vertices: Vec<Vector> = scene.vertices.iter().map(|&v| vector(v)).collect();
    let indices: Vec<[u32; 3]> = scene
        .triangles
        .iter()
        .map(|t| t.map(|i| i as u32))
        .collect();

    let mut world = PhysicsWorld {
        gravity: vector(options.gravity),
        integration_parameters: IntegrationParameters {
            dt: options.time_step,
            ..IntegrationParameters::default()
        },
        ..PhysicsWorld::default()
    };
    // The mesh: group 1; the balls: group 2, colliding with group 1 only.
    let mesh_groups = InteractionGroups::new(Group::GROUP_1, Group::ALL, InteractionTestMode::And);
    let ball_groups =
        InteractionGroups::new(Group::GROUP_2, Group::GROUP_1, InteractionTestMode::And);
    let mesh_collider = ColliderBuilder::trimesh(vertices, indices)
        .map_err(|e| format!("Rapier refuses the mesh {}: {e}", scene.name))?
        .collision_groups(mesh_groups)
        .restitution(options.restitution);
    let (_, mesh_handle) = world.insert(RigidBodyBuilder::fixed(), mesh_collider);
    let mut balls = Vec::new();
    for (position, velocity) in initial_states(options) {
        let body = RigidBodyBuilder::dynamic()
            .translation(vector(position))
            .linvel(vector(velocity))
            .ccd_enabled(true);
        let collider = ColliderBuilder::ball(options.radius)
            .restitution(options.restitution)
            .collision_groups(ball_groups);
        let (handle, _) = world.insert(body, collider);
        balls.push(Some(handle));
    }

    let shape = Ball::new(options.radius);
    let cast = ShapeCastOptions {
        max_time_of_impact: 1.0,
        target_distance: 0.0,
        // A ball that starts touching and moves away hits nothing (the
        // core's tests ignore such starts too).
        stop_at_penetration: false,
        compute_impact_geometry_on_penetration: true,
    };
    let step_nanos = options.time_step_nanos();
    let trimesh_triangles = &scene.triangles;
    let source = rapier_source(&world, mesh_handle, &cast);
    let counts = write_trace_file(&args.output, |trace| {
        trace.expected_source(&source)?;
        trace.scene(0, &scene_message(&scene, options))?;
        let (mut sweeps, mut hits, mut starting_in_contact) = (0u64, 0u64, 0u64);
        let gravity = vector(options.gravity);
        let dt = options.time_step;
        for frame in 0..options.frames {
            let log_time_nanos = frame * step_nanos;
            let pipeline = world.query_pipeline_with_filter(QueryFilter::only_fixed());
            for (ball, handle) in balls.iter_mut().enumerate() {
                let Some(h) = *handle else {
                    continue;
                };
                // The step's motion before contacts: Rapier's integration
                // (semi-implicit Euler: gravity, then the velocity).
                let body = &world.bodies[h];
                let p0 = body.translation();
                let p1 = p0 + (body.linvel() + gravity * dt) * dt;
                let inside =
                    |p: Vector| (0..3).all(|k| p[k] >= volume_min[k] && p[k] <= volume_max[k]);
                if !inside(p0) || !inside(p1) {
                    *handle = None;
                    continue;
                }
                let ball = ball as u32;
                trace.sweep(
                    log_time_nanos,
                    &SweepMsg {
                        frame,
                        ball,
                        radius: options.radius,
                        p0: array(p0),
                        p1: array(p1),
                    },
                )?;
                sweeps += 1;
                let answer =
                    pipeline.cast_shape(&Pose::from_translation(p0), p1 - p0, &shape, cast);
                let outcome = match answer {
                    None => OutcomeMsg::miss(frame, ball),
                    // Rapier's answer for a ball that starts inside the mesh
                    // (its solver lets resting balls sink by its allowed
                    // error): already touching, time of impact 0. The core
                    // has no such answer (it reports contacts that begin
                    // during the sweep), so no expectation is written.
                    Some((_, hit))
                        if hit.status == ShapeCastStatus::PenetratingOrWithinTargetDist =>
                    {
                        starting_in_contact += 1;
                        continue;
                    }
                    Some((collider, hit)) => {
                        hits += 1;
                        // The mesh is fixed at the origin: world = its frame.
                        let witness = hit.witness1;
                        let trimesh = world.colliders[collider]
                            .shape()
                            .as_trimesh()
                            .expect("the only fixed collider is the mesh");
                        let (_, (triangle, _)) =
                            trimesh.project_local_point_and_get_location(witness, false);
                        let corners = trimesh_triangles[triangle as usize]
                            .map(|i| vector(scene.vertices[i as usize]));
                        let (kind, feature) = classify(corners, witness, hit.normal1);
                        OutcomeMsg {
                            frame,
                            ball,
                            alpha: hit.time_of_impact.clamp(0.0, 1.0),
                            kind,
                            triangle: Some(Some(triangle)),
                            feature: Some(feature),
                            normal: Some(Some(array(hit.normal1))),
                            contact: Some(Some(array(witness))),
                        }
                    }
                };
                trace.expected(log_time_nanos, &outcome)?;
            }
            world.step();
        }
        Ok::<_, sweeptrace::trace::TraceError>((sweeps, hits, starting_in_contact))
    })
    .map_err(|e| e.to_string())?;
    Ok(counts)
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(args) => args,
        Err(message) => {
            eprintln!("error: {message}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let output = args.output.display().to_string();
    match run(args) {
        Ok((sweeps, hits, starting_in_contact)) => {
            println!(
                "wrote {output}: {sweeps} sweeps, {hits} hits found by Rapier's shape cast, \
                 {starting_in_contact} sweeps starting in contact (no expectation)"
            );
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
