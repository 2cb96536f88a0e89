//! The mesh sweep: every test of every candidate triangle, combined into one
//! outcome by the rules of SEMANTICS.md.

use nalgebra::{Point3, Vector3};

use super::bvh::{LEAF_SIZE, Visit, prefetch};
use super::error::SweepError;
use super::feature::{Feature, Kind};
use super::fragility::{FragileReason, Fragility};
use super::initial::initial_contact;
use super::mesh::{Mesh, Plane, Triangle};
use super::options::{ALPHA_SENSITIVITY, Facing, GRAZING_COSINE, Options, Sides};
use super::outcome::{Outcome, SweepHit, in_tie_window};
use super::path::{Sweep, SweptPath};
use super::record::{NoObserver, Observer, Skip, Verdict};
use super::sweep_edge::sweep_edge;
use super::sweep_face::{barycentric_and_distance, sweep_face};
use super::sweep_vertex::sweep_vertex;

/// How the candidate triangles are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Broadphase {
    /// Only triangles whose grown bounding boxes the path enters, nearest
    /// first, stopping past the best hit (the default).
    Bvh,
    /// Every triangle of the mesh.
    Exhaustive,
}

/// One hit, with what the tie order and the fragility flags need.
#[derive(Clone, Copy, Debug)]
struct Hit {
    alpha: f64,
    triangle: u32,
    feature: Feature,
    /// Position of the triangle in the mesh's storage order.
    position: u32,
    contact: Point3<f64>,
    /// Approach cosine: `|n · d| / |d|` for a face, `√disc / (2ρ|d|)` for
    /// an edge or a vertex.
    cosine: f64,
    /// The triangle's `|n · d| / |d|`.
    facing_cosine: f64,
    /// Distance of the contact from its feature's boundary (a length;
    /// infinite for a vertex).
    boundary: f64,
    /// The normal of the triangle as tested: its front normal, or `-n`
    /// when it was tested from its back (`sides = two`).
    normal: Vector3<f64>,
}

impl Hit {
    const EMPTY: Hit = Hit {
        alpha: 0.0,
        triangle: 0,
        // Never read: `Combiner::len` counts the slots that hold hits.
        feature: Feature::Face,
        position: 0,
        contact: Point3::new(0.0, 0.0, 0.0),
        cosine: 0.0,
        facing_cosine: 0.0,
        boundary: 0.0,
        normal: Vector3::new(0.0, 0.0, 0.0),
    };

    #[inline]
    fn order(&self) -> (Kind, u32, u8) {
        let (kind, index) = self.feature.order_key();
        (kind, self.triangle, index)
    }
}

/// Receives what a triangle's tests found: hits, and near misses (a test
/// rejected by less than the fragility band) with their `α`.
trait Sink {
    fn hit(&mut self, hit: Hit);
    fn near_miss(&mut self, _reason: FragileReason, _alpha: f64) {}
}

/// Runs the seven tests of one triangle; hands hits and near misses to `sink`.
#[inline]
fn test_triangle<O: Observer, S: Sink>(
    triangle: &Triangle,
    position: usize,
    path: &SweptPath,
    facing: Facing,
    observer: &mut O,
    sink: &mut S,
) {
    let rho = path.rho;
    let length = path.length;
    let facing_value = triangle.normal.dot(&path.d);
    let facing_cosine = if length > 0.0 {
        facing_value.abs() / length
    } else {
        0.0
    };
    let allowed = facing.allows(facing_value);
    let band = path.fragile_window();
    let band_distance = path.fragile_distance();
    let hit = |alpha: f64, feature: Feature, contact, cosine, boundary| Hit {
        alpha,
        triangle: triangle.index,
        feature,
        position: position as u32,
        contact,
        cosine,
        facing_cosine,
        boundary,
        normal: triangle.normal,
    };
    // Whether a face touch point at `beta` lies within the band of the triangle.
    let touch_near = |beta: f64| {
        let touch = path.at(beta) - triangle.normal * rho;
        barycentric_and_distance(triangle, &touch).1 >= -band_distance
    };

    let face = sweep_face(triangle, path, facing);
    observer.face(&face);
    match face.verdict {
        Verdict::Hit => {
            if let Some(h) = face.hit() {
                sink.hit(hit(
                    h.alpha,
                    Feature::Face,
                    h.touch,
                    facing_cosine,
                    h.boundary_distance,
                ));
            }
        }
        Verdict::StartsTooClose if allowed && facing_value < 0.0 => {
            let beta = (face.h0 - rho) / -facing_value;
            if beta >= -band && touch_near(0.0) {
                sink.near_miss(FragileReason::StartTouching, beta);
            }
        }
        Verdict::BeyondEnd => {
            if let Some(beta) = face.beta
                && beta <= 1.0 + band
                && touch_near(beta)
            {
                sink.near_miss(FragileReason::NearEnd, beta);
            }
        }
        Verdict::OutsideTriangle => {
            if let (Some(beta), Some(distance)) = (face.beta, face.boundary_distance)
                && distance >= -band_distance
            {
                sink.near_miss(FragileReason::NearBoundary, beta);
            }
        }
        _ => {}
    }

    // Near misses shared by the edge and vertex tests. `on_feature(s)` says
    // whether the contact at `s` lies within the band of the feature.
    let quadratic_near_miss = |sink: &mut S,
                               verdict: Verdict,
                               (a, b, c, discriminant): (f64, f64, f64, f64),
                               roots: Option<(f64, f64)>,
                               on_feature: &dyn Fn(f64) -> bool| {
        match verdict {
            Verdict::NoRealRoots if allowed => {
                // Closest approach within ρ + band of the feature's line or point.
                let reach = 4.0 * a * band_distance * (2.0 * rho + band_distance);
                let t = -b / (2.0 * a);
                if -discriminant <= reach && t >= -band && t <= 1.0 + band && on_feature(t) {
                    sink.near_miss(FragileReason::NearTangent, t);
                }
            }
            // Moving along the edge's line at a distance within the band of ρ.
            Verdict::Parallel
                if allowed && c.abs() <= band_distance * (2.0 * rho + band_distance) =>
            {
                sink.near_miss(FragileReason::NearTangent, 0.0);
            }
            Verdict::BeforeStart if allowed => {
                if let Some((s0, _)) = roots
                    && s0 >= -band
                    && on_feature(s0)
                {
                    sink.near_miss(FragileReason::StartTouching, s0);
                }
            }
            Verdict::BeyondEnd if allowed => {
                if let Some((s0, _)) = roots
                    && s0 <= 1.0 + band
                    && on_feature(s0)
                {
                    sink.near_miss(FragileReason::NearEnd, s0);
                }
            }
            Verdict::BackFacing if facing_cosine < GRAZING_COSINE => {
                // The facing rule could turn and let this hit through.
                if let Some((s0, _)) = roots {
                    sink.near_miss(FragileReason::Grazing, s0);
                }
            }
            _ => {}
        }
    };
    let approach = |discriminant: f64| discriminant.max(0.0).sqrt() / (2.0 * rho * length);

    for e in 0..3u8 {
        let r = sweep_edge(triangle, e, path, facing);
        observer.edge(&r);
        let (x0, x1) = (r.p0_in_edge.x, r.p1_in_edge.x);
        let on_edge = |s: f64| {
            let xc = x0 + s * (x1 - x0);
            xc >= -band_distance && xc <= r.length + band_distance
        };
        match r.verdict {
            Verdict::Hit => {
                if let (Some(h), Some(contact)) = (r.hit(), r.contact()) {
                    sink.hit(hit(
                        h.alpha,
                        Feature::Edge(e),
                        contact,
                        approach(r.discriminant),
                        h.xc.min(r.length - h.xc),
                    ));
                }
            }
            Verdict::OffEdge if allowed => {
                if let (Some((s0, _)), Some(xc)) = (r.roots, r.xc)
                    && xc >= -band_distance
                    && xc <= r.length + band_distance
                {
                    sink.near_miss(FragileReason::NearBoundary, s0);
                }
            }
            verdict => quadratic_near_miss(
                sink,
                verdict,
                (r.a, r.b, r.c, r.discriminant),
                r.roots,
                &on_edge,
            ),
        }
    }
    for v in 0..3u8 {
        let r = sweep_vertex(triangle, v, path, facing);
        observer.vertex(&r);
        match r.verdict {
            Verdict::Hit => {
                if let Some(alpha) = r.alpha() {
                    sink.hit(hit(
                        alpha,
                        Feature::Vertex(v),
                        r.position,
                        approach(r.discriminant),
                        f64::INFINITY,
                    ));
                }
            }
            verdict => quadratic_near_miss(
                sink,
                verdict,
                (r.a, r.b, r.c, r.discriminant),
                r.roots,
                &|_| true,
            ),
        }
    }
}

/// How many hits the combiner keeps without allocating; more within the
/// fragility band of the minimum (a vertex shared by very many triangles)
/// trigger a second, exhaustive pass.
const CAPACITY: usize = 24;

/// Collects the hits within the fragility band of the running minimum `α`
/// and the earliest near miss of each reason. Allocates nothing.
struct Combiner {
    min: f64,
    band: f64,
    hits: [Hit; CAPACITY],
    len: usize,
    overflow: bool,
    near_misses: [f64; FragileReason::ALL.len()],
}

impl Combiner {
    fn new(band: f64) -> Self {
        Combiner {
            min: f64::INFINITY,
            band,
            hits: [Hit::EMPTY; CAPACITY],
            len: 0,
            overflow: false,
            near_misses: [f64::INFINITY; FragileReason::ALL.len()],
        }
    }

    /// The broadphase cutoff: a triangle entered later cannot have a hit or
    /// a near miss that matters.
    fn cutoff(&self) -> f64 {
        self.min.min(1.0) + self.band
    }
}

impl Sink for Combiner {
    #[inline]
    fn hit(&mut self, hit: Hit) {
        if hit.alpha < self.min {
            self.min = hit.alpha;
            let (min, band) = (self.min, self.band);
            let mut k = 0;
            for i in 0..self.len {
                if in_tie_window(self.hits[i].alpha, min, band) {
                    self.hits[k] = self.hits[i];
                    k += 1;
                }
            }
            self.len = k;
        }
        if in_tie_window(hit.alpha, self.min, self.band) {
            if self.len < CAPACITY {
                self.hits[self.len] = hit;
                self.len += 1;
            } else {
                self.overflow = true;
            }
        }
    }

    #[inline]
    fn near_miss(&mut self, reason: FragileReason, alpha: f64) {
        let earliest = &mut self.near_misses[reason as usize];
        *earliest = earliest.min(alpha);
    }
}

/// Decides from the hits within the band of the final minimum, seen grouped
/// by triangle in mesh order: the primary, the normal sum and the flags.
struct Decision<'a> {
    path: &'a SweptPath,
    min: f64,
    window: f64,
    band: f64,
    primary: Option<Hit>,
    normal_sum: Vector3<f64>,
    last_position: Option<u32>,
    in_band: usize,
    fragile: Fragility,
}

impl Sink for Decision<'_> {
    fn hit(&mut self, h: Hit) {
        if !in_tie_window(h.alpha, self.min, self.band) {
            return;
        }
        self.in_band += 1;
        let f = &mut self.fragile;
        if h.feature == Feature::Face {
            if h.cosine < GRAZING_COSINE {
                f.insert(FragileReason::Grazing);
            }
        } else if h.cosine < GRAZING_COSINE {
            f.insert(FragileReason::NearTangent);
        }
        if h.facing_cosine < GRAZING_COSINE {
            f.insert(FragileReason::Grazing);
        }
        if h.boundary < self.path.fragile_distance() {
            f.insert(FragileReason::NearBoundary);
        }
        if h.alpha <= self.band {
            f.insert(FragileReason::StartTouching);
        }
        if h.alpha >= 1.0 - self.band {
            f.insert(FragileReason::NearEnd);
        }
        if self.path.rounding() > ALPHA_SENSITIVITY * self.path.length * h.cosine {
            f.insert(FragileReason::ImpreciseAlpha);
        }
        if in_tie_window(h.alpha, self.min, self.window) {
            if self.primary.is_none_or(|p| h.order() < p.order()) {
                self.primary = Some(h);
            }
            if self.last_position != Some(h.position) {
                self.normal_sum += h.normal;
                self.last_position = Some(h.position);
            }
        }
    }
}

/// The fast query: the outcome of `sweep` against `mesh`, using the BVH.
/// Allocates nothing.
pub fn sweep_mesh(mesh: &Mesh, sweep: &Sweep, options: &Options) -> Result<Outcome, SweepError> {
    sweep_mesh_with(mesh, sweep, options, Broadphase::Bvh, &mut NoObserver)
}

/// The explained query: like [`sweep_mesh`], and hands the record of every
/// test it runs to `observer` (the tests of every candidate triangle with
/// [`Broadphase::Bvh`], of every triangle with [`Broadphase::Exhaustive`];
/// an observer whose [`Observer::TESTS_EVERY_CANDIDATE`] is `false` gets,
/// for the triangles the fast query skips, only why they were skipped).
pub fn sweep_mesh_with<O: Observer>(
    mesh: &Mesh,
    sweep: &Sweep,
    options: &Options,
    broadphase: Broadphase,
    observer: &mut O,
) -> Result<Outcome, SweepError> {
    let path = SweptPath::against(mesh, sweep, options)?;
    let outcome = sweep_path(
        mesh,
        &path,
        options.facing,
        options.sides,
        broadphase,
        observer,
    );
    if !options.initial_overlap.is_rules()
        && let Some((hit, distance)) = initial_contact(mesh, &path, options)
    {
        // The tests ran for the observer; the answer is the start's contact.
        let mut fragile = Fragility::ROBUST;
        if path.rho - distance <= path.fragile_distance() {
            fragile.insert(FragileReason::StartTouching);
        }
        return Ok(Outcome {
            hit: Some(hit),
            tie_window: path.tie_window(),
            fragile,
        });
    }
    Ok(outcome)
}

/// Why the fast query may skip a triangle without testing it (`None`: it
/// is tested; always, for an observer that tests every candidate): every
/// test would end back-facing, and its facing value is far enough from 0
/// that rounding cannot turn the rule (near 0 it is tested for the
/// `grazing` flag).
///
/// Or: the whole path stays on one side of the triangle's plane, farther
/// from it than `ρ` plus a margin far above the fragility band (the one the
/// broadphase grows its boxes by). Every feature of the triangle lies in
/// that plane, so no test can hit, and none can come within the band of a
/// hit (the line of an edge, its vertices, its face are no nearer than the
/// plane): the tests would give no hit and no near miss.
#[inline]
fn skip<O: Observer>(
    normal: &Vector3<f64>,
    v0: &Point3<f64>,
    path: &SweptPath,
    facing: Facing,
) -> Option<Skip> {
    if O::TESTS_EVERY_CANDIDATE {
        return None;
    }
    let facing_value = normal.dot(&path.d);
    if !facing.allows(facing_value) && facing_value.abs() >= GRAZING_COSINE * path.length {
        return Some(Skip::BackFacing);
    }
    let h0 = normal.dot(&(path.p0 - v0));
    let h1 = h0 + facing_value;
    let clear = path.rho + path.broadphase_margin();
    ((h0 > clear && h1 > clear) || (h0 < -clear && h1 < -clear)).then_some(Skip::PlaneOutOfReach)
}

/// [`skip`] from a triangle's [`Plane`] alone (its record is not read),
/// with the plane as the tests see it under `sides`; and whether the
/// triangle is tested from its back (`sides = two`, the path moving toward
/// its back, `n · d > 0`: the tests then take its
/// [mirror](Triangle::mirrored), `-n`). One comparison under the rules.
#[inline]
fn skip_plane<O: Observer>(
    plane: &Plane,
    path: &SweptPath,
    (facing, sides): (Facing, Sides),
) -> (Option<Skip>, bool) {
    let back = sides == Sides::Two && plane.normal.dot(&path.d) > 0.0;
    let normal = if back { -plane.normal } else { plane.normal };
    (skip::<O>(&normal, &plane.v0, path, facing), back)
}

/// Asks for every cache line of `items` to be fetched.
#[inline]
fn prefetch_all<T>(items: &[T]) {
    for t in items {
        prefetch(t);
    }
}

fn visit_triangles<O: Observer>(
    mesh: &Mesh,
    path: &SweptPath,
    (facing, sides): (Facing, Sides),
    broadphase: Broadphase,
    observer: &mut O,
    combiner: &mut Combiner,
) {
    let triangles = mesh.triangles();
    let planes = mesh.planes();
    // The skip tests read the triangle's plane only ([`skip_plane`]); its
    // record is read when it is tested.
    let run = |position: usize,
               (skipped, back): (Option<Skip>, bool),
               combiner: &mut Combiner,
               observer: &mut O| match skipped {
        None => {
            let mirrored = back.then(|| triangles[position].mirrored());
            let t = mirrored.as_ref().unwrap_or(&triangles[position]);
            test_triangle(t, position, path, facing, observer, combiner)
        }
        Some(reason) => observer.skipped(planes[position].index, reason),
    };
    match broadphase {
        Broadphase::Exhaustive => {
            for (position, plane) in planes.iter().enumerate() {
                let decided = skip_plane::<O>(plane, path, (facing, sides));
                run(position, decided, combiner, observer);
            }
        }
        Broadphase::Bvh => {
            // Boxes grown by ρ plus a margin far above the fragility band,
            // so every hit and near miss that matters is visited.
            let grow = path.rho + path.broadphase_margin();
            let cutoff = combiner.cutoff();
            struct Leaves<'a, R, O> {
                run: R,
                triangles: &'a [Triangle],
                planes: &'a [Plane],
                path: &'a SweptPath,
                rules: (Facing, Sides),
                combiner: &'a mut Combiner,
                observer: &'a mut O,
            }
            impl<R, O> Visit for Leaves<'_, R, O>
            where
                R: Fn(usize, (Option<Skip>, bool), &mut Combiner, &mut O),
                O: Observer,
            {
                #[inline]
                fn leaf(&mut self, range: std::ops::Range<usize>) -> f64 {
                    self.observer.leaf(range.len());
                    // Each candidate's skip decided once, from its plane;
                    // the records of those that will be tested are fetched
                    // together, before the first test. A leaf holds at
                    // most LEAF_SIZE triangles.
                    let mut decided = [(None, false); LEAF_SIZE];
                    for (slot, position) in range.clone().enumerate() {
                        decided[slot] =
                            skip_plane::<O>(&self.planes[position], self.path, self.rules);
                        if decided[slot].0.is_none() {
                            prefetch(&self.triangles[position]);
                        }
                    }
                    for (slot, position) in range.enumerate() {
                        (self.run)(position, decided[slot], self.combiner, self.observer);
                    }
                    self.combiner.cutoff()
                }
                #[inline]
                fn node(&mut self, boxes: usize) {
                    self.observer.node(boxes);
                }
                #[inline]
                fn entered(&mut self, range: std::ops::Range<usize>) {
                    prefetch_all(&self.planes[range]);
                }
            }
            mesh.bvh().traverse_with(
                &path.p0,
                &path.d,
                grow,
                cutoff,
                &mut Leaves {
                    run,
                    triangles,
                    planes,
                    path,
                    rules: (facing, sides),
                    combiner,
                    observer,
                },
            );
        }
    }
}

fn sweep_path<O: Observer>(
    mesh: &Mesh,
    path: &SweptPath,
    facing: Facing,
    sides: Sides,
    broadphase: Broadphase,
    observer: &mut O,
) -> Outcome {
    let band = path.fragile_window();
    let mut combiner = Combiner::new(band);
    visit_triangles(
        mesh,
        path,
        (facing, sides),
        broadphase,
        observer,
        &mut combiner,
    );
    let triangles = mesh.triangles();
    let reference = combiner.min.min(1.0);
    let mut fragile = Fragility::ROBUST;
    for reason in FragileReason::ALL {
        if combiner.near_misses[reason as usize] <= reference + band {
            fragile.insert(reason);
        }
    }
    if combiner.min == f64::INFINITY {
        return Outcome {
            hit: None,
            tie_window: path.tie_window(),
            fragile,
        };
    }
    let mut decision = Decision {
        path,
        min: combiner.min,
        window: path.tie_window(),
        band,
        primary: None,
        normal_sum: Vector3::zeros(),
        last_position: None,
        in_band: 0,
        fragile,
    };
    if combiner.overflow {
        // More hits within the band than the combiner holds: test every
        // triangle again, in mesh order.
        for (position, (t, plane)) in triangles.iter().zip(mesh.planes()).enumerate() {
            if let (None, back) = skip_plane::<NoObserver>(plane, path, (facing, sides)) {
                let mirrored = back.then(|| t.mirrored());
                let t = mirrored.as_ref().unwrap_or(t);
                test_triangle(t, position, path, facing, &mut NoObserver, &mut decision);
            }
        }
    } else {
        // In mesh order so the normal's bits do not depend on the traversal.
        let hits = &mut combiner.hits[..combiner.len];
        hits.sort_unstable_by_key(|h| (h.position, h.order()));
        for h in hits.iter() {
            decision.hit(*h);
        }
    }
    if decision.in_band > 1 {
        decision.fragile.insert(FragileReason::Tie);
    }
    let Some(primary) = decision.primary else {
        unreachable!("the minimum α is itself a hit within the tie window");
    };
    let sum = decision.normal_sum;
    let norm = sum.norm();
    let normal = if norm > 1e-9 {
        sum / norm
    } else {
        primary.normal
    };
    Outcome {
        hit: Some(SweepHit {
            alpha: combiner.min,
            triangle: primary.triangle,
            feature: primary.feature,
            normal,
            contact: primary.contact,
        }),
        tie_window: decision.window,
        fragile: decision.fragile,
    }
}
