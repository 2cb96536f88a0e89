//! The face test: a moving ball against a triangle's plane.

use super::mesh::Triangle;
use super::options::{Facing, PARALLEL_TOLERANCE};
use super::path::Path;
use super::record::{FaceRecord, Verdict};

/// Runs the face test of SEMANTICS.md on `triangle`.
#[inline]
pub fn sweep_face(triangle: &Triangle, path: &Path, facing: Facing) -> FaceRecord {
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
        verdict: Verdict::Hit,
    };
    let rho = path.rho;
    record.verdict = if h0 < rho {
        Verdict::StartsTooClose
    } else if (h0 - h1).abs() <= PARALLEL_TOLERANCE * path.length {
        Verdict::Parallel
    } else if !facing.allows(normal_dot_d) || h1 > h0 {
        Verdict::BackFacing
    } else {
        let beta = (h0 - rho) / (h0 - h1);
        record.beta = Some(beta);
        if beta > 1.0 {
            Verdict::BeyondEnd
        } else {
            let touch = path.at(beta) - n * rho;
            record.touch = Some(touch);
            let bary = barycentric(triangle, &touch);
            record.barycentric = Some(bary);
            if bary.iter().all(|&w| w >= 0.0) {
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
#[inline]
pub fn barycentric(triangle: &Triangle, p: &nalgebra::Point3<f64>) -> [f64; 3] {
    let [a, b, c] = triangle.vertices;
    let v0 = b - a;
    let v1 = c - a;
    let v2 = p - a;
    let d00 = v0.dot(&v0);
    let d01 = v0.dot(&v1);
    let d11 = v1.dot(&v1);
    let d20 = v2.dot(&v0);
    let d21 = v2.dot(&v1);
    let denom = d00 * d11 - d01 * d01;
    let v = (d11 * d20 - d01 * d21) / denom;
    let w = (d00 * d21 - d01 * d20) / denom;
    [1.0 - v - w, v, w]
}
