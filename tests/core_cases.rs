//! Hand-built cases: every verdict of every test, with the expected numbers
//! worked out in the comments. Unless stated: triangle T = (0,0,0), (4,0,0),
//! (0,4,0) (front normal +z), r = 0.5, margin 0, facing non_strict.
//!
//! Edge 0 of T runs (0,0,0) → (4,0,0); its standard frame has x = (1,0,0),
//! y = n = (0,0,1), z = x × y = (0,-1,0), so a world point (x, y, z) maps to
//! (x, z, -y).

use libtest_mimic::Trial;
use sweeptrace::core::record::{NoObserver, Verdict};
use sweeptrace::core::{
    Broadphase, Facing, FragileReason, Kind, Mesh, MeshError, Options, Outcome, Sweep, SweepError,
    sweep_mesh, sweep_mesh_with,
};

use crate::ensure;
use crate::support::{close, edge, face, mesh, run, triangle_t, vertex};
use crate::trial;
use anyhow::Context as _;

const NS: Facing = Facing::NonStrict;
const TOL: f64 = 1e-12;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(face_hit_worked_example_1),
        trial!(face_starts_too_close),
        trial!(face_parallel),
        trial!(face_back_facing),
        trial!(face_beyond_end),
        trial!(face_outside_triangle),
        trial!(edge_hit_worked_example_2_start_before_s0),
        trial!(edge_start_between_s0_and_s1),
        trial!(edge_start_after_s1),
        trial!(edge_beyond_end),
        trial!(edge_double_root_tangent),
        trial!(edge_parallel_path),
        trial!(edge_no_real_roots),
        trial!(edge_off_edge),
        trial!(edge_back_facing),
        trial!(edge_strict_facing_rejects_n_dot_d_zero),
        trial!(hit_exactly_at_alpha_1_worked_example_4),
        trial!(zero_length_path),
        trial!(vertex_hit_worked_example_3),
        trial!(vertex_no_real_roots),
        trial!(vertex_before_start),
        trial!(vertex_beyond_end),
        trial!(vertex_back_facing),
        trial!(endpoint_contact_exactly_at_xc_eq_l_is_edge),
        trial!(shared_edge_reported_for_both),
        trial!(shared_edge_reported_for_one),
        trial!(shared_edge_reported_for_neither),
        trial!(cube_shared_edge_averaged_normal_worked_example_5),
        trial!(margin_shrinks_detection_radius),
        trial!(standard_frame_round_trip),
        trial!(bad_input_errors),
        trial!(degenerate_triangles_reported_and_skipped),
        trial!(edge_far_start_small_radius_discriminant_without_cancellation),
        trial!(very_long_path_never_nan),
        trial!(sliver_triangle_face_hit_barycentric_without_cancellation),
        trial!(zero_q_gives_a_double_root_only_when_c_is_zero),
        trial!(face_decides_direction_by_n_dot_d_alone),
    ]
}

fn face_hit_worked_example_1() -> anyhow::Result<()> {
    // h0 = 3, h1 = -3, β = (3 - 0.5) / 6 = 5/12, touch (1,1,0), barycentric
    // (1 - 0.25 - 0.25, 0.25, 0.25).
    let (o, recs) = run(
        &triangle_t(),
        [1.0, 1.0, 3.0],
        [1.0, 1.0, -3.0],
        0.5,
        0.0,
        NS,
    );
    let f = face(&recs, 0);
    ensure!(f.verdict == Verdict::Hit, "verdict {:?}", f.verdict);
    close("h0", f.h0, 3.0, TOL)?;
    close("h1", f.h1, -3.0, TOL)?;
    close("beta", f.beta.unwrap_or(f64::NAN), 5.0 / 12.0, TOL)?;
    let b = f.barycentric.context("no barycentric")?;
    close("bary a", b[0], 0.5, TOL)?;
    close("bary b", b[1], 0.25, TOL)?;
    ensure!(
        o.kind() == Kind::Face
            && o.hit.map(|h| h.triangle) == Some(0)
            && o.hit.and_then(|h| h.feature.index()).is_none(),
        "outcome {o:?}"
    );
    close("alpha", o.travelled(), 5.0 / 12.0, TOL)?;
    let c = o.hit.map(|h| h.contact).context("no contact")?;
    close("contact x", c.x, 1.0, TOL)?;
    close("contact z", c.z, 0.0, TOL)?;
    let n = o.hit.map(|h| h.normal).context("no normal")?;
    close("normal z", n.z, 1.0, TOL)
}

fn face_starts_too_close() -> anyhow::Result<()> {
    // h0 = 0.3 < ρ = 0.5: the ball starts within ρ of the plane.
    let (_, recs) = run(
        &triangle_t(),
        [1.0, 1.0, 0.3],
        [1.0, 1.0, -3.0],
        0.5,
        0.0,
        NS,
    );
    let f = face(&recs, 0);
    ensure!(
        f.verdict == Verdict::StartsTooClose,
        "verdict {:?}",
        f.verdict
    );
    close("h0", f.h0, 0.3, TOL)
}

fn face_parallel() -> anyhow::Result<()> {
    // h0 = h1 = 3.
    let (o, recs) = run(
        &triangle_t(),
        [1.0, 1.0, 3.0],
        [2.0, 1.0, 3.0],
        0.5,
        0.0,
        NS,
    );
    ensure!(
        face(&recs, 0).verdict == Verdict::Parallel,
        "verdict {:?}",
        face(&recs, 0).verdict
    );
    ensure!(
        o.kind() == Kind::None && o.travelled() == 1.0,
        "outcome {o:?}"
    );
    Ok(())
}

fn face_back_facing() -> anyhow::Result<()> {
    // Moving away from the front: h0 = 3, h1 = 5, n·d = 2 > 0.
    let (_, recs) = run(
        &triangle_t(),
        [1.0, 1.0, 3.0],
        [1.0, 1.0, 5.0],
        0.5,
        0.0,
        NS,
    );
    let f = face(&recs, 0);
    ensure!(f.verdict == Verdict::BackFacing, "verdict {:?}", f.verdict);
    close("n.d", f.normal_dot_d, 2.0, TOL)
}

fn face_beyond_end() -> anyhow::Result<()> {
    // h0 = 3, h1 = 2: β = 2.5 / 1 = 2.5 > 1.
    let (_, recs) = run(
        &triangle_t(),
        [1.0, 1.0, 3.0],
        [1.0, 1.0, 2.0],
        0.5,
        0.0,
        NS,
    );
    let f = face(&recs, 0);
    ensure!(f.verdict == Verdict::BeyondEnd, "verdict {:?}", f.verdict);
    close("beta", f.beta.unwrap_or(f64::NAN), 2.5, TOL)
}

fn face_outside_triangle() -> anyhow::Result<()> {
    // β = 5/12, touch (3,3,0): barycentric (1 - 0.75 - 0.75, 0.75, 0.75) = (-0.5, ...).
    let (_, recs) = run(
        &triangle_t(),
        [3.0, 3.0, 3.0],
        [3.0, 3.0, -3.0],
        0.5,
        0.0,
        NS,
    );
    let f = face(&recs, 0);
    ensure!(
        f.verdict == Verdict::OutsideTriangle,
        "verdict {:?}",
        f.verdict
    );
    close("bary a", f.barycentric.context("no bary")?[0], -0.5, TOL)
}

fn edge_hit_worked_example_2_start_before_s0() -> anyhow::Result<()> {
    // Worked example 2. p0 → (2, 3, 0.3), p1 → (2, -3, 0.3). A = 36, B = -36,
    // C = 9 + 0.09 - 0.25 = 8.84, disc = 1296 - 1272.96 = 23.04 (√ = 4.8),
    // roots (36 ∓ 4.8) / 72 = 0.43333, 0.56667; xc = 2; n·d = -6: α = 13/30.
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -0.3, 3.0],
        [2.0, -0.3, -3.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    close("p0 x", e.p0_in_edge.x, 2.0, TOL)?;
    close("p0 y", e.p0_in_edge.y, 3.0, TOL)?;
    close("p0 z", e.p0_in_edge.z, 0.3, TOL)?;
    close("p1 y", e.p1_in_edge.y, -3.0, TOL)?;
    close("A", e.a, 36.0, 1e-9)?;
    close("B", e.b, -36.0, 1e-9)?;
    close("C", e.c, 8.84, 1e-9)?;
    close("disc", e.discriminant, 23.04, 1e-9)?;
    let (s0, s1) = e.roots.context("no roots")?;
    close("s0", s0, 13.0 / 30.0, 1e-12)?;
    close("s1", s1, 17.0 / 30.0, 1e-12)?;
    close("xc", e.xc.unwrap_or(f64::NAN), 2.0, 1e-12)?;
    ensure!(e.verdict == Verdict::Hit, "verdict {:?}", e.verdict);
    // The face test's touch point (2, -0.3, 0) lies outside T.
    ensure!(
        face(&recs, 0).verdict == Verdict::OutsideTriangle,
        "face {:?}",
        face(&recs, 0).verdict
    );
    ensure!(
        o.kind() == Kind::Edge && o.hit.and_then(|h| h.feature.index()) == Some(0),
        "outcome {o:?}"
    );
    close("alpha", o.travelled(), 13.0 / 30.0, 1e-12)?;
    let c = o.hit.map(|h| h.contact).context("no contact")?;
    close("contact x", c.x, 2.0, 1e-12)?;
    close("contact y", c.y, 0.0, 1e-12)
}

fn edge_start_between_s0_and_s1() -> anyhow::Result<()> {
    // Start between S0 and S1 (the ball starts within ρ of the edge's line).
    // p0 → (2, 0.2, 0.3), p1 → (2, -3, 0.3): dy = -3.2, A = 10.24,
    // B = 2 (0.2 · -3.2) = -1.28, C = 0.04 + 0.09 - 0.25 = -0.12,
    // disc = 1.6384 + 4.9152 = 6.5536 (√ = 2.56), roots (1.28 ∓ 2.56) / 20.48
    // = -0.0625, 0.1875: s0 < 0 ≤ s1, before the start.
    let (_, recs) = run(
        &triangle_t(),
        [2.0, -0.3, 0.2],
        [2.0, -0.3, -3.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    let (s0, s1) = e.roots.context("no roots")?;
    close("s0", s0, -0.0625, 1e-12)?;
    close("s1", s1, 0.1875, 1e-12)?;
    ensure!(e.verdict == Verdict::BeforeStart, "verdict {:?}", e.verdict);
    Ok(())
}

fn edge_start_after_s1() -> anyhow::Result<()> {
    // Start after S1: p0 → (2, -3, 0.3), p1 → (2, -6, 0.3): A = 9, B = 18,
    // C = 8.84, disc = 324 - 318.24 = 5.76 (√ = 2.4), roots (-18 ∓ 2.4) / 18
    // = -1.13333, -0.86667: both negative.
    let (_, recs) = run(
        &triangle_t(),
        [2.0, -0.3, -3.0],
        [2.0, -0.3, -6.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    let (s0, s1) = e.roots.context("no roots")?;
    close("s0", s0, -20.4 / 18.0, 1e-12)?;
    close("s1", s1, -15.6 / 18.0, 1e-12)?;
    ensure!(e.verdict == Verdict::BeforeStart, "verdict {:?}", e.verdict);
    Ok(())
}

fn edge_beyond_end() -> anyhow::Result<()> {
    // p0 → (2, 3, 0.3), p1 → (2, 1, 0.3): A = 4, B = -12, C = 8.84,
    // disc = 144 - 141.44 = 2.56 (√ = 1.6), roots (12 ∓ 1.6) / 8 = 1.3, 1.7.
    let (_, recs) = run(
        &triangle_t(),
        [2.0, -0.3, 3.0],
        [2.0, -0.3, 1.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    close("s0", e.roots.context("no roots")?.0, 1.3, 1e-12)?;
    ensure!(e.verdict == Verdict::BeyondEnd, "verdict {:?}", e.verdict);
    Ok(())
}

fn edge_double_root_tangent() -> anyhow::Result<()> {
    // The path passes at exactly ρ from the edge's line: p0 → (2, 3, 0.5),
    // p1 → (2, -3, 0.5): A = 36, B = -36, C = 9 + 0.25 - 0.25 = 9,
    // disc = 1296 - 1296 = 0 (every value exact in binary): a double root
    // s0 = s1 = 0.5, xc = 2: a touching hit at α = 0.5.
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -0.5, 3.0],
        [2.0, -0.5, -3.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    ensure!(e.discriminant == 0.0, "discriminant {}", e.discriminant);
    ensure!(e.roots == Some((0.5, 0.5)), "roots {:?}", e.roots);
    ensure!(e.verdict == Verdict::Hit, "verdict {:?}", e.verdict);
    ensure!(
        o.kind() == Kind::Edge && o.travelled() == 0.5,
        "outcome {o:?}"
    );
    Ok(())
}

fn edge_parallel_path() -> anyhow::Result<()> {
    // Rolling along edge 0: p0 → (1, 0.2, 0.3), p1 → (3, 0.2, 0.3), A = 0.
    let (_, recs) = run(
        &triangle_t(),
        [1.0, -0.3, 0.2],
        [3.0, -0.3, 0.2],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    ensure!(e.verdict == Verdict::Parallel, "verdict {:?}", e.verdict);
    ensure!(e.a == 0.0, "A = {}", e.a);
    Ok(())
}

fn edge_no_real_roots() -> anyhow::Result<()> {
    // p0 → (2, 3, 2), p1 → (2, -3, 2): A = 36, B = -36, C = 9 + 4 - 0.25 =
    // 12.75, disc = 1296 - 1836 = -540.
    let (_, recs) = run(
        &triangle_t(),
        [2.0, -2.0, 3.0],
        [2.0, -2.0, -3.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    close("disc", e.discriminant, -540.0, 1e-9)?;
    ensure!(
        e.verdict == Verdict::NoRealRoots && e.roots.is_none(),
        "verdict {:?}",
        e.verdict
    );
    Ok(())
}

fn edge_off_edge() -> anyhow::Result<()> {
    // As example 2 but at x = 5: s0 = 13/30, xc = 5 > L = 4.
    let (_, recs) = run(
        &triangle_t(),
        [5.0, -0.3, 3.0],
        [5.0, -0.3, -3.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    close("xc", e.xc.unwrap_or(f64::NAN), 5.0, 1e-12)?;
    ensure!(e.verdict == Verdict::OffEdge, "verdict {:?}", e.verdict);
    Ok(())
}

fn edge_back_facing() -> anyhow::Result<()> {
    // Example 2 reversed: p0 → (2, -3, 0.3), p1 → (2, 3, 0.3): A = 36,
    // B = -36, same roots, xc = 2, but n·d = +6.
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -0.3, -3.0],
        [2.0, -0.3, 3.0],
        0.5,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    close("s0", e.roots.context("no roots")?.0, 13.0 / 30.0, 1e-12)?;
    ensure!(e.verdict == Verdict::BackFacing, "verdict {:?}", e.verdict);
    ensure!(o.kind() == Kind::None, "outcome {o:?}");
    Ok(())
}

fn edge_strict_facing_rejects_n_dot_d_zero() -> anyhow::Result<()> {
    // Edge 0 approached sideways within the plane's parallel: p0 = (2, -3, 0),
    // p1 = (2, 3, 0): n·d = 0. Frame: p0 → (2, 0, 3), p1 → (2, 0, -3);
    // A = 36, B = -36, C = 9 - 0.25 = 8.75, disc = 36, roots (36 ∓ 6)/72 =
    // 5/12, 7/12; xc = 2. non_strict accepts n·d = 0, strict rejects it.
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -3.0, 0.0],
        [2.0, 3.0, 0.0],
        0.5,
        0.0,
        Facing::NonStrict,
    );
    ensure!(
        edge(&recs, 0, 0).verdict == Verdict::Hit,
        "non_strict {:?}",
        edge(&recs, 0, 0).verdict
    );
    close("alpha", o.travelled(), 5.0 / 12.0, 1e-12)?;
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -3.0, 0.0],
        [2.0, 3.0, 0.0],
        0.5,
        0.0,
        Facing::Strict,
    );
    ensure!(
        edge(&recs, 0, 0).verdict == Verdict::BackFacing,
        "strict {:?}",
        edge(&recs, 0, 0).verdict
    );
    ensure!(o.kind() == Kind::None, "strict outcome {o:?}");
    Ok(())
}

fn hit_exactly_at_alpha_1_worked_example_4() -> anyhow::Result<()> {
    // Worked example 4: r = 0.625, p0 = (2, -0.375, 3), p1 = (2, -0.375, 0.5).
    // Frame: (2, 3, 0.375) → (2, 0.5, 0.375). A = 2.5² = 6.25,
    // B = 2 · 3 · -2.5 = -15, C = 9 + 0.140625 - 0.390625 = 8.75,
    // disc = 225 - 218.75 = 6.25, q = (15 + 2.5)/2 = 8.75, roots C/q = 1 and
    // q/A = 1.4: s0 = 1 exactly. A touch at the end is a collision.
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -0.375, 3.0],
        [2.0, -0.375, 0.5],
        0.625,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    ensure!(
        e.a == 6.25 && e.b == -15.0 && e.c == 8.75 && e.discriminant == 6.25,
        "quadratic {e:?}"
    );
    ensure!(e.roots == Some((1.0, 1.4)), "roots {:?}", e.roots);
    ensure!(
        o.kind() == Kind::Edge && o.travelled() == 1.0 && o.hit.map(|h| h.triangle) == Some(0),
        "outcome {o:?}"
    );
    Ok(())
}

fn zero_length_path() -> anyhow::Result<()> {
    // d = 0: face parallel, edges parallel (A = 0), vertices not moving.
    let (o, recs) = run(
        &triangle_t(),
        [2.0, -0.3, 3.0],
        [2.0, -0.3, 3.0],
        0.5,
        0.0,
        NS,
    );
    ensure!(
        face(&recs, 0).verdict == Verdict::Parallel,
        "face {:?}",
        face(&recs, 0).verdict
    );
    for i in 0..3 {
        ensure!(edge(&recs, 0, i).verdict == Verdict::Parallel, "edge {i}");
        ensure!(
            vertex(&recs, 0, i).verdict == Verdict::NotMoving,
            "vertex {i}"
        );
    }
    ensure!(
        o.kind() == Kind::None && o.travelled() == 1.0,
        "outcome {o:?}"
    );
    Ok(())
}

fn vertex_hit_worked_example_3() -> anyhow::Result<()> {
    // Worked example 3: p0 = (-0.3, -0.2, 3), p1 = (-0.3, -0.2, -3).
    // Edge 0 touches its line at s ≈ 0.4236 with xc = -0.3 < 0 (off the edge);
    // edge 2 (from (0,4,0) to (0,0,0)) touches its line beyond its end;
    // vertex 0: A = 36, B = 2 (0,0,-6)·(-0.3,-0.2,3) = -36, C = 0.09 + 0.04 + 9
    // - 0.25 = 8.88, disc = 1296 - 1278.72 = 17.28, s0 = (36 - √17.28) / 72
    // = 0.44226.
    let (o, recs) = run(
        &triangle_t(),
        [-0.3, -0.2, 3.0],
        [-0.3, -0.2, -3.0],
        0.5,
        0.0,
        NS,
    );
    let e0 = edge(&recs, 0, 0);
    ensure!(e0.verdict == Verdict::OffEdge, "edge 0 {:?}", e0.verdict);
    close("edge 0 xc", e0.xc.unwrap_or(f64::NAN), -0.3, 1e-12)?;
    let e2 = edge(&recs, 0, 2);
    ensure!(e2.verdict == Verdict::OffEdge, "edge 2 {:?}", e2.verdict);
    ensure!(
        e2.xc.unwrap_or(0.0) > e2.length,
        "edge 2 xc {:?} beyond L {}",
        e2.xc,
        e2.length
    );
    let v = vertex(&recs, 0, 0);
    close("A", v.a, 36.0, 1e-12)?;
    close("B", v.b, -36.0, 1e-12)?;
    close("C", v.c, 8.88, 1e-12)?;
    let want = (36.0 - 17.28f64.sqrt()) / 72.0;
    close("s0", v.roots.context("roots")?.0, want, 1e-12)?;
    ensure!(
        o.kind() == Kind::Vertex && o.hit.and_then(|h| h.feature.index()) == Some(0),
        "outcome {o:?}"
    );
    close("alpha", o.travelled(), 0.44226, 1e-5)?;
    let c = o.hit.map(|h| h.contact).context("contact")?;
    ensure!(c.coords.norm() == 0.0, "contact {c:?} is the vertex");
    Ok(())
}

fn vertex_no_real_roots() -> anyhow::Result<()> {
    // p0 = (-2, -2, 3): C = 4 + 4 + 9 - 0.25 = 16.75, disc = 1296 - 2412 < 0.
    let (_, recs) = run(
        &triangle_t(),
        [-2.0, -2.0, 3.0],
        [-2.0, -2.0, -3.0],
        0.5,
        0.0,
        NS,
    );
    let v = vertex(&recs, 0, 0);
    close("disc", v.discriminant, 1296.0 - 2412.0, 1e-9)?;
    ensure!(v.verdict == Verdict::NoRealRoots, "verdict {:?}", v.verdict);
    Ok(())
}

fn vertex_before_start() -> anyhow::Result<()> {
    // The ball starts overlapping vertex 0: C = 0.03 - 0.25 < 0, so s0 < 0.
    let (_, recs) = run(
        &triangle_t(),
        [-0.1, -0.1, 0.1],
        [-0.1, -0.1, -3.0],
        0.5,
        0.0,
        NS,
    );
    let v = vertex(&recs, 0, 0);
    close("C", v.c, 0.03 - 0.25, 1e-12)?;
    ensure!(v.verdict == Verdict::BeforeStart, "verdict {:?}", v.verdict);
    Ok(())
}

fn vertex_beyond_end() -> anyhow::Result<()> {
    // d = (0,0,-1): A = 1, B = -6, C = 8.88, disc = 0.48, s0 = (6 - √0.48)/2 = 2.6536.
    let (_, recs) = run(
        &triangle_t(),
        [-0.3, -0.2, 3.0],
        [-0.3, -0.2, 2.0],
        0.5,
        0.0,
        NS,
    );
    let v = vertex(&recs, 0, 0);
    close(
        "s0",
        v.roots.context("roots")?.0,
        (6.0 - 0.48f64.sqrt()) / 2.0,
        1e-12,
    )?;
    ensure!(v.verdict == Verdict::BeyondEnd, "verdict {:?}", v.verdict);
    Ok(())
}

fn vertex_back_facing() -> anyhow::Result<()> {
    // Example 3 reversed: same quadratic up to the sign of B... m = (-0.3,
    // -0.2, -3), d = (0,0,6): B = -36, s0 = 0.44226, but n·d = 6 > 0.
    let (o, recs) = run(
        &triangle_t(),
        [-0.3, -0.2, -3.0],
        [-0.3, -0.2, 3.0],
        0.5,
        0.0,
        NS,
    );
    let v = vertex(&recs, 0, 0);
    close(
        "s0",
        v.roots.context("roots")?.0,
        (36.0 - 17.28f64.sqrt()) / 72.0,
        1e-12,
    )?;
    ensure!(v.verdict == Verdict::BackFacing, "verdict {:?}", v.verdict);
    ensure!(o.kind() == Kind::None, "outcome {o:?}");
    Ok(())
}

fn endpoint_contact_exactly_at_xc_eq_l_is_edge() -> anyhow::Result<()> {
    // Example 4 moved to x = 4 = L: edge 0 gives s0 = 1 with xc = 4 = L
    // (accepted, boundary included); vertex 1 = (4,0,0) gives A = 6.25,
    // B = 2 (0,0,-2.5)·(0,-0.375,3) = -15, C = 0.140625 + 9 - 0.390625 = 8.75:
    // the same quadratic, s0 = 1. Exact tie: face < edge < vertex → edge.
    let (o, recs) = run(
        &triangle_t(),
        [4.0, -0.375, 3.0],
        [4.0, -0.375, 0.5],
        0.625,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    let v = vertex(&recs, 0, 1);
    ensure!(e.verdict == Verdict::Hit && e.xc == Some(4.0), "edge {e:?}");
    ensure!(
        v.verdict == Verdict::Hit && v.roots.map(|r| r.0) == Some(1.0),
        "vertex {v:?}"
    );
    ensure!(
        o.kind() == Kind::Edge
            && o.hit.and_then(|h| h.feature.index()) == Some(0)
            && o.travelled() == 1.0,
        "outcome {o:?}"
    );
    Ok(())
}

/// Two triangles sharing the edge (0,0,0)–(4,0,0): triangle 0 is T (front
/// +z), triangle 1 = (4,0,0), (0,0,0), (0,-4,-4), front (0,-1,1)/√2: a convex
/// ridge along the x axis. Its edge 0 runs (4,0,0) → (0,0,0).
fn ridge() -> Mesh {
    mesh(
        &[
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            [0.0, -4.0, -4.0],
        ],
        &[[0, 1, 2], [1, 0, 3]],
    )
}

/// Path through the point at distance 0.5 from the ridge in direction `u`
/// (unit, perpendicular to x) at β = 0.5, moving by `d` over the whole path.
fn ridge_path(u: [f64; 2], d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let c = [2.0, 0.5 * u[0], 0.5 * u[1]];
    let p0 = [c[0] - 0.5 * d[0], c[1] - 0.5 * d[1], c[2] - 0.5 * d[2]];
    let p1 = [c[0] + 0.5 * d[0], c[1] + 0.5 * d[1], c[2] + 0.5 * d[2]];
    (p0, p1)
}

fn shared_edge_reported_for_both() -> anyhow::Result<()> {
    // Contact direction u = (0, -1/2, √3/2) lies between both front normals;
    // d = (0,0,-6): n0·d = -6, n1·d = -6/√2: both front-facing. The ball
    // reaches the line at β = 0.5 (entering: u·d < 0). The faces' touch
    // points fall outside both triangles. Both report the edge at α = 0.5;
    // the primary is triangle 0 (lower index) and the normal the average.
    let (p0, p1) = ridge_path([-0.5, 3f64.sqrt() / 2.0], [0.0, 0.0, -6.0]);
    let (o, recs) = run(&ridge(), p0, p1, 0.5, 0.0, NS);
    let e0 = edge(&recs, 0, 0);
    let e1 = edge(&recs, 1, 0);
    ensure!(
        e0.verdict == Verdict::Hit && e1.verdict == Verdict::Hit,
        "edges {:?} {:?}",
        e0.verdict,
        e1.verdict
    );
    close("alpha 0", e0.roots.context("roots")?.0, 0.5, 1e-12)?;
    close("alpha 1", e1.roots.context("roots")?.0, 0.5, 1e-12)?;
    ensure!(o.kind() == Kind::Edge, "outcome {o:?}");
    close("alpha", o.travelled(), 0.5, 1e-12)?;
    let n = o.hit.map(|h| h.normal).context("normal")?;
    // normalize((0,0,1) + (0,-1,1)/√2)
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let want = nalgebra::Vector3::new(0.0, -s, 1.0 + s).normalize();
    close("normal y", n.y, want.y, 1e-12)?;
    close("normal z", n.z, want.z, 1e-12)
}

fn shared_edge_reported_for_one() -> anyhow::Result<()> {
    // u = (0, -1/2, √3/2), d = (0, -2, -1.8): n0·d = -1.8 ≤ 0 (front),
    // n1·d = (2 - 1.8)/√2 > 0 (back-facing); u·d = 1 - 1.56 < 0 (entering).
    let (p0, p1) = ridge_path([-0.5, 3f64.sqrt() / 2.0], [0.0, -2.0, -1.8]);
    let (o, recs) = run(&ridge(), p0, p1, 0.5, 0.0, NS);
    let e0 = edge(&recs, 0, 0);
    let e1 = edge(&recs, 1, 0);
    ensure!(e0.verdict == Verdict::Hit, "triangle 0 {:?}", e0.verdict);
    ensure!(
        e1.verdict == Verdict::BackFacing,
        "triangle 1 {:?}",
        e1.verdict
    );
    ensure!(
        o.kind() == Kind::Edge && o.hit.map(|h| h.triangle) == Some(0),
        "outcome {o:?}"
    );
    close("alpha", o.travelled(), 0.5, 1e-12)?;
    let n = o.hit.map(|h| h.normal).context("normal")?;
    close("normal z", n.z, 1.0, 1e-12)
}

fn shared_edge_reported_for_neither() -> anyhow::Result<()> {
    // From behind: u = (0, √3/2, -1/2), d = (0,0,2): n0·d = 2 > 0,
    // n1·d = 2/√2 > 0, u·d = -1 < 0: the line is reached at β = 0.5 within
    // the edge, and both triangles reject it as back-facing.
    let (p0, p1) = ridge_path([3f64.sqrt() / 2.0, -0.5], [0.0, 0.0, 2.0]);
    let (o, recs) = run(&ridge(), p0, p1, 0.5, 0.0, NS);
    for t in 0..2 {
        let e = edge(&recs, t, 0);
        ensure!(
            e.verdict == Verdict::BackFacing,
            "triangle {t}: {:?}",
            e.verdict
        );
        close("s0", e.roots.context("roots")?.0, 0.5, 1e-12)?;
    }
    ensure!(o.kind() == Kind::None, "outcome {o:?}");
    Ok(())
}

fn cube_shared_edge_averaged_normal_worked_example_5() -> anyhow::Result<()> {
    // Worked example 5: distance to the edge x = 1, z = 1 is 0.5 when
    // 0.0625 + (z - 1)² = 0.25, z = 1.43301, β = (3 - 1.43301)/6 = 0.26116.
    let cube = sweeptrace::sim::scenes::cube().to_mesh()?;
    let o = sweep_mesh(
        &cube,
        &Sweep::new([1.25, 0.125, 3.0], [1.25, 0.125, -3.0], 0.5),
        &Options::default(),
    )?;
    ensure!(o.kind() == Kind::Edge, "outcome {o:?}");
    close(
        "alpha",
        o.travelled(),
        (3.0 - (1.0 + 0.1875f64.sqrt())) / 6.0,
        1e-12,
    )?;
    let n = o.hit.map(|h| h.normal).context("normal")?;
    let s = std::f64::consts::FRAC_1_SQRT_2;
    close("normal x", n.x, s, 1e-12)?;
    close("normal y", n.y, 0.0, 1e-12)?;
    close("normal z", n.z, s, 1e-12)
}

fn margin_shrinks_detection_radius() -> anyhow::Result<()> {
    // Example 1 with r = 0.5, ε = 0.25: ρ = 0.25, β = (3 - 0.25)/6 = 11/24;
    // the contact is on the plane.
    let (o, _) = run(
        &triangle_t(),
        [1.0, 1.0, 3.0],
        [1.0, 1.0, -3.0],
        0.5,
        0.25,
        NS,
    );
    close("alpha", o.travelled(), 11.0 / 24.0, 1e-12)?;
    close(
        "contact z",
        o.hit.map(|h| h.contact).context("contact")?.z,
        0.0,
        1e-12,
    )
}

fn standard_frame_round_trip() -> anyhow::Result<()> {
    // For every edge of every cube triangle: v0 → origin, v1 → (L,0,0), the
    // third vertex at y = 0, z ≤ 0; world_from_edge inverts to_edge.
    let cube = sweeptrace::sim::scenes::cube().to_mesh()?;
    for t in cube.triangles() {
        for i in 0..3 {
            let f = &t.edges[i];
            let v0 = t.vertices[i];
            let v1 = t.vertices[(i + 1) % 3];
            let v2 = t.vertices[(i + 2) % 3];
            let a = f.to_edge(&v0);
            let b = f.to_edge(&v1);
            let c = f.to_edge(&v2);
            ensure!(a.coords.norm() < 1e-12, "v0 → {a:?}");
            close("v1 x", b.x, f.length, 1e-12)?;
            ensure!(b.y.abs() < 1e-12 && b.z.abs() < 1e-12, "v1 → {b:?}");
            ensure!(
                c.y.abs() < 1e-12 && c.z < 0.0,
                "third vertex → {c:?} not in z < 0 of y = 0"
            );
            let back = f.world_from_edge() * b;
            ensure!((back - v1).norm() < 1e-12, "world_from_edge(v1) = {back:?}");
            ensure!((f.to_world(&c) - v2).norm() < 1e-12, "to_world");
        }
    }
    Ok(())
}

fn bad_input_errors() -> anyhow::Result<()> {
    let m = triangle_t();
    let opts = Options::default();
    let e = sweep_mesh(&m, &Sweep::new([f64::NAN, 0.0, 0.0], [0.0; 3], 0.5), &opts).err();
    ensure!(
        matches!(e, Some(SweepError::NonFinite { field: "p0", .. })),
        "NaN p0: {e:?}"
    );
    let e = sweep_mesh(
        &m,
        &Sweep::new([0.0; 3], [0.0, f64::INFINITY, 0.0], 0.5),
        &opts,
    )
    .err();
    ensure!(
        matches!(e, Some(SweepError::NonFinite { field: "p1", .. })),
        "inf p1: {e:?}"
    );
    let e = sweep_mesh(&m, &Sweep::new([0.0; 3], [1e308, -1e308, 0.0], 0.5), &opts).err();
    ensure!(e.is_some(), "overflowing path length accepted");
    let e = sweep_mesh(&m, &Sweep::new([0.0; 3], [1.0; 3], 0.0), &opts).err();
    ensure!(
        matches!(e, Some(SweepError::NonPositiveRadius(_))),
        "radius 0: {e:?}"
    );
    let e = sweep_mesh(&m, &Sweep::new([0.0; 3], [1.0; 3], -1.0), &opts).err();
    ensure!(
        matches!(e, Some(SweepError::NonPositiveRadius(_))),
        "radius -1: {e:?}"
    );
    let big = Options {
        margin: 0.5,
        ..opts
    };
    let e = sweep_mesh(&m, &Sweep::new([0.0; 3], [1.0; 3], 0.5), &big).err();
    ensure!(
        matches!(e, Some(SweepError::MarginNotBelowRadius { .. })),
        "ε = r: {e:?}"
    );
    let e = Mesh::new(vec![], &[]).err();
    ensure!(
        matches!(e, Some(MeshError::Empty { .. })),
        "empty mesh: {e:?}"
    );
    let e = Mesh::new(vec![[0.0; 3]; 3], &[[0, 1, 3]]).err();
    ensure!(
        matches!(
            e,
            Some(MeshError::IndexOutOfRange {
                triangle: 0,
                index: 3,
                ..
            })
        ),
        "index: {e:?}"
    );
    let e = Mesh::new(vec![[0.0, f64::NAN, 0.0]; 3], &[[0, 1, 2]]).err();
    ensure!(
        matches!(e, Some(MeshError::NonFiniteVertex { vertex: 0, .. })),
        "NaN vertex: {e:?}"
    );
    let msg = SweepError::MarginNotBelowRadius {
        margin: 0.5,
        radius: 0.5,
    }
    .to_string();
    ensure!(
        msg.contains("margin") && msg.contains("radius"),
        "message {msg}"
    );
    Ok(())
}

fn degenerate_triangles_reported_and_skipped() -> anyhow::Result<()> {
    // Triangle 1 repeats an index, triangle 2 is collinear; both are left
    // out and never produce NaN; triangle 0 still works.
    let m = Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            [8.0, 0.0, 0.0],
        ],
        &[[0, 1, 2], [0, 0, 1], [0, 1, 3]],
    )?;
    let d: Vec<usize> = m.degenerate().iter().map(|d| d.index).collect();
    ensure!(d == vec![1, 2], "degenerate {d:?}");
    ensure!(
        m.triangles().len() == 1 && m.input_triangle_count() == 3,
        "counts"
    );
    let o = sweep_mesh(
        &m,
        &Sweep::new([6.0, 0.0, 3.0], [6.0, 0.0, -3.0], 0.5),
        &Options::default(),
    )?;
    ensure!(
        o.kind() == Kind::None && !o.travelled().is_nan(),
        "through the collinear triangle: {o:?}"
    );
    let e = Mesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        &[[0, 1, 2]],
    )
    .err();
    ensure!(
        matches!(
            e,
            Some(MeshError::Empty {
                triangles: 1,
                degenerate: 1
            })
        ),
        "all degenerate: {e:?}"
    );
    Ok(())
}

fn both_broadphases(m: &Mesh, p0: [f64; 3], p1: [f64; 3], r: f64) -> anyhow::Result<Outcome> {
    let sweep = Sweep::new(p0, p1, r);
    let fast = sweep_mesh(m, &sweep, &Options::default())?;
    let all = sweep_mesh_with(
        m,
        &sweep,
        &Options::default(),
        Broadphase::Exhaustive,
        &mut NoObserver,
    )?;
    ensure!(fast == all, "bvh {fast:?} != exhaustive {all:?}");
    Ok(all)
}

fn edge_far_start_small_radius_discriminant_without_cancellation() -> anyhow::Result<()> {
    // r = 1e-3, a path of length 2e5 straight down past edge 0 of T
    // (p0 = (2, -y, 1e5), p1 = (2, -y, -1e5)), so |p0| / ρ = 1e8.
    // In edge 0's frame p0 → (2, 1e5, y), p1 → (2, -1e5, y):
    // dy = -2e5, dz = 0, A = 4e10, B = 2·1e5·(-2e5) = -4e10,
    // C = 1e10 + y² - 1e-6. B² and 4AC are both 1.6e21, and their difference
    // is below one ulp of either, so B² - 4AC in floating point is noise.
    // The same value without cancellation: B² - 4AC = 4 (ρ² A - w²) with
    // w = y0 dz - z0 dy = 2e5·y.
    let r = 1e-3;
    // Miss: y = 1.5e-3 = 1.5ρ, w = 300, ρ²A = 4e4, w² = 9e4:
    // disc = 4 (4e4 - 9e4) = -2e5 < 0: no real roots. The face's touch
    // point (2, -1.5e-3, 0) is outside T: nothing is hit.
    let m = triangle_t();
    let (p0, p1) = ([2.0, -1.5e-3, 1e5], [2.0, -1.5e-3, -1e5]);
    let (o, recs) = run(&m, p0, p1, r, 0.0, NS);
    let e = edge(&recs, 0, 0);
    ensure!(
        e.verdict == Verdict::NoRealRoots,
        "edge 0 verdict {:?} (disc {})",
        e.verdict,
        e.discriminant
    );
    close("disc", e.discriminant, -2e5, 1e-3)?;
    ensure!(o.kind() == Kind::None, "outcome {o:?}");
    both_broadphases(&m, p0, p1, r)?;
    // Hit: y = 0.5e-3 = 0.5ρ, w = 100, disc = 4 (4e4 - 1e4) = 1.2e5. The
    // center is ρ from the edge's line at height ρ·√0.75 above it, so
    // s0 = (1e5 - ρ√0.75) / 2e5 = 0.5 - 4.330127e-9.
    let (p0, p1) = ([2.0, -0.5e-3, 1e5], [2.0, -0.5e-3, -1e5]);
    let (o, recs) = run(&m, p0, p1, r, 0.0, NS);
    let e = edge(&recs, 0, 0);
    close("disc", e.discriminant, 1.2e5, 1e-3)?;
    ensure!(
        o.kind() == Kind::Edge && o.hit.and_then(|h| h.feature.index()) == Some(0),
        "outcome {o:?}"
    );
    close(
        "alpha",
        o.travelled(),
        0.5 - r * 0.75f64.sqrt() / 2e5,
        1e-15,
    )?;
    both_broadphases(&m, p0, p1, r)?;
    Ok(())
}

fn very_long_path_never_nan() -> anyhow::Result<()> {
    // A finite path of length 2e100: B = 2 d·m ≈ -4e200, so B² overflows to
    // infinity, 4AC too, and B² - 4AC = inf - inf = NaN, which passed every
    // comparison and was reported as a hit with α = NaN.
    // Miss: p0 = (5, 5, 1e100), p1 = (5, 5, -1e100). The path's line is
    // 6/√2 ≈ 4.24 from T's hypotenuse and farther from its other edges and
    // vertices (edge 0: p0 → (5, 1e100, -5), w = y0 dz - z0 dy = -1e101,
    // w² = 1e202 > ρ²A = 1e200):
    // no edge or vertex is hit, and no record holds a NaN. The face's touch
    // point (5, 5, 0) is 4.24 outside T, but at this scale (S = 1e100, one
    // rounding about 2e84) that is far below the rounding of the inputs, so
    // the touch counts as on the boundary: a face hit at α = 0.5, flagged
    // near_boundary (the exact answer, a miss, is one rounding away).
    let m = triangle_t();
    let (p0, p1) = ([5.0, 5.0, 1e100], [5.0, 5.0, -1e100]);
    let (o, recs) = run(&m, p0, p1, 0.5, 0.0, NS);
    ensure!(
        o.kind() == Kind::Face
            && o.travelled() == 0.5
            && o.fragile.contains(FragileReason::NearBoundary),
        "outcome {o:?}"
    );
    ensure!(
        recs.iter()
            .all(|r| r.kind() == Kind::Face || r.alpha().is_none()),
        "an edge or vertex hit: {recs:?}"
    );
    for r in &recs {
        ensure!(!r.alpha().is_some_and(f64::is_nan), "NaN alpha in {r:?}");
    }
    both_broadphases(&m, p0, p1, 0.5)?;
    // Hit: p0 = (2, -0.3, 1e100) passes edge 0 at distance 0.3 < ρ = 0.5:
    // w = 0.3·2e100 = 6e99, disc = 4 (1e200 - 3.6e199) > 0, and
    // s0 = C / q = 1e200 / 2e200 = 0.5 (the offset ρ·0.8/2e100 is far below
    // one ulp of 0.5). The face's touch point (2, -0.3, 0) is 0.3 outside T,
    // but at this scale (S = 1e100, one rounding about 2e84) that is far
    // below rounding: the face and edge 0 are tied at α = 0.5, the tie
    // order reports the face, and the decision is flagged near_boundary.
    let (p0, p1) = ([2.0, -0.3, 1e100], [2.0, -0.3, -1e100]);
    let o = both_broadphases(&m, p0, p1, 0.5)?;
    ensure!(
        o.kind() == Kind::Face
            && o.hit.and_then(|h| h.feature.index()).is_none()
            && o.fragile.contains(FragileReason::NearBoundary),
        "outcome {o:?}"
    );
    close("alpha", o.travelled(), 0.5, 1e-15)
}

fn sliver_triangle_face_hit_barycentric_without_cancellation() -> anyhow::Result<()> {
    // A sliver a = (0,0,0), b = (1,0,0), c = (0.3, h, 0), h = 1e-9: |(b-a)×(c-a)|
    // = 1e-9 > DEGENERATE_TOLERANCE · longest² = 1e-12, so it is usable.
    // r = 0.25, p0 = (0.4, h/3, 2), p1 = (0.4, h/3, -2): h0 = 2, h1 = -2,
    // β = 1.75 / 4 = 0.4375, touch (0.4, h/3, 0). Its barycentric weights:
    // w_c = y / h = 1/3, w_b = x - 0.3 w_c = 0.3, w_a = 1 - 0.3 - 1/3 = 0.36667:
    // inside, a face hit at α = 0.4375. (Edge 0 is touched at the same α in
    // floating point, the center being only h/3 off its line, and the tie
    // goes to the face.) The Gram form d00 d11 - d01² = 0.09 - 0.09 of the
    // barycentric denominator rounds to 0 here: NaN weights, the face test
    // said outside_triangle and the outcome was an edge.
    let h = 1e-9;
    let m = mesh(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, h, 0.0]],
        &[[0, 1, 2]],
    );
    let (o, recs) = run(&m, [0.4, h / 3.0, 2.0], [0.4, h / 3.0, -2.0], 0.25, 0.0, NS);
    let f = face(&recs, 0);
    let b = f.barycentric.context("no barycentric")?;
    close("bary a", b[0], 1.0 - 0.3 - 1.0 / 3.0, 1e-6)?;
    close("bary b", b[1], 0.3, 1e-6)?;
    close("bary c", b[2], 1.0 / 3.0, 1e-6)?;
    ensure!(f.verdict == Verdict::Hit, "face verdict {:?}", f.verdict);
    ensure!(o.kind() == Kind::Face, "outcome {o:?}");
    close("alpha", o.travelled(), 0.4375, TOL)?;
    // Just outside edge b-c, which has y = h (1 - x) / 0.7 = (6/7) h at
    // x = 0.4: at y = 1.01 (6/7) h, w_c = 0.865714, w_b = 0.4 - 0.3 w_c =
    // 0.140286, w_a = 1 - w_b - w_c = -0.006 < 0: outside, every weight finite.
    let y = 1.01 * (6.0 / 7.0) * h;
    let (_, recs) = run(&m, [0.4, y, 2.0], [0.4, y, -2.0], 0.25, 0.0, NS);
    let f = face(&recs, 0);
    let b = f.barycentric.context("no barycentric")?;
    ensure!(b.iter().all(|w| w.is_finite()), "barycentric {b:?}");
    ensure!(
        f.verdict == Verdict::OutsideTriangle && (b[0] + 0.006).abs() < 1e-4,
        "face {:?}, barycentric {b:?}",
        f.verdict
    );
    Ok(())
}

/// Regression: the solver returned a double root at 0 whenever its `q` was
/// 0, without looking at `C`. Here the ball slides parallel to T's plane one
/// ulp further from edge 0's line than `ρ`: in the edge frame `B = 0`, the
/// discriminant (computed as `4 (ρ² A − w²)`) rounds to 0 and `C > 0`, so
/// the exact answer is no root. It used to be a phantom edge hit at `α = 0`.
fn zero_q_gives_a_double_root_only_when_c_is_zero() -> anyhow::Result<()> {
    let rho = 0.3650434993895252;
    let height = 0.36504349938952524;
    ensure!(height > rho, "the start is above ρ");
    let (o, recs) = run(
        &triangle_t(),
        [2.0, 0.0, height],
        [2.5, -1.5398316023792022, height],
        rho,
        0.0,
        NS,
    );
    let e = edge(&recs, 0, 0);
    ensure!(e.b == 0.0, "B = {}", e.b);
    ensure!(e.c > 0.0, "C = {}", e.c);
    ensure!(e.discriminant <= 0.0, "discriminant {}", e.discriminant);
    ensure!(e.verdict == Verdict::NoRealRoots, "verdict {:?}", e.verdict);
    ensure!(!o.is_hit(), "outcome {o:?}");
    Ok(())
}

/// The face test uses one quantity, `n · d`, for the facing rule, the
/// parallel test and `β`. With the triangle's first vertex far from a short,
/// nearly parallel path, `h0 - h1` (two dot products of long vectors,
/// subtracted) and `-(n · d)` disagree in their last bits and sometimes in
/// sign; every verdict must follow `n · d`.
fn face_decides_direction_by_n_dot_d_alone() -> anyhow::Result<()> {
    use sweeptrace::core::options::PARALLEL_TOLERANCE;
    use sweeptrace::core::{SweptPath, sweep_face};
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut sign_disagreements = 0;
    for _ in 0..20_000 {
        let a = [1e4 + next(), 1e4 * next(), next()];
        let b = [next(), 3.0 + next(), 0.1 * next()];
        let c = [next(), -3.0 + next(), 0.1 * next()];
        let m = mesh(&[a, b, c], &[[0, 1, 2]]);
        let t = m.triangles()[0];
        let n = t.normal;
        let along = n.cross(&nalgebra::Vector3::new(next(), next(), next()));
        let p0 = nalgebra::Point3::new(next(), next(), next()) + n * (0.5 + next());
        let d = (along + n * (1e-8 * next())) * 1e-3;
        let p1 = p0 + d;
        let path = SweptPath::new(&Sweep::new(p0.into(), p1.into(), 0.25), &Options::default())?;
        let r = sweep_face(&t, &path, NS);
        let nd = r.normal_dot_d;
        if (r.h0 - r.h1 > 0.0) != (-nd > 0.0) {
            sign_disagreements += 1;
        }
        match r.verdict {
            Verdict::StartsTooClose => ensure!(r.h0 < path.rho, "{r:?}"),
            Verdict::Parallel => {
                ensure!(nd.abs() <= PARALLEL_TOLERANCE * path.length, "{r:?}")
            }
            Verdict::BackFacing => ensure!(nd > 0.0, "{r:?}"),
            _ => {
                ensure!(nd < 0.0, "{r:?}");
                ensure!(r.beta == Some((r.h0 - path.rho) / -nd), "{r:?}");
            }
        }
    }
    ensure!(
        sign_disagreements > 0,
        "the search found no case where h0 - h1 and -(n·d) disagree in sign"
    );
    Ok(())
}
