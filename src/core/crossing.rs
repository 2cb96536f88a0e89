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
//!
//! A *flipped* triangle (wound against its neighbours, see
//! [`Topology::flipped`](super::topology::Topology::flipped)) is crossed in either
//! direction: front to back by its own winding as above, or back to front,
//! which is front to back by the winding its neighbours give it (the same
//! rule with `n` reversed). [`first_crossing_with_flipped`] takes that list.

use nalgebra::Point3;
use serde::Serialize;

use super::mesh::{Mesh, Plane, Triangle};
use super::options::{BROADPHASE_MARGIN, TIE_WINDOW_ULPS};
use super::sweep_face::barycentric_and_distance;

/// A front-to-back crossing of a triangle by a segment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Crossing {
    /// Input index of the triangle crossed.
    pub triangle: u32,
    /// Where the segment meets the triangle's plane.
    pub point: Point3<f64>,
    /// Fraction of the segment `p → q` at that point, in `[0, 1]`.
    pub fraction: f64,
    /// The segment went from the triangle's back to its front: a flipped
    /// triangle crossed the way its neighbours face.
    pub back_to_front: bool,
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
    crossing_along(triangle, 1.0, p, q, tau)
}

/// The back-to-front crossing of one triangle by `p → q` under tolerance
/// `tau`, if any: the front-to-back rule with the triangle's normal
/// reversed (how a flipped triangle is crossed the way its neighbours face).
#[inline]
pub fn triangle_crossing_back_to_front(
    triangle: &Triangle,
    p: &Point3<f64>,
    q: &Point3<f64>,
    tau: f64,
) -> Option<Crossing> {
    crossing_along(triangle, -1.0, p, q, tau)
}

/// The front-to-back crossing of `triangle` with its normal times `sign`.
#[inline]
fn crossing_along(
    triangle: &Triangle,
    sign: f64,
    p: &Point3<f64>,
    q: &Point3<f64>,
    tau: f64,
) -> Option<Crossing> {
    let n = triangle.normal * sign;
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
        back_to_front: sign < 0.0,
    })
}

/// Whether `p → q` passes the first condition of [`crossing_along`] in
/// either direction (it starts in front of the plane and ends behind it,
/// or the reverse), computed from the triangle's [`Plane`] alone: the same
/// values as from its record (negating `n` negates the heights exactly),
/// so a triangle this rejects is one [`crossing_of`] rejects, and the
/// record of most candidates is never read.
#[inline]
fn may_cross(plane: &Plane, p: &Point3<f64>, q: &Point3<f64>, tau: f64) -> bool {
    let hp = plane.normal.dot(&(p - plane.v0));
    let hq = plane.normal.dot(&(q - plane.v0));
    (hp >= -tau && hq < -tau) || (-hp >= -tau && -hq < -tau)
}

/// The crossing of one triangle, in both directions when it is one of the
/// `flipped` (ascending input indices).
#[inline]
fn crossing_of(
    triangle: &Triangle,
    flipped: &[u32],
    p: &Point3<f64>,
    q: &Point3<f64>,
    tau: f64,
) -> Option<Crossing> {
    triangle_crossing(triangle, p, q, tau).or_else(|| {
        (!flipped.is_empty() && flipped.binary_search(&triangle.index).is_ok())
            .then(|| triangle_crossing_back_to_front(triangle, p, q, tau))
            .flatten()
    })
}

/// Every triangle of `mesh` the segment `p → q` passes through, either way
/// (front to back, or back to front with [`Crossing::back_to_front`]), in
/// the order of the mesh's triangles; each triangle is tested, none
/// skipped (what an explanation of one sweep needs, not a replay). Empty
/// for a segment of length 0 or with a non-finite coordinate.
pub fn all_crossings(mesh: &Mesh, p: &Point3<f64>, q: &Point3<f64>) -> Vec<Crossing> {
    let length = (q - p).norm();
    if !(length > 0.0 && length.is_finite()) {
        return Vec::new();
    }
    let tau = crossing_tolerance(mesh, p, q);
    mesh.triangles()
        .iter()
        .filter_map(|t| {
            triangle_crossing(t, p, q, tau)
                .or_else(|| triangle_crossing_back_to_front(t, p, q, tau))
        })
        .collect()
}

/// The first front-to-back crossing of a triangle of `mesh` by the segment
/// `p → q` (see the module documentation), found through the mesh's BVH:
/// the smallest fraction, and among the crossings within the tie window of
/// it the lowest triangle index. `None` for a segment of length 0 or with a
/// non-finite coordinate. Allocates nothing.
pub fn first_crossing(mesh: &Mesh, p: &Point3<f64>, q: &Point3<f64>) -> Option<Crossing> {
    first_crossing_with_flipped(mesh, &[], p, q)
}

/// [`first_crossing`], with the triangles of `flipped` (input indices,
/// ascending: [`Topology::flipped`](super::topology::Topology::flipped)) crossed back
/// to front too (see the module documentation). Allocates nothing.
pub fn first_crossing_with_flipped(
    mesh: &Mesh,
    flipped: &[u32],
    p: &Point3<f64>,
    q: &Point3<f64>,
) -> Option<Crossing> {
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
    let planes = mesh.planes();
    // First pass: the smallest fraction.
    let mut first = f64::INFINITY;
    mesh.bvh().traverse(p, &d, grow, 1.0, |range| {
        for position in range {
            if may_cross(&planes[position], p, q, tau)
                && let Some(c) = crossing_of(&triangles[position], flipped, p, q, tau)
            {
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
            if may_cross(&planes[position], p, q, tau)
                && let Some(c) = crossing_of(&triangles[position], flipped, p, q, tau)
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
