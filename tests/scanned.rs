//! Exact ties on a real scanned mesh: the Stanford Bunny's lowest-resolution
//! reconstruction (`tests/fixtures/scanned/bunny_res4.obj`, 453 vertices,
//! 948 triangles, shared edges and vertices everywhere, a few duplicate
//! triangles as scanned), loaded through the OBJ loader.
//!
//! Scanned coordinates are not exact, so the vertices are snapped to the
//! dyadic grid 2⁻¹⁴ (multiples of 4 units, so that quarter points of edges
//! are grid points too): every coordinate is then an integer number of
//! units, exact in binary, and the reference below works on those integers.
//!
//! Construction of an exact first contact at a point `x` of the mesh: a
//! direction `w` with integer length `ρ = |w|` such that every vertex `y`
//! has `w·(y - x) ≤ 0` (a supporting plane of the mesh at `x`, so `x` is a
//! vertex or an edge point of the convex hull), the ball of radius `ρ`
//! centred at `x + w`, reached along a direction `d` with `w·d < 0`. The
//! ball stays in the open half-space `w·(p - x) > 0` until that moment and
//! then touches the mesh at `x` only: the tests that touch are known
//! exactly, and the rules' choice is the first of them in the tie order.
//! On a scanned mesh an edge is almost never perpendicular to a short
//! integer vector, so for edges `w` is searched in the lattice of integer
//! vectors perpendicular to the edge for lengths that are integers.

use std::collections::BTreeSet;
use std::path::Path;

use libtest_mimic::Trial;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sweeptrace::core::record::NoObserver;
use sweeptrace::core::{Broadphase, FragileReason, Kind, Sweep, sweep_mesh_with};
use sweeptrace::sim::scenes::SceneMesh;
use sweeptrace::suite::{CheckOptions, Status, check_reader, render_text};
use sweeptrace::trace::{SceneMsg, SweepMsg};

use crate::core_decisions::options;
use crate::ensure;
use crate::exact::{
    I3, cross3, dot3, exact_sqrt, exact_tie_set, in_closed_triangle, rational_length_vectors, sub3,
};
use crate::support::close;
use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(exact_ties_on_a_scanned_mesh_follow_the_rules),
        trial!(check_on_a_scanned_mesh_reports_ties_not_divergences),
    ]
}

/// Units per metre of the snapped grid (2¹⁴).
const UNITS: f64 = 16384.0;

/// The scanned mesh as the core sees it (snapped) and as integers.
struct Scanned {
    /// The snapped scene, coordinates `integer / UNITS`.
    scene: SceneMesh,
    /// Vertex coordinates in units of 2⁻¹⁴.
    vertices: Vec<I3>,
    /// Index triples; `None` for the triangles of zero area.
    triangles: Vec<Option<[usize; 3]>>,
    /// The vertices some triangle of nonzero area uses.
    used: Vec<I3>,
}

fn load_scanned() -> anyhow::Result<Scanned> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scanned/bunny_res4.obj");
    let loaded = sweeptrace::sim::load_obj(&path)?;
    ensure!(
        loaded.vertices.len() == 453 && loaded.triangles.len() == 948,
        "the bunny has 453 vertices and 948 triangles: {} {}",
        loaded.vertices.len(),
        loaded.triangles.len()
    );
    // Round to 2⁻¹² m, then count in units of 2⁻¹⁴ m.
    let vertices: Vec<I3> = loaded
        .vertices
        .iter()
        .map(|v| v.map(|c| 4 * (c * UNITS / 4.0).round() as i64))
        .collect();
    let scene = SceneMesh {
        name: format!("{} (snapped to 2^-12)", loaded.name),
        vertices: vertices
            .iter()
            .map(|v| v.map(|c| c as f64 / UNITS))
            .collect(),
        triangles: loaded.triangles.clone(),
    };
    let triangles: Vec<Option<[usize; 3]>> = loaded
        .triangles
        .iter()
        .map(|t| {
            let t = t.map(|i| i as usize);
            let v = t.map(|i| vertices[i]);
            (cross3(sub3(v[1], v[0]), sub3(v[2], v[0])) != [0, 0, 0]).then_some(t)
        })
        .collect();
    // The core must skip exactly the triangles of zero area.
    let mesh = scene.to_mesh()?;
    let skipped: BTreeSet<usize> = mesh.degenerate().iter().map(|d| d.index).collect();
    let zero: BTreeSet<usize> = (0..triangles.len())
        .filter(|&t| triangles[t].is_none())
        .collect();
    ensure!(
        skipped == zero,
        "degenerate triangles: the core skips {skipped:?}, zero area {zero:?}"
    );
    let used: BTreeSet<usize> = triangles.iter().flatten().flatten().copied().collect();
    let used = used.into_iter().map(|i| vertices[i]).collect();
    Ok(Scanned {
        scene,
        vertices,
        triangles,
        used,
    })
}

fn gcd(a: i64, b: i64) -> i64 {
    if b == 0 { a.abs() } else { gcd(b, a % b) }
}

/// `(g, s, t)` with `a s + b t = g = gcd(a, b) ≥ 0`.
fn extended_gcd(a: i64, b: i64) -> (i64, i64, i64) {
    if b == 0 {
        if a < 0 { (-a, -1, 0) } else { (a, 1, 0) }
    } else {
        let (g, s, t) = extended_gcd(b, a % b);
        (g, t, s - (a / b) * t)
    }
}

/// A reduced basis of the lattice of integer vectors perpendicular to the
/// nonzero integer vector `e`.
fn perpendicular_lattice(e: I3) -> anyhow::Result<(I3, I3)> {
    let g = gcd(gcd(e[0], e[1]), e[2]);
    let e = e.map(|c| c / g);
    let (mut u, mut v) = if e[0] == 0 && e[1] == 0 {
        ([1, 0, 0], [0, 1, 0])
    } else {
        let (g, s, t) = extended_gcd(e[0], e[1]);
        ([e[1] / g, -e[0] / g, 0], [-e[2] * s, -e[2] * t, g])
    };
    let c = cross3(u, v);
    ensure!(
        c == e || c == e.map(|k| -k),
        "not a basis of the lattice perpendicular to {e:?}: {u:?} {v:?}"
    );
    // Lagrange-Gauss reduction.
    loop {
        if dot3(u, u) > dot3(v, v) {
            std::mem::swap(&mut u, &mut v);
        }
        let (uu, uv) = (dot3(u, u), dot3(u, v));
        let k = (2 * uv + uu).div_euclid(2 * uu);
        if k == 0 {
            return Ok((u, v));
        }
        v = sub3(v, u.map(|c| c * k));
    }
}

/// The integer vectors `w ⟂ (b - a)` of integer length at most `max` with
/// `w·(y - a) ≤ 0` for every `y` (the normal cone of the mesh's convex hull
/// along the edge `a b`), or nothing if `a b` is not an edge of the hull
/// (or one in a plane of the hull only).
fn edge_normal_cone(used: &[I3], a: I3, b: I3, max: i64) -> anyhow::Result<Vec<(I3, i64)>> {
    let (u, v) = perpendicular_lattice(sub3(b, a))?;
    // The other vertices in lattice coordinates: w = i u + j v has
    // w·(y - a) = i p + j q with (p, q) = (u·(y - a), v·(y - a)).
    let cross = |a: [i64; 2], b: [i64; 2]| a[0] * b[1] - a[1] * b[0];
    let dot = |a: [i64; 2], b: [i64; 2]| a[0] * b[0] + a[1] * b[1];
    // The cone from `right` counterclockwise to `left` holds every (p, q),
    // spanning less than a half-turn.
    let mut cone: Option<([i64; 2], [i64; 2])> = None;
    for &y in used {
        let p = [dot3(u, sub3(y, a)), dot3(v, sub3(y, a))];
        if p == [0, 0] {
            continue;
        }
        let Some((right, left)) = cone else {
            cone = Some((p, p));
            continue;
        };
        let (cr, cl) = (cross(right, p), cross(p, left));
        if (cr == 0 && dot(right, p) < 0) || (cl == 0 && dot(left, p) < 0) {
            return Ok(Vec::new());
        }
        cone = if cr >= 0 && cl >= 0 {
            Some((right, left))
        } else if cr < 0 && cl > 0 {
            Some((p, left))
        } else if cr > 0 && cl < 0 {
            Some((right, p))
        } else {
            return Ok(Vec::new());
        };
    }
    let Some((right, left)) = cone else {
        return Ok(Vec::new());
    };
    let bound = |x: I3| (2f64.sqrt() * max as f64 / (dot3(x, x) as f64).sqrt()).ceil() as i64 + 1;
    let (bi, bj) = (bound(u), bound(v));
    let mut out = Vec::new();
    for i in -bi..=bi {
        for j in -bj..=bj {
            if dot([i, j], right) > 0 || dot([i, j], left) > 0 {
                continue;
            }
            let w: I3 = std::array::from_fn(|k| i * u[k] + j * v[k]);
            let s = dot3(w, w);
            if s == 0 || s > max * max {
                continue;
            }
            if let Some(r) = exact_sqrt(s) {
                out.push((w, r));
            }
        }
    }
    Ok(out)
}

/// One constructed sweep with its exact answer.
struct Contact {
    p0: [f64; 3],
    p1: [f64; 3],
    radius: f64,
    alpha: f64,
    /// The exact tie set, the rules' choice first.
    expected: Vec<(Kind, u32, u8)>,
    /// Whether `x` is an edge point that is not a vertex.
    on_edge: bool,
}

/// For the contact point `x` and the outward direction `w` (length `rho`),
/// a direction of approach and a path around the contact, or `None` if the
/// random direction approaches at a cosine under 0.3 or grazes a triangle
/// at `x`.
fn contact(
    rng: &mut ChaCha8Rng,
    m: &Scanned,
    x: I3,
    w: I3,
    rho: i64,
    on_edge: bool,
) -> Option<Contact> {
    let d0: I3 = std::array::from_fn(|_| rng.random_range(-6..=6i64));
    let scale = rng.random_range(1..=48i64);
    let d = d0.map(|c| c * scale);
    let dd = dot3(d, d);
    let wd = dot3(w, d);
    if dd == 0 || wd >= 0 || (wd as f64).powi(2) <= 0.09 * (rho * rho) as f64 * dd as f64 {
        return None;
    }
    let grazing = m.triangles.iter().flatten().any(|t| {
        let v = t.map(|i| m.vertices[i]);
        let n = cross3(sub3(v[1], v[0]), sub3(v[2], v[0]));
        let nd = dot3(n, d) as f64;
        in_closed_triangle(x, v, n) && nd * nd <= 1e-4 * dot3(n, n) as f64 * dd as f64
    });
    if grazing {
        return None;
    }
    let expected = exact_tie_set(
        &m.vertices,
        (0u32..)
            .zip(&m.triangles)
            .filter_map(|(t, tri)| tri.map(|tri| (t, tri))),
        x,
        w,
        d,
    );
    if expected.is_empty() {
        return None;
    }
    let (t0, t1) = (rng.random_range(1..5i64), rng.random_range(1..5i64));
    let at =
        |t: i64| -> [f64; 3] { std::array::from_fn(|k| (x[k] + w[k] + t * d[k]) as f64 / UNITS) };
    Some(Contact {
        p0: at(-t0),
        p1: at(t1),
        radius: rho as f64 / UNITS,
        alpha: t0 as f64 / (t0 + t1) as f64,
        expected,
        on_edge,
    })
}

/// Seeded exact contacts on the snapped bunny: at vertices of its convex
/// hull (directions of integer length up to 24, scaled by up to 40), and at
/// quarter points of the mesh edges that are edges of the hull (directions
/// in the lattice perpendicular to the edge, integer length up to 600).
fn scanned_contacts(m: &Scanned, seed: u64) -> anyhow::Result<(Vec<Contact>, usize)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    let directions = rational_length_vectors(24);
    for _ in 0..3000 {
        let (w0, r0) = directions[rng.random_range(0..directions.len())];
        let top = m
            .used
            .iter()
            .map(|&y| dot3(w0, y))
            .max()
            .context("no vertex")?;
        let support: Vec<I3> = m
            .used
            .iter()
            .copied()
            .filter(|&y| dot3(w0, y) == top)
            .collect();
        let x = support[rng.random_range(0..support.len())];
        let k = rng.random_range(1..=40i64);
        if let Some(c) = contact(&mut rng, m, x, w0.map(|c| c * k), r0 * k, false) {
            out.push(c);
        }
    }
    let mut edges = BTreeSet::new();
    for t in m.triangles.iter().flatten() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let mut hull_edges = 0;
    for (a, b) in edges {
        let (a, b) = (m.vertices[a], m.vertices[b]);
        if a == b {
            continue;
        }
        let cone = edge_normal_cone(&m.used, a, b, 600)?;
        if cone.is_empty() {
            continue;
        }
        hull_edges += 1;
        for _ in 0..80 {
            let (w, r) = cone[rng.random_range(0..cone.len())];
            let q = rng.random_range(0..=4i64);
            let x: I3 = std::array::from_fn(|k| a[k] + q * (b[k] - a[k]) / 4);
            let k = rng.random_range(1..=3i64);
            if let Some(c) = contact(&mut rng, m, x, w.map(|c| c * k), r * k, q % 4 != 0) {
                out.push(c);
            }
        }
    }
    Ok((out, hull_edges))
}

/// On the scanned bunny (snapped to a dyadic grid), balls sent at vertices
/// and edge points of its convex hull: the core's primary is the first of
/// the exact tie set in the rules' order, with both broadphases, its `α` is
/// the exact one, a tie of two or more tests is flagged `tie`, and the
/// reported tie set holds every exactly tied test.
fn exact_ties_on_a_scanned_mesh_follow_the_rules() -> anyhow::Result<()> {
    let m = load_scanned()?;
    let mesh = m.scene.to_mesh()?;
    let (contacts, hull_edges) = scanned_contacts(&m, 0x5ca7)?;
    let (mut multi, mut shared, mut on_edges) = (0usize, 0usize, 0usize);
    let mut by_kind = [0usize; 3];
    for (n, c) in contacts.iter().enumerate() {
        let first = c.expected[0];
        let sweep = Sweep::new(c.p0, c.p1, c.radius);
        for broadphase in [Broadphase::Bvh, Broadphase::Exhaustive] {
            let o = sweep_mesh_with(&mesh, &sweep, &options(), broadphase, &mut NoObserver)?;
            let got = (
                o.kind(),
                o.hit.map(|h| h.triangle).unwrap_or(u32::MAX),
                o.hit.and_then(|h| h.feature.index()).unwrap_or(0),
            );
            ensure!(
                got == first,
                "contact {n} (p0 {:?}, p1 {:?}, radius {:?}), {broadphase:?}: expected \
                 {first:?} (exact tie set {:?}), got {o:?}",
                c.p0,
                c.p1,
                c.radius,
                c.expected
            );
            close("alpha", o.travelled(), c.alpha, 1e-9)?;
            ensure!(
                c.expected.len() < 2 || o.fragile.contains(FragileReason::Tie),
                "contact {n}: a tie of {} tests is flagged: {o:?}",
                c.expected.len()
            );
        }
        let (_, ties) = sweeptrace::core::sweep_ties(&mesh, &sweep, &options())?;
        let reported: BTreeSet<(Kind, u32, u8)> = ties
            .iter()
            .map(|t| (t.kind(), t.triangle, t.feature.index().unwrap_or(0)))
            .collect();
        ensure!(
            c.expected.iter().all(|e| reported.contains(e)),
            "contact {n}: the tie set {ties:?} lacks some of {:?}",
            c.expected
        );
        multi += usize::from(c.expected.len() > 1);
        let triangles: BTreeSet<u32> = c.expected.iter().map(|e| e.1).collect();
        shared += usize::from(triangles.len() > 1);
        on_edges += usize::from(c.on_edge);
        by_kind[first.0 as usize] += 1;
    }
    println!(
        "    bunny_res4.obj (453 vertices, 948 triangles, {hull_edges} mesh edges on the convex \
         hull): {} exact contacts ({on_edges} inside edges, the rest at vertices); {multi} ties \
         of 2 or more tests, {shared} of them between triangles sharing the edge or vertex; \
         primary face {}, edge {}, vertex {}: every primary is the rules' choice with both \
         broadphases",
        contacts.len(),
        by_kind[0],
        by_kind[1],
        by_kind[2]
    );
    ensure!(
        contacts.len() > 1000 && on_edges > 300 && shared > 1000 && by_kind[1] > 300,
        "too few cases: {} contacts, {on_edges} on edges, {shared} shared, {by_kind:?}",
        contacts.len()
    );
    Ok(())
}

/// `check` on the bunny: expectations recorded by the differently rounding
/// engine of `alt_engine` (rule-following, but its own rounding picks among
/// exactly tied tests) are ties where they differ, never divergences.
fn check_on_a_scanned_mesh_reports_ties_not_divergences() -> anyhow::Result<()> {
    let m = load_scanned()?;
    let (contacts, _) = scanned_contacts(&m, 0xb0b)?;
    let scene = SceneMsg {
        name: Some(m.scene.name.clone()),
        vertices: m.scene.vertices.clone(),
        triangles: m.scene.triangles.clone(),
        margin: 0.0,
        facing: options().facing,
    };
    let sweeps: Vec<SweepMsg> = contacts
        .iter()
        .enumerate()
        .map(|(i, c)| SweepMsg {
            frame: i as u64,
            ball: 0,
            radius: c.radius,
            p0: c.p0,
            p1: c.p1,
        })
        .collect();
    let bytes = crate::alt_engine::alt_trace(&scene, &sweeps)?;
    // Separate probes, not one ball's trajectory: no tunnel judgement.
    let check_options = CheckOptions {
        fail_on_tunnel: false,
        ..CheckOptions::default()
    };
    let report = check_reader(bytes.as_slice(), "bunny", &check_options);
    let text = render_text(&report);
    ensure!(
        report.divergent == 0 && report.status() == Status::Ok,
        "a rule-following engine must not diverge on a robust decision:\n{text}"
    );
    let multi = contacts.iter().filter(|c| c.expected.len() > 1).count();
    let matches = report.compared - report.tie_members - report.fragile.count;
    println!(
        "    bunny: {} sweeps ({multi} exact ties of 2 or more tests), {matches} match, {} ties, \
         {} fragile divergences {:?}, 0 divergences",
        report.compared, report.tie_members, report.fragile.count, report.fragile.by_reason
    );
    ensure!(
        report.compared as usize == contacts.len() && report.tie_members >= 50,
        "the other engine should decide many exact ties otherwise: {} compared, {} ties",
        report.compared,
        report.tie_members
    );
    Ok(())
}
