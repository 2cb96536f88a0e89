//! Conversions from the core's types to Rerun's, and the colors.

use nalgebra::{UnitQuaternion, Vector3};
use rerun::{Color, ComponentDescriptor};

pub(crate) const MESH_COLOR: [u8; 4] = [170, 175, 185, 255];
pub(crate) const WIREFRAME_COLOR: [u8; 4] = [45, 50, 60, 255];
pub(crate) const P0_COLOR: [u8; 4] = [80, 140, 255, 90];
pub(crate) const P1_COLOR: [u8; 4] = [160, 160, 160, 60];
pub(crate) const CONTACT_BALL_COLOR: [u8; 4] = [255, 140, 0, 140];
pub(crate) const SWEEP_COLOR: [u8; 4] = [120, 170, 255, 255];
pub(crate) const HIT_COLOR: [u8; 4] = [230, 40, 40, 255];
pub(crate) const MISS_COLOR: [u8; 4] = [240, 200, 40, 255];
pub(crate) const NORMAL_COLOR: [u8; 4] = [40, 200, 80, 255];
pub(crate) const EXPECTED_COLOR: [u8; 4] = [230, 60, 230, 255];
/// The marker where a ball's centre went through a triangle.
pub(crate) const TUNNEL_COLOR: [u8; 4] = [255, 0, 90, 255];
pub(crate) const EDGE_COLOR: [u8; 4] = [230, 40, 40, 255];
pub(crate) const CYLINDER_COLOR: [u8; 4] = [255, 120, 120, 255];
pub(crate) const PATH_COLOR: [u8; 4] = [80, 140, 255, 255];
pub(crate) const AXIS_COLORS: [[u8; 4]; 3] =
    [[220, 60, 60, 255], [60, 200, 60, 255], [70, 110, 240, 255]];

/// Line radii in UI points (the same on screen at every zoom).
pub(crate) const WIREFRAME_POINTS: f32 = 0.75;
pub(crate) const OUTLINE_POINTS: f32 = 1.5;
pub(crate) const BOLD_EDGE_POINTS: f32 = 4.0;
pub(crate) const VERTEX_POINTS: f32 = 7.0;

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
