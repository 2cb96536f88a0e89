//! Tunnels explained by the mesh's defects: a ball through a flipped
//! triangle from the side its neighbours face is a tunnel (back to front by
//! the triangle's own winding), and a tunnel within ρ of a defect names it.
//!
//! The traces are built in memory, each sweep followed by the core's own
//! outcome as its expectation (so only the tunnels fail `check`):
//! - a 3 × 3 floor of 18 triangles at `z = 0`, front `+z`, with triangle 8
//!   (in the middle square) wound the other way: ball 0 falls through the
//!   middle of triangle 8 (a tunnel through the flipped triangle 8); ball 1
//!   starts 0.05 over triangle 0, within ρ, and moves down through it (an
//!   ordinary tunnel, far from the defect: it names nothing);
//! - two unit squares side by side whose touching edges are `1e-5` apart
//!   (a crack between triangles 0 and 3): a ball moved from above the
//!   floor to below it between two sweeps, 0.05 from the crack.

use libtest_mimic::Trial;
use sweeptrace::core::Facing;
use sweeptrace::replay::tunnel::TunnelKind;
use sweeptrace::suite::{CheckOptions, check_reader, render_json, render_text};
use sweeptrace::trace::{SceneMsg, SweepMsg};

use crate::ensure;
use crate::support::core_trace;
use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(flipped_floor_tunnel_names_the_flipped_triangle),
        trial!(ordinary_tunnel_names_nothing),
        trial!(tunnel_near_a_crack_names_the_crack),
    ]
}

const RADIUS: f64 = 0.1;

/// A floor of `n × n` unit squares at `z = 0`, front `+z`, two triangles
/// per square (`[a, b, c]`, `[a, c, d]` counter-clockwise from above),
/// square `(i, j)` holding triangles `2 (3 j + i)` and `2 (3 j + i) + 1`;
/// the triangles of `flipped` wound the other way.
pub(crate) fn floor(n: u64, flipped: &[usize]) -> SceneMsg {
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            vertices.push([i as f64, j as f64, 0.0]);
        }
    }
    let at = |i: u64, j: u64| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    for &t in flipped {
        triangles[t].swap(1, 2);
    }
    SceneMsg {
        name: Some("flipped floor".into()),
        vertices,
        triangles,
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

/// Two unit squares, `x ∈ [0, 1]` and `x ∈ [1 + 1e-5, 2]`, not welded.
fn cracked_floor() -> SceneMsg {
    let g = 1.0 + 1e-5;
    SceneMsg {
        name: Some("cracked floor".into()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [g, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [g, 1.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

pub(crate) fn sweep(frame: u64, ball: u32, p0: [f64; 3], p1: [f64; 3]) -> SweepMsg {
    SweepMsg {
        frame,
        ball,
        radius: RADIUS,
        p0,
        p1,
    }
}

/// The flipped floor's trace: ball 0 through the middle of the flipped
/// triangle 8 (centroid `(5/3, 4/3)`), ball 1 through triangle 0 from 0.05
/// over it (centroid `(2/3, 1/3)`).
fn flipped_trace() -> anyhow::Result<Vec<u8>> {
    let (x0, y0) = (5.0 / 3.0, 4.0 / 3.0);
    let (x1, y1) = (2.0 / 3.0, 1.0 / 3.0);
    core_trace(
        &floor(3, &[8]),
        &[
            sweep(0, 0, [x0, y0, 1.0], [x0, y0, 0.5]),
            sweep(0, 1, [x1, y1, 0.5], [x1, y1, 0.05]),
            sweep(1, 0, [x0, y0, 0.5], [x0, y0, -0.5]),
            sweep(1, 1, [x1, y1, 0.05], [x1, y1, -0.5]),
        ],
    )
}

fn flipped_floor_tunnel_names_the_flipped_triangle() -> anyhow::Result<()> {
    let report = check_reader(
        flipped_trace()?.as_slice(),
        "<memory>",
        &CheckOptions::default(),
    );
    let text = render_text(&report);
    ensure!(
        report.divergent == 0 && report.tunnels.count == 2,
        "two tunnels, no divergence:\n{text}"
    );
    let t = report
        .tunnels
        .details
        .iter()
        .find(|t| t.ball == 0)
        .context("no tunnel of ball 0")?;
    ensure!(
        t.frame == 1
            && t.tunnel.kind == TunnelKind::DuringSweep
            && t.tunnel.triangle == 8
            && t.tunnel.back_to_front,
        "{t:?}"
    );
    let through = t.tunnel.through.as_ref().context("names no defect")?;
    ensure!(through.text == "the flipped triangle 8", "{through:?}");
    ensure!(
        text.contains("frame 1, ball 0: through triangle 8 (back to front) during its sweep")
            && text.contains("through the flipped triangle 8"),
        "text:\n{text}"
    );
    let json: serde_json::Value = serde_json::from_str(&render_json(&[report], 1))?;
    let d = json["traces"][0]["tunnel_details"]
        .as_array()
        .and_then(|a| a.iter().find(|d| d["ball"] == 0))
        .context("no JSON tunnel of ball 0")?;
    ensure!(
        d["triangle"] == 8
            && d["back_to_front"] == true
            && d["through"]["kind"] == "flipped"
            && d["through"]["triangles"] == serde_json::json!([8])
            && d["through"]["text"] == "the flipped triangle 8",
        "{d}"
    );
    Ok(())
}

fn ordinary_tunnel_names_nothing() -> anyhow::Result<()> {
    let report = check_reader(
        flipped_trace()?.as_slice(),
        "<memory>",
        &CheckOptions::default(),
    );
    let text = render_text(&report);
    let t = report
        .tunnels
        .details
        .iter()
        .find(|t| t.ball == 1)
        .context(format!("no tunnel of ball 1:\n{text}"))?;
    ensure!(
        t.frame == 1 && t.tunnel.triangle == 0 && !t.tunnel.back_to_front,
        "{t:?}"
    );
    ensure!(t.tunnel.through.is_none(), "{t:?}");
    let line = t.line();
    ensure!(!line.contains(", through the"), "{line}");
    let json: serde_json::Value = serde_json::from_str(&render_json(&[report], 1))?;
    let d = json["traces"][0]["tunnel_details"]
        .as_array()
        .and_then(|a| a.iter().find(|d| d["ball"] == 1))
        .context("no JSON tunnel of ball 1")?;
    ensure!(
        d.get("through").is_none() && d.get("back_to_front").is_none(),
        "{d}"
    );
    Ok(())
}

fn tunnel_near_a_crack_names_the_crack() -> anyhow::Result<()> {
    let bytes = core_trace(
        &cracked_floor(),
        &[
            sweep(0, 0, [0.5, 0.5, 0.3], [0.95, 0.5, 0.3]),
            // Put below the floor by the engine: through triangle 0 at
            // (0.95, 0.5, 0), 0.05 from the crack.
            sweep(1, 0, [0.95, 0.5, -0.3], [0.95, 0.5, -0.6]),
        ],
    )?;
    let report = check_reader(bytes.as_slice(), "<memory>", &CheckOptions::default());
    let text = render_text(&report);
    ensure!(
        report.divergent == 0 && report.tunnels.count == 1,
        "one tunnel:\n{text}"
    );
    let t = report.tunnels.details.first().context("no tunnel")?;
    ensure!(
        t.tunnel.kind == TunnelKind::BetweenSweeps && t.tunnel.triangle == 0,
        "{t:?}"
    );
    let through = t.tunnel.through.as_ref().context("names no defect")?;
    let mut triangles = through.triangles.clone();
    triangles.sort_unstable();
    ensure!(
        through.kind.as_str() == "crack" && triangles == [0, 3],
        "{through:?}"
    );
    ensure!(
        (through.distance - 0.05).abs() < 1e-9,
        "distance {}",
        through.distance
    );
    ensure!(
        text.contains("through the crack between triangles"),
        "text:\n{text}"
    );
    Ok(())
}
