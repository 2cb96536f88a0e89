//! Records a trace from a real physics engine, Rapier (`rapier3d-f64`):
//! balls simulated by Rapier on a built-in scene or an OBJ mesh, and for
//! every ball and step the sweep Rapier's query pipeline tested and Rapier's
//! own answer for it, as the expected outcome.
//!
//! ```text
//! cargo run --example rapier_record -- --scene mini_golf -o rapier_mini_golf.mcap
//! cargo run --example rapier_record -- --mesh level.obj --radius 0.2 --position 0,0,5 -o level.mcap
//! sweeptrace check rapier_mini_golf.mcap --normal contact --tolerance 1e-5 --contact-tolerance 1e-5
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
//! `--fix-internal-edges` builds Rapier's mesh with
//! `TriMeshFlags::FIX_INTERNAL_EDGES`. After each step the recorder judges
//! the solver's contacts between each ball and the mesh (those touching, a
//! point at distance ≤ 0) with `check`'s ghost-contact rule and prints how
//! many are ghosts. `--expect contacts` writes the solver's contacts as
//! contact queries instead of the shape cast's expectations: for each ball
//! and step a `/contact` query at the ball's centre where the step's
//! contacts were computed (its start), with Rapier's prediction distance,
//! and every point of its manifolds against the mesh as the answer
//! (`/expected_contacts`), which `check` judges against the core's contact
//! set (examples/rapier/README.md, "Ghost contacts on a floor and a ramp").
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
use sweeptrace::replay::SceneState;
use sweeptrace::replay::ghost::{GHOST_DEGREES, GhostJudgement, judge_ghost};
use sweeptrace::sim::load_obj;
use sweeptrace::sim::scenes::BuiltinScene;
use sweeptrace::sim::scenes::SceneMesh;
use sweeptrace::sim::{SimOptions, initial_states, play_volume, scene_message};
use sweeptrace::trace::{ContactMsg, ContactPointMsg, ContactsMsg};
use sweeptrace::{ExpectedSource, OutcomeMsg, SweepMsg, Topology, write_trace_file};

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
  --velocity X,Y,Z    ball 0's starting velocity (default: the scene's)
  --fix-internal-edges
                      build the mesh with TriMeshFlags::FIX_INTERNAL_EDGES
  --expect cast|contacts
                      the expectations: Rapier's shape cast along each sweep
                      (default), or the solver's contacts at each step's
                      start as contact queries (`sweeptrace check` judges
                      them and lists their ghost contacts)

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
    /// Build Rapier's mesh with `TriMeshFlags::FIX_INTERNAL_EDGES`.
    pub fix_internal_edges: bool,
    /// What the expectations are.
    pub expect: Expect,
}

/// What a sweep's expectation is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Expect {
    /// Rapier's shape cast of the ball along the sweep (`--expect cast`).
    #[default]
    Cast,
    /// The solver's contacts at the start of the step (`--expect
    /// contacts`): a contact query per ball and step, answered with every
    /// point of the solver's manifolds against the mesh (the sweeps get no
    /// expectation).
    Contacts,
}

/// What the solver did at the seams, counted over the run: its contact
/// manifolds against the mesh that touch (a point at distance ≤ 0), and
/// those a `check` of them would call ghost contacts (an edge or vertex contact on an internal flat or concave place
/// whose normal leans more than `GHOST_DEGREES` from the faces').
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SolverContacts {
    /// Touching manifolds (one per triangle) between a ball and the mesh,
    /// summed over the steps.
    pub manifolds: u64,
    /// Of those, the ghost contacts.
    pub ghosts: u64,
}

/// What [`run`] wrote and saw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Sweeps written.
    pub sweeps: u64,
    /// Rapier's shape-cast hits among them.
    pub hits: u64,
    /// Sweeps that start in contact (written without an expectation).
    pub starting_in_contact: u64,
    /// The solver's contacts.
    pub solver: SolverContacts,
}

/// `X,Y,Z` as three finite numbers.
fn triple(flag: &str, value: &str) -> Result<[f64; 3], String> {
    let parts: Option<Vec<f64>> = value
        .split(',')
        .map(|p| p.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    match parts.as_deref() {
        Some(&[x, y, z]) => Ok([x, y, z]),
        _ => Err(format!("{flag}: expected X,Y,Z, got {value}")),
    }
}

fn parse_args() -> Result<Args, String> {
    let mut raw = std::env::args().skip(1);
    let (mut scene, mut mesh, mut output) = (None, None, None);
    let (mut balls, mut frames, mut seed, mut radius, mut position, mut velocity) =
        (None, None, None, None, None, None);
    let mut fix_internal_edges = false;
    let mut expect = Expect::Cast;
    while let Some(flag) = raw.next() {
        if flag == "-h" || flag == "--help" {
            println!("{USAGE}");
            std::process::exit(0);
        }
        if flag == "--fix-internal-edges" {
            fix_internal_edges = true;
            continue;
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
            "--position" => position = Some(triple("--position", &value)?),
            "--velocity" => velocity = Some(triple("--velocity", &value)?),
            "--expect" => {
                expect = match value.as_str() {
                    "cast" => Expect::Cast,
                    "contacts" => Expect::Contacts,
                    _ => return Err(format!("--expect: cast or contacts, got {value}")),
                }
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
    options.velocity = velocity.unwrap_or(options.velocity);
    // Rapier has no margin and no facing rule: the trace declares margin 0
    // and the default facing rule.
    options.margin = 0.0;
    options.validate().map_err(|e| e.to_string())?;
    Ok(Args {
        scene,
        mesh,
        output,
        options,
        fix_internal_edges,
        expect,
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
/// A trace of solver contacts (`--expect contacts`) says so in the setting
/// `expectations = solver_contacts`; without it the expectations are shape
/// casts.
pub fn rapier_source(
    world: &PhysicsWorld,
    mesh: ColliderHandle,
    cast: &ShapeCastOptions,
    expect: Expect,
) -> ExpectedSource {
    let collider = &world.colliders[mesh];
    let fix_internal_edges = collider
        .shape()
        .as_trimesh()
        .is_some_and(|t| t.flags().contains(TriMeshFlags::FIX_INTERNAL_EDGES));
    let parameters = &world.integration_parameters;
    let source = ExpectedSource::new("rapier3d-f64", rapier3d_f64::VERSION);
    let source = match expect {
        Expect::Cast => source,
        Expect::Contacts => source.setting("expectations", "solver_contacts"),
    };
    source
        .setting("fix_internal_edges", fix_internal_edges)
        .setting("contact_skin", collider.contact_skin())
        .setting("dt", parameters.dt)
        .setting("allowed_linear_error", parameters.allowed_linear_error())
        .setting("ccd", true)
        .setting("cast_target_distance", cast.target_distance)
        .setting("cast_stop_at_penetration", cast.stop_at_penetration)
        .setting("kind_tolerance", CLASSIFY_TOLERANCE)
}

/// One of the solver's contacts between a ball and the mesh (a point of
/// one of its manifolds).
struct SolverContact {
    /// As an engine's contact.
    point: ContactPointMsg,
    /// Whether it touches (distance ≤ 0; the others are speculative).
    touching: bool,
    /// Whether `check`'s rule (`judge_ghost`) calls it a ghost contact.
    ghost: bool,
}

/// The points of the solver's manifolds between the ball collider `ball`
/// (of ball number `ball_number`, at `frame`) and the mesh after a step:
/// each with its triangle, the kind and feature read from its point on the
/// mesh (as for a shape cast's answer), its normal from the mesh toward the
/// ball and its distance (the separation), judged by `check`'s ghost rule.
fn solver_contacts(
    world: &PhysicsWorld,
    (ball, frame, ball_number): (ColliderHandle, u64, u32),
    mesh: ColliderHandle,
    scene: &SceneState,
    corners_of: impl Fn(u32) -> Option<[Vector; 3]>,
) -> Vec<SolverContact> {
    let Some(pair) = world.contact_pair(ball, mesh) else {
        return Vec::new();
    };
    let mesh_first = pair.collider1 == mesh;
    let mut out = Vec::new();
    for manifold in pair.manifolds() {
        let (triangle, normal) = if mesh_first {
            (manifold.subshape1, manifold.data.normal)
        } else {
            (manifold.subshape2, -manifold.data.normal)
        };
        let Some(corners) = corners_of(triangle) else {
            continue;
        };
        for point in &manifold.points {
            // The mesh is fixed at the origin: its local frame is the world's.
            let witness = if mesh_first {
                point.local_p1
            } else {
                point.local_p2
            };
            let (kind, feature) = classify(corners, witness, normal);
            let mut outcome = OutcomeMsg::hit(frame, ball_number, 0.0, kind)
                .triangle(triangle)
                .normal(array(normal))
                .contact(array(witness));
            if let Some(feature) = feature {
                outcome = outcome.feature(feature);
            }
            let ghost = matches!(
                judge_ghost(
                    &scene.mesh,
                    &scene.topology,
                    &outcome,
                    0,
                    None,
                    GHOST_DEGREES
                ),
                GhostJudgement::Ghost(_)
            );
            out.push(SolverContact {
                point: ContactPointMsg {
                    triangle,
                    kind: Some(kind),
                    feature,
                    point: Some(array(witness)),
                    normal: Some(array(normal)),
                    separation: Some(point.dist),
                },
                touching: point.dist <= 0.0,
                ghost,
            });
        }
    }
    out
}

/// Writes the trace; returns what it wrote and what the solver did.
pub fn run(args: Args) -> Result<Counts, String> {
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
    let builder = if args.fix_internal_edges {
        ColliderBuilder::trimesh_with_flags(vertices, indices, TriMeshFlags::FIX_INTERNAL_EDGES)
    } else {
        ColliderBuilder::trimesh(vertices, indices)
    };
    let mesh_collider = builder
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
        let (handle, collider) = world.insert(body, collider);
        balls.push(Some((handle, collider)));
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
    let source = rapier_source(&world, mesh_handle, &cast, args.expect);
    let message = scene_message(&scene, options);
    let scene_state = SceneState {
        number: 0,
        index: 0,
        log_time_nanos: 0,
        name: message.name.clone(),
        mesh: core_mesh.clone(),
        topology: Topology::new(&message.vertices, &message.triangles)
            .map_err(|e| format!("scene {}: {e}", scene.name))?,
        options: sweeptrace::core::Options {
            margin: message.margin,
            facing: message.facing,
            ..Default::default()
        },
        normals: Default::default(),
        conventions: Default::default(),
    };
    let corners_of = |t: u32| {
        let triangle = trimesh_triangles.get(t as usize)?;
        Some(triangle.map(|i| vector(scene.vertices[i as usize])))
    };
    let counts = write_trace_file(&args.output, |trace| {
        trace.expected_source(&source)?;
        trace.scene(0, &message)?;
        let mut counts = Counts::default();
        let gravity = vector(options.gravity);
        let dt = options.time_step;
        // Each ball's centre at the start of the step: where the solver's
        // contacts of the step were computed.
        let mut starts: Vec<Option<Vector>> = vec![None; balls.len()];
        for frame in 0..options.frames {
            let log_time_nanos = frame * step_nanos;
            let pipeline = world.query_pipeline_with_filter(QueryFilter::only_fixed());
            for (ball, handle) in balls.iter_mut().enumerate() {
                starts[ball] = None;
                let Some((h, _)) = *handle else {
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
                starts[ball] = Some(p0);
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
                counts.sweeps += 1;
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
                        counts.starting_in_contact += 1;
                        continue;
                    }
                    Some((collider, hit)) => {
                        counts.hits += 1;
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
                        let outcome =
                            OutcomeMsg::hit(frame, ball, hit.time_of_impact.clamp(0.0, 1.0), kind)
                                .triangle(triangle)
                                .normal(array(hit.normal1))
                                .contact(array(witness));
                        match feature {
                            Some(feature) => outcome.feature(feature),
                            None => outcome,
                        }
                    }
                };
                if args.expect == Expect::Cast {
                    trace.expected(log_time_nanos, &outcome)?;
                }
            }
            world.step();
            for (ball, handle) in balls.iter().enumerate() {
                let Some((_, collider)) = *handle else {
                    continue;
                };
                let contacts = solver_contacts(
                    &world,
                    (collider, frame, ball as u32),
                    mesh_handle,
                    &scene_state,
                    corners_of,
                );
                counts.solver.manifolds += contacts.iter().filter(|c| c.touching).count() as u64;
                counts.solver.ghosts +=
                    contacts.iter().filter(|c| c.touching && c.ghost).count() as u64;
                if let (Expect::Contacts, Some(start)) = (args.expect, starts[ball]) {
                    let ball = ball as u32;
                    trace.contact(
                        log_time_nanos,
                        &ContactMsg {
                            frame,
                            ball,
                            radius: options.radius,
                            centre: array(start),
                            distance: 0.0,
                        },
                    )?;
                    trace.expected_contacts(
                        log_time_nanos,
                        &ContactsMsg {
                            frame,
                            ball,
                            contacts: contacts
                                .into_iter()
                                .filter(|c| c.touching)
                                .map(|c| c.point)
                                .collect(),
                        },
                    )?;
                }
            }
        }
        Ok::<_, sweeptrace::TraceError>(counts)
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
        Ok(c) => {
            println!(
                "wrote {output}: {} sweeps, {} hits found by Rapier's shape cast, \
                 {} sweeps starting in contact (no expectation)",
                c.sweeps, c.hits, c.starting_in_contact
            );
            println!(
                "Rapier's solver: {} ball-mesh contact manifolds over the steps, {} of them ghost contacts \
                 (an edge or vertex contact on an internal flat or concave edge, normal more than {GHOST_DEGREES}° \
                 from the faces')",
                c.solver.manifolds, c.solver.ghosts
            );
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
