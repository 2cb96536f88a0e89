//! The face test: a moving ball against a triangle's plane.

use super::mesh::Triangle;
use super::options::{Facing, PARALLEL_TOLERANCE};
use super::path::SweptPath;
use super::record::{FaceRecord, Verdict};

/// Runs the face test of SEMANTICS.md on `triangle`.
///
/// One quantity decides the direction of travel: `n · d` (mathematically
/// `h1 - h0`). It is the facing value, the parallel test
/// (`|n · d| ≤ PARALLEL_TOLERANCE · |d|`) and the denominator of
/// `β = (h0 - ρ) / -(n · d)`, so the three can never disagree by rounding.
/// `h1` is recorded for the explanation only.
///
/// The touch point counts as inside when its signed distance from the
/// triangle's boundary is at least `-`[`SweptPath::tie_distance`] (rounding
/// level; the exact contact just outside is an edge or vertex at the same
/// `α` within the tie window, which the tie order gives to the face).
#[inline]
pub fn sweep_face(triangle: &Triangle, path: &SweptPath, facing: Facing) -> FaceRecord {
    let n = triangle.normal;
    let a = triangle.vertices[0];
    let h0 = n.dot(&(path.p0 - a));
    let h1 = n.dot(&(path.p1 - a));
    let normal_dot_d = n.dot(&path.d);
    let mut record = FaceRecord {
        triangle: triangle.index,
        normal: n,
        normal_dot_d,
        h0,
        h1,
        beta: None,
        touch: None,
        barycentric: None,
        boundary_distance: None,
        back: triangle.back,
        verdict: Verdict::Hit,
    };
    let rho = path.rho;
    record.verdict = if h0 < rho {
        Verdict::StartsTooClose
    } else if normal_dot_d.abs() <= PARALLEL_TOLERANCE * path.length {
        Verdict::Parallel
    } else if !facing.allows(normal_dot_d) {
        // Here `n · d ≠ 0`, so both rules reject exactly `n · d > 0`: moving
        // away from the front.
        Verdict::BackFacing
    } else {
        let beta = (h0 - rho) / -normal_dot_d;
        record.beta = Some(beta);
        if beta > 1.0 {
            Verdict::BeyondEnd
        } else {
            let touch = path.at(beta) - n * rho;
            record.touch = Some(touch);
            let (bary, distance) = barycentric_and_distance(triangle, &touch);
            record.barycentric = Some(bary);
            record.boundary_distance = Some(distance);
            // Inside, boundary included, up to the tie distance (a touch
            // point that rounding put just outside; see TIE_WINDOW_ULPS).
            if distance >= -path.tie_distance() {
                Verdict::Hit
            } else {
                Verdict::OutsideTriangle
            }
        }
    };
    record
}

/// Barycentric coordinates (weights of `a`, `b`, `c`) of a point in the
/// triangle's plane.
///
/// Each weight is the signed area of the sub-triangle opposite its vertex
/// over the triangle's, measured along the front normal:
/// `w_a = n · ((b - p) × (c - p)) / n · ((b - a) × (c - a))`, and so on.
/// Unlike the Gram-matrix form, whose denominator `|b-a|²|c-a|² - ((b-a)·(c-a))²`
/// cancels to 0 on thin usable triangles, this stays accurate down to the
/// degeneracy tolerance. On a shared edge the two triangles' weights for it
/// are exact negatives (when their normals agree), so a point on the edge is
/// inside at least one of them.
#[inline]
pub fn barycentric(triangle: &Triangle, p: &nalgebra::Point3<f64>) -> [f64; 3] {
    let [a, b, c] = triangle.vertices;
    let n = triangle.normal;
    let area2 = n.dot(&(b - a).cross(&(c - a)));
    let (pa, pb, pc) = (a - p, b - p, c - p);
    [
        n.dot(&pb.cross(&pc)) / area2,
        n.dot(&pc.cross(&pa)) / area2,
        n.dot(&pa.cross(&pb)) / area2,
    ]
}

/// Barycentric coordinates of a point in the triangle's plane (as
/// [`barycentric`]) and its smallest signed distance from the lines of the
/// triangle's edges, in the plane: positive inside, 0 on the boundary,
/// negative outside (for a [mirrored](Triangle::mirrored) triangle too).
#[inline]
pub fn barycentric_and_distance(triangle: &Triangle, p: &nalgebra::Point3<f64>) -> ([f64; 3], f64) {
    let [a, b, c] = triangle.vertices;
    let n = triangle.normal;
    let area2 = n.dot(&(b - a).cross(&(c - a)));
    let (pa, pb, pc) = (a - p, b - p, c - p);
    // Twice the signed areas of the sub-triangles opposite a, b and c.
    let sub = [
        n.dot(&pb.cross(&pc)),
        n.dot(&pc.cross(&pa)),
        n.dot(&pa.cross(&pb)),
    ];
    // Opposite a is edge 1 (b → c), opposite b edge 2, opposite c edge 0.
    let lengths = [
        triangle.edges[1].length,
        triangle.edges[2].length,
        triangle.edges[0].length,
    ];
    // Measured along a mirrored triangle's normal `-n` (`sides = two`)
    // the signed areas change sign, and the area with them.
    let inside = if area2 < 0.0 { -1.0 } else { 1.0 };
    let distance = (0..3)
        .map(|i| inside * sub[i] / lengths[i])
        .fold(f64::INFINITY, f64::min);
    (sub.map(|s| s / area2), distance)
}
