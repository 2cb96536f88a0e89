//! `sweeptrace mesh` and the library's `Topology`: each fixture of
//! `tests/fixtures/mesh/` has exactly one known defect (and the clean box
//! none), found at the right triangles; the built-in scenes and the sample
//! traces' scenes have none.

use libtest_mimic::Trial;
use serde_json::Value;
use sweeptrace::Topology;
use sweeptrace::core::topology::DefectKind;
use sweeptrace::sim::scenes::BuiltinScene;

use crate::support::run_bin;
use crate::{ensure, os, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(mesh_fixtures_have_their_one_defect),
        trial!(mesh_clean_box_has_none),
        trial!(mesh_bad_input_exits_2),
        trial!(mesh_builtin_scenes),
        trial!(mesh_reads_a_traces_scenes),
        trial!(
            mesh_of_an_endless_input_is_bounded_and_named,
            timeout = std::time::Duration::from_secs(120)
        ),
    ]
}

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/mesh/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// `mesh --json FILE`: exit code and the first mesh's JSON.
fn mesh_json(file: &str) -> anyhow::Result<(i32, Value)> {
    let (code, out, err) = run_bin(os!["mesh", "--json", file])?;
    let v: Value = serde_json::from_str(&out)
        .map_err(|e| anyhow::anyhow!("{file}: stdout is not JSON ({e}): {out}{err}"))?;
    Ok((code, v["meshes"][0].clone()))
}

fn mesh_json_fixture_checks(
    name: &str,
    kind: &str,
    triangles: &[u64],
    exit: i32,
) -> anyhow::Result<()> {
    let (code, m) = mesh_json(&fixture(name))?;
    let defects = m["defects"]
        .as_array()
        .context(format!("{name}: no defects list"))?;
    ensure!(
        defects.len() == 1,
        "{name}: want exactly one defect, got {defects:?}"
    );
    let d = &defects[0];
    ensure!(d["kind"] == kind, "{name}: kind {} want {kind}", d["kind"]);
    let got: Vec<u64> = d["triangles"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_u64).collect())
        .unwrap_or_default();
    ensure!(
        got == triangles,
        "{name}: triangles {got:?} want {triangles:?}"
    );
    ensure!(
        d["vertices"].as_array().is_some_and(|a| !a.is_empty()),
        "{name}: no vertices in {d}"
    );
    ensure!(
        d["position"].as_array().is_some_and(|a| a.len() == 3),
        "{name}: position is not a point in {d}"
    );
    for class in ["boundary", "convex", "flat", "concave", "non_manifold"] {
        ensure!(
            m["edges"][class].is_u64(),
            "{name}: edges.{class} missing in {}",
            m["edges"]
        );
    }
    ensure!(code == exit, "{name}: exit {code} want {exit}");
    Ok(())
}

fn mesh_fixtures_have_their_one_defect() -> anyhow::Result<()> {
    mesh_json_fixture_checks("flipped_floor.obj", "flipped", &[9], 1)?;
    mesh_json_fixture_checks("crack_seam.obj", "crack", &[0, 3], 1)?;
    mesh_json_fixture_checks("t_junction.obj", "t_junction", &[1, 2, 3], 1)?;
    mesh_json_fixture_checks("fin.obj", "non_manifold_edge", &[0, 1, 8], 1)?;
    mesh_json_fixture_checks("duplicate_triangle.obj", "duplicate_triangle", &[3, 8], 1)?;
    // A sliver is a warning: exit 0.
    mesh_json_fixture_checks("sliver.obj", "sliver", &[0], 0)?;
    // The text names the flipped triangle and its neighbours.
    let (code, out, _) = run_bin(os!["mesh", &fixture("flipped_floor.obj")])?;
    ensure!(code == 1, "text report exit {code}");
    ensure!(
        out.contains("triangle 9")
            && out.contains("opposite to that of its 3 neighbours, triangles"),
        "text report: {out}"
    );
    ensure!(
        out.contains("verdict: 1 defect that changes collisions"),
        "no verdict: {out}"
    );
    Ok(())
}

fn mesh_clean_box_has_none() -> anyhow::Result<()> {
    let (code, m) = mesh_json(&fixture("clean_box.obj"))?;
    ensure!(code == 0, "exit {code}");
    ensure!(
        m["defects"] == Value::Array(vec![]),
        "defects {}",
        m["defects"]
    );
    ensure!(
        m["edges"]["convex"] == 12 && m["edges"]["flat"] == 6 && m["edges"]["boundary"] == 0,
        "edges {}",
        m["edges"]
    );
    Ok(())
}

fn mesh_bad_input_exits_2() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 7\n")?;
    let missing = dir.path().join("missing.obj");
    for file in [&bad, &missing] {
        let (code, out, err) = run_bin(&[std::ffi::OsStr::new("mesh"), file.as_os_str()])?;
        ensure!(code == 2, "{}: exit {code}, {out}{err}", file.display());
        ensure!(
            err.contains(&*file.display().to_string()) && !err.contains("panicked"),
            "{}: error does not name the file: {err}",
            file.display()
        );
    }
    let (code, out, _) = run_bin(os!["mesh", "--help"])?;
    ensure!(
        code == 0 && out.contains("non_manifold") && out.contains("Exit codes"),
        "help: {out}"
    );
    Ok(())
}

/// Every built-in scene but `mini_golf` is clean. `mini_golf` has eight
/// T-junctions, a real defect of the scene: each wall's bottom edge spans a
/// whole side of the green, whose boundary is split at the cup's grid lines
/// (x = 9.7, 10.3 and y = 1.7, 2.3), so those vertices lie on the walls'
/// edges.
/// Every built-in scene is clean: no defect at all (the mini-golf walls
/// once met the green in 8 T-junctions).
fn mesh_builtin_scenes() -> anyhow::Result<()> {
    for scene in BuiltinScene::all() {
        let s = scene.mesh();
        let t = Topology::new(&s.vertices, &s.triangles)?;
        let kinds: Vec<DefectKind> = t.defects().iter().map(|d| d.kind).collect();
        ensure!(kinds.is_empty(), "{}: defects {kinds:?}", scene.name());
    }
    Ok(())
}

/// `mesh` reads the scene of each sample trace (recorded from the
/// built-in scenes) and finds nothing wrong: exit 0.
fn mesh_reads_a_traces_scenes() -> anyhow::Result<()> {
    let dir = format!("{}/traces", env!("CARGO_MANIFEST_DIR"));
    let mut traces: Vec<String> = std::fs::read_dir(&dir)?
        .filter_map(Result::ok)
        .map(|e| e.path().display().to_string())
        .filter(|p| p.ends_with(".mcap"))
        .collect();
    traces.sort();
    ensure!(traces.len() >= 5, "sample traces: {traces:?}");
    for trace in &traces {
        let (code, m) = mesh_json(trace)?;
        ensure!(code == 0, "{trace}: exit {code}: {m}");
        ensure!(
            m["defects"].as_array().is_some_and(Vec::is_empty),
            "{trace}: defects {}",
            m["defects"]
        );
    }
    let golf = format!("{dir}/record_mini_golf.mcap");
    let (_, m) = mesh_json(&golf)?;
    ensure!(m["name"] == "mini_golf", "name {}", m["name"]);
    Ok(())
}

/// `mesh /dev/zero` reads up to the largest OBJ file it takes, then stops
/// with an error naming the file (before: it read until memory ran out,
/// then said "cannot read <input>"). Run under a 3 GB limit of address
/// space, so that a regression fails instead of taking the machine's
/// memory (issue 43, item 11).
fn mesh_of_an_endless_input_is_bounded_and_named() -> anyhow::Result<()> {
    let out = std::process::Command::new("sh")
        .args(["-c", "ulimit -v 3000000 && exec \"$0\" mesh /dev/zero"])
        .arg(env!("CARGO_BIN_EXE_sweeptrace"))
        .output()?;
    let (code, out, err) = (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    ensure!(
        code == 2
            && err
                .contains("/dev/zero is larger than 256 MiB: not a Wavefront OBJ file this reads")
            && !err.contains("<input>"),
        "exit {code}\n{out}{err}"
    );
    Ok(())
}
