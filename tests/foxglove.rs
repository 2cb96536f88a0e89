//! `replay --foxglove`: the Foxglove file reads back with the mcap crate
//! (channels, schemas, every message's content) and with Python's `mcap`;
//! when Node and tests/foxglove's packages are installed, every message is
//! validated against Foxglove's published schemas; the command leaves no
//! file behind on error.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use libtest_mimic::{Completion, Trial};
use serde_json::Value;

use sweeptrace::core::{Facing, Kind};
use sweeptrace::foxglove::{
    FoxgloveOptions, FoxgloveWriter, LOG_SCHEMA_JSON, SCENE_UPDATE_SCHEMA_JSON,
    SWEEP_NUMBERS_SCHEMA_JSON, rotation_from_x,
};
use sweeptrace::replay::{Detail, ReplayOptions, replay_events};
use sweeptrace::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceReader, TraceWriter};

use crate::support::run_bin;
use crate::{ensure, os, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(foxglove_file_reads_back_with_the_mcap_crate),
        trial!(arrow_rotation_takes_x_to_the_normal),
        trial!(foxglove_mesh_has_edge_classes_and_defects),
        trial!(python_and_node_read_and_validate_the_foxglove_file),
        trial!(replay_foxglove_writes_only_the_foxglove_file),
        trial!(replay_foxglove_errors_name_the_file_and_leave_no_partial_file),
        trial!(replay_foxglove_keeps_what_was_read_of_a_truncated_trace),
        trial!(replay_foxglove_killed_leaves_no_partial_target),
        trial!(replay_foxglove_carries_the_judged_contact_queries),
        trial!(a_new_scene_deletes_the_contact_queries_drawn_before_it),
    ]
}

/// Set to `1` (CI does, after `npm ci` in tests/foxglove) to make the
/// schema validation with Node fail, instead of being skipped, when Node or
/// the packages are missing.
const REQUIRE_NODE: &str = "SWEEPTRACE_REQUIRE_NODE";
/// As in trace_io: Python's `mcap` must be importable when set to `1`.
const REQUIRE_PYTHON: &str = "SWEEPTRACE_REQUIRE_PYTHON";

const TRACE_NAME: &str = "two_scenes.mcap";

fn triangle(name: &str, size: f64) -> SceneMsg {
    SceneMsg {
        name: Some(name.to_string()),
        vertices: vec![[0.0, 0.0, 0.0], [size, 0.0, 0.0], [0.0, size, 0.0]],
        triangles: vec![[0, 1, 2]],
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

fn down(frame: u64, ball: u32, x: f64) -> SweepMsg {
    SweepMsg {
        frame,
        ball,
        radius: 0.5,
        p0: [x, 1.0, 3.0],
        p1: [x, 1.0, -3.0],
    }
}

fn expected(frame: u64, ball: u32, alpha: f64, kind: Kind) -> OutcomeMsg {
    OutcomeMsg {
        frame,
        ball,
        alpha,
        kind,
        triangle: None,
        feature: None,
        normal: None,
        contact: None,
    }
}

/// Two scenes; ball 0 hits the triangle's face at α = 5/12 each frame,
/// ball 1 misses. Frame 1's expectation for ball 0 (α = 0.3) diverges.
fn two_scene_trace() -> anyhow::Result<Vec<u8>> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &triangle("first", 4.0))?;
    for frame in 0..3u64 {
        let t = 1_000_000_000 + frame * 500_000_000;
        if frame == 2 {
            w.scene(t, &triangle("second", 8.0))?;
        }
        w.sweep(t, &down(frame, 0, 1.0))?;
        let alpha = if frame == 1 { 0.3 } else { 5.0 / 12.0 };
        w.expected(t, &expected(frame, 0, alpha, Kind::Face))?;
        if frame < 2 {
            w.sweep(t, &down(frame, 1, 10.0))?;
            w.expected(t, &expected(frame, 1, 1.0, Kind::None))?;
        }
    }
    Ok(w.finish()?.into_inner())
}

/// The Foxglove file of `trace`, through the library.
fn foxglove_bytes(trace: &[u8]) -> anyhow::Result<Vec<u8>> {
    let options = ReplayOptions {
        explain: Some(Detail::Primary),
        ..ReplayOptions::default()
    };
    let mut writer = FoxgloveWriter::new(
        Cursor::new(Vec::new()),
        "test.foxglove.mcap",
        FoxgloveOptions {
            trace_name: TRACE_NAME.to_string(),
            ..FoxgloveOptions::default()
        },
    )?;
    for event in replay_events(TraceReader::new(trace, TRACE_NAME), options) {
        let event = event?;
        writer.event(&event)?;
    }
    Ok(writer.finish()?.into_inner())
}

/// Every message: (topic, schema name, log_time, JSON).
pub(crate) fn messages(bytes: &[u8]) -> anyhow::Result<Vec<(String, String, u64, Value)>> {
    let mut out = Vec::new();
    for m in mcap::MessageStream::new(bytes)? {
        let m = m?;
        let schema = m
            .channel
            .schema
            .as_ref()
            .map(|s| s.name.clone())
            .unwrap_or_default();
        let json: Value = serde_json::from_slice(&m.data)
            .map_err(|e| anyhow::anyhow!("{}: not JSON: {e}", m.channel.topic))?;
        out.push((m.channel.topic.clone(), schema, m.log_time, json));
    }
    Ok(out)
}

pub(crate) fn on<'a>(all: &'a [(String, String, u64, Value)], topic: &str) -> Vec<&'a Value> {
    all.iter()
        .filter(|(t, ..)| t == topic)
        .map(|(.., v)| v)
        .collect()
}

fn foxglove_file_reads_back_with_the_mcap_crate() -> anyhow::Result<()> {
    let bytes = foxglove_bytes(&two_scene_trace()?)?;

    // Channels, schemas, encodings; the embedded schemas are the checked-in copies.
    let summary = mcap::Summary::read(&bytes)?.context("no summary")?;
    let channels: BTreeMap<String, (String, String, String)> = summary
        .channels
        .values()
        .map(|c| {
            let s = c.schema.as_ref().expect("schema");
            (
                c.topic.clone(),
                (
                    s.name.clone(),
                    s.encoding.clone(),
                    c.message_encoding.clone(),
                ),
            )
        })
        .collect();
    let want: BTreeMap<String, (String, String, String)> = [
        ("/mesh", "foxglove.SceneUpdate"),
        ("/balls", "foxglove.SceneUpdate"),
        ("/sweeps", "foxglove.SceneUpdate"),
        ("/contacts", "foxglove.SceneUpdate"),
        ("/expected_outcome", "foxglove.SceneUpdate"),
        ("/ghosts", "foxglove.SceneUpdate"),
        ("/decisions", "foxglove.Log"),
        ("/numbers", "sweeptrace.SweepNumbers"),
    ]
    .into_iter()
    .map(|(t, s)| {
        (
            t.to_string(),
            (s.to_string(), "jsonschema".to_string(), "json".to_string()),
        )
    })
    .collect();
    ensure!(channels == want, "channels {channels:?}, want {want:?}");
    for schema in summary.schemas.values() {
        let text = match schema.name.as_str() {
            "foxglove.SceneUpdate" => SCENE_UPDATE_SCHEMA_JSON,
            "foxglove.Log" => LOG_SCHEMA_JSON,
            "sweeptrace.SweepNumbers" => SWEEP_NUMBERS_SCHEMA_JSON,
            other => anyhow::bail!("unexpected schema {other}"),
        };
        ensure!(
            schema.data.as_ref() == text.as_bytes(),
            "schema {} is not the embedded copy",
            schema.name
        );
    }

    let all = messages(&bytes)?;
    let times: Vec<u64> = all.iter().map(|(_, _, t, _)| *t).collect();
    ensure!(
        times.windows(2).all(|w| w[0] <= w[1]),
        "messages not in log_time order: {times:?}"
    );
    // 5 sweeps; the second scene also clears the 5 per-sweep scene channels.
    for (topic, n) in [
        ("/mesh", 2),
        ("/balls", 6),
        ("/sweeps", 6),
        ("/contacts", 6),
        ("/expected_outcome", 6),
        ("/ghosts", 6),
        ("/decisions", 5),
        ("/numbers", 5),
    ] {
        ensure!(
            on(&all, topic).len() == n,
            "{topic}: {} messages, want {n}",
            on(&all, topic).len()
        );
    }

    // The meshes: one entity `mesh`, frame-locked, three indices, three points.
    let meshes = on(&all, "/mesh");
    for (m, size) in meshes.iter().zip([4.0, 8.0]) {
        let e = &m["entities"][0];
        ensure!(
            e["id"] == "mesh" && e["frame_id"] == "world",
            "mesh entity {e}"
        );
        ensure!(e["frame_locked"] == true, "mesh not frame-locked");
        ensure!(
            e["lifetime"] == serde_json::json!({"sec": 0, "nsec": 0}),
            "mesh lifetime {}",
            e["lifetime"]
        );
        let t = &e["triangles"][0];
        ensure!(
            t["indices"] == serde_json::json!([0, 1, 2]),
            "indices {}",
            t["indices"]
        );
        ensure!(t["points"][1]["x"] == size, "points {}", t["points"]);
        // The triangle's edges: one entity, the boundary's.
        let edges = &m["entities"][1];
        ensure!(
            m["entities"].as_array().map(Vec::len) == Some(2)
                && edges["id"] == "mesh/edges/boundary"
                && edges["lines"][0]["indices"] == serde_json::json!([0, 1, 0, 2, 1, 2]),
            "edges {edges}"
        );
    }
    ensure!(
        meshes[0]["entities"][0]["timestamp"] == serde_json::json!({"sec": 0, "nsec": 0}),
        "first mesh timestamp"
    );
    // Timestamps are the trace's log_time: frame 1 is at 1.5 s.
    ensure!(
        on(&all, "/decisions")[2]["timestamp"]
            == serde_json::json!({"sec": 1, "nsec": 500_000_000}),
        "timestamp of frame 1: {}",
        on(&all, "/decisions")[2]["timestamp"]
    );
    // The clear at the second scene.
    let balls = on(&all, "/balls");
    let clears: Vec<&&Value> = balls
        .iter()
        .filter(|b| b["deletions"].as_array().is_some_and(|d| !d.is_empty()))
        .collect();
    ensure!(
        clears.len() == 1 && clears[0]["deletions"][0]["type"] == 1,
        "want one delete-all on /balls, got {clears:?}"
    );

    // Ball 0 of frame 0: at p0, at the contact (z = 3 - 6 · 5/12 = 0.5), at p1.
    let first = &balls[0]["entities"][0];
    ensure!(first["id"] == "ball/0", "first ball {}", first["id"]);
    let zs: Vec<f64> = first["spheres"]
        .as_array()
        .context("spheres")?
        .iter()
        .map(|s| s["pose"]["position"]["z"].as_f64().unwrap_or(f64::NAN))
        .collect();
    ensure!(zs == [3.0, 0.5, -3.0], "ball centres z {zs:?}");
    ensure!(
        first["spheres"][0]["size"]["x"] == 1.0,
        "diameter {}",
        first["spheres"][0]["size"]
    );
    // Ball 1 misses: two spheres, and its contact entity is deleted.
    ensure!(
        balls[1]["entities"][0]["spheres"].as_array().map(Vec::len) == Some(2),
        "a miss draws the ball at p0 and p1 only"
    );
    let contacts = on(&all, "/contacts");
    ensure!(
        contacts[0]["entities"][0]["arrows"][0]["pose"]["position"]
            == serde_json::json!({"x": 1.0, "y": 1.0, "z": 0.0}),
        "normal arrow at the contact: {}",
        contacts[0]["entities"][0]["arrows"][0]
    );
    ensure!(
        contacts[1]["deletions"][0]["id"] == "contact/1"
            && contacts[1]["deletions"][0]["type"] == 0,
        "a miss deletes its contact: {}",
        contacts[1]
    );

    // The decisions: WARNING only at the divergent sweep (frame 1, ball 0),
    // with check's report of it.
    let decisions = on(&all, "/decisions");
    for (i, d) in decisions.iter().enumerate() {
        let divergent = i == 2;
        ensure!(
            d["level"] == if divergent { 3 } else { 2 },
            "decision {i}: level {} ({})",
            d["level"],
            d["message"]
        );
        ensure!(d["file"] == TRACE_NAME, "file {}", d["file"]);
    }
    let text = decisions[2]["message"].as_str().unwrap_or_default();
    ensure!(
        text.starts_with("frame 1 ball 0: face collision at α = 0.41667")
            && text.contains("alpha: expected 0.3, got 0.41667")
            && text.contains("why not:"),
        "divergent decision text: {text}"
    );
    ensure!(
        decisions[0]["name"] == "ball 0",
        "name {}",
        decisions[0]["name"]
    );
    let expected_outcome = on(&all, "/expected_outcome");
    let e = &expected_outcome[2]["entities"][0];
    ensure!(
        e["id"] == "expected/0" && e["spheres"][0]["pose"]["position"]["z"] == 3.0 - 6.0 * 0.3,
        "expected ball at α = 0.3: {e}"
    );
    ensure!(
        expected_outcome[0]["entities"]
            .as_array()
            .is_some_and(Vec::is_empty),
        "no expected entity where the sweep matches"
    );

    // The numbers: α and the face test's numbers; the miss has no test numbers.
    let numbers = on(&all, "/numbers");
    ensure!(
        numbers[0]["alpha"] == 5.0 / 12.0 && numbers[0]["kind"] == "face",
        "numbers {}",
        numbers[0]
    );
    ensure!(
        numbers[0]["face"]["h0"] == 3.0 && numbers[0]["face"]["beta"] == 5.0 / 12.0,
        "face numbers {}",
        numbers[0]["face"]
    );
    ensure!(
        numbers[2]["failed"] == 1 && numbers[2]["expected_alpha"] == 0.3,
        "divergent numbers {}",
        numbers[2]
    );
    ensure!(
        numbers[1]["kind"] == "none" && numbers[1]["alpha"] == 1.0 && numbers[1]["failed"] == 0,
        "miss numbers {}",
        numbers[1]
    );
    Ok(())
}

/// The mesh update of a floor with a flipped triangle: the previous
/// scene's entities deleted, then the mesh, an entity per edge class it has
/// (a line list, two indices per edge, in the class's colour) and one per
/// defect kind with one text per defect.
fn foxglove_mesh_has_edge_classes_and_defects() -> anyhow::Result<()> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &crate::support::flipped_floor())?;
    let trace = w.finish()?.into_inner();
    let all = messages(&foxglove_bytes(&trace)?)?;
    let meshes = on(&all, "/mesh");
    ensure!(meshes.len() == 1, "{} mesh updates", meshes.len());
    let update = meshes[0];
    ensure!(
        update["deletions"][0]["type"] == 1,
        "deletions {}",
        update["deletions"]
    );
    let entities = update["entities"].as_array().context("no entities")?;
    let ids: Vec<&str> = entities.iter().filter_map(|e| e["id"].as_str()).collect();
    ensure!(
        ids == [
            "mesh",
            "mesh/edges/boundary",
            "mesh/edges/flat",
            "mesh/defects/flipped"
        ],
        "entity ids {ids:?}"
    );
    let indices = |i: usize| entities[i]["lines"][0]["indices"].as_array().map(Vec::len);
    ensure!(
        indices(1) == Some(2 * 12) && indices(2) == Some(2 * 21),
        "edge indices: boundary {:?}, flat {:?}",
        indices(1),
        indices(2)
    );
    ensure!(
        entities[1]["lines"][0]["color"] != entities[2]["lines"][0]["color"],
        "boundary and flat edges in one colour"
    );
    let texts = entities[3]["texts"].as_array().context("no texts")?;
    ensure!(
        texts.len() == 1
            && texts[0]["text"] == "flipped triangle 9"
            && entities[3]["spheres"].as_array().map(Vec::len) == Some(1),
        "defect texts {texts:?}"
    );
    // At the flipped triangle's centroid.
    let p = &texts[0]["pose"]["position"];
    let centroid = [(1.0 + 1.0 + 2.0) / 3.0, (1.0 + 2.0 + 2.0) / 3.0];
    ensure!(
        p["x"]
            .as_f64()
            .is_some_and(|x| (x - centroid[0]).abs() < 1e-12)
            && p["y"]
                .as_f64()
                .is_some_and(|y| (y - centroid[1]).abs() < 1e-12),
        "defect at {p}, centroid {centroid:?}"
    );
    Ok(())
}

fn arrow_rotation_takes_x_to_the_normal() -> anyhow::Result<()> {
    use nalgebra::{Quaternion, UnitQuaternion, Vector3};
    for n in [
        Vector3::new(0.0, 0.0, 1.0),
        Vector3::new(-1.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.6, -0.8, 0.0),
        Vector3::new(1.0, 2.0, -2.0) / 3.0,
    ] {
        let q = rotation_from_x(&n);
        let q = UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z));
        let x = q * Vector3::x();
        ensure!(
            (x - n).norm() < 1e-12,
            "rotation of +x is {x:?}, want {n:?}"
        );
    }
    Ok(())
}

fn run(cmd: &mut std::process::Command) -> anyhow::Result<std::process::Output> {
    cmd.output()
        .map_err(|e| anyhow::anyhow!("running {cmd:?}: {e}"))
}

fn output_text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Whether `var` is set to `1`.
fn required(var: &str) -> bool {
    std::env::var_os(var).is_some_and(|v| v == "1")
}

/// Reads `file` back with Python's `mcap` (scripts/foxglove_dump.py: the
/// channels, and `scenes` scenes and `sweeps` sweeps), dumping its messages
/// to `dump`, and validates every message against Foxglove's published
/// schemas with Node (tests/foxglove/validate.mjs). Returns why a step
/// was skipped (Python's `mcap`, or Node or its packages, missing and not
/// required), `None` when everything ran; `dump` exists when Python ran.
pub(crate) fn validate_foxglove_file(
    file: &Path,
    scenes: u64,
    sweeps: u64,
    dump: &Path,
) -> anyhow::Result<Option<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let python_missing = match std::process::Command::new("python3")
        .args(["-c", "import mcap"])
        .output()
    {
        Ok(o) if o.status.success() => None,
        Ok(_) => Some("python3 cannot import the `mcap` package".to_string()),
        Err(e) => Some(format!("python3 cannot be run ({e})")),
    };
    if let Some(missing) = python_missing {
        if required(REQUIRE_PYTHON) {
            anyhow::bail!("{missing}, and {REQUIRE_PYTHON}=1 requires it");
        }
        return Ok(Some(format!(
            "skipped: {missing}; {REQUIRE_PYTHON}=1 makes this a failure"
        )));
    }
    let script = root.join("scripts/foxglove_dump.py");
    let ok = run(std::process::Command::new("python3")
        .arg(&script)
        .arg(file)
        .args([
            "--scenes",
            &scenes.to_string(),
            "--sweeps",
            &sweeps.to_string(),
        ])
        .arg("--dump")
        .arg(dump))?;
    ensure!(
        ok.status.success(),
        "foxglove_dump.py: {}",
        output_text(&ok)
    );
    let packages = root.join("tests/foxglove/node_modules/@foxglove/schemas");
    let node_missing = match std::process::Command::new("node").arg("--version").output() {
        Ok(o) if o.status.success() && packages.is_dir() => None,
        Ok(o) if o.status.success() => {
            Some("tests/foxglove has no node_modules (run `npm ci` there)".to_string())
        }
        _ => Some("node cannot be run".to_string()),
    };
    if let Some(missing) = node_missing {
        if required(REQUIRE_NODE) {
            anyhow::bail!("{missing}, and {REQUIRE_NODE}=1 requires it");
        }
        return Ok(Some(format!(
            "Python read the file; the schema validation was skipped: {missing}; \
             {REQUIRE_NODE}=1 makes this a failure"
        )));
    }
    let validate = root.join("tests/foxglove/validate.mjs");
    let node = run(std::process::Command::new("node").arg(&validate).arg(dump))?;
    ensure!(
        node.status.success(),
        "validate.mjs: {}",
        output_text(&node)
    );
    Ok(None)
}

fn python_and_node_read_and_validate_the_foxglove_file() -> anyhow::Result<Completion> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir()?;
    let file = dir.path().join("two_scenes.foxglove.mcap");
    std::fs::write(&file, foxglove_bytes(&two_scene_trace()?)?)?;
    let dump = dir.path().join("dump.jsonl");
    let skipped = validate_foxglove_file(&file, 2, 5, &dump)?;
    if dump.is_file() {
        let bad = run(std::process::Command::new("python3")
            .arg(root.join("scripts/foxglove_dump.py"))
            .arg(&file)
            .args(["--scenes", "2", "--sweeps", "6"]))?;
        ensure!(
            !bad.status.success(),
            "foxglove_dump.py accepted a wrong count"
        );
    }
    if let Some(why) = skipped {
        return Ok(Completion::ignored_with(why));
    }
    let validate = root.join("tests/foxglove/validate.mjs");
    // And it can fail: a Log level outside the schema's.
    let text = std::fs::read_to_string(&dump)?;
    let broken = dir.path().join("broken.jsonl");
    std::fs::write(&broken, text.replacen("\"level\": 2", "\"level\": 7", 1))?;
    let node = run(std::process::Command::new("node")
        .arg(&validate)
        .arg(&broken))?;
    ensure!(
        !node.status.success(),
        "validate.mjs accepted a Log level of 7: {}",
        output_text(&node)
    );
    Ok(Completion::Completed)
}

fn sample_trace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_cube_corner_margin.mcap")
}

/// The names of the entries of `dir`, sorted.
fn entries(dir: &Path) -> anyhow::Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    Ok(names)
}

fn replay_foxglove_writes_only_the_foxglove_file() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let out = run(crate::support::bin()
        .current_dir(dir.path())
        .arg("replay")
        .arg(sample_trace())
        .args(["--foxglove", "out.mcap", "--frames", "20..40"]))?;
    ensure!(
        out.status.code() == Some(0),
        "exit {:?}: {}",
        out.status.code(),
        output_text(&out)
    );
    // No default .rrd besides it.
    ensure!(
        entries(dir.path())? == ["out.mcap"],
        "files written: {:?}",
        entries(dir.path())?
    );
    let bytes = std::fs::read(dir.path().join("out.mcap"))?;
    let all = messages(&bytes)?;
    let frames: Vec<u64> = on(&all, "/numbers")
        .iter()
        .filter_map(|n| n["frame"].as_u64())
        .collect();
    ensure!(
        !frames.is_empty() && frames.iter().all(|f| (20..40).contains(f)),
        "frames {frames:?}"
    );
    ensure!(
        output_text(&out).contains("wrote the Foxglove file out.mcap"),
        "{}",
        output_text(&out)
    );
    Ok(())
}

fn replay_foxglove_errors_name_the_file_and_leave_no_partial_file() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let bad = dir.path().join("bad.mcap");
    let target = dir.path().join("out.mcap");
    // A target in a directory that does not exist: an error naming it.
    let nowhere = dir.path().join("missing/out.mcap");
    let (code, _, stderr) = run_bin(os!(
        "replay",
        sample_trace().as_os_str(),
        "--foxglove",
        nowhere.as_os_str()
    ))?;
    ensure!(code == 2, "exit {code}: {stderr}");
    ensure!(
        stderr.contains("missing/out.mcap"),
        "error does not name the target: {stderr}"
    );
    ensure!(
        entries(dir.path())?.is_empty(),
        "left behind: {:?}",
        entries(dir.path())?
    );
    // Data that is not MCAP: an error (exit 2) that leaves no output at all
    // (only a trace that ends early keeps what was read), and no `wrote`.
    std::fs::write(&bad, b"this is not an MCAP file at all")?;
    let (code, _, stderr) = run_bin(os!(
        "replay",
        bad.as_os_str(),
        "--foxglove",
        target.as_os_str()
    ))?;
    ensure!(code == 2, "exit {code}: {stderr}");
    ensure!(
        stderr.contains("bad.mcap") && !stderr.contains("wrote"),
        "error does not name the trace, or says it wrote: {stderr}"
    );
    ensure!(
        entries(dir.path())? == ["bad.mcap"],
        "left behind: {:?}",
        entries(dir.path())?
    );
    // A target that is a directory is refused, naming it.
    let (code, _, stderr) = run_bin(os!(
        "replay",
        sample_trace().as_os_str(),
        "--foxglove",
        dir.path().as_os_str()
    ))?;
    ensure!(code == 2, "exit {code} for a directory target: {stderr}");
    ensure!(
        stderr.contains("not a regular file"),
        "directory target: {stderr}"
    );
    ensure!(
        entries(dir.path())? == ["bad.mcap"],
        "left behind: {:?}",
        entries(dir.path())?
    );
    Ok(())
}

fn replay_foxglove_keeps_what_was_read_of_a_truncated_trace() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let bytes = std::fs::read(sample_trace())?;
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3])?;
    let target = dir.path().join("out.mcap");
    let (code, _, stderr) = run_bin(os!(
        "replay",
        cut.as_os_str(),
        "--foxglove",
        target.as_os_str()
    ))?;
    ensure!(code == 3, "exit {code}: {stderr}");
    let written = std::fs::read(&target)?;
    let all = messages(&written)?;
    ensure!(
        !on(&all, "/numbers").is_empty() && on(&all, "/mesh").len() == 1,
        "the sweeps read before the cut are in the file"
    );
    ensure!(
        mcap::Summary::read(&written)?.is_some(),
        "the file written from a truncated trace is complete (summary)"
    );
    Ok(())
}

/// `replay --foxglove` killed (SIGKILL) at several moments: the target is
/// absent or a complete file (its summary reads), never a partial one; what
/// is left besides is a temporary file named after the target.
fn replay_foxglove_killed_leaves_no_partial_target() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let target = dir.path().join("golf.mcap");
    let trace = Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_mini_golf.mcap");
    // The delays only vary where the run is when killed; the property must
    // hold at any of them.
    for delay_ms in [0u64, 20, 60, 150, 400] {
        let mut child = crate::support::bin()
            .arg("replay")
            .arg(&trace)
            .arg("--foxglove")
            .arg(&target)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()?;
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        if target.exists() {
            let bytes = std::fs::read(&target)?;
            ensure!(
                mcap::Summary::read(&bytes).is_ok_and(|s| s.is_some()),
                "after a kill at {delay_ms} ms the target is not a complete file"
            );
        }
        for name in entries(dir.path())? {
            if name == "golf.mcap" {
                continue;
            }
            ensure!(
                name.starts_with(".golf.mcap.partial-"),
                "an unexpected file is left: {name}"
            );
            std::fs::remove_file(dir.path().join(name))?;
        }
    }
    Ok(())
}

/// `replay --foxglove` of a trace with contact queries: each query judged
/// as `check` judges it, on `/contact_queries` (a marker per answered
/// contact, the ghost in the ghost colour with the faces' normal beside its
/// own) and `/contact_decisions` (WARNING for the ghost, INFO for the query
/// that agrees); Python reads the file and Node validates every message
/// against Foxglove's schemas. A trace without queries has neither channel
/// (the other tests' channel lists).
fn replay_foxglove_carries_the_judged_contact_queries() -> anyhow::Result<Completion> {
    use sweeptrace::trace::{ContactMsg, ContactPointMsg, ContactsMsg};
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("seam.mcap");
    let quad = SceneMsg {
        name: Some("quad".into()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        margin: 0.0,
        facing: Facing::NonStrict,
    };
    let face = |triangle: u32, point: [f64; 3], separation: f64| ContactPointMsg {
        triangle,
        kind: Some(Kind::Face),
        feature: None,
        point: Some(point),
        normal: Some([0.0, 0.0, 1.0]),
        separation: Some(separation),
    };
    let lean = nalgebra::Vector3::new(0.125, -0.125, 0.375);
    let mut w = TraceWriter::new(std::fs::File::create(&trace)?)?;
    w.scene(0, &quad)?;
    w.sweep(
        1,
        &SweepMsg {
            frame: 0,
            ball: 0,
            radius: 0.5,
            p0: [1.5, 0.5, 2.0],
            p1: [1.5, 0.5, 0.0],
        },
    )?;
    for (frame, centre, contacts) in [
        (
            1,
            [1.125, 0.875, 0.375],
            vec![
                face(0, [1.125, 0.875, 0.0], -0.125),
                // The seam's contact with the geometric normal: a ghost.
                ContactPointMsg {
                    triangle: 1,
                    kind: Some(Kind::Edge),
                    feature: Some(0),
                    point: Some([1.0, 1.0, 0.0]),
                    normal: Some(lean.normalize().into()),
                    separation: Some(lean.norm() - 0.5),
                },
            ],
        ),
        (2, [1.5, 0.5, 0.25], vec![face(0, [1.5, 0.5, 0.0], -0.25)]),
    ] {
        w.contact(
            2 * frame,
            &ContactMsg {
                frame,
                ball: 0,
                radius: 0.5,
                centre,
                distance: 0.0,
            },
        )?;
        w.expected_contacts(
            2 * frame + 1,
            &ContactsMsg {
                frame,
                ball: 0,
                contacts,
            },
        )?;
    }
    w.finish()?;
    let out = dir.path().join("seam.foxglove.mcap");
    let (code, _, stderr) = run_bin(os!(
        "replay",
        trace.as_os_str(),
        "--foxglove",
        out.as_os_str()
    ))?;
    ensure!(
        code == 0 && stderr.contains("contacts in the Foxglove file: 2 queries drawn (3 contacts, 0 diverging from the core's, 1 ghost contact)"),
        "exit {code}: {stderr}"
    );
    let all = messages(&std::fs::read(&out)?)?;
    let queries = on(&all, "/contact_queries");
    let logs = on(&all, "/contact_decisions");
    ensure!(
        queries.len() == 2 && logs.len() == 2,
        "{} and {} messages",
        queries.len(),
        logs.len()
    );
    let seam = &queries[0]["entities"][0];
    // The ghost colour, cyan (0, 215, 255).
    let is_ghost = |x: &Value| {
        x["color"]["r"].as_f64() == Some(0.0)
            && x["color"]["g"].as_f64() == Some(215.0 / 255.0)
            && x["color"]["b"].as_f64() == Some(1.0)
    };
    let ghost_spheres = seam["spheres"]
        .as_array()
        .map_or(0, |s| s.iter().filter(|x| is_ghost(x)).count());
    ensure!(
        seam["id"] == "contact_query/0"
            && ghost_spheres == 1
            && seam["arrows"].as_array().map(Vec::len) == Some(3)
            && seam["metadata"]
                .to_string()
                .contains("ghost contact: frame 1, ball 0: edge 1.0"),
        "the seam's query: {seam:#}"
    );
    ensure!(
        logs[0]["level"] != logs[1]["level"]
            && logs[0]["message"]
                .as_str()
                .is_some_and(|m| m.contains("ghost contact"))
            && logs[1]["message"]
                .as_str()
                .is_some_and(|m| m.contains("the core finds 1 contact, the answer has 1")),
        "the logs: {logs:#?}"
    );
    let dump = dir.path().join("dump.jsonl");
    if let Some(why) = validate_foxglove_file(&out, 1, 1, &dump)? {
        return Ok(Completion::ignored_with(why));
    }
    Ok(Completion::Completed)
}

/// At a new scene the previous scene's contact queries are deleted from
/// `/contact_queries` (one deletion of every entity, at the scene's
/// `log_time`), as the per-sweep topics' entities are: a mini-golf contact
/// trace with its scene sent again before frame 100.
fn a_new_scene_deletes_the_contact_queries_drawn_before_it() -> anyhow::Result<()> {
    use sweeptrace::trace::EventBody;
    let dir = tempfile::tempdir()?;
    let source = crate::contacts::record(dir.path(), &[])?;
    let events: Vec<_> =
        TraceReader::new(std::fs::File::open(&source)?, "golf").collect::<Result<_, _>>()?;
    let scene = events
        .iter()
        .find(|e| matches!(e.body, EventBody::Scene(_)))
        .context("no scene")?
        .clone();
    let at = events
        .iter()
        .position(|e| matches!(&e.body, EventBody::Sweep(s) if s.frame == 100))
        .context("no frame 100")?;
    let t = events[at].header.log_time_nanos;
    let trace = dir.path().join("two_scenes.mcap");
    let mut w = TraceWriter::new(std::fs::File::create(&trace)?)?;
    for (i, event) in events.iter().enumerate() {
        if i == at {
            let mut again = scene.clone();
            again.header.log_time_nanos = t;
            crate::support::write_event(&mut w, &again)?;
        }
        crate::support::write_event(&mut w, event)?;
    }
    w.finish()?;
    let out = dir.path().join("two_scenes.foxglove.mcap");
    let (code, _, stderr) = run_bin(os!("replay", &trace, "--foxglove", &out))?;
    ensure!(code == 0, "exit {code}: {stderr}");
    let all = messages(&std::fs::read(&out)?)?;
    let queries: Vec<(u64, &Value)> = all
        .iter()
        .filter(|(topic, ..)| topic == "/contact_queries")
        .map(|(_, _, time, v)| (*time, v))
        .collect();
    let deletions: Vec<usize> = (0..queries.len())
        .filter(|&i| {
            queries[i].1["deletions"]
                .as_array()
                .is_some_and(|d| !d.is_empty())
        })
        .collect();
    ensure!(deletions.len() == 1, "deletions at {deletions:?}");
    let (time, clear) = queries[deletions[0]];
    ensure!(
        time == t
            && clear["deletions"][0]["type"] == 1
            && clear["entities"].as_array().is_some_and(Vec::is_empty),
        "at {time} (the scene at {t}): {clear}"
    );
    ensure!(
        queries[..deletions[0]].iter().all(|(time, _)| *time < t)
            && queries[deletions[0] + 1..]
                .iter()
                .all(|(time, _)| *time >= t)
            && deletions[0] > 0
            && deletions[0] + 1 < queries.len(),
        "the deletion is not between the two scenes' queries"
    );
    Ok(())
}
