//! Decisions by the rules, not by rounding: the tie window, the tie set
//! and the fragility flags.

use libtest_mimic::Trial;
use sweeptrace::core::{
    Broadphase, CollectRecords, Facing, FragileReason, Kind, Options, Sweep, sweep_mesh,
    sweep_mesh_with, sweep_ties,
};

use crate::ensure;
use crate::support::{close, mesh, run};
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial(
            "core_decisions::shared_edge_tie_goes_to_the_lower_triangle",
            shared_edge_tie_goes_to_the_lower_triangle,
        ),
        trial(
            "core_decisions::quad_centre_drop_is_a_face_hit",
            quad_centre_drop_is_a_face_hit,
        ),
        trial(
            "core_decisions::tie_set_lists_every_tied_hit_primary_first",
            tie_set_lists_every_tied_hit_primary_first,
        ),
        trial(
            "core_decisions::clear_hit_is_robust_with_a_single_member_tie_set",
            clear_hit_is_robust_with_a_single_member_tie_set,
        ),
        trial(
            "core_decisions::fragile_serializes_as_reason_names",
            fragile_serializes_as_reason_names,
        ),
    ]
}

const NS: Facing = Facing::NonStrict;

fn options() -> Options {
    Options {
        margin: 0.0,
        facing: NS,
    }
}

/// Two triangles sharing the edge (0,0,0)-(5,1,0): edge 0 of triangle 0 and
/// edge 0 of triangle 1 (run the other way). The path meets the shared edge
/// first; both edge tests hit at the same α up to rounding, and the rules
/// give the lower triangle. Rounding used to give triangle 1.
fn shared_edge_tie_goes_to_the_lower_triangle() -> Result<(), String> {
    let m = mesh(
        &[
            [0.0, 0.0, 0.0],
            [5.0, 1.0, 0.0],
            [-3.0, 3.0, -1.0],
            [1.0, -6.0, 0.0],
        ],
        &[[0, 1, 2], [1, 0, 3]],
    );
    let (p0, p1) = ([3.336, 1.292, 5.152], [3.447, 0.324, -2.578]);
    for broadphase in [Broadphase::Bvh, Broadphase::Exhaustive] {
        let mut records = CollectRecords::default();
        let o = sweep_mesh_with(
            &m,
            &Sweep::new(p0, p1, 0.5),
            &options(),
            broadphase,
            &mut records,
        )
        .map_err(|e| e.to_string())?;
        ensure!(
            o.kind == Kind::Edge && o.triangle == Some(0) && o.feature == Some(0),
            "{broadphase:?}: outcome {o:?}"
        );
        ensure!(
            o.fragile.contains(FragileReason::Tie),
            "a tie between triangles is flagged: {o:?}"
        );
        let ties = o.tie_set(&records.records);
        ensure!(
            ties.len() == 2
                && ties[0].triangle == 0
                && ties[1].triangle == 1
                && ties.iter().all(|t| t.kind == Kind::Edge),
            "tie set {ties:?}"
        );
    }
    Ok(())
}

/// A planar quad split along a diagonal, the ball dropped along the normal
/// onto the centre, which lies on the diagonal: the touch point is on both
/// triangles' boundary, so both faces hit at the same α and the rules give
/// a face hit on the lower triangle (not the diagonal edge that rounding
/// used to choose when both touch points came out just outside).
fn quad_centre_drop_is_a_face_hit() -> Result<(), String> {
    let vertices = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, -2.0],
        [2.0, 2.0, -4.0],
        [0.0, 2.0, -2.0],
    ];
    for triangles in [[[0, 1, 2], [0, 2, 3]], [[0, 1, 3], [1, 2, 3]]] {
        let m = mesh(&vertices, &triangles);
        let (p0, p1) = ([3.0, 3.0, 0.0], [-1.0, -1.0, -4.0]);
        let o = sweep_mesh(&m, &Sweep::new(p0, p1, 0.25), &options()).map_err(|e| e.to_string())?;
        ensure!(
            o.kind == Kind::Face && o.triangle == Some(0) && o.feature.is_none(),
            "{triangles:?}: outcome {o:?}"
        );
        // From (3,3,0) to the centre (1,1,-2) is 2√3; contact at 0.25 from
        // the plane along the path of length 4√3: α = (2√3 - 0.25) / (4√3).
        let s3 = 3f64.sqrt();
        close("alpha", o.alpha, (2.0 * s3 - 0.25) / (4.0 * s3), 1e-12)?;
        let n = o.normal.ok_or("no normal")?;
        close("normal x", n.x, 1.0 / s3, 1e-12)?;
        let (_, ties) =
            sweep_ties(&m, &Sweep::new(p0, p1, 0.25), &options()).map_err(|e| e.to_string())?;
        ensure!(
            ties.first()
                .is_some_and(|t| t.kind == Kind::Face && t.triangle == 0),
            "tie set {ties:?}"
        );
        ensure!(
            ties.iter().any(|t| t.kind == Kind::Face && t.triangle == 1),
            "both faces are in the tie set: {ties:?}"
        );
    }
    Ok(())
}

/// The cube of worked example 5: the edge x = 1, z = 1 is hit by a triangle
/// of the +x face and one of the +z face. The tie set holds both, the
/// primary first, and `matches` accepts either as an expectation.
fn tie_set_lists_every_tied_hit_primary_first() -> Result<(), String> {
    let m = sweeptrace::scenes::cube()
        .to_mesh()
        .map_err(|e| e.to_string())?;
    let sweep = Sweep::new([1.25, 0.125, 3.0], [1.25, 0.125, -3.0], 0.5);
    let (o, ties) = sweep_ties(&m, &sweep, &options()).map_err(|e| e.to_string())?;
    ensure!(o.kind == Kind::Edge, "outcome {o:?}");
    ensure!(ties.len() >= 2, "tie set {ties:?}");
    ensure!(
        Some(ties[0].triangle) == o.triangle && ties[0].feature == o.feature,
        "primary first: {ties:?} vs {o:?}"
    );
    let triangles: std::collections::BTreeSet<u32> = ties.iter().map(|t| t.triangle).collect();
    ensure!(triangles.len() >= 2, "two triangles tie: {ties:?}");
    for t in &ties {
        ensure!(o.ties_with(t.alpha), "{t:?} is in the window");
        ensure!(
            t.matches(t.kind, Some(Some(t.triangle)), Some(t.feature)),
            "{t:?} matches itself"
        );
        ensure!(
            t.matches(t.kind, None, None),
            "{t:?} matches an expectation without triangle and feature"
        );
    }
    Ok(())
}

/// Worked example 1: a face hit in the middle of the triangle, head on, is
/// robust and its tie set is itself.
fn clear_hit_is_robust_with_a_single_member_tie_set() -> Result<(), String> {
    let (o, records) = run(
        &crate::support::triangle_t(),
        [1.0, 1.0, 3.0],
        [1.0, 1.0, -3.0],
        0.5,
        0.0,
        NS,
    );
    ensure!(o.kind == Kind::Face, "outcome {o:?}");
    ensure!(o.fragile.is_robust(), "flags {}", o.fragile);
    let ties = o.tie_set(&records);
    ensure!(
        ties.len() == 1 && ties[0].kind == Kind::Face && ties[0].feature.is_none(),
        "tie set {ties:?}"
    );
    ensure!(
        ties[0].matches(Kind::Face, Some(Some(0)), Some(Some(0))),
        "an expected face with feature 0 (older recordings) matches"
    );
    ensure!(
        ties[0].matches(Kind::Face, Some(Some(0)), Some(None)),
        "an expected face with feature null matches"
    );
    ensure!(
        !ties[0].matches(Kind::Edge, Some(Some(0)), Some(Some(0))),
        "another kind does not match"
    );
    Ok(())
}

fn fragile_serializes_as_reason_names() -> Result<(), String> {
    use sweeptrace::core::Fragility;
    let f = Fragility::ROBUST
        .with(FragileReason::NearBoundary)
        .with(FragileReason::Tie);
    let json = serde_json::to_string(&f).map_err(|e| e.to_string())?;
    ensure!(json == r#"["tie","near_boundary"]"#, "json {json}");
    ensure!(f.to_string() == "tie, near_boundary", "text {f}");
    let json = serde_json::to_string(&Fragility::ROBUST).map_err(|e| e.to_string())?;
    ensure!(json == "[]", "json {json}");
    Ok(())
}
