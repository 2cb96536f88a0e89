//! Unit tests of `sides = two` ([`Sides::Two`]): a triangle met from behind
//! is a hit with the mirrored normal, for every kind of test, and the
//! two-sided answer is the one-sided answer of the mirrored sweep.

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};

use super::explain::describe;
use super::record::CollectRecords;
use super::{
    Broadphase, Facing, Feature, InitialOverlap, Mesh, Options, Outcome, Sides, Sweep, sweep_mesh,
    sweep_mesh_with,
};

/// SEMANTICS.md's triangle `T`: front normal `+z`.
fn triangle_t() -> Mesh {
    Mesh::new(
        vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        &[[0, 1, 2]],
    )
    .expect("valid mesh")
}

fn options(sides: Sides) -> Options {
    Options {
        sides,
        ..Options::default()
    }
}

fn sweep(mesh: &Mesh, p0: [f64; 3], p1: [f64; 3], radius: f64, sides: Sides) -> Outcome {
    sweep_mesh(mesh, &Sweep::new(p0, p1, radius), &options(sides)).expect("valid sweep")
}

/// `p` mirrored through the plane `z = 0` (exact in binary).
fn mirror_z(p: [f64; 3]) -> [f64; 3] {
    [p[0], p[1], -p[2]]
}

/// The worked examples 1 to 3 of SEMANTICS.md (face, edge 0, vertex 0),
/// each coming from behind `T` (mirrored through its plane): no
/// collision under one side; under two, the front's `α`, feature and
/// contact, with the normal `-z`.
#[test]
fn worked_examples_from_behind_hit_only_under_two_sides() {
    let mesh = triangle_t();
    let examples = [
        ([1.0, 1.0, 3.0], [1.0, 1.0, -3.0], Feature::Face),
        ([2.0, -0.3, 3.0], [2.0, -0.3, -3.0], Feature::Edge(0)),
        ([-0.3, -0.2, 3.0], [-0.3, -0.2, -3.0], Feature::Vertex(0)),
    ];
    for (p0, p1, feature) in examples {
        let front = sweep(&mesh, p0, p1, 0.5, Sides::One)
            .hit
            .expect("a hit from the front");
        assert_eq!(front.feature, feature);
        // Two sides change nothing from the front.
        assert_eq!(sweep(&mesh, p0, p1, 0.5, Sides::Two).hit, Some(front));

        let (b0, b1) = (mirror_z(p0), mirror_z(p1));
        assert_eq!(
            sweep(&mesh, b0, b1, 0.5, Sides::One).hit,
            None,
            "{feature:?} from behind under one side"
        );
        let back = sweep(&mesh, b0, b1, 0.5, Sides::Two)
            .hit
            .expect("a hit from behind under two sides");
        assert_eq!(back.feature, feature);
        assert_eq!(back.alpha, front.alpha, "{feature:?}");
        assert_eq!(back.normal, Vector3::new(0.0, 0.0, -1.0), "{feature:?}");
        let c = front.contact;
        assert_eq!(back.contact, Point3::new(c.x, c.y, -c.z), "{feature:?}");
    }
    // Worked example 1's α: 5/12.
    let face = sweep(&mesh, [1.0, 1.0, -3.0], [1.0, 1.0, 3.0], 0.5, Sides::Two);
    assert_eq!(face.hit.map(|h| h.alpha), Some(2.5 / 6.0));
}

/// Seeded random sweeps against a random triangle: under two sides, a
/// sweep moving toward the back gives the one-sided answer of the sweep
/// mirrored through the triangle's plane (its normal and contact mirrored
/// back); any other sweep the one-sided answer itself. The mirror is an
/// independent way to the same answer: it moves the inputs, not the tests.
#[test]
fn two_sided_alpha_is_the_front_alpha_of_the_mirrored_sweep() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5143);
    let mut compared = [0usize; 3];
    let mut from_behind = 0;
    for _ in 0..400 {
        let mut point = |scale: f64| {
            [
                rng.random_range(-scale..scale),
                rng.random_range(-scale..scale),
                rng.random_range(-scale..scale),
            ]
        };
        let (a, b, c) = (point(2.0), point(2.0), point(2.0));
        let Ok(mesh) = Mesh::new(vec![a, b, c], &[[0, 1, 2]]) else {
            continue;
        };
        let t = mesh.triangles()[0];
        let n = t.normal;
        let origin = t.vertices[0];
        let mirror = |p: [f64; 3]| {
            let p = Point3::from(p);
            let m = p - n * (2.0 * n.dot(&(p - origin)));
            [m.x, m.y, m.z]
        };
        let (p0, p1) = (point(4.0), point(4.0));
        let radius = rng.random_range(0.1..1.5);
        let two = sweep(&mesh, p0, p1, radius, Sides::Two);
        let back = n.dot(&(Point3::from(p1) - Point3::from(p0))) > 0.0;
        let reference = if back {
            sweep(&mesh, mirror(p0), mirror(p1), radius, Sides::One)
        } else {
            sweep(&mesh, p0, p1, radius, Sides::One)
        };
        if !two.fragile.is_robust() || !reference.fragile.is_robust() {
            continue;
        }
        match (two.hit, reference.hit) {
            (None, None) => {}
            (Some(h), Some(r)) => {
                assert_eq!(h.feature, r.feature, "{p0:?} -> {p1:?}");
                assert!((h.alpha - r.alpha).abs() < 1e-9, "{h:?} {r:?}");
                let normal = if back { -r.normal } else { r.normal };
                assert!((h.normal - normal).norm() < 1e-9, "{h:?} {r:?}");
                let c = r.contact;
                let contact = if back {
                    mirror([c.x, c.y, c.z])
                } else {
                    [c.x, c.y, c.z]
                };
                assert!((h.contact - Point3::from(contact)).norm() < 1e-9);
                compared[h.feature.kind() as usize] += 1;
                from_behind += usize::from(back);
            }
            (h, r) => panic!("{p0:?} -> {p1:?} r {radius}: two sides {h:?}, mirrored {r:?}"),
        }
    }
    // The seed reaches every kind of hit, many of them from behind.
    assert!(compared.iter().all(|&k| k > 0), "{compared:?}");
    assert!(from_behind > 10, "{from_behind} hits from behind");
}

/// A unit cube's 12 outward triangles.
fn cube() -> Mesh {
    let v = |i: u32| {
        [
            f64::from(i & 1) * 2.0 - 1.0,
            f64::from((i >> 1) & 1) * 2.0 - 1.0,
            f64::from((i >> 2) & 1) * 2.0 - 1.0,
        ]
    };
    let faces = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let triangles: Vec<[u64; 3]> = faces
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Mesh::new((0..8).map(v).collect(), &triangles).expect("valid cube")
}

/// A ball inside a closed box meets only back faces: one side lets it
/// out, two sides stop it at the wall with the wall's normal turned
/// inward; the BVH finds what testing every triangle finds, and the fast
/// query skips no back face under two sides.
#[test]
fn a_ball_inside_a_box_hits_the_wall_only_under_two_sides() {
    let mesh = cube();
    let (p0, p1) = ([0.0, 0.25, 0.125], [2.0, 0.25, 0.125]);
    assert_eq!(sweep(&mesh, p0, p1, 0.5, Sides::One).hit, None);
    let two = sweep(&mesh, p0, p1, 0.5, Sides::Two);
    let hit = two.hit.expect("the +x wall from inside");
    assert_eq!((hit.alpha, hit.feature), (0.25, Feature::Face));
    assert_eq!(hit.normal, Vector3::new(-1.0, 0.0, 0.0));
    let s = Sweep::new(p0, p1, 0.5);
    let mut records = CollectRecords::default();
    let exhaustive = sweep_mesh_with(
        &mesh,
        &s,
        &options(Sides::Two),
        Broadphase::Exhaustive,
        &mut records,
    )
    .expect("valid sweep");
    assert_eq!(exhaustive.hit, two.hit);
    let hit_record = records
        .records
        .iter()
        .find(|r| r.alpha().is_some())
        .expect("the wall's face record");
    assert!(hit_record.back());
    assert!(
        describe(hit_record).contains("(back side)"),
        "{}",
        describe(hit_record)
    );
}

/// The facing rule under two sides sees `-|n · d|`: `non_strict` lets
/// every path through, `strict` only rejects the one parallel to the
/// plane (conform's `facing.strict` case: in the plane, toward edge 0).
#[test]
fn strict_facing_under_two_sides_rejects_only_parallel_paths() {
    let mesh = triangle_t();
    let in_plane = Sweep::new([2.0, -3.0, 0.0], [2.0, 3.0, 0.0], 0.5);
    for (facing, hits) in [(Facing::NonStrict, true), (Facing::Strict, false)] {
        for sides in [Sides::One, Sides::Two] {
            let o = Options {
                facing,
                sides,
                ..Options::default()
            };
            let outcome = sweep_mesh(&mesh, &in_plane, &o).expect("valid sweep");
            assert_eq!(outcome.hit.is_some(), hits, "{facing} {sides}");
        }
    }
    let from_behind = Sweep::new([1.0, 1.0, -3.0], [1.0, 1.0, 3.0], 0.5);
    let strict_two = Options {
        facing: Facing::Strict,
        sides: Sides::Two,
        ..Options::default()
    };
    let outcome = sweep_mesh(&mesh, &from_behind, &strict_two).expect("valid sweep");
    assert_eq!(outcome.hit.map(|h| h.feature), Some(Feature::Face));
}

/// Under `initial_overlap = alpha0`, a ball that starts within ρ behind a
/// triangle and moves toward it: an initial contact only under two sides,
/// with the normal facing it.
#[test]
fn an_initial_contact_from_behind_counts_only_under_two_sides() {
    let mesh = triangle_t();
    let s = Sweep::new([1.0, 1.0, -0.25], [1.0, 1.0, 1.0], 0.5);
    let alpha0 = |sides| Options {
        initial_overlap: InitialOverlap::Alpha0,
        sides,
        ..Options::default()
    };
    let one = sweep_mesh(&mesh, &s, &alpha0(Sides::One)).expect("valid sweep");
    assert_eq!(one.hit, None);
    let two = sweep_mesh(&mesh, &s, &alpha0(Sides::Two)).expect("valid sweep");
    let hit = two.hit.expect("an initial contact");
    assert_eq!((hit.alpha, hit.feature), (0.0, Feature::Face));
    assert_eq!(hit.normal, Vector3::new(0.0, 0.0, -1.0));
}

#[test]
fn sides_parse_from_their_names_and_refuse_others() {
    assert_eq!("one".parse::<Sides>(), Ok(Sides::One));
    assert_eq!("two".parse::<Sides>(), Ok(Sides::Two));
    assert!("both".parse::<Sides>().is_err());
    assert_eq!(Sides::default(), Sides::One);
    assert!(Sides::One.is_rules() && !Sides::Two.is_rules());
    // The default is not written, so options under the rules serialise as
    // they always did.
    let json = serde_json::to_string(&Options::default()).expect("serialises");
    assert!(!json.contains("sides"), "{json}");
}
