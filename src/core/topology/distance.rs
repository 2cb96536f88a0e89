//! Distances from a point or a segment to a defect's place (its triangles,
//! edges or vertices): how near a tunnel's crossing point, or a ball's
//! path, comes to a defect.

use nalgebra::Point3;

/// One piece of a defect's place.
#[derive(Clone, Copy, Debug)]
pub(super) enum Place {
    /// A triangle, its interior included (its edges when it has no area).
    Triangle(Point3<f64>, Point3<f64>, Point3<f64>),
    /// An edge.
    Segment(Point3<f64>, Point3<f64>),
    /// A vertex.
    Point(Point3<f64>),
}

impl Place {
    /// Closest distance from `p` to the place.
    pub(super) fn distance_to_point(&self, p: &Point3<f64>) -> f64 {
        match self {
            Place::Triangle(a, b, c) => point_triangle_distance(p, a, b, c),
            Place::Segment(a, b) => point_segment_distance(p, a, b),
            Place::Point(a) => (a - p).norm(),
        }
    }

    /// Closest distance from the segment `p q` to the place.
    pub(super) fn distance_to_segment(&self, p: &Point3<f64>, q: &Point3<f64>) -> f64 {
        match self {
            Place::Triangle(a, b, c) => segment_triangle_distance(p, q, a, b, c),
            Place::Segment(a, b) => segment_segment_distance(p, q, a, b),
            Place::Point(a) => point_segment_distance(a, p, q),
        }
    }
}

/// Closest distance from `p` to the segment `a b`.
pub(crate) fn point_segment_distance(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).norm()
}

/// The unit normal of the triangle `a b c`, `None` when it has no area.
fn unit_normal(
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> Option<nalgebra::Vector3<f64>> {
    let cross = (b - a).cross(&(c - a));
    let area2 = cross.norm();
    (area2.is_finite() && area2 > 0.0).then(|| cross / area2)
}

/// Whether `p`, a point of the plane of `a b c` (unit normal `n`), lies in
/// the triangle, boundary included.
fn in_triangle(
    p: &Point3<f64>,
    n: &nalgebra::Vector3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> bool {
    [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(u, v)| n.dot(&(*v - *u).cross(&(p - *u))) >= 0.0)
}

/// Closest distance from `p` to the triangle `a b c` (its edges when it has
/// no area).
pub(super) fn point_triangle_distance(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> f64 {
    let edges = point_segment_distance(p, a, b)
        .min(point_segment_distance(p, b, c))
        .min(point_segment_distance(p, c, a));
    let Some(n) = unit_normal(a, b, c) else {
        return edges;
    };
    if in_triangle(p, &n, a, b, c) {
        n.dot(&(p - a)).abs().min(edges)
    } else {
        edges
    }
}

/// Closest distance between the segments `p q` and `a b` (Ericson,
/// *Real-Time Collision Detection*, 5.1.9), either of them possibly a
/// point.
pub(super) fn segment_segment_distance(
    p: &Point3<f64>,
    q: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
) -> f64 {
    let d1 = q - p;
    let d2 = b - a;
    let r = p - a;
    let (l1, l2) = (d1.norm_squared(), d2.norm_squared());
    let f = d2.dot(&r);
    let (s, t) = if l1 <= 0.0 && l2 <= 0.0 {
        (0.0, 0.0)
    } else if l1 <= 0.0 {
        (0.0, (f / l2).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if l2 <= 0.0 {
            ((-c / l1).clamp(0.0, 1.0), 0.0)
        } else {
            let bb = d1.dot(&d2);
            let denom = l1 * l2 - bb * bb;
            let mut s = if denom > 0.0 {
                ((bb * f - c * l2) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (bb * s + f) / l2;
            if t < 0.0 {
                t = 0.0;
                s = (-c / l1).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((bb - c) / l1).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p + d1 * s) - (a + d2 * t)).norm()
}

/// Closest distance from the segment `p q` to the triangle `a b c`: 0 when
/// the segment passes through it, otherwise the nearest of its ends to the
/// triangle and of the triangle's edges to the segment.
pub(super) fn segment_triangle_distance(
    p: &Point3<f64>,
    q: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> f64 {
    if let Some(n) = unit_normal(a, b, c) {
        let (hp, hq) = (n.dot(&(p - a)), n.dot(&(q - a)));
        if (hp <= 0.0) != (hq <= 0.0) || hp == 0.0 || hq == 0.0 {
            let t = if hp == hq { 0.0 } else { hp / (hp - hq) };
            let x = p + (q - p) * t.clamp(0.0, 1.0);
            if in_triangle(&x, &n, a, b, c) {
                return 0.0;
            }
        }
    }
    point_triangle_distance(p, a, b, c)
        .min(point_triangle_distance(q, a, b, c))
        .min(segment_segment_distance(p, q, a, b))
        .min(segment_segment_distance(p, q, b, c))
        .min(segment_segment_distance(p, q, c, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    #[test]
    fn segments_crossing_at_a_distance() {
        // Two perpendicular segments 2 apart in z.
        let d = segment_segment_distance(
            &pt(-1.0, 0.0, 0.0),
            &pt(1.0, 0.0, 0.0),
            &pt(0.0, -1.0, 2.0),
            &pt(0.0, 1.0, 2.0),
        );
        assert!((d - 2.0).abs() < 1e-12, "{d}");
        // Parallel, offset along their line: end to end.
        let d = segment_segment_distance(
            &pt(0.0, 0.0, 0.0),
            &pt(1.0, 0.0, 0.0),
            &pt(3.0, 0.0, 0.0),
            &pt(4.0, 0.0, 0.0),
        );
        assert!((d - 2.0).abs() < 1e-12, "{d}");
        // A point against a segment.
        let p = pt(0.5, 3.0, 0.0);
        let d = segment_segment_distance(&p, &p, &pt(0.0, 0.0, 0.0), &pt(1.0, 0.0, 0.0));
        assert!((d - 3.0).abs() < 1e-12, "{d}");
    }

    #[test]
    fn segment_through_beside_and_over_a_triangle() {
        let (a, b, c) = (pt(0.0, 0.0, 0.0), pt(4.0, 0.0, 0.0), pt(0.0, 4.0, 0.0));
        // Through its interior.
        let d = segment_triangle_distance(&pt(1.0, 1.0, 2.0), &pt(1.0, 1.0, -2.0), &a, &b, &c);
        assert_eq!(d, 0.0);
        // Down beside the hypotenuse, 1 from it.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let (x, y) = (2.0 + s, 2.0 + s);
        let d = segment_triangle_distance(&pt(x, y, 2.0), &pt(x, y, -2.0), &a, &b, &c);
        assert!((d - 1.0).abs() < 1e-12, "{d}");
        // Level over it, 0.5 above.
        let d = segment_triangle_distance(&pt(0.5, 0.5, 0.5), &pt(1.5, 0.5, 0.5), &a, &b, &c);
        assert!((d - 0.5).abs() < 1e-12, "{d}");
    }
}
