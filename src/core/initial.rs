//! The initial contact of a ball that starts within `ρ` of the mesh: the
//! answer of an engine that reports such a start as a hit at `α = 0`
//! ([`InitialOverlap::Alpha0`](super::InitialOverlap::Alpha0)), as Jolt,
//! PhysX without `eASSUME_NO_INITIAL_OVERLAP` and parry with
//! `stop_at_penetration` do. The rules of SEMANTICS.md report no collision
//! there (a face test whose ball starts within `ρ` of the plane rejects it).
//!
//! The contact is the point of the mesh nearest to the ball's centre at
//! `p0`, among the triangles whose facing rule lets the path through (an
//! engine that ignores back faces ignores them at the start too; under
//! `sides = two` every triangle, one the path moves toward the back of
//! with the normal `-n`, as in the sweep), named by
//! the region of the triangle it lies in: the face's interior, an edge or a
//! vertex. Every triangle in contact is a hit at `α = 0`, so they tie: the
//! primary is the first in the rules' tie order (face < edge < vertex, then
//! triangle, then feature), and the normal the average of their front
//! normals, as for any tie. An engine that names another one (the deepest,
//! say) names a member of the tie set.

use nalgebra::Point3;

use super::feature::Feature;
use super::mesh::{Mesh, Triangle};
use super::options::{InitialOverlap, Options, Sides};
use super::outcome::SweepHit;
use super::path::SweptPath;

/// The point of `triangle` nearest to `p` and the feature whose region it
/// lies in (Ericson, *Real-Time Collision Detection*, 5.1.5: the Voronoi
/// regions of the vertices, then of the edges, then the face).
pub(crate) fn closest_point(triangle: &Triangle, p: &Point3<f64>) -> (Point3<f64>, Feature) {
    let [a, b, c] = triangle.vertices;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        // Edge 2 runs from c to a.
        return (a + ac * w, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, Feature::Face)
}

/// Every initial contact of `path` against `mesh` under `facing`: for each
/// triangle the facing rule lets the path through whose nearest point
/// lies closer than `ρ` to `p0`, that point as a hit at `α = 0` (its
/// normal the triangle's front normal), with its distance from `p0`; in
/// the rules' tie order (face < edge < vertex, then triangle, then
/// feature). All of them are hits at the same `α`: a tie.
///
/// Under [`InitialOverlap::Alpha0Always`] the direction is not asked: every
/// triangle within `ρ` whose front holds the centre (or, two-sided, any,
/// the normal facing the centre). Under [`InitialOverlap::Alpha0Deeper`]
/// the same triangles, those whose nearest point the path closes in on.
pub fn initial_contacts(mesh: &Mesh, path: &SweptPath, options: &Options) -> Vec<(SweepHit, f64)> {
    let (facing, sides) = (options.facing, options.sides);
    // Under `alpha0_always` and `alpha0_deeper` the side is the centre's;
    // under `alpha0_deeper` the path must close in on the contact point.
    let always = matches!(
        options.initial_overlap,
        InitialOverlap::Alpha0Always | InitialOverlap::Alpha0Deeper
    );
    let deeper = options.initial_overlap == InitialOverlap::Alpha0Deeper;
    let triangles = mesh.triangles();
    let mut found = Vec::new();
    let mut consider = |t: &Triangle| {
        let (point, feature) = closest_point(t, &path.p0);
        let normal = if always {
            // The side the centre is on, whatever the direction.
            let centre_side = t.normal.dot(&(path.p0 - point));
            match (centre_side < 0.0, sides) {
                (false, _) => t.normal,
                (true, Sides::Two) => -t.normal,
                (true, Sides::One) => return,
            }
        } else {
            // Under `sides = two` a triangle the path moves toward the back
            // of is its mirror, as in the sweep: normal `-n`.
            let normal_dot_d = t.normal.dot(&path.d);
            if !facing.allows(sides.facing_value(normal_dot_d)) {
                return;
            }
            if sides.flips(normal_dot_d) {
                -t.normal
            } else {
                t.normal
            }
        };
        let distance = (path.p0 - point).norm();
        if deeper && (path.p0 - point).dot(&path.d) >= 0.0 {
            return;
        }
        if distance < path.rho {
            let hit = SweepHit {
                alpha: 0.0,
                triangle: t.index,
                feature,
                normal,
                contact: point,
            };
            found.push((hit, distance));
        }
    };
    if path.length > 0.0 {
        // The leaves whose boxes, grown by ρ, hold `p0`: the path enters
        // them at `t = 0`.
        let grow = path.rho + path.broadphase_margin();
        mesh.bvh().traverse(&path.p0, &path.d, grow, 0.0, |range| {
            for position in range {
                consider(&triangles[position]);
            }
            0.0
        });
    } else {
        triangles.iter().for_each(&mut consider);
    }
    found.sort_by_key(|(h, _)| {
        let (kind, index) = h.feature.order_key();
        (kind, h.triangle, index)
    });
    found
}

/// The initial contact of `path`, as the rules decide a tie: the first of
/// [`initial_contacts`] in the tie order, its normal the normalised
/// average of the front normals of every triangle in contact; with the
/// smallest distance from `p0` among them. `None` when the ball starts
/// clear of every triangle it moves toward.
pub(crate) fn initial_contact(
    mesh: &Mesh,
    path: &SweptPath,
    options: &Options,
) -> Option<(SweepHit, f64)> {
    let contacts = initial_contacts(mesh, path, options);
    let (first, _) = contacts.first()?;
    let mut hit = *first;
    let mut sum = nalgebra::Vector3::zeros();
    let mut last = None;
    for (h, _) in &contacts {
        if last != Some(h.triangle) {
            sum += h.normal;
            last = Some(h.triangle);
        }
    }
    if sum.norm() > 1e-9 {
        hit.normal = sum.normalize();
    }
    let nearest = contacts
        .iter()
        .map(|(_, d)| *d)
        .fold(f64::INFINITY, f64::min);
    Some((hit, nearest))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{Options, Sweep};

    fn floor() -> Mesh {
        Mesh::new(
            vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
            &[[0, 1, 2]],
        )
        .expect("valid mesh")
    }

    #[test]
    fn closest_point_names_the_region() {
        let m = floor();
        let t = &m.triangles()[0];
        let at = |x, y, z| closest_point(t, &Point3::new(x, y, z));
        assert_eq!(
            at(1.0, 1.0, 2.0),
            (Point3::new(1.0, 1.0, 0.0), Feature::Face)
        );
        assert_eq!(
            at(2.0, -1.0, 0.5),
            (Point3::new(2.0, 0.0, 0.0), Feature::Edge(0))
        );
        assert_eq!(
            at(3.0, 3.0, 0.0),
            (Point3::new(2.0, 2.0, 0.0), Feature::Edge(1))
        );
        assert_eq!(
            at(-1.0, 2.0, 0.0),
            (Point3::new(0.0, 2.0, 0.0), Feature::Edge(2))
        );
        assert_eq!(at(-1.0, -1.0, 1.0).1, Feature::Vertex(0));
        assert_eq!(at(5.0, -0.5, 0.0).1, Feature::Vertex(1));
        assert_eq!(at(-0.5, 5.0, 0.0).1, Feature::Vertex(2));
    }

    #[test]
    fn a_start_within_rho_is_a_contact_and_one_beyond_is_not() {
        let m = floor();
        let path = |z: f64, dz: f64| {
            let s = Sweep::new([1.0, 1.0, z], [1.0, 1.0, z + dz], 0.5);
            SweptPath::new(&s, &Options::default()).expect("valid sweep")
        };
        let alpha0 = Options {
            initial_overlap: InitialOverlap::Alpha0,
            ..Options::default()
        };
        let (hit, distance) = initial_contact(&m, &path(0.25, -1.0), &alpha0).expect("a contact");
        assert_eq!(distance, 0.25);
        assert_eq!((hit.alpha, hit.feature), (0.0, Feature::Face));
        assert_eq!(hit.contact, Point3::new(1.0, 1.0, 0.0));
        assert!(initial_contact(&m, &path(0.75, -1.0), &alpha0).is_none());
        // Moving away from the front: the facing rule rejects the triangle.
        assert!(initial_contact(&m, &path(0.25, 1.0), &alpha0).is_none());
        // Not moving at all: every triangle is looked at.
        assert!(initial_contact(&m, &path(0.25, 0.0), &alpha0).is_some());
    }

    /// Issue 47: Rapier's `stopAtPenetration` (parry's
    /// `stop_at_penetration`) reports a start within ρ as a hit at α = 0
    /// whatever the direction, moving away included; its normal faces the
    /// centre (two-sided: from behind, `-n`; one-sided, nothing behind).
    #[test]
    fn alpha0_always_is_a_contact_whatever_the_direction() {
        let m = floor();
        let path = |z: f64, dz: f64| {
            let s = Sweep::new([1.0, 1.0, z], [1.0, 1.0, z + dz], 0.5);
            SweptPath::new(&s, &Options::default()).expect("valid sweep")
        };
        let always = |sides| Options {
            initial_overlap: InitialOverlap::Alpha0Always,
            sides,
            ..Options::default()
        };
        for dz in [-1.0, 0.0, 1.0] {
            let (hit, distance) =
                initial_contact(&m, &path(0.25, dz), &always(Sides::One)).expect("a contact");
            assert_eq!(
                (distance, hit.alpha, hit.feature),
                (0.25, 0.0, Feature::Face)
            );
            assert_eq!(hit.normal, nalgebra::Vector3::z(), "dz {dz}");
        }
        // From behind: two-sided, the normal faces the centre; one-sided,
        // no contact.
        let (hit, _) =
            initial_contact(&m, &path(-0.25, -1.0), &always(Sides::Two)).expect("a contact");
        assert_eq!(hit.normal, -nalgebra::Vector3::z());
        assert!(initial_contact(&m, &path(-0.25, -1.0), &always(Sides::One)).is_none());
        assert!(initial_contact(&m, &path(0.75, 1.0), &always(Sides::Two)).is_none());
    }

    /// Issue 47: with `stop_at_penetration` false, parry and Rapier report
    /// a start within ρ only when the path goes deeper, judged at the
    /// contact point. A ball overlapping the floor's corner vertex and
    /// moving down but away from the vertex is a contact under `alpha0`
    /// (the facing rule sees it approach the plane) and none under
    /// `alpha0_deeper`; moving toward the vertex it is one under both; not
    /// moving, it is none under `alpha0_deeper`.
    #[test]
    fn alpha0_deeper_judges_the_direction_at_the_contact_point() {
        let m = floor();
        let path = |p0: [f64; 3], d: [f64; 3]| {
            let p1 = [p0[0] + d[0], p0[1] + d[1], p0[2] + d[2]];
            SweptPath::new(&Sweep::new(p0, p1, 0.5), &Options::default()).expect("valid sweep")
        };
        let with = |initial_overlap| Options {
            initial_overlap,
            ..Options::default()
        };
        let (alpha0, deeper) = (
            with(InitialOverlap::Alpha0),
            with(InitialOverlap::Alpha0Deeper),
        );
        // Over the corner (0, 0, 0), 0.3 × √3 ≈ 0.52 > ρ: start nearer.
        let start = [-0.2, -0.2, 0.2];
        let away = path(start, [-0.1, -0.1, -0.05]);
        let (hit, _) = initial_contact(&m, &away, &alpha0).expect("alpha0: a contact");
        assert_eq!(hit.feature, Feature::Vertex(0));
        assert!(initial_contact(&m, &away, &deeper).is_none());
        let toward = path(start, [0.1, 0.1, -0.05]);
        let (hit, _) = initial_contact(&m, &toward, &deeper).expect("deeper: a contact");
        assert_eq!((hit.alpha, hit.feature), (0.0, Feature::Vertex(0)));
        assert_eq!(hit.normal, m.triangles()[0].normal);
        assert!(initial_contact(&m, &path(start, [0.0, 0.0, 0.0]), &deeper).is_none());
        // On the face, the two agree: toward the plane a contact, away none.
        assert!(initial_contact(&m, &path([1.0, 1.0, 0.25], [0.0, 0.0, -1.0]), &deeper).is_some());
        assert!(initial_contact(&m, &path([1.0, 1.0, 0.25], [0.0, 0.0, 1.0]), &deeper).is_none());
    }
}
