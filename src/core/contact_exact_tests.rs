//! The contact set on near-ties, against exact arithmetic: integer
//! coordinates (exact in `f64`, large enough that the core's dot products
//! round), centres placed on or one unit beside the boundaries where the
//! answer changes (a vertex's region and an edge's, an edge's and the
//! face's, the reach, the plane under `sides = one`), and the same
//! decisions computed with big integers. Away from a boundary the core
//! must decide exactly as the exact computation; on one, either side, with
//! the same point.

use nalgebra::Point3;
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::contact::{ContactQuery, contact_set};
use super::{Feature, Mesh, Sides};

type V = [BigInt; 3];

fn big(p: [i64; 3]) -> V {
    p.map(BigInt::from)
}

fn sub(a: &V, b: &V) -> V {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn dot(a: &V, b: &V) -> BigInt {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

fn cross(a: &V, b: &V) -> V {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

fn ratio(num: &BigInt, den: &BigInt) -> f64 {
    // The quotient to 64 bits after the point (truncated: an error below
    // 2^-64, far below the band), then rounded once to f64.
    let quotient: BigInt = (num << 64usize) / den;
    quotient.to_f64().unwrap_or(f64::NAN) / 2f64.powi(64)
}

/// The exact answer for one triangle: the feature (Ericson's regions with
/// the boundaries of SEMANTICS.md: a vertex's region holds its boundary, an
/// edge's holds its boundary with the face's), the squared distance as a
/// fraction, the closest point (rounded once to `f64`), whether the centre
/// lies on a region boundary, and the centre's height over the plane times
/// `|n|` (its sign: which side), and that height (rounded once).
struct Exact {
    feature: Feature,
    distance_squared: (BigInt, BigInt),
    point: Point3<f64>,
    on_boundary: bool,
    side: BigInt,
    height: f64,
}

fn exact(v: &[[i64; 3]; 3], p: [i64; 3]) -> Exact {
    let (a, b, c, p) = (big(v[0]), big(v[1]), big(v[2]), big(p));
    let (ab, ac) = (sub(&b, &a), sub(&c, &a));
    let n = cross(&ab, &ac);
    let (ap, bp, cp) = (sub(&p, &a), sub(&p, &b), sub(&p, &c));
    let (d1, d2) = (dot(&ab, &ap), dot(&ac, &ap));
    let (d3, d4) = (dot(&ab, &bp), dot(&ac, &bp));
    let (d5, d6) = (dot(&ab, &cp), dot(&ac, &cp));
    let vc = &d1 * &d4 - &d3 * &d2;
    let vb = &d5 * &d2 - &d1 * &d6;
    let va = &d3 * &d6 - &d5 * &d4;
    let on_boundary = [
        &d1,
        &d2,
        &d3,
        &d4,
        &d5,
        &d6,
        &vc,
        &vb,
        &va,
        &(&d4 - &d3),
        &(&d5 - &d6),
    ]
    .iter()
    .any(|x| x.is_zero());
    let zero = BigInt::zero();
    let one = BigInt::from(1);
    let to_point =
        |x: &V, den: &BigInt| Point3::new(ratio(&x[0], den), ratio(&x[1], den), ratio(&x[2], den));
    // The closest point on segment `from + t·dir` at `t = num / den`.
    let on_edge = |from: &V, dir: &V, along: &V| -> ((BigInt, BigInt), Point3<f64>) {
        let (t, len2) = (dot(along, dir), dot(dir, dir));
        let d2 = dot(along, along) * &len2 - &t * &t;
        let q = [0, 1, 2].map(|k| &from[k] * &len2 + &dir[k] * &t);
        let point = to_point(&q, &len2);
        ((d2, len2), point)
    };
    let (feature, distance_squared, point) = if d1 <= zero && d2 <= zero {
        (
            Feature::Vertex(0),
            (dot(&ap, &ap), one.clone()),
            to_point(&a, &one),
        )
    } else if d3 >= zero && d4 <= d3 {
        (
            Feature::Vertex(1),
            (dot(&bp, &bp), one.clone()),
            to_point(&b, &one),
        )
    } else if vc <= zero && d1 >= zero && d3 <= zero {
        let (d, q) = on_edge(&a, &ab, &ap);
        (Feature::Edge(0), d, q)
    } else if d6 >= zero && d5 <= d6 {
        (
            Feature::Vertex(2),
            (dot(&cp, &cp), one.clone()),
            to_point(&c, &one),
        )
    } else if vb <= zero && d2 >= zero && d6 <= zero {
        let (d, q) = on_edge(&a, &ac, &ap);
        (Feature::Edge(2), d, q)
    } else if va <= zero && &d4 - &d3 >= zero && &d5 - &d6 >= zero {
        let bc = sub(&c, &b);
        let (d, q) = on_edge(&b, &bc, &bp);
        (Feature::Edge(1), d, q)
    } else {
        let (h, n2) = (dot(&n, &ap), dot(&n, &n));
        let q = [0, 1, 2].map(|k| &p[k] * &n2 - &n[k] * &h);
        (Feature::Face, (&h * &h, n2.clone()), to_point(&q, &n2))
    };
    let side = dot(&n, &ap);
    let height = side.to_f64().unwrap_or(f64::NAN) / ratio(&dot(&n, &n), &one).sqrt();
    Exact {
        feature,
        distance_squared,
        point,
        on_boundary,
        side,
        height,
    }
}

/// Whether `d = num / den` compares with `r²` (`r` an `f64`, exactly a
/// dyadic fraction): `Less`, `Equal` or `Greater`, exactly.
fn compare_squared(d: &(BigInt, BigInt), r: f64) -> std::cmp::Ordering {
    // r = m · 2^e exactly.
    let (m, e) = {
        let bits = r.to_bits();
        let exponent = ((bits >> 52) & 0x7ff) as i64;
        let mantissa = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
        (BigInt::from(mantissa), exponent - 1075)
    };
    let r2 = &m * &m;
    // d.0 / d.1 vs r2 · 2^(2e)
    let (lhs, rhs) = if e >= 0 {
        (d.0.clone(), (&r2 * &d.1) << (2 * e) as usize)
    } else {
        (&d.0 << (-2 * e) as usize, &r2 * &d.1)
    };
    lhs.cmp(&rhs)
}

#[test]
fn the_contact_set_agrees_with_exact_arithmetic_on_near_ties() {
    let mut rng = ChaCha8Rng::seed_from_u64(4545);
    // Coordinates up to 2^28 units: exact in f64, and their dot products
    // (up to about 2^58) round.
    let offset = 1i64 << 28;
    let mut counts = [0usize; 6]; // cases, on a boundary, members, near the reach, behind, decided exactly
    for _ in 0..4_000 {
        let o = [0; 3].map(|_| rng.random_range(-offset..offset));
        let size = 1i64 << rng.random_range(8..20);
        let mut vertex = || [0, 1, 2].map(|k| o[k] + 2 * rng.random_range(-size..size));
        let v = [vertex(), vertex(), vertex()];
        let d = vertex();
        let as_f64 = |p: [i64; 3]| p.map(|x| x as f64);
        // Two triangles sharing edge 0 (v0 v1), the second reversed.
        let Ok(mesh) = Mesh::new(
            vec![as_f64(v[0]), as_f64(v[1]), as_f64(v[2]), as_f64(d)],
            &[[0, 1, 2], [1, 0, 3]],
        ) else {
            continue;
        };
        let triangles = [v, [v[1], v[0], d]];
        let (a, b, c) = (big(v[0]), big(v[1]), big(v[2]));
        let (ab, ac) = (sub(&b, &a), sub(&c, &a));
        let n = cross(&ab, &ac);
        let small = |rng: &mut ChaCha8Rng| big([0; 3].map(|_| rng.random_range(-3..=3)));
        for _ in 0..8 {
            // A point on a boundary of triangle 0's regions, exactly.
            let on = match rng.random_range(0..3) {
                // Vertex 0's region and edge 0's: (p - a) ⊥ ab.
                0 => {
                    let w = small(&mut rng);
                    let u = cross(&ab, &w);
                    [0, 1, 2].map(|k| &a[k] + &u[k])
                }
                // Edge 0's region and the face's: on the edge (its
                // midpoint, the vertices being even), at a height along n
                // scaled down to about the triangle's size.
                1 => {
                    let scale =
                        BigInt::from(rng.random_range(0..4)) * BigInt::from(size) * BigInt::from(4);
                    let n_len = (dot(&n, &n).sqrt() + 1u32).max(BigInt::from(1));
                    [0, 1, 2].map(|k| (&a[k] + &b[k]) / 2 + &n[k] * &scale / &n_len)
                }
                // Vertex 2's region and edge 1's: (p - c) ⊥ (c - b).
                _ => {
                    let w = small(&mut rng);
                    let u = cross(&sub(&c, &b), &w);
                    [0, 1, 2].map(|k| &c[k] + &u[k])
                }
            };
            let on = on.map(|x| x.to_i64().expect("coordinates fit"));
            // Exactly on it, or one unit beside it.
            let jitter = if rng.random_bool(0.5) {
                [0; 3]
            } else {
                [0; 3].map(|_| rng.random_range(-1..=1))
            };
            let p = [0, 1, 2].map(|k| on[k] + jitter[k]);
            let reference: Vec<Exact> = triangles.iter().map(|t| exact(t, p)).collect();
            // The reach: generous, or the f64 nearest to one triangle's
            // exact distance (a tie with the reach, within rounding).
            let nearest = ratio(
                &reference[0].distance_squared.0,
                &reference[0].distance_squared.1,
            )
            .sqrt();
            let at_reach = rng.random_bool(0.4);
            let radius = if at_reach {
                nearest
            } else {
                nearest * 1.5 + size as f64
            };
            if !(radius.is_finite() && radius > 0.0) {
                continue;
            }
            let sides = if rng.random_bool(0.5) {
                Sides::One
            } else {
                Sides::Two
            };
            let query = ContactQuery {
                centre: Point3::from(p.map(|x| x as f64)),
                radius,
                distance: 0.0,
            };
            let set = contact_set(&mesh, &query, sides);
            counts[0] += 1;
            // The rounding band: a few thousand units of f64's epsilon of
            // the scale, far below the one-unit steps beside a boundary.
            let scale = p
                .iter()
                .chain(v.iter().flatten())
                .map(|x| x.abs())
                .max()
                .unwrap_or(1) as f64;
            let band = 4096.0 * f64::EPSILON * scale;
            for (t, e) in reference.iter().enumerate() {
                let got = set.iter().find(|c| c.triangle as usize == t);
                let distance = ratio(&e.distance_squared.0, &e.distance_squared.1).sqrt();
                let near_reach = (distance - radius).abs() <= band;
                if mesh.triangle_by_index(t as u32).is_none() {
                    continue; // degenerate: not usable
                }
                let near_plane = e.height.abs() <= band;
                let within =
                    compare_squared(&e.distance_squared, radius) != std::cmp::Ordering::Greater;
                let in_front = !e.side.is_negative() || sides == Sides::Two;
                counts[3] += usize::from(near_reach);
                counts[4] += usize::from(!in_front);
                if !(near_reach || (near_plane && sides == Sides::One)) {
                    assert_eq!(
                        got.is_some(),
                        within && in_front,
                        "triangle {t} of {triangles:?} at {p:?}, radius {radius}, {sides:?}: \
                         exact distance {distance}"
                    );
                }
                let Some(got) = got else { continue };
                counts[2] += 1;
                assert!(
                    (got.point - e.point).norm() <= band,
                    "point {} ({:?}) vs exact {} ({:?}, on a boundary: {}) (triangle {t} of \
                     {triangles:?} at {p:?})",
                    got.point,
                    got.feature,
                    e.point,
                    e.feature,
                    e.on_boundary
                );
                assert!(
                    (got.separation - (distance - radius)).abs() <= band,
                    "separation {} vs exact {}",
                    got.separation,
                    distance - radius
                );
                if e.on_boundary {
                    counts[1] += 1;
                } else {
                    counts[5] += 1;
                    assert_eq!(
                        got.feature, e.feature,
                        "feature of triangle {t} of {triangles:?} at {p:?} (off every boundary)"
                    );
                }
            }
        }
    }
    let [cases, on_boundary, members, near_reach, behind, decided] = counts;
    assert!(cases >= 30_000, "{cases} cases");
    assert!(
        on_boundary >= 5_000 && decided >= 5_000 && near_reach >= 3_000 && behind >= 1_000,
        "too few near-ties to trust the test: {members} contacts, {on_boundary} on a region \
         boundary, {decided} beside one, {near_reach} at the reach, {behind} behind"
    );
}
