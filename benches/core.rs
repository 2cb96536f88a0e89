//! Core throughput against parry3d-f64, on the same meshes and sweeps.
//!
//! Run: `cargo bench --no-default-features --bench core`
//!
//! Besides parry, two explained queries on the same sweeps: what
//! `replay --detail primary` runs (`CollectPrimary`: the records it keeps,
//! the verdicts counted) and the same with every test's record collected
//! (`CollectRecords`, what `--detail candidates` keeps, and what primary did
//! before `CollectPrimary`); their ratio to `sweeptrace` is the cost of
//! explaining.
//!
//! Meshes are height fields of about 10^3, 10^5 and 10^6 triangles built
//! from a seed; 4,096 sweeps per mesh (a ball of radius 0.25 falling from
//! above the terrain, with sideways motion) are cycled so that no single
//! branch-predicted case is what gets measured. Before timing, the bench
//! prints how often the two libraries agree on hit or miss and the largest
//! difference in α where both hit.
//!
//! The group `topology` measures, on the height field of 1,002,528
//! triangles, the build of its `Topology` (weld, edges by class, defects)
//! against the BVH build alone (`Mesh::build_bvh_again`) and the whole
//! `Mesh::new` (validation, normals, standard frames and the BVH); before
//! timing it prints the topology's bytes per triangle (the capacities of
//! its vectors).
//!
//! The group `session` measures the fast and the explained query and parry
//! on the sweeps of a real session's shape instead: 4,096 sweeps taken
//! evenly from the simulation `record --scene terrain --terrain-cells {224,
//! 708} --balls 64 --seed 1 --frames 1954` writes (100,352 and 1,002,528
//! triangles; balls falling, bouncing and rolling on the terrain), in trace
//! order, with the same agreement check.

use std::hash::{Hash, Hasher};
use std::hint::black_box;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, Throughput, criterion_group};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sweeptrace::core::record::{CollectRecords, CountVisits, Observer, Skip};
use sweeptrace::core::topology::Topology;
use sweeptrace::core::{
    Broadphase, ContactQuery, Mesh, Options, Outcome, Sides, Sweep, contact_set, sweep_mesh,
    sweep_mesh_with,
};
use sweeptrace::replay::{CollectPrimary, primary_records};
use sweeptrace::sim::{self, scenes::BuiltinScene};

#[path = "parry_cast.rs"]
mod parry_cast;

use parry3d_f64::shape::TriMesh;

const RADIUS: f64 = 0.25;
const SWEEPS: usize = 4096;

fn height(x: f64, y: f64) -> f64 {
    1.5 * (0.31 * x).sin() * (0.23 * y).cos() + 0.4 * (1.7 * x + 0.5 * y).sin()
}

/// A height field of `2 n²` triangles, spacing 1, fronts facing +z.
fn terrain(n: usize) -> (Vec<[f64; 3]>, Vec<[u64; 3]>) {
    let w = n + 1;
    let mut vertices = Vec::with_capacity(w * w);
    for j in 0..w {
        for i in 0..w {
            let (x, y) = (i as f64, j as f64);
            vertices.push([x, y, height(x, y)]);
        }
    }
    let mut triangles = Vec::with_capacity(2 * n * n);
    for j in 0..n as u64 {
        for i in 0..n as u64 {
            let a = j * w as u64 + i;
            let w = w as u64;
            triangles.push([a, a + 1, a + w + 1]);
            triangles.push([a, a + w + 1, a + w]);
        }
    }
    (vertices, triangles)
}

fn sweeps(n: usize, seed: u64) -> Vec<Sweep> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let extent = n as f64;
    (0..SWEEPS)
        .map(|_| {
            let x = rng.random_range(2.0..extent - 2.0);
            let y = rng.random_range(2.0..extent - 2.0);
            let p0 = [x, y, 2.5 + rng.random_range(0.0..2.0)];
            let p1 = [
                x + rng.random_range(-1.5..1.5),
                y + rng.random_range(-1.5..1.5),
                p0[2] - rng.random_range(0.5..5.0),
            ];
            Sweep::new(p0, p1, RADIUS)
        })
        .collect()
}

struct Setup {
    n: usize,
    triangles: usize,
    ours: Mesh,
    parry: TriMesh,
    sweeps: Vec<Sweep>,
}

fn setup(n: usize) -> Setup {
    let (vertices, triangles) = terrain(n);
    let parry = parry_cast::parry_mesh(&vertices, &triangles).expect("valid terrain for parry");
    let ours = Mesh::new(vertices, &triangles).expect("valid terrain");
    Setup {
        n,
        triangles: triangles.len(),
        ours,
        parry,
        sweeps: sweeps(n, 7 + n as u64),
    }
}

fn parry_cast(mesh: &TriMesh, s: &Sweep) -> Option<f64> {
    parry_cast::parry_cast(mesh, s.p0.into(), s.p1.into(), s.radius)
}

/// Prints how often sweeptrace and parry agree on hit or miss over the
/// setup's sweeps, the largest difference in α where both hit, and a digest
/// of every outcome of sweeptrace (its `Debug` text, which writes every
/// number exactly) to compare two builds' outcomes bit for bit. Panics if no
/// sweep hits, which would make the bench measure misses only.
fn agreement(label: &str, s: &Setup) {
    let options = Options::default();
    let (mut both, mut neither, mut only_ours, mut only_parry) = (0, 0, 0, 0);
    let mut worst = 0.0f64;
    let mut digest = std::hash::DefaultHasher::new();
    for sw in &s.sweeps {
        let ours = sweep_mesh(&s.ours, sw, &options).expect("valid sweep");
        format!("{ours:?}").hash(&mut digest);
        match (ours.is_hit(), parry_cast(&s.parry, sw)) {
            (true, Some(t)) => {
                both += 1;
                worst = worst.max((t - ours.travelled()).abs());
            }
            (false, None) => neither += 1,
            (true, None) => only_ours += 1,
            (false, Some(_)) => only_parry += 1,
        }
    }
    println!(
        "agreement, {label} on {} triangles: {both} both hit, {neither} both miss, {only_ours} only sweeptrace, {only_parry} only parry; largest alpha difference {worst:.2e}; outcome digest {:016x}",
        s.triangles,
        digest.finish()
    );
    assert!(both > 0, "no sweep of {label} hits the mesh");
    visits(label, s, &options);
}

/// Prints the per-node figures of the fast query over the setup's sweeps
/// (deterministic counts, no timing): the means per sweep of the tree's
/// nodes opened, child boxes tested, leaves and candidate triangles handed
/// over, candidates tested and skipped; and the bytes of a node, of a
/// triangle's record and of the whole tree. The counting observer runs
/// what the fast query runs (checked: same outcome for every sweep).
fn visits(label: &str, s: &Setup, options: &Options) {
    let mut count = CountVisits::default();
    for sw in &s.sweeps {
        let counted = sweep_mesh_with(&s.ours, sw, options, Broadphase::Bvh, &mut count);
        let fast = sweep_mesh(&s.ours, sw, options);
        assert_eq!(
            format!("{counted:?}"),
            format!("{fast:?}"),
            "the counting observer changes an outcome"
        );
    }
    let per = |n: u64| n as f64 / s.sweeps.len() as f64;
    let bytes = s.ours.bytes();
    println!(
        "per sweep, {label} on {} triangles: {:.2} nodes opened, {:.2} child boxes tested, {:.2} leaves, {:.2} candidate triangles (planes read), {:.2} tested (whole record read), {:.2} skipped back-facing, {:.2} skipped out of reach; {} bytes a node, {} a triangle plane, {} a triangle record; tree {:.2} MB ({} nodes), triangle planes {:.1} MB, triangle records {:.1} MB, index maps {:.1} MB",
        s.triangles,
        per(count.nodes),
        per(count.boxes),
        per(count.leaves),
        per(count.candidates),
        per(count.tested),
        per(count.skipped.get(Skip::BackFacing)),
        per(count.skipped.get(Skip::PlaneOutOfReach)),
        bytes.node,
        bytes.plane,
        bytes.triangle,
        bytes.nodes as f64 / 1e6,
        bytes.nodes / bytes.node,
        bytes.planes as f64 / 1e6,
        bytes.triangles as f64 / 1e6,
        bytes.index_maps as f64 / 1e6,
    );
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("sweep");
    group.sample_size(20);
    group.warm_up_time(std::time::Duration::from_secs(1));
    group.measurement_time(std::time::Duration::from_secs(4));
    for n in [22usize, 71, 224, 708] {
        let s = setup(n);
        agreement("falling", &s);
        let options = Options::default();
        group.throughput(Throughput::Elements(1));
        let mut i = 0usize;
        group.bench_with_input(BenchmarkId::new("sweeptrace", s.triangles), &s, |b, s| {
            b.iter(|| {
                i = (i + 1) % SWEEPS;
                black_box(sweep_mesh(&s.ours, &s.sweeps[i], &options).ok())
            })
        });
        // The explained queries: each observer, then what the replay keeps.
        explained_bench(&mut group, &s, "explained-primary", |s, sweep| {
            let mut collect = CollectPrimary::default();
            let outcome = explained(s, sweep, &options, &mut collect)?;
            let verdicts = collect.verdict_counts();
            black_box((collect.into_primary_records(&outcome), verdicts));
            Some(())
        });
        explained_bench(&mut group, &s, "explained-every-record", |s, sweep| {
            let mut collect = CollectRecords::default();
            let outcome = explained(s, sweep, &options, &mut collect)?;
            black_box(primary_records(&outcome, collect.records));
            Some(())
        });
        let mut i = 0usize;
        group.bench_with_input(BenchmarkId::new("parry", s.triangles), &s, |b, s| {
            b.iter(|| {
                i = (i + 1) % SWEEPS;
                black_box(parry_cast(&s.parry, &s.sweeps[i]))
            })
        });
        let _ = s.n;
    }
    group.finish();
}

/// The explained query of `sweep` with `observer` (BVH broadphase).
fn explained<O: Observer>(
    s: &Setup,
    sweep: &Sweep,
    options: &Options,
    observer: &mut O,
) -> Option<Outcome> {
    sweep_mesh_with(&s.ours, sweep, options, Broadphase::Bvh, observer).ok()
}

/// A bench named `name` of `run` over the setup's sweeps, cycled.
fn explained_bench(
    group: &mut BenchmarkGroup<'_, WallTime>,
    s: &Setup,
    name: &str,
    mut run: impl FnMut(&Setup, &Sweep) -> Option<()>,
) {
    let mut i = 0usize;
    group.bench_with_input(BenchmarkId::new(name, s.triangles), s, |b, s| {
        b.iter(|| {
            i = (i + 1) % SWEEPS;
            run(s, &s.sweeps[i])
        })
    });
}

/// A session's mesh (for both libraries), options and 4,096 of its sweeps
/// (see the module documentation) on the terrain of `cells × cells` cells.
fn session(cells: usize) -> (Setup, Options) {
    let scene = BuiltinScene::Terrain.mesh_with_terrain_cells(cells);
    let mesh = scene.to_mesh().expect("valid terrain");
    let options = sim::SimOptions {
        balls: 64,
        seed: 1,
        frames: 1954,
        ..BuiltinScene::Terrain.sim_options()
    };
    let mut all = Vec::new();
    sim::simulate(&mesh, &options, |event| -> Result<(), sim::SimError> {
        let s = event.sweep;
        all.push(Sweep::new(s.p0, s.p1, s.radius));
        Ok(())
    })
    .expect("the session simulates");
    let step = (all.len() / SWEEPS).max(1);
    let sweeps: Vec<Sweep> = all.into_iter().step_by(step).take(SWEEPS).collect();
    let parry =
        parry_cast::parry_mesh(&scene.vertices, &scene.triangles).expect("valid terrain for parry");
    let setup = Setup {
        n: cells,
        triangles: scene.triangles.len(),
        ours: mesh,
        parry,
        sweeps,
    };
    (setup, options.core_options())
}

fn bench_session(c: &mut Criterion) {
    let mut group = c.benchmark_group("session");
    group.sample_size(20);
    group.warm_up_time(std::time::Duration::from_secs(1));
    group.measurement_time(std::time::Duration::from_secs(4));
    group.throughput(Throughput::Elements(1));
    for cells in [224usize, 708] {
        let (s, options) = session(cells);
        assert_eq!(options, Options::default(), "parry has no margin");
        agreement("session", &s);
        let n = s.sweeps.len();
        let mut i = 0usize;
        group.bench_with_input(BenchmarkId::new("sweeptrace", s.triangles), &s, |b, s| {
            b.iter(|| {
                i = (i + 1) % n;
                black_box(sweep_mesh(&s.ours, &s.sweeps[i], &options).ok())
            })
        });
        let mut i = 0usize;
        group.bench_with_input(
            BenchmarkId::new("explained-primary", s.triangles),
            &s,
            |b, s| {
                b.iter(|| {
                    i = (i + 1) % n;
                    let mut collect = CollectPrimary::default();
                    let outcome = explained(s, &s.sweeps[i], &options, &mut collect);
                    let verdicts = collect.verdict_counts();
                    black_box((outcome.map(|o| collect.into_primary_records(&o)), verdicts))
                })
            },
        );
        let mut i = 0usize;
        group.bench_with_input(BenchmarkId::new("parry", s.triangles), &s, |b, s| {
            b.iter(|| {
                i = (i + 1) % n;
                black_box(parry_cast(&s.parry, &s.sweeps[i]))
            })
        });
        // The contact query `record --contacts` makes after each of these
        // sweeps: the ball where the sweep leaves it, contact distance a
        // tenth of the radius.
        let queries: Vec<ContactQuery> = s
            .sweeps
            .iter()
            .map(|w| {
                let alpha = sweep_mesh(&s.ours, w, &options).map_or(1.0, |o| o.travelled());
                ContactQuery {
                    centre: w.p0 + (w.p1 - w.p0) * alpha,
                    radius: w.radius,
                    distance: w.radius / 10.0,
                }
            })
            .collect();
        let touching = queries
            .iter()
            .filter(|q| !contact_set(&s.ours, q, Sides::One).is_empty())
            .count();
        println!(
            "contacts {}: {touching} of {} queries touch the mesh",
            s.triangles,
            queries.len()
        );
        let mut i = 0usize;
        group.bench_with_input(BenchmarkId::new("contacts", s.triangles), &s, |b, s| {
            b.iter(|| {
                i = (i + 1) % n;
                black_box(contact_set(&s.ours, &queries[i], Sides::One))
            })
        });
    }
    group.finish();
}

fn bench_topology(c: &mut Criterion) {
    let (vertices, triangles) = terrain(708);
    let mesh = Mesh::new(vertices.clone(), &triangles).expect("valid terrain");
    let topology = Topology::new(&vertices, &triangles).expect("valid terrain");
    let counts = topology.edge_counts();
    println!(
        "topology of {} triangles: {} edges ({} flat, {} convex, {} concave, {} boundary), {} defects, {:.1} bytes per triangle",
        triangles.len(),
        counts.total(),
        counts.flat,
        counts.convex,
        counts.concave,
        counts.boundary,
        topology.defects().len(),
        topology.heap_bytes() as f64 / triangles.len() as f64
    );
    let mut group = c.benchmark_group("topology");
    group.sample_size(10);
    group.warm_up_time(std::time::Duration::from_secs(1));
    group.measurement_time(std::time::Duration::from_secs(8));
    group.throughput(Throughput::Elements(triangles.len() as u64));
    group.bench_function(BenchmarkId::new("topology", triangles.len()), |b| {
        b.iter(|| black_box(Topology::new(&vertices, &triangles).ok()))
    });
    group.bench_function(BenchmarkId::new("bvh", triangles.len()), |b| {
        b.iter(|| black_box(mesh.build_bvh_again()))
    });
    group.bench_function(BenchmarkId::new("mesh", triangles.len()), |b| {
        b.iter_batched(
            || vertices.clone(),
            |v| black_box(Mesh::new(v, &triangles).ok()),
            criterion::BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group!(benches, bench, bench_session, bench_topology);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
