//! An independent oracle for the collision core that does not use the
//! quadratics: per front-facing triangle, the first β at which the distance
//! from the ball's center to the triangle equals ρ, found by Newton steps
//! from the left on that distance. The distance from a point to a triangle
//! (a convex set) is convex along a line, so Newton from the left never
//! steps over the first root: each step lands at or before it.
//!
//! Everything here is written from the geometry, not from the core.

use nalgebra::{Point3, Vector3};
use sweeptrace::core::{Facing, Kind};

/// A triangle for the oracle: vertices and front normal.
#[derive(Clone, Copy, Debug)]
pub struct OTri {
    pub v: [Point3<f64>; 3],
    pub n: Vector3<f64>,
    pub index: u32,
}

impl OTri {
    pub fn new(index: u32, a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> OTri {
        let v = [Point3::from(a), Point3::from(b), Point3::from(c)];
        let n = (v[1] - v[0]).cross(&(v[2] - v[0])).normalize();
        OTri { v, n, index }
    }
}

/// Where on a triangle the closest point lies, and how far (in relative
/// terms) it is from the boundary of that region.
#[derive(Clone, Copy, Debug)]
pub struct Closest {
    pub point: Point3<f64>,
    pub kind: Kind,
    /// Smallest relative distance to a region boundary (0 = on it).
    pub boundary_margin: f64,
}

/// Closest point of a triangle to `p`: the projection onto the plane if it
/// falls inside, otherwise the nearest point of the three segments.
pub fn closest(t: &OTri, p: &Point3<f64>) -> Closest {
    let [a, b, c] = t.v;
    let q = p - t.n * t.n.dot(&(p - a));
    // Signed areas of the sub-triangles opposite each vertex, over the total.
    let area = (b - a).cross(&(c - a)).dot(&t.n);
    let wa = (c - b).cross(&(q - b)).dot(&t.n) / area;
    let wb = (a - c).cross(&(q - c)).dot(&t.n) / area;
    let wc = (b - a).cross(&(q - a)).dot(&t.n) / area;
    if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
        return Closest {
            point: q,
            kind: Kind::Face,
            boundary_margin: wa.min(wb).min(wc),
        };
    }
    let mut best: Option<(f64, Closest)> = None;
    for i in 0..3 {
        let s0 = t.v[i];
        let s1 = t.v[(i + 1) % 3];
        let e = s1 - s0;
        let u = (p - s0).dot(&e) / e.norm_squared();
        let (point, kind, margin) = if u <= 0.0 {
            (s0, Kind::Vertex, -u)
        } else if u >= 1.0 {
            (s1, Kind::Vertex, u - 1.0)
        } else {
            (s0 + e * u, Kind::Edge, u.min(1.0 - u))
        };
        let d = (p - point).norm();
        if best.as_ref().is_none_or(|(bd, _)| d < *bd) {
            best = Some((
                d,
                Closest {
                    point,
                    kind,
                    boundary_margin: margin,
                },
            ));
        }
    }
    let mut out = best.expect("three segments").1;
    // Also how far the projection is from entering the face region.
    let face_margin = -wa.min(wb).min(wc);
    out.boundary_margin = out.boundary_margin.min(face_margin);
    out
}

/// First contact of one triangle along the path, by Newton steps from the left.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    pub beta: f64,
    pub kind: Kind,
    pub boundary_margin: f64,
    /// Cosine between the path and the contact direction (1 = head on).
    pub approach: f64,
}

pub enum Root {
    Contact(Contact),
    None,
    /// Did not converge in the step budget (grazing).
    NoConvergence,
}

pub fn first_contact(t: &OTri, p0: &Point3<f64>, d: &Vector3<f64>, rho: f64) -> Root {
    let len = d.norm();
    if len == 0.0 {
        return Root::None;
    }
    let mut beta = 0.0f64;
    for _ in 0..200 {
        let c = p0 + d * beta;
        let cl = closest(t, &c);
        let to = c - cl.point;
        let dist = to.norm();
        let g = dist - rho;
        if g <= 1e-13 * (1.0 + rho) {
            let approach = if dist > 0.0 {
                -to.dot(d) / (dist * len)
            } else {
                1.0
            };
            return Root::Contact(Contact {
                beta,
                kind: cl.kind,
                boundary_margin: cl.boundary_margin,
                approach,
            });
        }
        let slope = to.dot(d) / dist;
        if slope >= 0.0 {
            return Root::None;
        }
        beta += g / -slope;
        if beta > 1.0 + 1e-12 {
            return Root::None;
        }
    }
    Root::NoConvergence
}

/// The oracle's verdict on a sweep against triangles.
#[derive(Clone, Debug)]
pub enum OracleResult {
    /// Excluded as ill-conditioned, with the reason (counted by the caller).
    Excluded(&'static str),
    /// No contact on the path.
    Miss,
    /// First contact at `alpha`; `touching` = triangles whose own contact
    /// lies within the tie tolerance of `alpha`; `kind` when unambiguous.
    Hit {
        alpha: f64,
        touching: Vec<u32>,
        kind: Option<Kind>,
    },
}

/// Tolerances of the comparison, in one place.
pub const START_CLEARANCE: f64 = 1e-6;
pub const MIN_APPROACH_COSINE: f64 = 1e-3;
pub const RADIUS_PERTURBATION: f64 = 1e-7;
pub const BOUNDARY_MARGIN: f64 = 1e-7;
pub const FACING_MARGIN: f64 = 1e-9;
pub const TIE: f64 = 1e-7;

fn earliest(
    tris: &[&OTri],
    p0: &Point3<f64>,
    d: &Vector3<f64>,
    rho: f64,
) -> Result<Vec<(u32, Contact)>, &'static str> {
    let mut out = Vec::new();
    for t in tris {
        match first_contact(t, p0, d, rho) {
            Root::Contact(c) if c.beta <= 1.0 => out.push((t.index, c)),
            Root::Contact(_) | Root::None => {}
            Root::NoConvergence => return Err("no convergence (grazing)"),
        }
    }
    Ok(out)
}

/// Runs the oracle, applying every exclusion rule. The rules are:
/// - the ball starts within `START_CLEARANCE` of touching a front-facing
///   triangle (touching at the start);
/// - a triangle's facing value `n·d` is within `FACING_MARGIN·|d|` of 0
///   (the facing rule's boundary);
/// - the first contact approaches at a cosine below `MIN_APPROACH_COSINE`
///   (grazing: the discriminant is near zero);
/// - hit or miss changes when ρ moves by ±`RADIUS_PERTURBATION` (near miss,
///   or a contact at the very end of the path).
///
/// A contact within `BOUNDARY_MARGIN` of a feature boundary keeps α in the
/// comparison but not its kind.
pub fn oracle(tris: &[OTri], p0: [f64; 3], p1: [f64; 3], rho: f64, facing: Facing) -> OracleResult {
    let p0 = Point3::from(p0);
    let d = Point3::from(p1) - p0;
    let len = d.norm();
    let mut front = Vec::new();
    for t in tris {
        let nd = t.n.dot(&d);
        if nd.abs() <= FACING_MARGIN * len {
            return OracleResult::Excluded("facing boundary");
        }
        let ok = match facing {
            Facing::NonStrict => nd <= 0.0,
            Facing::Strict => nd < 0.0,
        };
        if ok {
            front.push(t);
        }
    }
    for t in &front {
        let cl = closest(t, &p0);
        if (p0 - cl.point).norm() - rho < START_CLEARANCE {
            return OracleResult::Excluded("touching at the start");
        }
    }
    let (contacts, lo, hi) = match (
        earliest(&front, &p0, &d, rho),
        earliest(&front, &p0, &d, rho - RADIUS_PERTURBATION),
        earliest(&front, &p0, &d, rho + RADIUS_PERTURBATION),
    ) {
        (Ok(c), Ok(lo), Ok(hi)) => (c, lo, hi),
        _ => return OracleResult::Excluded("grazing"),
    };
    if lo.is_empty() != hi.is_empty() {
        return OracleResult::Excluded("near miss or contact at the end");
    }
    if contacts.is_empty() {
        return OracleResult::Miss;
    }
    let alpha = contacts
        .iter()
        .map(|c| c.1.beta)
        .fold(f64::INFINITY, f64::min);
    let firsts: Vec<&(u32, Contact)> = contacts
        .iter()
        .filter(|c| c.1.beta <= alpha + TIE)
        .collect();
    if firsts.iter().any(|c| c.1.approach < MIN_APPROACH_COSINE) {
        return OracleResult::Excluded("grazing");
    }
    let touching: Vec<u32> = firsts.iter().map(|c| c.0).collect();
    let kind = if firsts.len() == 1 && firsts[0].1.boundary_margin > BOUNDARY_MARGIN {
        Some(firsts[0].1.kind)
    } else {
        None
    };
    OracleResult::Hit {
        alpha,
        touching,
        kind,
    }
}
