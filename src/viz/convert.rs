//! Conversions from the core's types to Rerun's, and the colors (those
//! shared with the Foxglove output are in [`crate::palette`]).

use nalgebra::{UnitQuaternion, Vector3};
use rerun::{Color, ComponentDescriptor};

use crate::core::topology::EdgeClass;
pub(crate) use crate::palette::{
    BOUNDARY_EDGE_COLOR, CONCAVE_EDGE_COLOR, CONTACT_BALL_COLOR, CONVEX_EDGE_COLOR, DEFECT_COLOR,
    EXPECTED_COLOR, FACE_NORMAL_COLOR, FLAT_EDGE_COLOR, GHOST_COLOR, HIT_COLOR, MESH_COLOR,
    MISS_COLOR, NON_MANIFOLD_EDGE_COLOR, NORMAL_COLOR, P0_COLOR, P1_COLOR, SWEEP_COLOR,
    TUNNEL_COLOR,
};
pub(crate) const EDGE_COLOR: [u8; 4] = [230, 40, 40, 255];
pub(crate) const CYLINDER_COLOR: [u8; 4] = [255, 120, 120, 255];
pub(crate) const PATH_COLOR: [u8; 4] = [80, 140, 255, 255];
pub(crate) const AXIS_COLORS: [[u8; 4]; 3] =
    [[220, 60, 60, 255], [60, 200, 60, 255], [70, 110, 240, 255]];
/// The colors of the series of a plot with several (A, B, C, discriminant,
/// s0, s1; h0, h1, β take the first three): distinct on the viewer's dark
/// background.
pub(crate) const SERIES_COLORS: [[u8; 4]; 6] = [
    [240, 200, 60, 255],
    [90, 180, 250, 255],
    [240, 110, 190, 255],
    [160, 160, 160, 255],
    [90, 210, 120, 255],
    [250, 140, 60, 255],
];

/// Line radii in UI points (the same on screen at every zoom).
pub(crate) const OUTLINE_POINTS: f32 = 1.5;
pub(crate) const BOLD_EDGE_POINTS: f32 = 4.0;
pub(crate) const VERTEX_POINTS: f32 = 7.0;
pub(crate) const DEFECT_POINTS: f32 = 6.0;

/// The colour and the line radius (UI points) of the mesh's edges of
/// `class`: flat edges faint and thin, convex and concave in colours of
/// their own, boundary and non-manifold edges loud and thick.
pub(crate) fn edge_style(class: EdgeClass) -> ([u8; 4], f32) {
    match class {
        EdgeClass::Flat => (FLAT_EDGE_COLOR, 0.5),
        EdgeClass::Convex => (CONVEX_EDGE_COLOR, 1.25),
        EdgeClass::Concave => (CONCAVE_EDGE_COLOR, 1.25),
        EdgeClass::Boundary => (BOUNDARY_EDGE_COLOR, 1.75),
        EdgeClass::NonManifold => (NON_MANIFOLD_EDGE_COLOR, 2.25),
    }
}

pub(crate) fn f32x3(v: Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

pub(crate) fn rgba(c: [u8; 4]) -> Color {
    Color::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}

pub(crate) fn albedo(c: [u8; 4]) -> rerun::datatypes::Rgba32 {
    rerun::datatypes::Rgba32::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}

/// A radius in UI points.
pub(crate) fn ui_points(points: f32) -> rerun::components::Radius {
    rerun::components::Radius::new_ui_points(points)
}

/// The descriptor `AnyValues::with_component::<C>(name, ..)` gives.
pub(crate) fn any_value<C: rerun::Component>(name: &'static str) -> ComponentDescriptor {
    ComponentDescriptor::partial(name).with_component_type(C::name())
}

/// A Rerun quaternion.
pub(crate) fn quaternion(q: &UnitQuaternion<f64>) -> rerun::Quaternion {
    rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
}

/// Length and rotation of a capsule (which lies along +z) from the origin
/// along `d`.
pub(crate) fn capsule_pose(d: &Vector3<f64>) -> (f32, rerun::Quaternion) {
    let length = d.norm();
    let q = if length > 0.0 {
        UnitQuaternion::rotation_between(&Vector3::z(), d).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
        })
    } else {
        UnitQuaternion::identity()
    };
    (length as f32, quaternion(&q))
}
