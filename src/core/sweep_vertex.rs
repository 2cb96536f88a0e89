//! The vertex test: a moving ball against one of a triangle's corners.

use super::mesh::Triangle;
use super::options::Facing;
use super::path::SweptPath;
use super::quadratic;
use super::record::{Verdict, VertexRecord};

/// Runs the vertex test of SEMANTICS.md on vertex `vertex` (0..3) of `triangle`.
#[inline]
pub fn sweep_vertex(
    triangle: &Triangle,
    vertex: u8,
    path: &SweptPath,
    facing: Facing,
) -> VertexRecord {
    let position = triangle.vertices[vertex as usize];
    let m = path.p0 - position;
    let a = path.d.dot(&path.d);
    let b = 2.0 * path.d.dot(&m);
    let c = m.dot(&m) - path.rho * path.rho;
    // B² - 4AC without cancellation: 4 (ρ² A - |d × m|²).
    let discriminant =
        quadratic::discriminant_from_cross(a, path.rho, path.d.cross(&m).norm_squared());
    let normal_dot_d = triangle.normal.dot(&path.d);
    let mut record = VertexRecord {
        triangle: triangle.index,
        vertex,
        position,
        a,
        b,
        c,
        discriminant,
        roots: None,
        normal_dot_d,
        back: triangle.back,
        verdict: Verdict::Hit,
    };
    record.verdict = if a == 0.0 {
        Verdict::NotMoving
    } else {
        record.roots = quadratic::solve(a, b, c, discriminant);
        match quadratic::first_contact(record.roots) {
            Err(verdict) => verdict,
            Ok(_) if !facing.allows(normal_dot_d) => Verdict::BackFacing,
            Ok(_) => Verdict::Hit,
        }
    };
    record
}
