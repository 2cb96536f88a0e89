//! A second, independent implementation of SEMANTICS.md's rules that rounds
//! differently, standing for a user's engine: `check` on the traces it
//! records must report ties (an equally valid answer to the tie order),
//! never divergences on robust decisions.
//!
//! What differs from the core, on purpose:
//! - normals from `(c - b) × (a - b)` scaled by `1 / √(n·n)`;
//! - face: heights measured from the triangle's centroid, `β` from
//!   `(h0 - ρ) / (h0 - h1)` as SEMANTICS.md writes it, the touch point
//!   inside by Gram-matrix barycentric coordinates with no tolerance at
//!   all (boundary included exactly);
//! - edge: no standard frame; the path's components perpendicular to the
//!   edge in world coordinates, the smaller root in the geometric form
//!   `s0 = (t* - √(ρ²A - |d⊥ × m⊥|²) / A)` around the closest approach,
//!   `xc` by projection on the edge's direction;
//! - vertex: the same geometric form in world coordinates;
//! - combination: every hit evaluated, the minimum of its own `α`, the tie
//!   order applied to the hits at exactly that computed `α` (so its own
//!   rounding decides between exactly tied hits, as in an engine without a
//!   tie window), the normals of the triangles hit within `1e-10` of it
//!   averaged in triangle order.
//!
//! The traces (built with `TraceWriter`) are full of exact ties: a terrain
//! with integer heights hit at its vertices, edge midpoints and cell
//! centres; the cube hit at its corners, edges and face diagonals; the
//! closed box hit from inside at its corners, edges and seams.

use std::io::Cursor;

use libtest_mimic::Trial;
use sweeptrace::core::{Facing, Kind};
use sweeptrace::sim::scenes;
use sweeptrace::suite::{CheckOptions, Status, check_reader, render_text};
use sweeptrace::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceWriter};

use crate::ensure;
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(differently_rounding_engine_gives_ties_not_divergences),
        trial!(tie_member_is_judged_with_its_own_contact),
    ]
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: V, k: f64) -> V {
    [a[0] * k, a[1] * k, a[2] * k]
}
/// Summed from z down to x: another rounding than the core's.
fn dot(a: V, b: V) -> f64 {
    a[2] * b[2] + a[1] * b[1] + a[0] * b[0]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

struct AltTriangle {
    index: u32,
    v: [V; 3],
    n: V,
}

fn alt_mesh(scene: &SceneMsg) -> Vec<AltTriangle> {
    scene
        .triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let v = t.map(|k| scene.vertices[k as usize]);
            let raw = cross(sub(v[2], v[1]), sub(v[0], v[1]));
            let n = scale(raw, 1.0 / dot(raw, raw).sqrt());
            AltTriangle {
                index: i as u32,
                v,
                n,
            }
        })
        .collect()
}

#[derive(Clone, Copy, Debug)]
struct AltHit {
    alpha: f64,
    kind: Kind,
    triangle: u32,
    feature: u8,
    contact: V,
}

/// The smaller root of `|m + s d|² = ρ²` for `m`, `d` in any space, in the
/// geometric form around the closest approach `t* = -(m·d)/A`.
fn first_touch(m: V, d: V, rho: f64) -> Option<f64> {
    let a = dot(d, d);
    if a == 0.0 {
        return None;
    }
    let c = cross(d, m);
    let under = rho * rho * a - dot(c, c);
    if under < 0.0 {
        return None;
    }
    let s0 = (-dot(m, d) - under.sqrt()) / a;
    (0.0..=1.0).contains(&s0).then_some(s0)
}

fn alt_triangle_hits(
    t: &AltTriangle,
    p0: V,
    p1: V,
    rho: f64,
    facing: Facing,
    out: &mut Vec<AltHit>,
) {
    let d = sub(p1, p0);
    let nd = dot(t.n, d);
    let allowed = match facing {
        Facing::NonStrict => nd <= 0.0,
        Facing::Strict => nd < 0.0,
    };
    if !allowed {
        return;
    }
    // Face, heights from the centroid.
    let centroid = scale(add(add(t.v[0], t.v[1]), t.v[2]), 1.0 / 3.0);
    let h0 = dot(t.n, sub(p0, centroid));
    let h1 = dot(t.n, sub(p1, centroid));
    if h0 >= rho && h0 != h1 {
        let beta = (h0 - rho) / (h0 - h1);
        if beta <= 1.0 {
            let q = sub(add(p0, scale(d, beta)), scale(t.n, rho));
            // Gram-matrix barycentric coordinates, boundary included exactly.
            let (e0, e1, w) = (sub(t.v[1], t.v[0]), sub(t.v[2], t.v[0]), sub(q, t.v[0]));
            let (d00, d01, d11) = (dot(e0, e0), dot(e0, e1), dot(e1, e1));
            let (d20, d21) = (dot(w, e0), dot(w, e1));
            let den = d00 * d11 - d01 * d01;
            let b1 = (d11 * d20 - d01 * d21) / den;
            let b2 = (d00 * d21 - d01 * d20) / den;
            if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 {
                out.push(AltHit {
                    alpha: beta,
                    kind: Kind::Face,
                    triangle: t.index,
                    feature: 0,
                    contact: q,
                });
            }
        }
    }
    // Edges, in world coordinates: components perpendicular to the edge.
    for e in 0..3u8 {
        let (a, b) = (t.v[e as usize], t.v[(e as usize + 1) % 3]);
        let edge = sub(b, a);
        let length = dot(edge, edge).sqrt();
        let u = scale(edge, 1.0 / length);
        let m = sub(p0, a);
        let m_perp = sub(m, scale(u, dot(m, u)));
        let d_perp = sub(d, scale(u, dot(d, u)));
        if dot(d_perp, d_perp) <= 1e-24 * dot(d, d) {
            continue;
        }
        if let Some(s0) = first_touch(m_perp, d_perp, rho) {
            let xc = dot(add(m, scale(d, s0)), u);
            if (0.0..=length).contains(&xc) {
                out.push(AltHit {
                    alpha: s0,
                    kind: Kind::Edge,
                    triangle: t.index,
                    feature: e,
                    contact: add(a, scale(u, xc)),
                });
            }
        }
    }
    // Vertices.
    for k in 0..3u8 {
        let v = t.v[k as usize];
        if let Some(s0) = first_touch(sub(p0, v), d, rho) {
            out.push(AltHit {
                alpha: s0,
                kind: Kind::Vertex,
                triangle: t.index,
                feature: k,
                contact: v,
            });
        }
    }
}

/// The alternative engine's outcome of one sweep.
fn alt_sweep(mesh: &[AltTriangle], s: &SweepMsg, margin: f64, facing: Facing) -> OutcomeMsg {
    let rho = s.radius - margin;
    let mut hits = Vec::new();
    for t in mesh {
        alt_triangle_hits(t, s.p0, s.p1, rho, facing, &mut hits);
    }
    let min = hits.iter().map(|h| h.alpha).fold(f64::INFINITY, f64::min);
    // The primary: the tie order among the hits at exactly the minimum
    // computed α (rounding decides between exactly tied hits, as in an
    // engine without a tie window); normals: averaged over the hits within
    // 1e-10 of it.
    let tied: Vec<&AltHit> = hits.iter().filter(|h| h.alpha <= min + 1e-10).collect();
    let Some(primary) = tied
        .iter()
        .filter(|h| h.alpha == min)
        .min_by_key(|h| (h.kind, h.triangle, h.feature))
        .copied()
    else {
        return OutcomeMsg::miss(s.frame, s.ball);
    };
    let mut triangles: Vec<u32> = tied.iter().map(|h| h.triangle).collect();
    triangles.sort_unstable();
    triangles.dedup();
    let sum = triangles
        .iter()
        .fold([0.0; 3], |acc, &t| add(acc, mesh[t as usize].n));
    let norm = dot(sum, sum).sqrt();
    let normal = if norm > 1e-9 {
        scale(sum, 1.0 / norm)
    } else {
        mesh[primary.triangle as usize].n
    };
    OutcomeMsg {
        frame: s.frame,
        ball: s.ball,
        alpha: min,
        kind: primary.kind,
        triangle: Some(Some(primary.triangle)),
        feature: Some((primary.kind != Kind::Face).then_some(primary.feature)),
        normal: Some(Some(normal)),
        contact: Some(Some(primary.contact)),
    }
}

/// A trace of `scene` and `sweeps` with the alternative engine's outcomes
/// as expectations.
pub(crate) fn alt_trace(scene: &SceneMsg, sweeps: &[SweepMsg]) -> anyhow::Result<Vec<u8>> {
    let mesh = alt_mesh(scene);
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, scene)?;
    for (i, s) in sweeps.iter().enumerate() {
        let t = 1 + i as u64;
        w.sweep(t, s)?;
        w.expected(t, &alt_sweep(&mesh, s, scene.margin, scene.facing))?;
    }
    Ok(w.finish()?.into_inner())
}

fn sweep(frame: u64, radius: f64, target: V, from: V) -> SweepMsg {
    SweepMsg {
        frame,
        ball: 0,
        radius,
        p0: add(target, from),
        p1: sub(target, scale(from, 0.5)),
    }
}

/// A deterministic stream of small integers (no dependency on a seed crate).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) % n
    }
}

/// A height field of `cells`² unit cells with integer heights (mostly flat
/// patches, some steps of 1), diagonals alternating; drops aimed at
/// vertices, edge midpoints and cell centres, vertically and slanted.
fn terrain(cells: usize) -> (SceneMsg, Vec<SweepMsg>) {
    let mut rng = Lcg(7);
    let k = cells + 1;
    let heights: Vec<f64> = (0..k * k)
        .map(|_| [0.0, 0.0, 0.0, 1.0][rng.next(4) as usize])
        .collect();
    let vertices: Vec<V> = (0..k * k)
        .map(|i| [(i % k) as f64, (i / k) as f64, heights[i]])
        .collect();
    let mut triangles = Vec::new();
    for j in 0..cells {
        for i in 0..cells {
            let v = |a: usize, b: usize| ((j + b) * k + i + a) as u64;
            let (a, b, c, d) = (v(0, 0), v(1, 0), v(1, 1), v(0, 1));
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    let scene = SceneMsg {
        name: Some("integer_terrain".into()),
        vertices,
        triangles,
        margin: 0.0,
        facing: Facing::NonStrict,
    };
    let mut sweeps = Vec::new();
    let mut frame = 0;
    let directions: [V; 4] = [
        [0.0, 0.0, 4.0],
        [1.0, 0.5, 4.0],
        [-0.5, 1.0, 3.0],
        [0.25, -0.75, 2.0],
    ];
    for j in 1..cells {
        for i in 1..cells {
            let h = heights[j * k + i];
            for (dx, dy) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)] {
                let target = [i as f64 + dx, j as f64 + dy, h + 0.5];
                let direction = directions[rng.next(4) as usize];
                let radius = [0.25, 0.5][rng.next(2) as usize];
                sweeps.push(sweep(frame, radius, target, direction));
                frame += 1;
            }
        }
    }
    (scene, sweeps)
}

fn mesh_scene(mesh: scenes::SceneMesh, margin: f64, facing: Facing) -> SceneMsg {
    SceneMsg {
        name: Some(mesh.name),
        vertices: mesh.vertices,
        triangles: mesh.triangles,
        margin,
        facing,
    }
}

/// The cube [-1, 1]³: drops along the diagonals onto its corners, along
/// the bisectors onto its edges, along the normals onto its face
/// diagonals (the seams of each face's two triangles) and centres.
fn cube() -> (SceneMsg, Vec<SweepMsg>) {
    let scene = mesh_scene(scenes::cube(), 0.0625, Facing::NonStrict);
    let mut sweeps = Vec::new();
    let mut frame = 0;
    let signs = [-1.0, 1.0];
    let mut push = |target: V, from: V, sweeps: &mut Vec<SweepMsg>| {
        for radius in [0.25, 0.5] {
            sweeps.push(sweep(frame, radius, target, from));
            frame += 1;
        }
    };
    for &x in &signs {
        for &y in &signs {
            for &z in &signs {
                push([x, y, z], [x * 2.0, y * 2.0, z * 2.0], &mut sweeps);
                push([x, y, z], [x * 2.0, y * 1.0, z * 3.0], &mut sweeps);
            }
        }
    }
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for &a in &signs {
            for &b in &signs {
                // The edge where faces u = a and v = b meet, at 3 points.
                for t in [-0.5, 0.0, 0.75] {
                    let mut target = [0.0; 3];
                    target[axis] = t;
                    target[u] = a;
                    target[v] = b;
                    let mut from = [0.0; 3];
                    from[u] = a * 2.0;
                    from[v] = b * 2.0;
                    push(target, from, &mut sweeps);
                }
            }
            // Face u = a: its diagonal seam and its centre, along the normal.
            for (s, r) in [(0.5, 0.5), (-0.25, -0.25), (0.5, -0.5), (0.0, 0.0)] {
                let mut target = [0.0; 3];
                target[u] = a;
                target[axis] = s;
                target[v] = r;
                let mut from = [0.0; 3];
                from[u] = a * 3.0;
                push(target, from, &mut sweeps);
            }
        }
    }
    (scene, sweeps)
}

/// The closed box [-2, 2]³ from inside (2 × 2 quads per face): from the
/// centre toward its corners, edge points and face seams.
fn closed_box() -> (SceneMsg, Vec<SweepMsg>) {
    let scene = mesh_scene(scenes::closed_box(), 0.0, Facing::Strict);
    let mut sweeps = Vec::new();
    let mut frame = 0;
    let mut targets: Vec<V> = Vec::new();
    let grid = [-2.0, -1.0, 0.0, 1.0, 2.0];
    for &x in &grid {
        for &y in &grid {
            for &z in &grid {
                let on_boundary = [x, y, z].iter().any(|c: &f64| c.abs() == 2.0);
                if on_boundary {
                    targets.push([x, y, z]);
                }
            }
        }
    }
    for target in targets {
        for (radius, start) in [(0.25, [0.0, 0.0, 0.0]), (0.5, [0.5, -0.25, 0.25])] {
            // From `start` to `target` and a bit beyond.
            let d = sub(target, start);
            sweeps.push(SweepMsg {
                frame,
                ball: 0,
                radius,
                p0: start,
                p1: add(start, scale(d, 1.25)),
            });
            frame += 1;
        }
    }
    (scene, sweeps)
}

/// A rotation about the axis `(1, 2, 3)` by 0.7 rad, then a scale and an
/// offset: the same configurations (shared vertices stay shared, bit for
/// bit), with coordinates that no longer compute exactly.
fn transformed(
    (scene, sweeps): (SceneMsg, Vec<SweepMsg>),
    label: &str,
    factor: f64,
    rotate: bool,
    offset: V,
) -> (SceneMsg, Vec<SweepMsg>) {
    let axis = {
        let a = [1.0, 2.0, 3.0];
        scale(a, 1.0 / dot(a, a).sqrt())
    };
    let (sin, cos) = 0.7f64.sin_cos();
    let map = |p: V| -> V {
        let r = if rotate {
            // Rodrigues' formula.
            add(
                add(scale(p, cos), scale(cross(axis, p), sin)),
                scale(axis, dot(axis, p) * (1.0 - cos)),
            )
        } else {
            p
        };
        add(scale(r, factor), offset)
    };
    let scene = SceneMsg {
        name: scene.name.map(|n| format!("{n} ({label})")),
        vertices: scene.vertices.into_iter().map(map).collect(),
        ..scene
    };
    let sweeps = sweeps
        .into_iter()
        .map(|s| SweepMsg {
            radius: s.radius * factor,
            p0: map(s.p0),
            p1: map(s.p1),
            ..s
        })
        .collect();
    (scene, sweeps)
}

fn scenes() -> Vec<(SceneMsg, Vec<SweepMsg>)> {
    let mut out = Vec::new();
    for make in [|| terrain(8), cube, closed_box] {
        out.push(make());
        out.push(transformed(
            make(),
            "scaled by 0.3, moved",
            0.3,
            false,
            [0.1, 0.7, -0.2],
        ));
        out.push(transformed(
            make(),
            "rotated, moved",
            1.0,
            true,
            [10.5, -3.25, 0.4],
        ));
    }
    out
}

fn differently_rounding_engine_gives_ties_not_divergences() -> anyhow::Result<()> {
    let mut totals = [0u64; 4];
    let mut lines = Vec::new();
    for (scene, sweeps) in scenes() {
        let name = scene.name.clone().unwrap_or_default();
        let bytes = alt_trace(&scene, &sweeps)?;
        // The sweeps are separate probes of the geometry, not one ball's
        // trajectory: the jumps between them are not tunnels of an engine.
        let options = CheckOptions {
            fail_on_tunnel: false,
            ..CheckOptions::default()
        };
        let report = check_reader(bytes.as_slice(), &name, &options);
        let text = render_text(&report);
        ensure!(
            report.divergent == 0 && report.status() == Status::Ok,
            "{name}: a rule-following engine must not diverge on a robust decision:\n{text}"
        );
        if std::env::var_os("ALT_ENGINE_VERBOSE").is_some() {
            eprintln!("{text}");
        }
        let matches = report.compared - report.tie_members - report.fragile.count;
        lines.push(format!(
            "{name}: {} sweeps, {matches} match, {} ties, {} fragile divergences {:?}",
            report.compared, report.tie_members, report.fragile.count, report.fragile.by_reason
        ));
        for (t, n) in totals.iter_mut().zip([
            report.compared,
            matches,
            report.tie_members,
            report.fragile.count,
        ]) {
            *t += n;
        }
    }
    eprintln!("{}", lines.join("\n"));
    eprintln!(
        "total: {} sweeps, {} match, {} ties, {} fragile divergences, 0 divergences",
        totals[0], totals[1], totals[2], totals[3]
    );
    ensure!(
        totals[2] >= 200,
        "the traces must hold many exact ties the other engine decides otherwise: {lines:?}"
    );
    Ok(())
}

/// A valley: two planes meeting at `x = 0, z = 0`, a ball dropped into
/// it touches both at once, at two points. An engine reporting the second
/// face with its own contact point is a tie; the same with the first
/// face's contact is a divergence.
fn tie_member_is_judged_with_its_own_contact() -> anyhow::Result<()> {
    let scene = SceneMsg {
        name: Some("valley".into()),
        vertices: vec![
            [-2.0, -2.0, 2.0],
            [0.0, -2.0, 0.0],
            [0.0, 2.0, 0.0],
            [-2.0, 2.0, 2.0],
            [2.0, -2.0, 2.0],
            [2.0, 2.0, 2.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]],
        margin: 0.0,
        facing: Facing::NonStrict,
    };
    let s = SweepMsg {
        frame: 0,
        ball: 0,
        radius: 0.5,
        p0: [0.0, 0.25, 5.0],
        p1: [0.0, 0.25, 0.0],
    };
    let core = sweeptrace::Mesh::new(scene.vertices.clone(), &scene.triangles)?;
    let outcome = sweeptrace::sweep_mesh(
        &core,
        &sweeptrace::Sweep::new(s.p0, s.p1, s.radius),
        &Default::default(),
    )?;
    ensure!(
        outcome.kind() == Kind::Face && outcome.hit.map(|h| h.triangle) == Some(0),
        "the core: face 0 (the lower of the two tied faces): {outcome:?}"
    );
    let h = 0.5 / 2f64.sqrt();
    let second = OutcomeMsg {
        frame: 0,
        ball: 0,
        alpha: outcome.travelled(),
        kind: Kind::Face,
        triangle: Some(Some(3)),
        feature: Some(None),
        normal: Some(Some([0.0, 0.0, 1.0])),
        contact: Some(Some([h, 0.25, h])),
    };
    let judge = |e: &OutcomeMsg| -> anyhow::Result<sweeptrace::suite::TraceReport> {
        let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
        w.scene(0, &scene)?;
        w.sweep(1, &s)?;
        w.expected(1, e)?;
        let bytes = w.finish()?.into_inner();
        Ok(check_reader(
            bytes.as_slice(),
            "valley",
            &CheckOptions::default(),
        ))
    };
    let report = judge(&second)?;
    ensure!(
        report.tie_members == 1 && report.divergent == 0 && report.fragile.count == 0,
        "the second face with its own contact is a tie:\n{}",
        render_text(&report)
    );
    let wrong = OutcomeMsg {
        contact: Some(Some([-h, 0.25, h])),
        ..second
    };
    let report = judge(&wrong)?;
    ensure!(
        report.tie_members == 0 && report.divergent + report.fragile.count == 1,
        "the second face with the first face's contact is not:\n{}",
        render_text(&report)
    );
    Ok(())
}
