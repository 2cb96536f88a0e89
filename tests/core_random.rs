//! Seeded random comparisons of the core: against the independent oracle
//! (no quadratics), against parry3d-f64, and of the BVH broadphase against
//! testing every triangle.

use libtest_mimic::Trial;
use nalgebra::{Point3, Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sweeptrace::core::record::{
    CollectRecords, EdgeRecord, FaceRecord, NoObserver, Observer, Skip, SkipCounts, TestRecord,
    VerdictCounts, VertexRecord,
};
use sweeptrace::core::{
    Broadphase, Facing, Kind, Mesh, Options, Outcome, Sides, Sweep, sweep_mesh, sweep_mesh_with,
};
use sweeptrace::replay::{CollectPrimary, primary_records};

use crate::oracle::{OTri, OracleResult, oracle};
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(oracle_agreement_100k_sweeps),
        trial!(parry_agreement_front_facing),
        trial!(bvh_equals_exhaustive),
        trial!(primary_collector_equals_collecting_every_record),
    ]
}

/// Agreement on α within this absolute tolerance.
const ALPHA_TOLERANCE: f64 = 1e-7;
/// Agreement with parry on α within this tolerance.
const PARRY_TOLERANCE: f64 = 1e-5;

struct Case {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u64; 3]>,
    p0: [f64; 3],
    p1: [f64; 3],
    radius: f64,
    margin: f64,
    facing: Facing,
}

pub(crate) fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    rng.random_range(lo..hi)
}

pub(crate) fn random_point(rng: &mut ChaCha8Rng, s: f64) -> [f64; 3] {
    [
        uniform(rng, -s, s),
        uniform(rng, -s, s),
        uniform(rng, -s, s),
    ]
}

pub(crate) fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::from(random_point(rng, 1.0));
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A random well-shaped triangle (area and angles bounded away from 0).
pub(crate) fn random_triangle(rng: &mut ChaCha8Rng) -> [[f64; 3]; 3] {
    loop {
        let t = [
            random_point(rng, 2.0),
            random_point(rng, 2.0),
            random_point(rng, 2.0),
        ];
        let [a, b, c] = t.map(Point3::from);
        let area2 = (b - a).cross(&(c - a)).norm();
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        if area2 > 0.3 * longest * longest * 0.5 && area2 > 0.5 {
            return t;
        }
    }
}

/// A 3×3 grid of vertices (8 triangles) with random heights, rotated.
pub(crate) fn random_patch(rng: &mut ChaCha8Rng) -> (Vec<[f64; 3]>, Vec<[u64; 3]>) {
    let rot = Rotation3::from_scaled_axis(unit(rng) * uniform(rng, 0.0, std::f64::consts::PI));
    let offset = Vector3::from(random_point(rng, 0.5));
    let mut vertices = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            let p = Vector3::new(i as f64 - 1.0, j as f64 - 1.0, uniform(rng, -0.4, 0.4)) * 1.3;
            vertices.push((rot * p + offset).into());
        }
    }
    let flip = rng.random_bool(0.3);
    let mut triangles = Vec::new();
    for j in 0..2u64 {
        for i in 0..2u64 {
            let a = j * 3 + i;
            let (b, c, d) = (a + 1, a + 4, a + 3);
            let (t1, t2) = if rng.random_bool(0.5) {
                ([a, b, c], [a, c, d])
            } else {
                ([a, b, d], [b, c, d])
            };
            for mut t in [t1, t2] {
                if flip {
                    t.swap(1, 2);
                }
                triangles.push(t);
            }
        }
    }
    (vertices, triangles)
}

/// A sweep aimed near a random point of a random triangle, so that about
/// half of the sweeps hit.
pub(crate) fn random_sweep(
    rng: &mut ChaCha8Rng,
    vertices: &[[f64; 3]],
    triangles: &[[u64; 3]],
) -> ([f64; 3], [f64; 3], f64, f64, Facing) {
    let t = triangles[rng.random_range(0..triangles.len())];
    let [a, b, c] = t.map(|i| Vector3::from(vertices[i as usize]));
    let (mut u, mut v) = (uniform(rng, 0.0, 1.0), uniform(rng, 0.0, 1.0));
    if u + v > 1.0 {
        u = 1.0 - u;
        v = 1.0 - v;
    }
    let radius = uniform(rng, 0.05, 0.8);
    let target = a + (b - a) * u + (c - a) * v + unit(rng) * uniform(rng, 0.0, 2.0 * radius);
    let p0 = target + unit(rng) * uniform(rng, 1.0, 4.0);
    let p1 = p0 + (target - p0) * uniform(rng, 0.3, 1.6);
    let margin = if rng.random_bool(0.5) {
        0.0
    } else {
        uniform(rng, 0.0, 0.5 * radius)
    };
    let facing = if rng.random_bool(0.8) {
        Facing::NonStrict
    } else {
        Facing::Strict
    };
    (p0.into(), p1.into(), radius, margin, facing)
}

fn random_case(rng: &mut ChaCha8Rng) -> Case {
    let (vertices, triangles) = if rng.random_bool(0.6) {
        (random_triangle(rng).to_vec(), vec![[0, 1, 2]])
    } else {
        random_patch(rng)
    };
    let (p0, p1, radius, margin, facing) = random_sweep(rng, &vertices, &triangles);
    Case {
        vertices,
        triangles,
        p0,
        p1,
        radius,
        margin,
        facing,
    }
}

fn oracle_triangles(case: &Case) -> Vec<OTri> {
    case.triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let [a, b, c] = t.map(|k| case.vertices[k as usize]);
            OTri::new(i as u32, a, b, c)
        })
        .collect()
}

fn run_core(case: &Case) -> anyhow::Result<(Mesh, Outcome)> {
    let mesh = Mesh::new(case.vertices.clone(), &case.triangles)?;
    let options = Options {
        margin: case.margin,
        facing: case.facing,
        ..Options::default()
    };
    let o = sweep_mesh(&mesh, &Sweep::new(case.p0, case.p1, case.radius), &options)?;
    Ok((mesh, o))
}

fn describe(case: &Case, o: &Outcome) -> String {
    format!(
        "p0 {:?} p1 {:?} r {} margin {} facing {} triangles {:?} vertices {:?}: core {:?}",
        case.p0, case.p1, case.radius, case.margin, case.facing, case.triangles, case.vertices, o
    )
}

fn oracle_agreement_100k_sweeps() -> anyhow::Result<()> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0001);
    const N: usize = 100_000;
    let mut excluded: std::collections::BTreeMap<&str, usize> = Default::default();
    let (mut hits, mut misses, mut kind_compared, mut unique_primary) = (0, 0, 0, 0);
    let mut failures = Vec::new();
    for _ in 0..N {
        let case = random_case(&mut rng);
        let (_, o) = run_core(&case)?;
        let rho = case.radius - case.margin;
        match oracle(&oracle_triangles(&case), case.p0, case.p1, rho, case.facing) {
            OracleResult::Excluded(why) => *excluded.entry(why).or_default() += 1,
            OracleResult::Miss => {
                misses += 1;
                if o.is_hit() {
                    failures.push(format!("oracle: miss; {}", describe(&case, &o)));
                }
            }
            OracleResult::Hit {
                alpha,
                touching,
                kind,
            } => {
                hits += 1;
                let tri_ok = o
                    .hit
                    .map(|h| h.triangle)
                    .is_some_and(|t| touching.contains(&t));
                let alpha_ok = o.is_hit() && (o.travelled() - alpha).abs() <= ALPHA_TOLERANCE;
                let kind_ok = kind.is_none_or(|k| k == o.kind());
                if kind.is_some() {
                    kind_compared += 1;
                }
                if touching.len() == 1 {
                    unique_primary += 1;
                }
                if !(tri_ok && alpha_ok && kind_ok) {
                    failures.push(format!(
                        "oracle: alpha {alpha} touching {touching:?} kind {kind:?}; {}",
                        describe(&case, &o)
                    ));
                }
            }
        }
    }
    let total_excluded: usize = excluded.values().sum();
    println!(
        "    {N} sweeps: {hits} hits and {misses} misses compared, {total_excluded} excluded as ill-conditioned {excluded:?}; \
         kind compared on {kind_compared}, primary triangle unique on {unique_primary}; {} disagreements",
        failures.len()
    );
    crate::ensure!(
        hits > N / 4 && misses > N / 10,
        "the generator hits too rarely: {hits} hits, {misses} misses"
    );
    crate::ensure!(
        total_excluded < N / 20,
        "too many exclusions: {total_excluded}"
    );
    if !failures.is_empty() {
        anyhow::bail!(
            "{} disagreements, first:\n{}",
            failures.len(),
            failures[..failures.len().min(5)].join("\n")
        );
    }
    Ok(())
}

fn parry_agreement_front_facing() -> anyhow::Result<()> {
    use parry3d_f64::math::{Pose, Vector};
    use parry3d_f64::query::{ShapeCastOptions, cast_shapes};
    use parry3d_f64::shape::{Ball, Triangle};
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0002);
    let (mut compared, mut skipped, mut hits) = (0usize, 0usize, 0usize);
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    while compared < 12_000 {
        let t = random_triangle(&mut rng);
        let vertices = t.to_vec();
        let triangles = vec![[0, 1, 2]];
        let (p0, p1, radius, margin, facing) = random_sweep(&mut rng, &vertices, &triangles);
        let case = Case {
            vertices,
            triangles,
            p0,
            p1,
            radius,
            margin,
            facing,
        };
        let tri = OTri::new(0, t[0], t[1], t[2]);
        let d = Point3::from(p1) - Point3::from(p0);
        let front = match facing {
            Facing::NonStrict => tri.n.dot(&d) <= 0.0,
            Facing::Strict => tri.n.dot(&d) < 0.0,
        };
        if !front {
            continue;
        }
        let rho = radius - margin;
        // The same ill-conditioned cases as the oracle comparison are left out.
        if matches!(
            oracle(std::slice::from_ref(&tri), p0, p1, rho, facing),
            OracleResult::Excluded(_)
        ) {
            skipped += 1;
            continue;
        }
        let v = |p: [f64; 3]| Vector::new(p[0], p[1], p[2]);
        let ball = Ball::new(rho);
        let shape = Triangle::new(v(t[0]), v(t[1]), v(t[2]));
        let hit = cast_shapes(
            &Pose::from_translation(v(p0)),
            v(p1) - v(p0),
            &ball,
            &Pose::IDENTITY,
            Vector::ZERO,
            &shape,
            ShapeCastOptions::with_max_time_of_impact(1.0),
        )
        .map_err(|_| anyhow::anyhow!("parry: unsupported shapes"))?;
        if hit.is_some_and(|h| h.time_of_impact <= 0.0) {
            skipped += 1; // starts penetrating
            continue;
        }
        let (_, o) = run_core(&case)?;
        compared += 1;
        match hit {
            Some(h) => {
                hits += 1;
                let diff = (h.time_of_impact - o.travelled()).abs();
                if !o.is_hit() || diff > PARRY_TOLERANCE {
                    failures.push(format!(
                        "parry toi {}; {}",
                        h.time_of_impact,
                        describe(&case, &o)
                    ));
                } else {
                    worst = worst.max(diff);
                }
            }
            None => {
                if o.is_hit() {
                    failures.push(format!("parry: miss; {}", describe(&case, &o)));
                }
            }
        }
    }
    println!(
        "    {compared} front-facing sweeps compared with parry ({hits} hits), {skipped} skipped (penetrating at start or ill-conditioned); \
         largest alpha difference {worst:.2e}; {} disagreements",
        failures.len()
    );
    if !failures.is_empty() {
        anyhow::bail!(
            "{} disagreements, first:\n{}",
            failures.len(),
            failures[..failures.len().min(5)].join("\n")
        );
    }
    // An agreement over misses only would say nothing about the hits:
    // most sweeps are compared, and a good share of them hit.
    crate::ensure!(
        compared * 2 > compared + skipped && hits * 5 > compared,
        "too little compared to mean anything: {compared} compared ({hits} hits), {skipped} skipped"
    );
    Ok(())
}

/// The mesh of `vertices` and `triangles`, and its usable (non-degenerate)
/// triangles by vertex indices.
fn mesh_and_usable(
    vertices: &[[f64; 3]],
    triangles: &[[u64; 3]],
) -> anyhow::Result<(Mesh, Vec<[u64; 3]>)> {
    let mesh = Mesh::new(vertices.to_vec(), triangles)?;
    let usable = mesh
        .triangles()
        .iter()
        .map(|t| t.vertex_indices.map(u64::from))
        .collect();
    Ok((mesh, usable))
}

/// Mesh `m` of the random comparisons: a bumpy height field for even `m`,
/// a random triangle soup for odd.
fn random_mesh(rng: &mut ChaCha8Rng, m: usize) -> (Vec<[f64; 3]>, Vec<[u64; 3]>) {
    if m.is_multiple_of(2) {
        let n = 24 + m * 2;
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
                v.push([
                    x,
                    y,
                    0.3 * (x * 1.3).sin() * (y * 0.7).cos() + uniform(rng, -0.05, 0.05),
                ]);
            }
        }
        let mut t = Vec::new();
        let w = (n + 1) as u64;
        for j in 0..n as u64 {
            for i in 0..n as u64 {
                let a = j * w + i;
                t.push([a, a + 1, a + w + 1]);
                t.push([a, a + w + 1, a + w]);
            }
        }
        (v, t)
    } else {
        let mut v = Vec::new();
        let mut t = Vec::new();
        for k in 0..600u64 {
            let c = random_point(rng, 5.0);
            for _ in 0..3 {
                let o = random_point(rng, 0.6);
                v.push([c[0] + o[0], c[1] + o[1], c[2] + o[2]]);
            }
            t.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        (v, t)
    }
}

/// Every record, and the triangles skipped with their reasons, of a sweep
/// that skips what the fast query skips.
#[derive(Default)]
struct SkippingRecords {
    records: Vec<TestRecord>,
    skipped: Vec<(u32, Skip)>,
}

impl Observer for SkippingRecords {
    const TESTS_EVERY_CANDIDATE: bool = false;
    fn face(&mut self, r: &FaceRecord) {
        self.records.push(TestRecord::Face(*r));
    }
    fn edge(&mut self, r: &EdgeRecord) {
        self.records.push(TestRecord::Edge(*r));
    }
    fn vertex(&mut self, r: &VertexRecord) {
        self.records.push(TestRecord::Vertex(*r));
    }
    fn skipped(&mut self, triangle: u32, reason: Skip) {
        self.skipped.push((triangle, reason));
    }
}

/// At `--detail primary` the core skips, untested, the candidates the fast
/// query skips, counting them by reason, and the replay keeps only the hits
/// and the nearest miss of the tested ones while the tests run
/// (`CollectPrimary`). Against collecting every record of every candidate
/// (`CollectRecords`): the same outcome; the skipped triangles are exactly
/// the candidates not tested, none of their tests hits, a back-facing one
/// moves away from its front (`n · d > 0`) and an out-of-reach one has the
/// whole path farther than ρ on one side of its plane; the verdicts counted
/// are those of the tested candidates' records, the skips those listed; and
/// the records kept are what `primary_records` chooses among the tested.
/// Under `sides = two` too (where the skip tests read the plane as the
/// mirrored triangle's): the fast query's outcome is that of collecting
/// every record.
fn primary_collector_equals_collecting_every_record() -> anyhow::Result<()> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0004);
    let (mut checked, mut hits, mut ties) = (0, 0, 0);
    let mut skips = SkipCounts::default();
    for m in 0..6 {
        let (vertices, triangles) = random_mesh(&mut rng, m);
        let (mesh, usable) = mesh_and_usable(&vertices, &triangles)?;
        for _ in 0..800 {
            let (p0, p1, radius, margin, facing) = random_sweep(&mut rng, &vertices, &usable);
            let sweep = Sweep::new(p0, p1, radius);
            let options = Options {
                margin,
                facing,
                ..Options::default()
            };
            for broadphase in [Broadphase::Bvh, Broadphase::Exhaustive] {
                let at = || format!("{p0:?} -> {p1:?} ({broadphase:?})");
                if broadphase == Broadphase::Bvh {
                    let two = Options {
                        sides: Sides::Two,
                        ..options
                    };
                    let mut every_two = CollectRecords::default();
                    let all_two = sweep_mesh_with(&mesh, &sweep, &two, broadphase, &mut every_two)?;
                    if format!("{:?}", sweep_mesh(&mesh, &sweep, &two)?) != format!("{all_two:?}") {
                        anyhow::bail!("{}: sides = two, the fast query's outcome differs", at());
                    }
                }
                let mut every = CollectRecords::default();
                let outcome = sweep_mesh_with(&mesh, &sweep, &options, broadphase, &mut every)?;
                let mut skipping = SkippingRecords::default();
                let again = sweep_mesh_with(&mesh, &sweep, &options, broadphase, &mut skipping)?;
                let mut primary = CollectPrimary::default();
                let third = sweep_mesh_with(&mesh, &sweep, &options, broadphase, &mut primary)?;
                if format!("{outcome:?}") != format!("{again:?}")
                    || format!("{outcome:?}") != format!("{third:?}")
                {
                    anyhow::bail!("{}: outcomes differ", at());
                }
                let skipped: std::collections::HashMap<u32, Skip> =
                    skipping.skipped.iter().copied().collect();
                if skipped.len() != skipping.skipped.len() {
                    anyhow::bail!("{}: a triangle skipped twice", at());
                }
                let tested: Vec<TestRecord> = every
                    .records
                    .iter()
                    .filter(|r| !skipped.contains_key(&r.triangle()))
                    .copied()
                    .collect();
                if tested != skipping.records {
                    anyhow::bail!("{}: the tested records are not the others", at());
                }
                // Every record of each skipped triangle, gathered in one
                // pass (a search of all records per skipped triangle made
                // this test two thirds of its own time).
                let mut of_skipped: std::collections::HashMap<u32, Vec<&TestRecord>> =
                    std::collections::HashMap::new();
                for r in &every.records {
                    if skipped.contains_key(&r.triangle()) {
                        of_skipped.entry(r.triangle()).or_default().push(r);
                    }
                }
                for (&t, &reason) in &skipped {
                    let of_t = of_skipped.get(&t).map_or(&[][..], Vec::as_slice);
                    let face = of_t.iter().find_map(|r| match r {
                        TestRecord::Face(f) => Some(*f),
                        _ => None,
                    });
                    let Some(face) = face.filter(|_| of_t.len() == 7) else {
                        anyhow::bail!("{}: skipped triangle {t} is not a candidate", at());
                    };
                    let rho = sweep.radius - margin;
                    let fits = match reason {
                        Skip::BackFacing => face.normal_dot_d > 0.0,
                        Skip::PlaneOutOfReach => {
                            (face.h0 > rho && face.h1 > rho) || (face.h0 < -rho && face.h1 < -rho)
                        }
                    };
                    if !fits || of_t.iter().any(|r| r.alpha().is_some()) {
                        anyhow::bail!("{}: triangle {t} skipped as {reason}: {face:?}", at());
                    }
                    skips.add(reason);
                }
                let counts: VerdictCounts = tested.iter().map(|r| r.verdict()).collect();
                if primary.verdict_counts() != counts {
                    anyhow::bail!(
                        "{}: verdict counts {:?}, expected {counts:?}",
                        at(),
                        primary.verdict_counts()
                    );
                }
                let listed = SkipCounts::from_reasons(skipping.skipped.iter().map(|(_, r)| *r));
                if primary.skip_counts() != listed {
                    anyhow::bail!("{}: skip counts differ", at());
                }
                let want = primary_records(&outcome, tested);
                let got = primary.into_primary_records(&outcome);
                if got != want {
                    anyhow::bail!("{}: records {got:?}, expected {want:?}", at());
                }
                checked += 1;
                hits += usize::from(outcome.is_hit());
                ties += usize::from(want.len() > 1);
            }
        }
    }
    // The comparison covers hits, misses, ties and both reasons to skip.
    if hits < checked / 10 || hits > checked * 9 / 10 || ties == 0 {
        anyhow::bail!("{checked} sweeps: {hits} hits, {ties} with ties: not a useful mix");
    }
    if Skip::ALL.iter().any(|&r| skips.get(r) == 0) {
        anyhow::bail!("{checked} sweeps: skipped {skips:?}: not a useful mix");
    }
    Ok(())
}

fn bvh_equals_exhaustive() -> anyhow::Result<()> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0003);
    let mut checked = 0;
    let mut hits = 0;
    for m in 0..12 {
        let (vertices, triangles) = random_mesh(&mut rng, m);
        let (mesh, usable) = mesh_and_usable(&vertices, &triangles)?;
        for _ in 0..2_000 {
            let (p0, p1, radius, margin, facing) = random_sweep(&mut rng, &vertices, &usable);
            let sweep = Sweep::new(p0, p1, radius);
            let options = Options {
                margin,
                facing,
                ..Options::default()
            };
            let fast = sweep_mesh(&mesh, &sweep, &options)?;
            let all = sweep_mesh_with(
                &mesh,
                &sweep,
                &options,
                Broadphase::Exhaustive,
                &mut NoObserver,
            )?;
            checked += 1;
            if fast.kind() != Kind::None {
                hits += 1;
            }
            if fast != all {
                anyhow::bail!(
                    "mesh {m}: p0 {p0:?} p1 {p1:?} r {radius} margin {margin}: bvh {fast:?} != exhaustive {all:?}"
                );
            }
        }
    }
    println!(
        "    {checked} sweeps on 12 meshes of 1,152 to 1,800 triangles: BVH identical to exhaustive ({hits} hits)"
    );
    crate::ensure!(
        hits > checked / 5,
        "too few hits ({hits}) to exercise the BVH"
    );
    Ok(())
}
