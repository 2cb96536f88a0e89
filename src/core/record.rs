//! What each test computed: the records handed to an [`Observer`].

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::feature::{Feature, Kind};
use super::mesh::StandardFrame;

/// The verdict of one test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// A collision at the record's `alpha`.
    Hit,
    /// Face: the ball starts within `ρ` of the plane, or behind it.
    StartsTooClose,
    /// Face: moving parallel to the plane (`|n · d| ≤ PARALLEL_TOLERANCE · |d|`).
    /// Edge: path parallel to the edge
    /// (or of zero length).
    Parallel,
    /// Vertex: the path has zero length.
    NotMoving,
    /// The path's line never comes within `ρ` (negative discriminant).
    NoRealRoots,
    /// The first contact lies before the start of the path (`s0 < 0`).
    BeforeStart,
    /// The first contact lies beyond the end of the path (`β > 1`, `s0 > 1`).
    BeyondEnd,
    /// Edge: the contact with the edge's line is outside `[0, L]`.
    OffEdge,
    /// Face: the touch point is outside the triangle.
    OutsideTriangle,
    /// The facing rule rejects the direction of travel.
    BackFacing,
}

impl Verdict {
    /// Snake-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Hit => "hit",
            Verdict::StartsTooClose => "starts_too_close",
            Verdict::Parallel => "parallel",
            Verdict::NotMoving => "not_moving",
            Verdict::NoRealRoots => "no_real_roots",
            Verdict::BeforeStart => "before_start",
            Verdict::BeyondEnd => "beyond_end",
            Verdict::OffEdge => "off_edge",
            Verdict::OutsideTriangle => "outside_triangle",
            Verdict::BackFacing => "back_facing",
        }
    }

    /// Every verdict, in declaration order.
    pub const ALL: [Verdict; 10] = [
        Verdict::Hit,
        Verdict::StartsTooClose,
        Verdict::Parallel,
        Verdict::NotMoving,
        Verdict::NoRealRoots,
        Verdict::BeforeStart,
        Verdict::BeyondEnd,
        Verdict::OffEdge,
        Verdict::OutsideTriangle,
        Verdict::BackFacing,
    ];
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

// `VerdictCounts` counts at `verdict as usize`: that must be the verdict's
// index in `Verdict::ALL`.
const _: () = {
    let mut i = 0;
    while i < Verdict::ALL.len() {
        assert!(Verdict::ALL[i] as usize == i);
        i += 1;
    }
};

/// How many tests ended with each verdict.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VerdictCounts([u64; Verdict::ALL.len()]);

impl VerdictCounts {
    /// Counts one test that ended with `verdict`.
    #[inline]
    pub fn add(&mut self, verdict: Verdict) {
        self.0[verdict as usize] += 1;
    }

    /// How many tests ended with `verdict`.
    pub fn get(&self, verdict: Verdict) -> u64 {
        self.0[verdict as usize]
    }

    /// Whether no test was counted.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|&n| n == 0)
    }

    /// The verdicts that occurred with their counts, in the order of
    /// [`Verdict::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (Verdict, u64)> + '_ {
        Verdict::ALL
            .iter()
            .zip(self.0)
            .filter(|(_, n)| *n > 0)
            .map(|(v, n)| (*v, n))
    }
}

impl std::ops::AddAssign for VerdictCounts {
    fn add_assign(&mut self, other: VerdictCounts) {
        for (n, m) in self.0.iter_mut().zip(other.0) {
            *n += m;
        }
    }
}

impl FromIterator<Verdict> for VerdictCounts {
    fn from_iter<I: IntoIterator<Item = Verdict>>(verdicts: I) -> Self {
        let mut counts = VerdictCounts::default();
        for v in verdicts {
            counts.add(v);
        }
        counts
    }
}

/// Everything the face test computed.
///
/// Only the core builds records (the type is `#[non_exhaustive]`), so a
/// `Hit` verdict always comes with the values it was decided on:
/// [`FaceRecord::hit`] returns them typed. The `Option` fields are what the
/// test computed before it stopped, whatever the verdict (a miss has them
/// too, e.g. the roots of `before_start`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct FaceRecord {
    /// Input index of the triangle.
    pub triangle: u32,
    /// Its front normal.
    pub normal: Vector3<f64>,
    /// `n · d` (mathematically `h1 - h0`): the one quantity the test uses
    /// for the facing rule, the parallel test and `β`.
    pub normal_dot_d: f64,
    /// Signed distance of `p0` from the plane.
    pub h0: f64,
    /// Signed distance of `p1` from the plane (shown in explanations; the
    /// decisions use `n · d`, never `h0 - h1`).
    pub h1: f64,
    /// `(h0 - ρ) / -(n · d)`, when computed.
    pub beta: Option<f64>,
    /// The touch point `p0 + β d - ρ n`, when computed.
    pub touch: Option<Point3<f64>>,
    /// Barycentric coordinates of the touch point (weights of `a`, `b`, `c`).
    pub barycentric: Option<[f64; 3]>,
    /// Smallest signed distance of the touch point from the triangle's edge
    /// lines (positive inside); the touch point counts as inside when this
    /// is at least minus the tie distance.
    pub boundary_distance: Option<f64>,
    /// Whether the test ran on the triangle seen from its back
    /// (`sides = two`): the normal and `n · d` are then the mirror's, `-n`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub back: bool,
    /// The verdict.
    pub verdict: Verdict,
}

/// Everything the edge test computed.
///
/// Only the core builds records (the type is `#[non_exhaustive]`), so a
/// `Hit` verdict always comes with the values it was decided on:
/// [`EdgeRecord::hit`] returns them typed. The `Option` fields are what the
/// test computed before it stopped, whatever the verdict (a miss has them
/// too, e.g. the roots of `before_start`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct EdgeRecord {
    /// Input index of the triangle.
    pub triangle: u32,
    /// Edge index `i` (joins the triangle's vertices `i` and `(i + 1) mod 3`).
    pub edge: u8,
    /// The standard frame.
    #[serde(skip)]
    pub frame: StandardFrame,
    /// Length `L` of the edge.
    pub length: f64,
    /// `p0` in the standard frame.
    pub p0_in_edge: Point3<f64>,
    /// `p1` in the standard frame.
    pub p1_in_edge: Point3<f64>,
    /// `A` of the quadratic.
    pub a: f64,
    /// `B` of the quadratic.
    pub b: f64,
    /// `C` of the quadratic.
    pub c: f64,
    /// `B² - 4AC`, computed as `4 (ρ² A - w²)` with `w = y0 dz - z0 dy`
    /// (the same value, without the cancellation of `B² - 4AC`).
    pub discriminant: f64,
    /// Roots `s0 ≤ s1`, when real.
    pub roots: Option<(f64, f64)>,
    /// Contact with the edge's line, `xc = x0 + s0 (x1 - x0)`, when computed.
    pub xc: Option<f64>,
    /// `n · d` in world coordinates.
    pub normal_dot_d: f64,
    /// Whether the test ran on the triangle seen from its back
    /// (`sides = two`): the normal and `n · d` are then the mirror's, `-n`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub back: bool,
    /// The verdict.
    pub verdict: Verdict,
}

/// Everything the vertex test computed.
///
/// Only the core builds records (the type is `#[non_exhaustive]`), so a
/// `Hit` verdict always comes with the values it was decided on:
/// [`VertexRecord::hit`] returns them typed. The `Option` fields are what the
/// test computed before it stopped, whatever the verdict (a miss has them
/// too, e.g. the roots of `before_start`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct VertexRecord {
    /// Input index of the triangle.
    pub triangle: u32,
    /// Which of the triangle's vertices (0, 1, 2).
    pub vertex: u8,
    /// Its position.
    pub position: Point3<f64>,
    /// `A = d · d`.
    pub a: f64,
    /// `B = 2 d · (p0 - v)`.
    pub b: f64,
    /// `C = |p0 - v|² - ρ²`.
    pub c: f64,
    /// `B² - 4AC`, computed as `4 (ρ² A - |d × (p0 - v)|²)` (the same value,
    /// without the cancellation of `B² - 4AC`).
    pub discriminant: f64,
    /// Roots `s0 ≤ s1`, when real.
    pub roots: Option<(f64, f64)>,
    /// `n · d` in world coordinates.
    pub normal_dot_d: f64,
    /// Whether the test ran on the triangle seen from its back
    /// (`sides = two`): the normal and `n · d` are then the mirror's, `-n`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub back: bool,
    /// The verdict.
    pub verdict: Verdict,
}

/// What a face test that hit found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceHit {
    /// `α` of the collision (the record's `β`).
    pub alpha: f64,
    /// The touch point on the triangle.
    pub touch: Point3<f64>,
    /// The touch point's signed distance from the triangle's boundary
    /// ([`FaceRecord::boundary_distance`]).
    pub boundary_distance: f64,
}

/// What an edge test that hit found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeHit {
    /// `α` of the collision (the smaller root `s0`).
    pub alpha: f64,
    /// The contact on the edge's line, `xc`, in the standard frame.
    pub xc: f64,
}

impl FaceRecord {
    /// What the test found, if its verdict is a hit (a face test that hits
    /// has computed `β`, the touch point and its distance from the
    /// boundary; a record that says hit without them is not a hit).
    #[inline]
    pub fn hit(&self) -> Option<FaceHit> {
        match (self.verdict, self.beta, self.touch, self.boundary_distance) {
            (Verdict::Hit, Some(alpha), Some(touch), Some(boundary_distance)) => Some(FaceHit {
                alpha,
                touch,
                boundary_distance,
            }),
            (verdict, ..) => {
                debug_assert!(verdict != Verdict::Hit, "face hit without its values");
                None
            }
        }
    }

    /// `α` of the collision, if the verdict is a hit.
    #[inline]
    pub fn alpha(&self) -> Option<f64> {
        self.hit().map(|h| h.alpha)
    }
}

impl EdgeRecord {
    /// What the test found, if its verdict is a hit (an edge test that hits
    /// has computed its roots and `xc`; a record that says hit without them
    /// is not a hit).
    #[inline]
    pub fn hit(&self) -> Option<EdgeHit> {
        match (self.verdict, self.roots, self.xc) {
            (Verdict::Hit, Some((s0, _)), Some(xc)) => Some(EdgeHit { alpha: s0, xc }),
            (verdict, ..) => {
                debug_assert!(verdict != Verdict::Hit, "edge hit without its values");
                None
            }
        }
    }

    /// `α` of the collision, if the verdict is a hit.
    #[inline]
    pub fn alpha(&self) -> Option<f64> {
        self.hit().map(|h| h.alpha)
    }

    /// The point `xc` of the edge the ball touches, in world coordinates,
    /// if the verdict is a hit.
    #[inline]
    pub fn contact(&self) -> Option<Point3<f64>> {
        self.hit()
            .map(|h| self.frame.to_world(&Point3::new(h.xc, 0.0, 0.0)))
    }
}

/// What a vertex test that hit found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexHit {
    /// `α` of the collision (the smaller root `s0`).
    pub alpha: f64,
    /// The vertex the ball touches.
    pub position: Point3<f64>,
}

impl VertexRecord {
    /// What the test found, if its verdict is a hit (a vertex test that
    /// hits has computed its roots; a record that says hit without them is
    /// not a hit).
    #[inline]
    pub fn hit(&self) -> Option<VertexHit> {
        match (self.verdict, self.roots) {
            (Verdict::Hit, Some((s0, _))) => Some(VertexHit {
                alpha: s0,
                position: self.position,
            }),
            (verdict, _) => {
                debug_assert!(verdict != Verdict::Hit, "vertex hit without its roots");
                None
            }
        }
    }

    /// `α` of the collision, if the verdict is a hit.
    #[inline]
    pub fn alpha(&self) -> Option<f64> {
        self.hit().map(|h| h.alpha)
    }
}

/// Receives every test's record during an explained sweep.
///
/// All methods have empty defaults; the fast query uses [`NoObserver`],
/// for which the compiler removes every call.
pub trait Observer {
    /// Whether records are wanted at all. When `false`, the sweep may skip
    /// triangles whose every test would end back-facing.
    const WANTS_RECORDS: bool = true;

    /// Whether every candidate triangle is tested. When `false`, the sweep
    /// skips, as the fast query does, the candidates none of whose tests
    /// can hit or come near a hit ([`Skip`]), and hands each to
    /// [`Observer::skipped`] instead of its records. By default, only an
    /// observer that wants no records lets triangles be skipped.
    const TESTS_EVERY_CANDIDATE: bool = Self::WANTS_RECORDS;

    /// A candidate triangle (its input index) was skipped without testing
    /// it, for `reason` (only when [`Observer::TESTS_EVERY_CANDIDATE`] is
    /// `false`).
    #[inline]
    fn skipped(&mut self, _triangle: u32, _reason: Skip) {}

    /// The BVH broadphase opened a node of its tree and tested the segment
    /// against its `boxes` child boxes.
    #[inline]
    fn node(&mut self, _boxes: usize) {}

    /// The BVH broadphase handed over a leaf of `triangles` candidates
    /// (each then tested or [skipped](Observer::skipped)).
    #[inline]
    fn leaf(&mut self, _triangles: usize) {}

    /// A face test finished.
    #[inline]
    fn face(&mut self, _record: &FaceRecord) {}
    /// An edge test finished.
    #[inline]
    fn edge(&mut self, _record: &EdgeRecord) {}
    /// A vertex test finished.
    #[inline]
    fn vertex(&mut self, _record: &VertexRecord) {}
}

/// Why the sweep skipped a candidate triangle without testing it (the
/// fast query's shortcuts; see [`Observer::TESTS_EVERY_CANDIDATE`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Skip {
    /// The facing rule rejects the direction of travel, by a margin that
    /// rounding cannot turn: every test would end back-facing.
    BackFacing,
    /// The whole path stays on one side of the triangle's plane, farther
    /// from it than `ρ` plus the broadphase's margin: no test can hit or
    /// come within the fragility band of a hit.
    PlaneOutOfReach,
}

impl Skip {
    /// Snake-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Skip::BackFacing => "back_facing",
            Skip::PlaneOutOfReach => "plane_out_of_reach",
        }
    }

    /// In words, as the recording's text says it (`12 back-facing
    /// candidates skipped`).
    pub fn words(self) -> &'static str {
        match self {
            Skip::BackFacing => "back-facing",
            Skip::PlaneOutOfReach => "out-of-reach",
        }
    }

    /// Every reason, in declaration order.
    pub const ALL: [Skip; 2] = [Skip::BackFacing, Skip::PlaneOutOfReach];
}

impl std::fmt::Display for Skip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How many candidate triangles were skipped for each [`Skip`] reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SkipCounts([u64; Skip::ALL.len()]);

impl SkipCounts {
    /// Counts one triangle skipped for `reason`.
    #[inline]
    pub fn add(&mut self, reason: Skip) {
        self.0[reason as usize] += 1;
    }

    /// How many were skipped for `reason`.
    pub fn get(&self, reason: Skip) -> u64 {
        self.0[reason as usize]
    }

    /// The counts of `reasons`.
    pub fn from_reasons(reasons: impl IntoIterator<Item = Skip>) -> Self {
        let mut counts = SkipCounts::default();
        for r in reasons {
            counts.add(r);
        }
        counts
    }

    /// How many were skipped, for any reason.
    pub fn total(&self) -> u64 {
        self.0.iter().sum()
    }

    /// Whether none was skipped.
    pub fn is_empty(&self) -> bool {
        self.total() == 0
    }

    /// The reasons that occurred with their counts, in the order of
    /// [`Skip::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (Skip, u64)> + '_ {
        Skip::ALL
            .iter()
            .zip(self.0)
            .filter(|(_, n)| *n > 0)
            .map(|(r, n)| (*r, n))
    }

    /// In words: `12 back-facing, 3 out-of-reach candidates skipped`
    /// (`1 back-facing candidate skipped`); empty when none was.
    pub fn words(&self) -> String {
        if self.is_empty() {
            return String::new();
        }
        let parts: Vec<String> = self
            .iter()
            .map(|(r, n)| format!("{n} {}", r.words()))
            .collect();
        let noun = if self.total() == 1 {
            "candidate"
        } else {
            "candidates"
        };
        format!("{} {noun} skipped", parts.join(", "))
    }
}

impl std::ops::AddAssign for SkipCounts {
    fn add_assign(&mut self, other: SkipCounts) {
        for (n, m) in self.0.iter_mut().zip(other.0) {
            *n += m;
        }
    }
}

// `SkipCounts` counts at `reason as usize`: that must be its index in
// `Skip::ALL`.
const _: () = {
    let mut i = 0;
    while i < Skip::ALL.len() {
        assert!(Skip::ALL[i] as usize == i);
        i += 1;
    }
};

/// The observer of the fast path: wants nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;

impl Observer for NoObserver {
    const WANTS_RECORDS: bool = false;
}

/// The observer of the benchmark's per-node counts: runs what the fast
/// query runs (it wants no records, so the same candidates are skipped) and
/// counts, over the sweeps it observes, the nodes the broadphase opens, the
/// child boxes it tests, the leaves and candidate triangles it hands over,
/// and the candidates tested (their seven tests run) or skipped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CountVisits {
    /// Nodes of the tree opened.
    pub nodes: u64,
    /// Child boxes tested against the segment (up to `bvh::WIDTH`, eight, a node).
    pub boxes: u64,
    /// Leaves handed over.
    pub leaves: u64,
    /// Candidate triangles handed over (each reads its plane, the normal
    /// and first vertex kept apart from the records, for the skip tests).
    pub candidates: u64,
    /// Candidates tested: their face, edge and vertex tests ran (reading
    /// the whole record).
    pub tested: u64,
    /// Candidates skipped, by reason.
    pub skipped: SkipCounts,
}

impl Observer for CountVisits {
    const WANTS_RECORDS: bool = false;

    #[inline]
    fn node(&mut self, boxes: usize) {
        self.nodes += 1;
        self.boxes += boxes as u64;
    }
    #[inline]
    fn leaf(&mut self, triangles: usize) {
        self.leaves += 1;
        self.candidates += triangles as u64;
    }
    #[inline]
    fn skipped(&mut self, _triangle: u32, reason: Skip) {
        self.skipped.add(reason);
    }
    #[inline]
    fn face(&mut self, _record: &FaceRecord) {
        self.tested += 1;
    }
}

/// Any test's record.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "test", rename_all = "snake_case")]
pub enum TestRecord {
    /// A face test.
    Face(FaceRecord),
    /// An edge test.
    Edge(EdgeRecord),
    /// A vertex test.
    Vertex(VertexRecord),
}

impl TestRecord {
    /// The triangle tested.
    pub fn triangle(&self) -> u32 {
        match self {
            TestRecord::Face(r) => r.triangle,
            TestRecord::Edge(r) => r.triangle,
            TestRecord::Vertex(r) => r.triangle,
        }
    }
    /// The kind of feature tested.
    pub fn kind(&self) -> Kind {
        self.feature().kind()
    }
    /// The feature the test is about.
    pub fn feature(&self) -> Feature {
        match self {
            TestRecord::Face(_) => Feature::Face,
            TestRecord::Edge(r) => Feature::Edge(r.edge),
            TestRecord::Vertex(r) => Feature::Vertex(r.vertex),
        }
    }
    /// Whether the test ran on the triangle seen from its back (`sides = two`).
    pub fn back(&self) -> bool {
        match self {
            TestRecord::Face(r) => r.back,
            TestRecord::Edge(r) => r.back,
            TestRecord::Vertex(r) => r.back,
        }
    }
    /// The verdict.
    pub fn verdict(&self) -> Verdict {
        match self {
            TestRecord::Face(r) => r.verdict,
            TestRecord::Edge(r) => r.verdict,
            TestRecord::Vertex(r) => r.verdict,
        }
    }
    /// `α` if a hit.
    pub fn alpha(&self) -> Option<f64> {
        match self {
            TestRecord::Face(r) => r.alpha(),
            TestRecord::Edge(r) => r.alpha(),
            TestRecord::Vertex(r) => r.alpha(),
        }
    }

    /// The point of the mesh the test touches, if it is a hit: the face's
    /// touch point, the point `xc` on the edge, or the vertex. The one
    /// definition of a hit's contact (the outcome's `contact` is its
    /// primary test's).
    pub fn contact(&self) -> Option<Point3<f64>> {
        match self {
            TestRecord::Face(r) => r.hit().map(|h| h.touch),
            TestRecord::Edge(r) => r.contact(),
            TestRecord::Vertex(r) => r.alpha().map(|_| r.position),
        }
    }
}

/// An observer that keeps every record (for the explained query).
#[derive(Clone, Debug, Default)]
pub struct CollectRecords {
    /// The records, in the order the tests ran.
    pub records: Vec<TestRecord>,
}

impl Observer for CollectRecords {
    fn face(&mut self, r: &FaceRecord) {
        self.records.push(TestRecord::Face(*r));
    }
    fn edge(&mut self, r: &EdgeRecord) {
        self.records.push(TestRecord::Edge(*r));
    }
    fn vertex(&mut self, r: &VertexRecord) {
        self.records.push(TestRecord::Vertex(*r));
    }
}
