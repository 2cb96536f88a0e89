//! parry3d-f64's answer to one sweep, shared by the core bench and the
//! `parry_replay` example (the peer of `replay --outcomes`): the first time
//! of impact in `[0, 1]` of a `Ball` of `radius` moving from `p0` to `p1`
//! against a `TriMesh`, by `cast_shapes`; and that `TriMesh` built from a
//! scene's vertices and vertex-index triples.

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{ShapeCastOptions, cast_shapes};
use parry3d_f64::shape::{Ball, TriMesh, TriMeshBuilderError};

pub fn parry_cast(mesh: &TriMesh, p0: [f64; 3], p1: [f64; 3], radius: f64) -> Option<f64> {
    let v = |p: [f64; 3]| Vector::new(p[0], p[1], p[2]);
    cast_shapes(
        &Pose::from_translation(v(p0)),
        v(p1) - v(p0),
        &Ball::new(radius),
        &Pose::IDENTITY,
        Vector::ZERO,
        mesh,
        ShapeCastOptions::with_max_time_of_impact(1.0),
    )
    .ok()
    .flatten()
    .map(|h| h.time_of_impact)
}

pub fn parry_mesh(
    vertices: &[[f64; 3]],
    triangles: &[[u64; 3]],
) -> Result<TriMesh, TriMeshBuilderError> {
    TriMesh::new(
        vertices
            .iter()
            .map(|v| Vector::new(v[0], v[1], v[2]))
            .collect(),
        triangles.iter().map(|t| t.map(|i| i as u32)).collect(),
    )
}
