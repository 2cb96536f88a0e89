//! Ghost contacts (issue 24): expected edge or vertex contacts on an
//! internal flat or concave edge whose normal leans off the faces, listed by
//! `check` apart from divergences; the same contacts on a ridge are not
//! ghosts. The traces are built here with the library's writer (the
//! fixtures are shared with `ghost_marks`).

use std::io::Cursor;

use libtest_mimic::Trial;
use sweeptrace::core::{Facing, Kind, Options, Sweep, sweep_mesh};
use sweeptrace::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceWriter};

use crate::ensure;
use crate::support::{mesh, run_bin};
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(ghost_tilted_seam_contacts_are_listed),
        trial!(ghost_not_on_a_convex_ridge),
        trial!(ghost_sample_traces_have_none),
    ]
}

/// A floor of two coplanar triangles, fronts `+z`, sharing the seam from
/// vertex 0 `(-5, -5, 0)` to vertex 2 `(5, 5, 0)`: edge 2 of triangle 0.
pub(crate) fn seam_floor() -> SceneMsg {
    SceneMsg {
        name: Some("seam".into()),
        vertices: vec![
            [-5.0, -5.0, 0.0],
            [5.0, -5.0, 0.0],
            [5.0, 5.0, 0.0],
            [-5.0, 5.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

/// A ridge along `y = 0` at height 1: edge 1 of triangle 1 (vertices 2, 3),
/// convex, shared with triangle 2.
fn ridge() -> SceneMsg {
    SceneMsg {
        name: Some("ridge".into()),
        vertices: vec![
            [-5.0, -5.0, 0.0],
            [5.0, -5.0, 0.0],
            [5.0, 0.0, 1.0],
            [-5.0, 0.0, 1.0],
            [5.0, 5.0, 0.0],
            [-5.0, 5.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3], [3, 2, 4], [3, 4, 5]],
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

/// 10° off `+z`, toward `+x`.
pub(crate) fn tilted() -> [f64; 3] {
    let a = 10f64.to_radians();
    [a.sin(), 0.0, a.cos()]
}

/// A trace of `scene` whose balls fall onto the points `at` (frame, ball,
/// x, y, top), each expectation the core's α with the contact named as
/// edge `feature` of `triangle` and the normal `normal(frame, ball)`.
pub(crate) fn trace(
    scene: &SceneMsg,
    at: &[(u64, u32, f64, f64, f64)],
    triangle: u32,
    feature: u8,
    normal: impl Fn(u64, u32) -> [f64; 3],
) -> anyhow::Result<Vec<u8>> {
    let m = mesh(&scene.vertices, &scene.triangles);
    let options = Options {
        margin: scene.margin,
        facing: scene.facing,
        ..Options::default()
    };
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, scene)?;
    for &(frame, ball, x, y, top) in at {
        let s = SweepMsg {
            frame,
            ball,
            radius: 0.5,
            p0: [x, y, top + 2.0],
            p1: [x, y, top + 0.2],
        };
        let t = 1_000_000 * (frame + 1);
        w.sweep(t, &s)?;
        let o = sweep_mesh(&m, &Sweep::new(s.p0, s.p1, s.radius), &options)?;
        ensure!(o.kind() != Kind::None, "frame {frame}, ball {ball} misses");
        let mut e = OutcomeMsg::from_outcome(frame, ball, &o);
        e.kind = Kind::Edge;
        e.triangle = Some(Some(triangle));
        e.feature = Some(Some(feature));
        e.normal = Some(Some(normal(frame, ball)));
        w.expected(t, &e)?;
    }
    Ok(w.finish()?.into_inner())
}

/// Tilted at frames 1 and 3 of ball 0 and frame 2 of ball 2.
pub(crate) fn is_tilted(frame: u64, ball: u32) -> bool {
    matches!((frame, ball), (1, 0) | (3, 0) | (2, 2))
}

pub(crate) fn sweeps_along(y_of: impl Fn(f64) -> f64, top: f64) -> Vec<(u64, u32, f64, f64, f64)> {
    let mut v = Vec::new();
    for frame in 0..4u64 {
        for ball in 0..3u32 {
            let x = -3.0 + frame as f64 + 0.5 * ball as f64;
            v.push((frame, ball, x, y_of(x), top));
        }
    }
    v
}

pub(crate) fn write(
    bytes: &[u8],
    dir: &tempfile::TempDir,
    name: &str,
) -> anyhow::Result<std::path::PathBuf> {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes)?;
    Ok(path)
}

fn ghost_tilted_seam_contacts_are_listed() -> anyhow::Result<()> {
    let bytes = trace(&seam_floor(), &sweeps_along(|x| x, 0.0), 0, 2, |f, b| {
        if is_tilted(f, b) {
            tilted()
        } else {
            [0.0, 0.0, 1.0]
        }
    })?;
    let dir = tempfile::tempdir()?;
    let path = write(&bytes, &dir, "seam.mcap")?;
    let args = |extra: &[&str]| {
        let mut a: Vec<std::ffi::OsString> = vec!["check".into(), path.clone().into()];
        a.extend(["--no-config", "--fields", "alpha"].map(Into::into));
        a.extend(extra.iter().map(Into::into));
        a
    };
    let run = |extra: &[&str]| {
        let a = args(extra);
        let refs: Vec<&std::ffi::OsStr> = a.iter().map(|s| s.as_os_str()).collect();
        run_bin(&refs)
    };
    let (code, out, err) = run(&[])?;
    ensure!(code == 1, "exit {code}\n{out}\n{err}");
    ensure!(out.contains("3 ghost contacts"), "stdout:\n{out}");
    let listed: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("ghost contact: "))
        .collect();
    ensure!(listed.len() == 3, "stdout:\n{out}");
    for (line, (frame, ball)) in listed.iter().zip([(1, 0), (2, 2), (3, 0)]) {
        ensure!(
            line.contains(&format!(
                "ghost contact: frame {frame}, ball {ball}: edge 0.2, an internal flat edge \
                 shared with triangle 1: the expected normal is 10.0° from the faces' normal \
                 (0, 0, 1)"
            )) && line.contains("would be bumped"),
            "line: {line}\nstdout:\n{out}"
        );
    }
    ensure!(!out.contains("diverge ("), "stdout:\n{out}");

    let (code, out, err) = run(&["--json"])?;
    ensure!(code == 1, "exit {code}\n{out}\n{err}");
    let json: serde_json::Value = serde_json::from_str(&out)?;
    let r = &json["traces"][0];
    ensure!(r["ghosts"] == 3 && r["divergent"] == 0, "json: {r}");
    ensure!(
        r["ghosts_unjudged"] == 0 && r["fail_on_ghost"] == true,
        "json: {r}"
    );
    let g = &r["ghost_contacts"][0];
    ensure!(
        g["frame"] == 1 && g["ball"] == 0 && g["triangle"] == 0 && g["feature"] == 2,
        "json: {g}"
    );
    ensure!(
        g["kind"] == "edge" && g["place"] == "flat" && g["neighbour"] == 1,
        "json: {g}"
    );
    let angle = g["angle_degrees"].as_f64().unwrap_or(f64::NAN);
    ensure!((angle - 10.0).abs() < 1e-9, "angle {angle}");
    ensure!(r["ghost_contacts"][1]["ball"] == 2, "json: {r}");

    let (code, out, err) = run(&["--allow-ghosts"])?;
    ensure!(code == 0, "exit {code}\n{out}\n{err}");
    ensure!(
        out.starts_with("ok ")
            && out.contains("3 ghost contacts (not failures: ghost contacts allowed)"),
        "stdout:\n{out}"
    );
    // A wider threshold lets them pass.
    let (code, out, err) = run(&["--ghost-degrees", "15"])?;
    ensure!(code == 0, "exit {code}\n{out}\n{err}");
    Ok(())
}

fn ghost_not_on_a_convex_ridge() -> anyhow::Result<()> {
    // The same tilted normals on the ridge's edge are not ghosts.
    let bytes = trace(&ridge(), &sweeps_along(|_| 0.0, 1.0), 1, 1, |f, b| {
        if is_tilted(f, b) {
            tilted()
        } else {
            [0.0, 0.0, 1.0]
        }
    })?;
    let dir = tempfile::tempdir()?;
    let path = write(&bytes, &dir, "ridge.mcap")?;
    let (code, out, err) = run_bin(&[
        "check".as_ref(),
        path.as_os_str(),
        "--no-config".as_ref(),
        "--fields".as_ref(),
        "alpha".as_ref(),
        "--json".as_ref(),
    ])?;
    ensure!(code == 0, "exit {code}\n{out}\n{err}");
    let json: serde_json::Value = serde_json::from_str(&out)?;
    let r = &json["traces"][0];
    ensure!(
        r["ghosts"] == 0 && r["ghost_contacts"] == serde_json::json!([]),
        "json: {r}"
    );
    Ok(())
}

fn ghost_sample_traces_have_none() -> anyhow::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["traces", "examples/rapier"] {
        let path = root.join(dir);
        let (code, out, err) = run_bin(&["check".as_ref(), path.as_os_str(), "--json".as_ref()])?;
        let json: serde_json::Value =
            serde_json::from_str(&out).map_err(|e| anyhow::anyhow!("{e}: {out}\n{err}"))?;
        let traces = json["traces"].as_array().cloned().unwrap_or_default();
        ensure!(!traces.is_empty(), "{dir}: no traces\n{out}");
        for t in &traces {
            ensure!(
                t["ghosts"] == 0,
                "{dir}: {}: {}",
                t["trace"],
                t["ghost_contacts"]
            );
        }
        if dir == "traces" {
            ensure!(code == 0, "{dir}: exit {code}\n{err}");
        }
    }
    Ok(())
}
