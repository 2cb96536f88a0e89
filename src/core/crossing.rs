//! Where a segment passes through the mesh from the front of a triangle to
//! its back: the geometric fact behind a *tunnel* (a ball whose centre went
//! through a surface), independent of any collision test.
//!
//! The rule (see SEMANTICS.md, "Tunnelling"): with `h(x) = n · (x − a)` the
//! signed height of a point over a triangle's plane and `τ` the crossing
//! tolerance ([`crossing_tolerance`]), the segment `p → q` crosses the
//! triangle front to back when
//! - it does not start behind the plane: `h(p) ≥ −τ` (a start on the plane,
//!   within rounding, counts as in front),
//! - it ends behind it: `h(q) < −τ`,
//! - the point where it meets the plane, at `t = h(p) / (h(p) − h(q))`
//!   (clamped to `[0, 1]`), lies inside the triangle, boundary included, up
//!   to `τ` (its smallest signed distance from the edge lines is `≥ −τ`), so
//!   that a segment through a shared edge or vertex is found on one of its
//!   triangles.
//!
//! A segment lying in the plane, moving behind to behind, or back to front
//! never crosses. The first crossing is the one at the smallest `t`; the
//! crossings within the tie window `TIE_WINDOW_ULPS · u / |q − p|` of it
//! (several triangles meeting at an edge or vertex) go to the lowest
//! triangle index.

use nalgebra::Point3;
use serde::Serialize;

use super::mesh::{Mesh, Triangle};
use super::options::{BROADPHASE_MARGIN, TIE_WINDOW_ULPS};
use super::sweep_face::barycentric_and_distance;

/// A front-to-back crossing of a triangle by a segment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Crossing {
    /// Input index of the triangle crossed.
    pub triangle: u32,
    /// Where the segment meets the triangle's plane.
    pub point: Point3<f64>,
    /// Fraction of the segment `p → q` at that point, in `[0, 1]`.
    pub fraction: f64,
}

/// The magnitude `S = max(|p|∞, |q|∞, |mesh bounds|∞)` the rounding of a
/// crossing test is relative to.
fn scale(mesh: &Mesh, p: &Point3<f64>, q: &Point3<f64>) -> f64 {
    let (lo, hi) = mesh.bounds();
    p.coords
        .amax()
        .max(q.coords.amax())
        .max(lo.coords.amax())
        .max(hi.coords.amax())
}

/// The crossing tolerance `τ` of the segment `p → q` against `mesh`: the
/// tie distance `TIE_WINDOW_ULPS · u`, with `u = f64::EPSILON · S` and
/// `S = max(|p|∞, |q|∞, |mesh bounds|∞)`, the rounding unit of the heights
/// and barycentric distances computed (the unit of the sweep's tie
/// distance, [`SweptPath::tie_distance`](super::SweptPath::tie_distance)).
pub fn crossing_tolerance(mesh: &Mesh, p: &Point3<f64>, q: &Point3<f64>) -> f64 {
    TIE_WINDOW_ULPS * f64::EPSILON * scale(mesh, p, q)
}

/// The crossing of one triangle by `p → q` under tolerance `tau`, if any.
#[inline]
pub fn triangle_crossing(
    triangle: &Triangle,
    p: &Point3<f64>,
    q: &Point3<f64>,
    tau: f64,
) -> Option<Crossing> {
    let n = triangle.normal;
    let a = triangle.vertices[0];
    let hp = n.dot(&(p - a));
    let hq = n.dot(&(q - a));
    // NaN fails both comparisons: no crossing.
    if !(hp >= -tau && hq < -tau) {
        return None;
    }
    // hp ≥ −τ > hq, so the denominator is positive.
    let t = (hp / (hp - hq)).clamp(0.0, 1.0);
    let point = p + (q - p) * t;
    let (_, distance) = barycentric_and_distance(triangle, &point);
    (distance >= -tau).then_some(Crossing {
        triangle: triangle.index,
        point,
        fraction: t,
    })
}

/// The first front-to-back crossing of a triangle of `mesh` by the segment
/// `p → q` (see the module documentation), found through the mesh's BVH:
/// the smallest fraction, and among the crossings within the tie window of
/// it the lowest triangle index. `None` for a segment of length 0 or with a
/// non-finite coordinate. Allocates nothing.
pub fn first_crossing(mesh: &Mesh, p: &Point3<f64>, q: &Point3<f64>) -> Option<Crossing> {
    let d = q - p;
    let length = d.norm();
    let finite = p
        .coords
        .iter()
        .chain(q.coords.iter())
        .all(|v| v.is_finite());
    if !(finite && length > 0.0 && length.is_finite()) {
        return None;
    }
    let s = scale(mesh, p, q);
    let tau = TIE_WINDOW_ULPS * f64::EPSILON * s;
    let window = (tau / length).min(1.0);
    // Boxes grown by τ plus a margin far above it, as the sweep grows them.
    let grow = tau + BROADPHASE_MARGIN * s;
    let triangles = mesh.triangles();
    // First pass: the smallest fraction.
    let mut first = f64::INFINITY;
    mesh.bvh().traverse(p, &d, grow, 1.0, |range| {
        for position in range {
            if let Some(c) = triangle_crossing(&triangles[position], p, q, tau) {
                first = first.min(c.fraction);
            }
        }
        (first + window).min(1.0)
    });
    if first == f64::INFINITY {
        return None;
    }
    // Second pass (only when something crossed): the lowest triangle among
    // the crossings tied with the first.
    let cutoff = (first + window).min(1.0);
    let mut best: Option<Crossing> = None;
    mesh.bvh().traverse(p, &d, grow, cutoff, |range| {
        for position in range {
            if let Some(c) = triangle_crossing(&triangles[position], p, q, tau)
                && c.fraction <= first + window
                && best.is_none_or(|b| c.triangle < b.triangle)
            {
                best = Some(c);
            }
        }
        cutoff
    });
    best
}
