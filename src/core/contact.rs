//! The contact set of a ball at rest: what a physics engine's contact
//! generation should report for a sphere of radius `ρ` centred at `c`
//! against the mesh (SEMANTICS.md, "Contacts").
//!
//! A sweep asks *when* a moving ball first touches the mesh; a contact
//! query asks *what it touches now*. Every usable triangle whose closest
//! point lies within `ρ + s` of the centre (`s`, the engine's speculative
//! contact distance, 0 by default) is in the set, once, with the feature
//! whose region holds that point (face, edge or vertex), the point itself,
//! the signed separation `|c − q| − ρ` (negative: the ball penetrates), the
//! geometric normal `(c − q) / |c − q|` and the triangle's normal on the
//! centre's side. The edge feature is computed as in the sweep's edge test:
//! in the edge's standard frame (`v0` at the origin, `v1` on `+x`), where
//! the closest point of the edge is `(clamp(x, 0, L), 0, 0)`.
//!
//! The same place reached through several triangles (a vertex shared by
//! six, an edge by two) is in the set once per triangle: the set is the
//! reference, and an engine that reports such a place once, through any
//! of its triangles, names one of them (the judge groups them by the
//! mesh's weld).

use nalgebra::{Point3, Vector3};

use super::feature::Feature;
use super::initial::closest_point;
use super::mesh::{Mesh, Triangle};
use super::options::Sides;

/// One contact query: a ball of `radius` at `centre`, and the engine's
/// contact `distance` (how far beyond touching a triangle still counts; 0
/// for contacts that touch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactQuery {
    /// The ball's centre.
    pub centre: Point3<f64>,
    /// The ball's radius `ρ` (finite, `> 0`).
    pub radius: f64,
    /// The speculative contact distance `s` (finite, `≥ 0`).
    pub distance: f64,
}

impl ContactQuery {
    /// How far from the centre a triangle's closest point may be: `ρ + s`.
    pub fn reach(&self) -> f64 {
        self.radius + self.distance
    }
}

/// One triangle's contact with the ball (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The triangle's index in the scene's triangle list.
    pub triangle: u32,
    /// The feature whose region holds the closest point.
    pub feature: Feature,
    /// The triangle's point closest to the centre.
    pub point: Point3<f64>,
    /// `|c − q| − ρ`: positive apart, zero touching, negative penetrating.
    pub separation: f64,
    /// The geometric normal, from the point toward the centre; the face
    /// normal on the centre's side when the centre lies on the triangle.
    pub normal: Vector3<f64>,
    /// The triangle's front normal, or its back normal when the centre is
    /// behind it (only under [`Sides::Two`]).
    pub face_normal: Vector3<f64>,
}

/// The closest point of `triangle` to `p`, with its feature, the edge
/// feature's point computed in the edge's standard frame.
pub(crate) fn closest_feature(triangle: &Triangle, p: &Point3<f64>) -> (Point3<f64>, Feature) {
    let (point, feature) = closest_point(triangle, p);
    match feature {
        Feature::Edge(e) => {
            let frame = &triangle.edges[e as usize];
            let x = frame.to_edge(p).x.clamp(0.0, frame.length);
            (frame.to_world(&Point3::new(x, 0.0, 0.0)), feature)
        }
        _ => (point, feature),
    }
}

/// The contact of `triangle` with the ball of `query`, if its closest point
/// is within reach and (under [`Sides::One`]) the centre is not behind it.
pub(crate) fn triangle_contact(
    triangle: &Triangle,
    query: &ContactQuery,
    sides: Sides,
) -> Option<Contact> {
    let (point, feature) = closest_feature(triangle, &query.centre);
    let towards = query.centre - point;
    let gap = towards.norm();
    // A NaN gap (a non-finite query) is no contact.
    if gap.is_nan() || gap > query.reach() {
        return None;
    }
    let side = triangle.normal.dot(&towards);
    let face_normal = match (side < 0.0, sides) {
        (false, _) => triangle.normal,
        (true, Sides::Two) => -triangle.normal,
        (true, Sides::One) => return None,
    };
    let normal = if gap > 0.0 {
        towards / gap
    } else {
        face_normal
    };
    Some(Contact {
        triangle: triangle.index,
        feature,
        point,
        separation: gap - query.radius,
        normal,
        face_normal,
    })
}

/// Every contact of the ball of `query` with `mesh`: one per usable
/// triangle within reach, by separation (least first), then triangle
/// index. `sides`: whether a triangle whose back faces the centre counts
/// ([`Sides::Two`]) or not ([`Sides::One`], the rules).
pub fn contact_set(mesh: &Mesh, query: &ContactQuery, sides: Sides) -> Vec<Contact> {
    let mut found = Vec::new();
    let reach = query.reach();
    if !(reach.is_finite() && query.centre.iter().all(|c| c.is_finite())) {
        return found;
    }
    // The leaves whose boxes lie within the reach of the centre. The boxes
    // are rounded outward; the margin covers the rounding of the distance.
    let size = query.centre.iter().fold(reach, |m, c| m.max(c.abs()));
    let grow = reach + 8.0 * f64::EPSILON * size;
    let (triangles, planes) = (mesh.triangles(), mesh.planes());
    // The closest point lies in the triangle's plane, so its distance is at
    // least the centre's height over the plane, and (one-sided) the centre
    // is behind it when that height is negative: a cheap rejection, kept
    // loose by the rounding of the height so that `triangle_contact`
    // decides every case it could accept.
    let slack = 64.0 * f64::EPSILON * size;
    let far = reach + slack;
    mesh.bvh().within(&query.centre, grow, |range| {
        for position in range {
            let plane = &planes[position];
            let height = plane.normal.dot(&(query.centre - plane.v0));
            if height.abs() > reach + slack || (sides == Sides::One && height < -slack) {
                continue;
            }
            // The triangle lies within `extent` of `v0`: on a height
            // field the plane test keeps every triangle under the
            // ball's reach, this one those the ball can touch, before
            // the triangle's whole record is read (in a large mesh, a
            // cache miss each).
            // In the plane: the centre's foot lies within
            // `sqrt(far² - height²)` of the closest point, itself within
            // `extent` of `v0` (tighter than the same bound in space
            // when the ball rests on the plane, as on a height field).
            let extent = f64::from(plane.extent);
            let in_plane = (query.centre - plane.v0).norm_squared() - height * height;
            let within = (far * far - height * height).max(0.0).sqrt() + extent;
            if in_plane > within * within * (1.0 + 16.0 * f64::EPSILON) {
                continue;
            }
            // Then its bounding box, which holds the closest point.
            let triangle = &triangles[position];
            if box_distance_squared(&triangle.vertices, &query.centre) > far * far {
                continue;
            }
            if let Some(contact) = triangle_contact(triangle, query, sides) {
                found.push(contact);
            }
        }
    });
    // By separation, then triangle (each key distinct): the keys sorted
    // apart from the contacts, which are large to move.
    let mut order: Vec<(f64, u32, u32)> = found
        .iter()
        .enumerate()
        .map(|(i, c)| (c.separation, c.triangle, i as u32))
        .collect();
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    order.iter().map(|&(_, _, i)| found[i as usize]).collect()
}

/// The squared distance from `p` to the bounding box of `vertices`.
fn box_distance_squared(vertices: &[Point3<f64>; 3], p: &Point3<f64>) -> f64 {
    let [a, b, c] = vertices;
    (0..3)
        .map(|k| {
            let (lo, hi) = (a[k].min(b[k]).min(c[k]), a[k].max(b[k]).max(c[k]));
            let d = (lo - p[k]).max(p[k] - hi).max(0.0);
            d * d
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{ContactQuery, contact_set};
    use crate::core::{Feature, Mesh, Sides};

    fn query(centre: [f64; 3], radius: f64) -> ContactQuery {
        ContactQuery {
            centre: Point3::from(centre),
            radius,
            distance: 0.0,
        }
    }

    /// A 2×2 grid of unit squares in z = 0, two triangles each, fronts up.
    fn floor() -> Mesh {
        let mut vertices = Vec::new();
        for y in 0..3 {
            for x in 0..3 {
                vertices.push([x as f64, y as f64, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        for y in 0..2u64 {
            for x in 0..2u64 {
                let i = y * 3 + x;
                triangles.push([i, i + 1, i + 4]);
                triangles.push([i, i + 4, i + 3]);
            }
        }
        Mesh::new(vertices, &triangles).unwrap()
    }

    #[test]
    fn a_ball_resting_on_a_face_touches_that_face_only() {
        let set = contact_set(&floor(), &query([0.7, 0.2, 0.25], 0.25), Sides::One);
        assert_eq!(set.len(), 1);
        let c = &set[0];
        assert_eq!((c.triangle, c.feature), (0, Feature::Face));
        assert_eq!(c.point, Point3::new(0.7, 0.2, 0.0));
        assert_eq!(c.separation, 0.0);
        assert_eq!(c.normal, Vector3::z());
    }

    #[test]
    fn a_shared_vertex_is_in_the_set_once_per_triangle() {
        // The centre vertex (1, 1) is shared by six of the eight triangles;
        // a ball above it touches all six at that vertex (or at the faces
        // whose region holds it), at the same separation.
        let set = contact_set(&floor(), &query([1.0, 1.0, 0.2], 0.25), Sides::One);
        assert_eq!(set.len(), 6, "{set:?}");
        for c in &set {
            assert_eq!(c.point, Point3::new(1.0, 1.0, 0.0), "{c:?}");
            assert!((c.separation + 0.05).abs() < 1e-15);
        }
        // Sorted by separation, then triangle: all tie, so by triangle.
        let triangles: Vec<u32> = set.iter().map(|c| c.triangle).collect();
        assert_eq!(triangles, [0, 1, 3, 4, 6, 7]);
        assert!(set.iter().all(|c| matches!(c.feature, Feature::Vertex(_))));
    }

    #[test]
    fn the_back_of_a_one_sided_triangle_touches_nothing() {
        let below = query([0.7, 0.2, -0.2], 0.25);
        assert!(contact_set(&floor(), &below, Sides::One).is_empty());
        let two = contact_set(&floor(), &below, Sides::Two);
        assert_eq!(two.len(), 1);
        assert_eq!(two[0].face_normal, -Vector3::z());
        assert_eq!(two[0].normal, -Vector3::z());
    }

    #[test]
    fn the_contact_distance_reaches_beyond_touching() {
        let apart = ContactQuery {
            distance: 0.1,
            ..query([0.7, 0.2, 0.3], 0.25)
        };
        let set = contact_set(&floor(), &apart, Sides::One);
        assert_eq!(set.len(), 1);
        assert!((set[0].separation - 0.05).abs() < 1e-15);
        assert!(contact_set(&floor(), &query([0.7, 0.2, 0.3], 0.25), Sides::One).is_empty());
    }

    #[test]
    fn an_edge_contact_is_its_point_on_the_edge_and_leans_toward_the_centre() {
        // Beyond the floor's edge x = 2, centre above and outside.
        let set = contact_set(&floor(), &query([2.1, 0.5, 0.1], 0.25), Sides::One);
        assert_eq!(set.len(), 1);
        let c = &set[0];
        assert!(matches!(c.feature, Feature::Edge(_)));
        assert!((c.point - Point3::new(2.0, 0.5, 0.0)).norm() < 1e-15);
        let expected = Vector3::new(0.1, 0.0, 0.1).normalize();
        assert!((c.normal - expected).norm() < 1e-15);
    }

    /// The contact set against a brute-force computation written another
    /// way: the projection on the plane when it falls inside the triangle
    /// (barycentric coordinates from areas), else the nearest of the three
    /// segments' closest points; over every triangle, no hierarchy.
    #[test]
    fn the_contact_set_agrees_with_brute_force_on_random_scenes() {
        let mut rng = ChaCha8Rng::seed_from_u64(45);
        let mut cases = 0usize;
        let mut contacts = 0usize;
        for _ in 0..1_000 {
            let n = rng.random_range(1..40usize);
            let mut vertices = Vec::new();
            let mut triangles = Vec::new();
            for t in 0..n as u64 {
                let c = [0; 3].map(|_| rng.random_range(-4.0..4.0));
                let size = if t % 5 == 0 { 6.0 } else { 1.5 };
                for _ in 0..3 {
                    vertices.push([0, 1, 2].map(|k| c[k] + rng.random_range(-size..size)));
                }
                triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
            }
            let Ok(mesh) = Mesh::new(vertices, &triangles) else {
                continue;
            };
            for _ in 0..100 {
                let sides = if rng.random_bool(0.5) {
                    Sides::One
                } else {
                    Sides::Two
                };
                let q = ContactQuery {
                    centre: Point3::from([0; 3].map(|_| rng.random_range(-6.0..6.0))),
                    radius: rng.random_range(0.05..2.5),
                    distance: if rng.random_bool(0.3) {
                        rng.random_range(0.0..0.5)
                    } else {
                        0.0
                    },
                };
                cases += 1;
                let set = contact_set(&mesh, &q, sides);
                contacts += set.len();
                let mut expected = Vec::new();
                for t in mesh.triangles() {
                    let (point, vertex_or_edge, margin) = brute_closest(t.vertices, &q.centre);
                    let gap = (q.centre - point).norm();
                    let side = t.normal.dot(&(q.centre - point));
                    let near_boundary = (gap - q.reach()).abs() < 1e-9 || side.abs() < 1e-9;
                    let inside = gap <= q.reach() && (side >= 0.0 || sides == Sides::Two);
                    let got = set.iter().find(|c| c.triangle == t.index);
                    if near_boundary {
                        continue;
                    }
                    assert_eq!(got.is_some(), inside, "triangle {} at {q:?}", t.index);
                    let Some(got) = got else { continue };
                    expected.push(t.index);
                    assert!((got.point - point).norm() < 1e-9, "{got:?} vs {point}");
                    assert!((got.separation - (gap - q.radius)).abs() < 1e-9);
                    if margin > 1e-9 {
                        let kind = match got.feature {
                            Feature::Face => 0,
                            Feature::Edge(_) => 1,
                            Feature::Vertex(_) => 2,
                        };
                        assert_eq!(kind, vertex_or_edge, "{got:?} at {q:?}");
                    }
                    if gap > 1e-9 {
                        assert!((got.normal - (q.centre - point) / gap).norm() < 1e-9);
                    }
                }
                assert!(set.windows(2).all(|w| w[0].separation <= w[1].separation));
            }
        }
        assert!(cases >= 100_000 - 2_000, "{cases} cases");
        assert!(
            contacts > 20_000,
            "only {contacts} contacts: the scenes are too sparse"
        );
    }

    /// The closest point of triangle `v` to `p`, its kind (0 face, 1 edge,
    /// 2 vertex) and how far `p` is from a change of kind (a near-tie below
    /// 1e-9 leaves the kind unchecked).
    fn brute_closest(v: [Point3<f64>; 3], p: &Point3<f64>) -> (Point3<f64>, u8, f64) {
        let n = (v[1] - v[0]).cross(&(v[2] - v[0]));
        let area = n.norm();
        let unit = n / area;
        let q = p - unit * unit.dot(&(p - v[0]));
        let bary = [0, 1, 2].map(|i| {
            let (a, b) = (v[(i + 1) % 3], v[(i + 2) % 3]);
            (b - a).cross(&(q - a)).dot(&unit) / area
        });
        let min_bary = bary.iter().cloned().fold(f64::INFINITY, f64::min);
        if min_bary >= 0.0 {
            return (q, 0, min_bary * area.sqrt());
        }
        let mut best = (Point3::origin(), 1u8, f64::INFINITY, 0.0);
        for i in 0..3 {
            let (a, b) = (v[i], v[(i + 1) % 3]);
            let ab = b - a;
            let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let point = a + ab * t;
            let d = (p - point).norm();
            if d < best.2 {
                let kind = if t == 0.0 || t == 1.0 { 2 } else { 1 };
                // How far along the edge's line from either end: where the
                // kind turns between edge and vertex.
                let along = (p - a).dot(&ab) / ab.norm();
                let margin = along.abs().min((along - ab.norm()).abs());
                best = (point, kind, d, margin.min(-min_bary * area.sqrt()));
            }
        }
        (best.0, best.1, best.3)
    }
}
