//! `sweeptrace record`: built-in scenes, OBJ loading, the simulation and
//! the sample traces it recorded.

use std::collections::{BTreeSet, HashSet};
use std::io::Cursor;
use std::path::PathBuf;

use libtest_mimic::Trial;
use nalgebra::{Point3, Vector3};

use sweeptrace::core::{Facing, Kind, Mesh, Options, Sweep, sweep_mesh};
use sweeptrace::sim::scenes::{self, BuiltinScene, SceneMesh};
use sweeptrace::sim::{self, SimError, SimOptions};
use sweeptrace::trace::{
    EventBody, OutcomeMsg, SceneMsg, SweepMsg, TraceEvent, TraceReader, TraceWriter,
};

use crate::{ensure, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(same_seed_gives_identical_bytes),
        trial!(regenerate_script_reproduces_every_sample_trace),
        trial!(expected_equals_sweep_mesh_rerun_on_recorded_sweeps),
        trial!(no_nan_and_balls_stay_in_the_play_volume),
        trial!(runaway_balls_are_stopped_not_nan),
        trial!(sub_steps_are_separate_frames_in_time_order),
        trial!(invalid_options_are_errors),
        trial!(scenes_have_no_degenerate_triangles),
        trial!(scenes_face_the_play_side),
        trial!(terrain_has_at_least_100k_triangles),
        trial!(obj_loads),
        trial!(bad_obj_is_a_clear_error),
        trial!(sample_traces_cover_every_kind),
    ]
}

type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// A small scene for the simulation tests (the terrain at 32 cells).
fn scene(name: &str) -> SceneMesh {
    BuiltinScene::from_name(name)
        .expect("built-in scene")
        .mesh_with_terrain_cells(32)
}

/// Records `scene` with `options` into memory, as `sweeptrace record` does.
fn record(scene: &SceneMesh, options: &SimOptions) -> anyhow::Result<Vec<u8>> {
    let mesh = scene.to_mesh()?;
    let mut writer = TraceWriter::new(Cursor::new(Vec::new()))?;
    writer.scene(0, &sim::scene_message(scene, options))?;
    sim::simulate(&mesh, options, |event| -> Result<(), BoxError> {
        writer.sweep(event.log_time_nanos, &event.sweep)?;
        writer.expected(event.log_time_nanos, &event.outcome)?;
        Ok(())
    })
    .map_err(|e| anyhow::anyhow!(e))?;
    Ok(writer.finish()?.into_inner())
}

/// Every sweep and outcome of a simulation, without a trace.
fn events(mesh: &Mesh, options: &SimOptions) -> anyhow::Result<(Vec<sim::Event>, sim::SimSummary)> {
    let mut out = Vec::new();
    let summary = sim::simulate(mesh, options, |e| -> Result<(), SimError> {
        out.push(*e);
        Ok(())
    })
    .map_err(|e| anyhow::anyhow!(e))?;
    Ok((out, summary))
}

struct Read {
    scenes: Vec<SceneMsg>,
    sweeps: Vec<(u64, SweepMsg)>,
    expected: Vec<OutcomeMsg>,
}

fn read(bytes: &[u8], name: &str) -> anyhow::Result<Read> {
    let mut r = Read {
        scenes: Vec::new(),
        sweeps: Vec::new(),
        expected: Vec::new(),
    };
    for event in TraceReader::new(Cursor::new(bytes), name) {
        let event = event?;
        match event.body {
            EventBody::Scene(scene) => r.scenes.push(scene),
            EventBody::Sweep(sweep) => r.sweeps.push((event.header.log_time_nanos, sweep)),
            EventBody::Expected(outcome) => r.expected.push(outcome),
            EventBody::Contact(_) | EventBody::ExpectedContacts(_) => {}
        }
    }
    Ok(r)
}

fn same_seed_gives_identical_bytes() -> anyhow::Result<()> {
    for name in ["mini_golf", "terrain"] {
        let s = scene(name);
        let options = SimOptions {
            frames: 120,
            ..BuiltinScene::from_name(name)
                .expect("built-in scene")
                .sim_options()
        };
        let a = record(&s, &options)?;
        let b = record(&s, &options)?;
        ensure!(
            a == b,
            "{name}: two recordings with seed {} differ",
            options.seed
        );
        let c = record(
            &s,
            &SimOptions {
                seed: options.seed + 1,
                ..options
            },
        )?;
        ensure!(
            a != c,
            "{name}: a different seed gave the same bytes (is the jitter used?)"
        );
    }
    Ok(())
}

fn expected_equals_sweep_mesh_rerun_on_recorded_sweeps() -> anyhow::Result<()> {
    for (name, margin, facing) in [
        ("bowl", 0.02, Facing::NonStrict),
        ("cube", 0.05, Facing::NonStrict),
        ("box", 0.0, Facing::Strict),
        ("terrain", 0.0, Facing::NonStrict),
    ] {
        let s = scene(name);
        let options = SimOptions {
            frames: 150,
            margin,
            facing,
            ..BuiltinScene::from_name(name)
                .expect("built-in scene")
                .sim_options()
        };
        let bytes = record(&s, &options)?;
        let trace = read(&bytes, name)?;
        ensure!(
            trace.scenes.len() == 1,
            "{name}: {} scenes",
            trace.scenes.len()
        );
        let scene_msg = &trace.scenes[0];
        ensure!(
            scene_msg.margin == margin && scene_msg.facing == facing,
            "{name}: scene options not recorded"
        );
        let mesh = Mesh::new(scene_msg.vertices.clone(), &scene_msg.triangles)?;
        let core = Options {
            margin: scene_msg.margin,
            facing: scene_msg.facing,
            ..Options::default()
        };
        ensure!(!trace.sweeps.is_empty(), "{name}: no sweeps");
        ensure!(
            trace.sweeps.len() == trace.expected.len(),
            "{name}: {} sweeps but {} expectations",
            trace.sweeps.len(),
            trace.expected.len()
        );
        for ((_, sweep), expected) in trace.sweeps.iter().zip(&trace.expected) {
            let outcome = sweep_mesh(&mesh, &Sweep::new(sweep.p0, sweep.p1, sweep.radius), &core)
                .map_err(|e| anyhow::anyhow!("{name} frame {}: {e}", sweep.frame))?;
            let again = OutcomeMsg::from_outcome(sweep.frame, sweep.ball, &outcome);
            ensure!(
                again == *expected,
                "{name} frame {} ball {}: recorded {expected:?}, re-run {again:?}",
                sweep.frame,
                sweep.ball
            );
        }
    }
    Ok(())
}

fn finite(p: &[f64; 3]) -> bool {
    p.iter().all(|v| v.is_finite())
}

fn check_bounded(name: &str, mesh: &Mesh, options: &SimOptions) -> anyhow::Result<sim::SimSummary> {
    let (lo, hi) = sim::play_volume(mesh, options.radius);
    let (events, summary) = events(mesh, options)?;
    ensure!(!events.is_empty(), "{name}: no sweeps");
    let mut stopped: HashSet<u32> = HashSet::new();
    for s in &summary.stopped {
        stopped.insert(s.ball);
    }
    for e in &events {
        let sw = &e.sweep;
        ensure!(
            finite(&sw.p0) && finite(&sw.p1),
            "{name} frame {}: non-finite sweep {sw:?}",
            sw.frame
        );
        ensure!(
            e.outcome.alpha.is_finite(),
            "{name} frame {}: alpha {}",
            sw.frame,
            e.outcome.alpha
        );
        if let Some(Some(n)) = e.outcome.normal {
            ensure!(finite(&n), "{name} frame {}: normal {n:?}", sw.frame);
        }
        // Every sweep starts inside the play volume (a ball that left it
        // records nothing more).
        let p0 = Point3::from(sw.p0);
        ensure!(
            (0..3).all(|i| p0[i] >= lo[i] && p0[i] <= hi[i]),
            "{name} frame {} ball {}: starts outside the play volume at {:?}",
            sw.frame,
            sw.ball,
            sw.p0
        );
    }
    ensure!(
        stopped.len() == summary.stopped.len(),
        "{name}: a ball was stopped twice: {:?}",
        summary.stopped
    );
    Ok(summary)
}

fn no_nan_and_balls_stay_in_the_play_volume() -> anyhow::Result<()> {
    for name in BuiltinScene::all().map(BuiltinScene::name) {
        let s = scene(name);
        let mesh = s.to_mesh()?;
        let options = SimOptions {
            frames: 200,
            ..BuiltinScene::from_name(name)
                .expect("built-in scene")
                .sim_options()
        };
        let summary = check_bounded(name, &mesh, &options)?;
        if name == "box" {
            ensure!(
                summary.stopped.is_empty(),
                "box: a ball escaped the closed box: {:?}",
                summary.stopped
            );
        }
    }
    Ok(())
}

fn runaway_balls_are_stopped_not_nan() -> anyhow::Result<()> {
    let s = scene("triangle");
    let mesh = s.to_mesh()?;
    let options = SimOptions {
        balls: 3,
        velocity: [1e6, -3e5, 2e5],
        velocity_jitter: 1e5,
        gravity: [0.0, 0.0, -1e9],
        frames: 1000,
        ..BuiltinScene::Triangle.sim_options()
    };
    let summary = check_bounded("triangle", &mesh, &options)?;
    ensure!(
        summary.stopped.len() == 3,
        "expected all 3 balls stopped, got {:?}",
        summary.stopped
    );
    ensure!(
        summary.sim_frames < 1000,
        "the simulation should end once every ball stopped"
    );
    Ok(())
}

fn sub_steps_are_separate_frames_in_time_order() -> anyhow::Result<()> {
    let s = scene("box");
    let mesh = s.to_mesh()?;
    let options = SimOptions {
        frames: 300,
        ..BuiltinScene::Box.sim_options()
    };
    let (events, summary) = events(&mesh, &options)?;
    let mut seen = HashSet::new();
    let mut last = (0u64, 0u64);
    for e in &events {
        ensure!(
            seen.insert((e.sweep.frame, e.sweep.ball)),
            "(frame {}, ball {}) recorded twice",
            e.sweep.frame,
            e.sweep.ball
        );
        ensure!(
            (e.sweep.frame, e.log_time_nanos) >= last && e.log_time_nanos >= last.1,
            "frame {} at {} ns after frame {} at {} ns",
            e.sweep.frame,
            e.log_time_nanos,
            last.0,
            last.1
        );
        ensure!(
            e.sweep.frame == e.outcome.frame && e.sweep.ball == e.outcome.ball,
            "outcome does not match its sweep"
        );
        last = (e.sweep.frame, e.log_time_nanos);
    }
    ensure!(
        summary.trace_frames > summary.sim_frames,
        "no sub-steps happened in the box: {summary:?}"
    );
    ensure!(
        summary.sweeps == events.len() as u64,
        "summary counts {} sweeps, {} seen",
        summary.sweeps,
        events.len()
    );
    Ok(())
}

fn invalid_options_are_errors() -> anyhow::Result<()> {
    let base = SimOptions::default();
    let cases: Vec<(&str, SimOptions)> = vec![
        (
            "margin",
            SimOptions {
                margin: base.radius,
                ..base
            },
        ),
        (
            "margin",
            SimOptions {
                margin: -0.1,
                ..base
            },
        ),
        (
            "radius",
            SimOptions {
                radius: f64::NAN,
                ..base
            },
        ),
        (
            "radius",
            SimOptions {
                radius: 0.0,
                ..base
            },
        ),
        ("balls", SimOptions { balls: 0, ..base }),
        (
            "time_step",
            SimOptions {
                time_step: 0.0,
                ..base
            },
        ),
        (
            "restitution",
            SimOptions {
                restitution: 1.5,
                ..base
            },
        ),
        (
            "velocity",
            SimOptions {
                velocity: [f64::INFINITY, 0.0, 0.0],
                ..base
            },
        ),
        (
            "max_substeps",
            SimOptions {
                max_substeps: 0,
                ..base
            },
        ),
    ];
    let mesh = scene("cube").to_mesh()?;
    for (field, options) in cases {
        match sim::simulate::<SimError>(&mesh, &options, |_| Ok(())) {
            Err(SimError::Invalid { field: f, .. }) if f == field => {}
            other => {
                anyhow::bail!("{field}: expected an error naming `{field}`, got {other:?}");
            }
        }
    }
    Ok(())
}

fn scenes_have_no_degenerate_triangles() -> anyhow::Result<()> {
    for name in BuiltinScene::all().map(BuiltinScene::name) {
        let s = BuiltinScene::from_name(name)
            .map(BuiltinScene::mesh)
            .context(format!("{name} missing"))?;
        ensure!(s.name == *name, "scene `{name}` is named `{}`", s.name);
        let mesh = s.to_mesh().map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        ensure!(
            mesh.degenerate().is_empty(),
            "{name}: degenerate triangles {:?}",
            mesh.degenerate()
        );
        ensure!(
            mesh.triangles().len() == s.triangles.len(),
            "{name}: {} usable of {}",
            mesh.triangles().len(),
            s.triangles.len()
        );
        // Cheap and deterministic.
        ensure!(
            BuiltinScene::from_name(name).map(BuiltinScene::mesh) == Some(s),
            "{name}: two builds differ"
        );
    }
    ensure!(
        BuiltinScene::from_name("no_such_scene")
            .map(BuiltinScene::mesh)
            .is_none(),
        "unknown names must give None"
    );
    Ok(())
}

/// Checks that a point just in front of every triangle is where the ball
/// plays and a point just behind it is not (only the second where the front
/// is `hidden`: covered by another solid, like the green under the ramp).
fn check_sides(
    name: &str,
    plays: impl Fn(&Point3<f64>) -> bool,
    hidden: impl Fn(&Point3<f64>) -> bool,
) -> anyhow::Result<()> {
    let s = BuiltinScene::from_name(name)
        .map(BuiltinScene::mesh)
        .context(format!("{name} missing"))?;
    let mesh = s.to_mesh()?;
    for t in mesh.triangles() {
        let [a, b, c] = t.vertices;
        let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
        let front = centroid + t.normal * 1e-3;
        let back = centroid - t.normal * 1e-3;
        ensure!(
            (hidden(&front) || plays(&front)) && !plays(&back),
            "{name}: triangle {} (normal {:?}) faces away from where the ball plays",
            t.index,
            t.normal
        );
    }
    Ok(())
}

fn scenes_face_the_play_side() -> anyhow::Result<()> {
    // The closed box: inward.
    let h = scenes::BOX_HALF_WIDTH;
    check_sides("box", |p| p.iter().all(|v| v.abs() < h), |_| false)?;
    let mesh = scenes::closed_box().to_mesh()?;
    for t in mesh.triangles() {
        ensure!(
            t.normal
                .dot(&(Point3::origin() - t.vertices[0]))
                .is_sign_positive(),
            "box: triangle {} points outward",
            t.index
        );
    }
    // The bowl: above its surface (the paraboloid is convex, so a point
    // just above a flat triangle is above the surface only near its centre;
    // use the triangle's plane instead: the normal points up).
    let bowl = scenes::bowl().to_mesh()?;
    for t in bowl.triangles() {
        ensure!(
            t.normal.z.is_sign_positive(),
            "bowl: triangle {} faces down ({:?})",
            t.index,
            t.normal
        );
        // Up and toward the axis.
        let c = (t.vertices[0].coords + t.vertices[1].coords + t.vertices[2].coords) / 3.0;
        let outward = Vector3::new(c.x, c.y, 0.0);
        ensure!(
            (t.normal.dot(&outward) - 1e-12).is_sign_negative(),
            "bowl: triangle {} leans outward",
            t.index
        );
    }
    // The terrain: up.
    let terrain = scenes::terrain(16).to_mesh()?;
    ensure!(
        terrain.triangles().iter().all(|t| t.normal.z > 0.0),
        "terrain: a triangle faces down"
    );
    // The mini-golf hole: above the green (and outside the ramp), or in the cup.
    let [length, width] = scenes::GREEN;
    let in_ramp = |p: &Point3<f64>| {
        p.x > 3.0 && p.x < 5.5 && p.y > 1.0 && p.y < 3.0 && p.z < 0.25 * (p.x - 3.0) / 2.5
    };
    check_sides(
        "mini_golf",
        |p| {
            let on_green = p.x > 0.0 && p.x < length && p.y > 0.0 && p.y < width && p.z > 0.0;
            let in_cup =
                (p.x - 10.0).abs() < 0.3 && (p.y - 2.0).abs() < 0.3 && p.z > -0.4 && p.z < 0.4;
            (on_green && !in_ramp(p)) || in_cup
        },
        |p| in_ramp(p) && p.z < 0.01,
    )?;
    // The cube: outward.
    check_sides("cube", |p| p.iter().any(|v| v.abs() > 1.0), |_| false)?;
    Ok(())
}

fn terrain_has_at_least_100k_triangles() -> anyhow::Result<()> {
    let t = BuiltinScene::from_name("terrain")
        .map(BuiltinScene::mesh)
        .context("terrain missing")?;
    ensure!(
        t.triangles.len() >= 100_000,
        "terrain has {} triangles",
        t.triangles.len()
    );
    let mesh = t.to_mesh()?;
    ensure!(
        mesh.degenerate().is_empty(),
        "terrain: {} degenerate",
        mesh.degenerate().len()
    );
    let small = scenes::terrain(10);
    ensure!(
        small.triangles.len() == 200,
        "terrain(10) has {} triangles",
        small.triangles.len()
    );
    ensure!(
        small.vertices.len() == 121,
        "terrain(10) has {} vertices",
        small.vertices.len()
    );
    ensure!(
        scenes::terrain(0).triangles.len() == 2,
        "terrain(0) is clamped to one cell"
    );
    // The deterministic sine is a sine.
    for i in -200..200 {
        let x = f64::from(i) * 0.37;
        ensure!(
            ((scenes::det_sin(x) - x.sin()).abs() - 1e-9).is_sign_negative(),
            "det_sin({x}) = {}",
            scenes::det_sin(x)
        );
    }
    Ok(())
}

fn obj_loads() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("ramp.obj");
    let text = "# a unit quad facing +z and a triangle in another object\n\
                o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n\
                o tri\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 5 6 7\n";
    std::fs::write(&path, text)?;
    let scene = sim::load_obj(&path)?;
    ensure!(scene.name == "ramp", "named `{}`", scene.name);
    ensure!(
        scene.triangles.len() == 3,
        "{} triangles",
        scene.triangles.len()
    );
    ensure!(
        scene.vertices.len() == 7,
        "{} vertices",
        scene.vertices.len()
    );
    let mesh = scene.to_mesh()?;
    ensure!(
        mesh.triangles().iter().all(|t| t.normal.z > 0.99),
        "OBJ faces must keep their winding (+z)"
    );
    // The loaded scene records like a built-in one.
    let options = SimOptions {
        frames: 60,
        position: [0.25, 0.25, 2.0],
        radius: 0.1,
        ..SimOptions::default()
    };
    let (events, summary) = events(&mesh, &options)?;
    ensure!(
        summary.face > 0,
        "a ball dropped on the OBJ's top triangle must hit it: {summary:?}"
    );
    ensure!(!events.is_empty(), "no events");
    Ok(())
}

fn bad_obj_is_a_clear_error() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let cases = [
        (
            "parse.obj",
            "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n",
            "not a valid Wavefront OBJ file: line 2 (`v 1 zero 0`)",
        ),
        (
            "range.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            "not a valid Wavefront OBJ file: line 4 (`f 1 2 9`)",
        ),
        (
            "empty.obj",
            "# nothing here\nv 0 0 0\n",
            "holds no triangle",
        ),
    ];
    for (file, text, want) in cases {
        let path = dir.path().join(file);
        std::fs::write(&path, text)?;
        match sim::load_obj(&path) {
            Ok(s) => {
                anyhow::bail!(
                    "{file}: loaded {} triangles, expected an error",
                    s.triangles.len()
                );
            }
            Err(e) => {
                let msg = e.to_string();
                ensure!(
                    msg.contains(want) && msg.contains(file),
                    "{file}: unclear error `{msg}`"
                );
            }
        }
    }
    let missing = dir.path().join("missing.obj");
    match sim::load_obj(&missing) {
        Err(e) => ensure!(
            e.to_string().contains("missing.obj: cannot open: "),
            "missing file: `{e}`"
        ),
        Ok(_) => return Err(anyhow::anyhow!("a missing file loaded")),
    }
    Ok(())
}

fn sample_traces_cover_every_kind() -> anyhow::Result<()> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("traces");
    let mut kinds = BTreeSet::new();
    let (mut several_balls, mut margin, mut strict, mut count) = (false, false, false, 0);
    let entries = std::fs::read_dir(&dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    for entry in entries {
        let path = entry?.path();
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if !(name.starts_with("record_") && name.ends_with(".mcap")) {
            continue;
        }
        count += 1;
        let bytes = std::fs::read(&path)?;
        ensure!(
            bytes.len() < 1 << 20,
            "{name} is {} bytes (over 1 MiB)",
            bytes.len()
        );
        let trace = read(&bytes, &name)?;
        for s in &trace.scenes {
            margin |= s.margin > 0.0;
            strict |= s.facing == Facing::Strict;
        }
        several_balls |= trace.sweeps.iter().any(|(_, s)| s.ball > 0);
        kinds.extend(trace.expected.iter().map(|o| o.kind));
        ensure!(
            trace.expected.len() == trace.sweeps.len(),
            "{name}: not every sweep has an expectation"
        );
    }
    ensure!(
        count >= 4,
        "expected at least 4 recorded sample traces in traces/, found {count}"
    );
    for kind in [Kind::Face, Kind::Edge, Kind::Vertex, Kind::None] {
        ensure!(
            kinds.contains(&kind),
            "no sample trace has a `{kind}` outcome (kinds: {kinds:?})"
        );
    }
    ensure!(several_balls, "no sample trace has several balls");
    ensure!(margin, "no sample trace has a non-zero margin");
    ensure!(strict, "no sample trace uses the strict facing rule");
    Ok(())
}

/// `scripts/regenerate_traces.sh` rebuilds `traces/` bit for bit: each of
/// its `record NAME ARGS` lines, run with this build into a temporary
/// directory, gives the committed `traces/NAME` byte for byte, and every
/// committed trace is made by one of them. (A sample written by an older
/// recorder, such as `"feature": 0` where `record` now writes `null` for a
/// face, fails here: regenerate the samples with the script.)
fn regenerate_script_reproduces_every_sample_trace() -> anyhow::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let script = std::fs::read_to_string(root.join("scripts/regenerate_traces.sh"))
        .map_err(|e| anyhow::anyhow!("scripts/regenerate_traces.sh: {e}"))?;
    let commands: Vec<(String, Vec<String>)> = script
        .lines()
        .filter_map(|l| l.strip_prefix("record "))
        .map(|rest| {
            let mut words = rest.split_whitespace().map(str::to_string);
            let name = words.next().unwrap_or_default();
            (name, words.collect())
        })
        .collect();
    ensure!(
        commands.len() >= 5,
        "record lines found in the script: {commands:?}"
    );
    let dir = tempfile::tempdir()?;
    let mut problems = Vec::new();
    let mut made = BTreeSet::new();
    for (name, args) in &commands {
        let fresh = dir.path().join(name);
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
            .arg("record")
            .args(args)
            .arg("-o")
            .arg(&fresh)
            .output()?;
        ensure!(
            out.status.success(),
            "record {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
        made.insert(name.clone());
        let fresh = std::fs::read(&fresh)?;
        let committed = std::fs::read(root.join("traces").join(name))
            .map_err(|e| anyhow::anyhow!("traces/{name}: {e}"))?;
        if fresh != committed {
            let at = fresh
                .iter()
                .zip(&committed)
                .position(|(a, b)| a != b)
                .unwrap_or(fresh.len().min(committed.len()));
            let why = match (trace_events(&fresh), trace_events(&committed)) {
                (Ok(a), Ok(b)) if a == b => "the same messages, other bytes (the container \
                     or library string changed)"
                    .to_string(),
                (Ok(a), Ok(b)) => match a.iter().zip(&b).position(|(x, y)| x != y) {
                    Some(i) => format!(
                        "message {i} differs: the script makes {:?}, the committed file holds {:?}",
                        a[i], b[i]
                    ),
                    None => format!("{} messages made, {} committed", a.len(), b.len()),
                },
                (a, b) => format!("reading them: {:?} / {:?}", a.err(), b.err()),
            };
            problems.push(format!(
                "traces/{name}: {} bytes made, {} committed, first difference at byte {at}: {why}",
                fresh.len(),
                committed.len()
            ));
        }
    }
    for entry in std::fs::read_dir(root.join("traces"))? {
        let name = entry?.file_name();
        let name = name.to_string_lossy();
        if name.ends_with(".mcap") && !made.contains(name.as_ref()) {
            problems.push(format!("traces/{name} is not made by the script"));
        }
    }
    ensure!(
        problems.is_empty(),
        "regenerate with scripts/regenerate_traces.sh:\n{}",
        problems.join("\n")
    );
    Ok(())
}

/// Every trace event of `bytes`, in order.
fn trace_events(bytes: &[u8]) -> anyhow::Result<Vec<TraceEvent>> {
    TraceReader::new(bytes, "<memory>")
        .collect::<Result<Vec<_>, _>>()
        .map_err(anyhow::Error::from)
}
