//! The class of the edge (or vertex) an outcome hit: in `replay`'s outcome
//! lines (`edge_class`) and in the `sweep` explanation ("edge 0.1: a convex
//! edge shared with triangle 5").

use libtest_mimic::Trial;
use sweeptrace::core::{Facing, Kind};
use sweeptrace::replay::{ReplayEvent, ReplayOptions, replay_events};
use sweeptrace::trace::{SceneMsg, TraceReader};

use crate::ensure;
use crate::support::core_trace;
use crate::support::run_bin;
use crate::trial;
use crate::tunnel_through::{floor, sweep};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(replay_outcome_lines_name_the_edge_class),
        trial!(sweep_explanation_names_the_edge_class),
        trial!(sweep_explanation_names_a_flat_internal_edge),
    ]
}

/// On the 3 × 3 floor (front `+z`): ball 0 falls just outside its edge
/// `x = 0` (a boundary edge), ball 1 falls onto the middle of triangle 4 (a
/// face: no class).
fn replay_outcome_lines_name_the_edge_class() -> anyhow::Result<()> {
    let bytes = core_trace(
        &floor(3, &[]),
        &[
            sweep(0, 0, [-0.05, 1.5, 1.0], [-0.05, 1.5, -1.0]),
            sweep(0, 1, [1.6, 0.4, 1.0], [1.6, 0.4, -1.0]),
        ],
    )?;
    let mut lines = Vec::new();
    for e in replay_events(
        TraceReader::new(bytes.as_slice(), "<memory>"),
        ReplayOptions::default(),
    ) {
        if let ReplayEvent::Sweep(r) = e? {
            lines.push((r.ball, r.outcome.kind(), r.outcome_line()?));
        }
    }
    let (_, kind, line) = lines.iter().find(|l| l.0 == 0).context("no ball 0")?;
    ensure!(*kind == Kind::Edge, "ball 0 hits an edge: {line}");
    let v: serde_json::Value = serde_json::from_str(line)?;
    ensure!(v["edge_class"] == "boundary", "{line}");
    let (_, kind, line) = lines.iter().find(|l| l.0 == 1).context("no ball 1")?;
    ensure!(*kind == Kind::Face, "ball 1 hits a face: {line}");
    let v: serde_json::Value = serde_json::from_str(line)?;
    ensure!(v["edge_class"].is_null(), "{line}");
    Ok(())
}

fn sweep_explanation_names_the_edge_class() -> anyhow::Result<()> {
    let args = [
        "sweep", "--scene", "cube", "--radius", "0.5", "--from", "3,3,0", "--to", "0,0,0",
    ];
    let os: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
    let (code, out, err) = run_bin(&os)?;
    ensure!(code == 0, "exit {code}\n{err}");
    ensure!(
        out.contains("\nedge 0.1: a convex edge shared with triangle 5\n"),
        "{out}"
    );
    let mut json_args = os.clone();
    json_args.push("--json".as_ref());
    let (code, out, err) = run_bin(&json_args)?;
    ensure!(code == 0, "exit {code}\n{err}");
    let v: serde_json::Value = serde_json::from_str(&out)?;
    ensure!(
        v["outcome"]["edge_class"] == "convex"
            && v["place"] == "edge 0.1: a convex edge shared with triangle 5",
        "{v}"
    );
    // A vertex: the corner (1, 1, 1), where the edges are convex.
    let args = [
        "sweep", "--scene", "cube", "--radius", "0.5", "--from", "3,3,3", "--to", "0,0,0",
    ];
    let os: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
    let (_, out, _) = run_bin(&os)?;
    ensure!(
        out.contains(": a convex vertex (the most telling class of its"),
        "{out}"
    );
    Ok(())
}

/// A unit square folded along its diagonal `(0, 0, 0)–(1, 1, 0)` by `1e-4`
/// (the other corners at `z = −1e-4`): a convex crease whose dihedral
/// sine (about 1.4e-4) is under the flat threshold, so the diagonal is an
/// internal `flat` edge. A ball falling onto the diagonal touches the
/// crease first, and that is an edge hit.
fn sweep_explanation_names_a_flat_internal_edge() -> anyhow::Result<()> {
    let e = 1e-4;
    let scene = SceneMsg {
        name: Some("folded square".into()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, -e],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, -e],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        margin: 0.0,
        facing: Facing::NonStrict,
    };
    let bytes = core_trace(&scene, &[sweep(0, 0, [0.5, 0.5, 1.0], [0.5, 0.5, -1.0])])?;
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("folded.mcap");
    std::fs::write(&path, &bytes)?;
    let args: Vec<&std::ffi::OsStr> = vec![
        "sweep".as_ref(),
        "--trace".as_ref(),
        path.as_os_str(),
        "--frame".as_ref(),
        "0".as_ref(),
        "--ball".as_ref(),
        "0".as_ref(),
    ];
    let (code, out, err) = run_bin(&args)?;
    ensure!(code == 0, "exit {code}\n{err}");
    let place = out
        .lines()
        .find(|l| l.starts_with("edge "))
        .with_context(|| format!("no place line in\n{out}"))?;
    ensure!(
        place == "edge 0.2: an internal flat edge shared with triangle 1"
            || place == "edge 1.0: an internal flat edge shared with triangle 0",
        "{out}"
    );
    Ok(())
}
