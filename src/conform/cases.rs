//! The conformance cases: small scenes and one sweep each, grouped by the
//! rule of docs/SEMANTICS.md they exercise, then the contact queries'
//! (super::contact_cases). Every number is exact in binary where the
//! rule's boundary matters, so the rules, not rounding, decide.

use crate::core::{Facing, Feature, Kind};
use crate::sim::scenes;
use crate::trace::{ContactMsg, SceneMsg, SweepMsg};

/// One case: a scene, a sweep or a contact query, and what the core
/// decides (checked by the test suite, so a case cannot silently stop
/// testing its rule).
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// The rule, e.g. `edge.miss.beyond-v1`.
    pub rule: &'static str,
    /// Index of the case within its rule, from 0.
    pub index: usize,
    /// What the case does, in words.
    pub what: &'static str,
    /// The scene.
    pub scene: SceneMsg,
    /// What the engine is asked (its frame is the case's number in the
    /// suite, ball 0).
    pub query: CaseQuery,
    /// The kind of the core's outcome; for a contact query, of its
    /// contact set's first contact (`none` when the set is empty).
    pub kind: Kind,
}

/// What a case asks the engine.
#[derive(Clone, Debug, PartialEq)]
pub enum CaseQuery {
    /// A sweep.
    Sweep(SweepMsg),
    /// A contact query (`conform --contacts`).
    Contact {
        /// The query.
        query: ContactMsg,
        /// The core's contact set for it: each contact's triangle and
        /// feature, in the set's order.
        set: Vec<(u32, Feature)>,
    },
}

impl Case {
    /// `rule/index`, the name `conform --case` takes.
    pub fn id(&self) -> String {
        format!("{}/{}", self.rule, self.index)
    }

    /// The case's frame: its number in the suite.
    pub fn frame(&self) -> u64 {
        match &self.query {
            CaseQuery::Sweep(sweep) => sweep.frame,
            CaseQuery::Contact { query, .. } => query.frame,
        }
    }

    /// Its sweep, unless it is a contact query.
    pub fn sweep(&self) -> Option<&SweepMsg> {
        match &self.query {
            CaseQuery::Sweep(sweep) => Some(sweep),
            CaseQuery::Contact { .. } => None,
        }
    }

    /// Its contact query, unless it is a sweep.
    pub fn contact(&self) -> Option<&ContactMsg> {
        match &self.query {
            CaseQuery::Sweep(_) => None,
            CaseQuery::Contact { query, .. } => Some(query),
        }
    }
}

/// Triangle T of the worked examples.
pub(super) fn triangle_t(margin: f64, facing: Facing) -> SceneMsg {
    scene(
        "triangle_t",
        vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        vec![[0, 1, 2]],
        margin,
        facing,
    )
}

pub(super) fn scene(
    name: &str,
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u64; 3]>,
    margin: f64,
    facing: Facing,
) -> SceneMsg {
    SceneMsg {
        name: Some(name.to_string()),
        vertices,
        triangles,
        margin,
        facing,
    }
}

fn cube() -> SceneMsg {
    let mesh = scenes::cube();
    scene(
        &mesh.name,
        mesh.vertices,
        mesh.triangles,
        0.0,
        Facing::NonStrict,
    )
}

/// A square `[0, 2]²` at z = 0 as two triangles sharing the diagonal.
pub(super) fn quad() -> SceneMsg {
    scene(
        "quad",
        vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        0.0,
        Facing::NonStrict,
    )
}

/// A pyramid: apex (0, 0, 1) over the square `[-1, 1]²` at z = 0, four
/// triangles facing up and out.
fn pyramid() -> SceneMsg {
    scene(
        "pyramid",
        vec![
            [0.0, 0.0, 1.0],
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
        0.0,
        Facing::NonStrict,
    )
}

/// A floor at z = 0 (triangle 1, facing up) over a fin (triangle 0) whose
/// edge 2, from (2, 1, 0) to (0, 1, 0), lies in the floor's plane; the fin
/// hangs below it, slanted, facing up and toward -y.
fn fin_under_floor() -> SceneMsg {
    scene(
        "fin_under_floor",
        vec![
            [0.0, 1.0, 0.0],
            [1.0, 0.0, -1.0],
            [2.0, 1.0, 0.0],
            [-1.0, -1.0, 0.0],
            [4.0, -1.0, 0.0],
            [-1.0, 4.0, 0.0],
        ],
        vec![[0, 1, 2], [3, 4, 5]],
        0.0,
        Facing::NonStrict,
    )
}

/// Triangle T listed third, after a triangle with a repeated index and a
/// zero-area one lying on T's edge 0.
fn with_degenerate() -> SceneMsg {
    scene(
        "degenerate",
        vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            [2.0, 0.0, 0.0],
        ],
        vec![[0, 0, 1], [0, 3, 1], [0, 1, 2]],
        0.0,
        Facing::NonStrict,
    )
}

/// A floor at z = 0 listed first (triangle 0) under a smaller platform at
/// z = 1 (triangle 1): a ball coming down meets the platform first, though
/// the floor comes first in the list and in a walk of the triangles by
/// index.
fn platform_over_floor() -> SceneMsg {
    scene(
        "platform_over_floor",
        vec![
            [-2.0, -2.0, 0.0],
            [6.0, -2.0, 0.0],
            [-2.0, 6.0, 0.0],
            [-1.0, -1.0, 1.0],
            [3.0, -1.0, 1.0],
            [-1.0, 3.0, 1.0],
        ],
        vec![[0, 1, 2], [3, 4, 5]],
        0.0,
        Facing::NonStrict,
    )
}

/// A ridge along the y axis: two triangles sharing the edge from
/// (0, 2, 0) to (0, -2, 0) (edge 2 of each), each falling away at a slope
/// of 1/8, so their normals (±1, 0, 8)/√65 meet at 2·atan(1/8) ≈ 14.25°: a
/// convex edge, active under a 5° threshold, inactive under 30°.
fn shallow_ridge() -> SceneMsg {
    scene(
        "shallow_ridge",
        vec![
            [0.0, -2.0, 0.0],
            [2.0, 0.0, -0.25],
            [0.0, 2.0, 0.0],
            [-2.0, 0.0, -0.25],
        ],
        vec![[0, 1, 2], [2, 3, 0]],
        0.0,
        Facing::NonStrict,
    )
}

/// Cells per side of [`terrain`].
const TERRAIN_CELLS: usize = 40;

/// A height field of 40 × 40 unit cells, 3,200 triangles: vertex (i, j) at
/// (i, j, (i - 20)(j - 20)/128), a saddle, so no two triangles of a cell
/// are coplanar. Cell (i, j) is triangles 2(40j + i) (below its diagonal)
/// and 2(40j + i) + 1 (above it), both facing up. Every number is exact in
/// binary and in single precision.
fn terrain() -> SceneMsg {
    let n = TERRAIN_CELLS;
    let mut vertices = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64, j as f64);
            vertices.push([x, y, (x - 20.0) * (y - 20.0) / 128.0]);
        }
    }
    let v = |i: usize, j: usize| (j * (n + 1) + i) as u64;
    let mut triangles = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    scene("terrain", vertices, triangles, 0.0, Facing::NonStrict)
}

/// A sweep straight down onto triangle `2(40j + i) + upper` of [`terrain`]
/// (cell (i, j), the triangle above its diagonal when `upper`), through a
/// point 1/4 from two of its edges: a ball of radius 1/8 touches that face
/// and nothing else.
fn onto_terrain(i: usize, j: usize, upper: bool) -> ([f64; 3], [f64; 3]) {
    let (u, w) = if upper { (0.25, 0.75) } else { (0.75, 0.25) };
    let (x, y) = (i as f64 + u, j as f64 + w);
    ([x, y, 5.0], [x, y, -5.0])
}

/// Every case, in the order of [`RULES`](super::RULES), numbered as frames
/// from 0: the sweeps, then the contact queries.
pub fn cases() -> Vec<Case> {
    let t = || triangle_t(0.0, Facing::NonStrict);
    let tm = || triangle_t(0.125, Facing::NonStrict);
    let ts = || triangle_t(0.0, Facing::Strict);
    type Spec = (
        &'static str,
        &'static str,
        SceneMsg,
        f64,
        [f64; 3],
        [f64; 3],
        Kind,
    );
    let mut specs: Vec<Spec> = vec![
        (
            "face.hit",
            "straight down onto the middle (worked example 1)",
            t(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "face.hit",
            "slanted onto the face",
            t(),
            0.5,
            [1.5, 0.75, 2.0],
            [1.25, 1.0, -1.0],
            Kind::Face,
        ),
        (
            "face.hit",
            "a small ball that stops just past the plane",
            t(),
            0.25,
            [0.5, 2.5, 1.0],
            [0.5, 2.5, 0.0],
            Kind::Face,
        ),
        (
            "face.near-edge",
            "down onto the face 1/64 from edge 0: 0.39 % of the altitude",
            t(),
            0.5,
            [2.0, 0.015625, 3.0],
            [2.0, 0.015625, -3.0],
            Kind::Face,
        ),
        (
            "face.near-edge",
            "down onto the face 1/64 inside the hypotenuse (x + y = 4 - 1/64): 0.39 % of the altitude",
            t(),
            0.5,
            [2.0, 1.984375, 3.0],
            [2.0, 1.984375, -3.0],
            Kind::Face,
        ),
        (
            "face.miss.outside-triangle",
            "down beside the hypotenuse, far from it",
            t(),
            0.5,
            [3.0, 3.0, 3.0],
            [3.0, 3.0, -3.0],
            Kind::None,
        ),
        (
            "face.miss.beyond-end",
            "stops above the plane",
            t(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, 1.0],
            Kind::None,
        ),
        (
            "face.miss.parallel",
            "flies over the face at height 2",
            t(),
            0.5,
            [1.0, 1.0, 2.0],
            [2.0, 1.0, 2.0],
            Kind::None,
        ),
        (
            "face.miss.back-facing",
            "up through the triangle from behind",
            t(),
            0.5,
            [1.0, 1.0, -3.0],
            [1.0, 1.0, 3.0],
            Kind::None,
        ),
        (
            "start.inside",
            "starts 0.25 above the face and moves down through it",
            t(),
            0.5,
            [1.0, 1.0, 0.25],
            [1.0, 1.0, -1.0],
            Kind::None,
        ),
        (
            "start.touching",
            "starts exactly ρ above the face, moving down",
            t(),
            0.5,
            [1.0, 1.0, 0.5],
            [1.0, 1.0, -1.0],
            Kind::Face,
        ),
        (
            "start.moving-away",
            "starts 0.25 above the face (within ρ) and moves straight up, away",
            t(),
            0.5,
            [1.0, 1.0, 0.25],
            [1.0, 1.0, 3.0],
            Kind::None,
        ),
        (
            "start.moving-away",
            "starts exactly ρ above the face (touching) and moves straight up, away",
            t(),
            0.5,
            [1.0, 1.0, 0.5],
            [1.0, 1.0, 3.0],
            Kind::None,
        ),
        (
            "start.moving-away",
            "starts 0.25 above the face and leaves it slanted, up and sideways",
            t(),
            0.5,
            [1.0, 1.0, 0.25],
            [2.0, 1.5, 2.0],
            Kind::None,
        ),
        (
            "path.zero-length",
            "resting above the face",
            t(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, 3.0],
            Kind::None,
        ),
        (
            "path.zero-length",
            "resting on the face, within ρ",
            t(),
            0.5,
            [1.0, 1.0, 0.25],
            [1.0, 1.0, 0.25],
            Kind::None,
        ),
        (
            "edge.hit",
            "down past edge 0 (worked example 2)",
            t(),
            0.5,
            [2.0, -0.3, 3.0],
            [2.0, -0.3, -3.0],
            Kind::Edge,
        ),
        (
            "edge.hit",
            "down past edge 1, the hypotenuse",
            t(),
            0.5,
            [2.25, 2.0, 3.0],
            [2.25, 2.0, -3.0],
            Kind::Edge,
        ),
        (
            "edge.hit",
            "slanted onto edge 2",
            t(),
            0.5,
            [-1.0, 2.0, 3.0],
            [0.5, 2.0, -3.0],
            Kind::Edge,
        ),
        (
            "edge.miss.no-real-roots",
            "down 0.75 beside edge 0",
            t(),
            0.5,
            [2.0, -0.75, 3.0],
            [2.0, -0.75, -3.0],
            Kind::None,
        ),
        (
            "edge.miss.before-start",
            "starts against edge 0, moves away in the plane's direction",
            t(),
            0.5,
            [2.0, -0.25, 0.125],
            [2.0, -3.0, 0.125],
            Kind::None,
        ),
        (
            "edge.miss.beyond-end",
            "stops above edge 0",
            t(),
            0.5,
            [2.0, -0.3, 3.0],
            [2.0, -0.3, 1.0],
            Kind::None,
        ),
        (
            "edge.miss.beyond-v1",
            "down past the end v1 = (4, 0, 0) of edge 0: vertex 1",
            t(),
            0.5,
            [4.25, -0.25, 3.0],
            [4.25, -0.25, -3.0],
            Kind::Vertex,
        ),
        (
            "edge.miss.before-v0",
            "down before the start v0 = (0, 0, 0) of edge 0: vertex 0 (worked example 3)",
            t(),
            0.5,
            [-0.3, -0.2, 3.0],
            [-0.3, -0.2, -3.0],
            Kind::Vertex,
        ),
        (
            "edge.miss.parallel",
            "along edge 0's direction, 0.25 beside it and 0.125 above",
            t(),
            0.5,
            [1.0, -0.25, 0.125],
            [3.0, -0.25, 0.125],
            Kind::None,
        ),
        (
            "edge.miss.back-facing",
            "up past edge 0 from behind",
            t(),
            0.5,
            [2.0, -0.3, -3.0],
            [2.0, -0.3, 3.0],
            Kind::None,
        ),
        (
            "vertex.hit",
            "down by vertex 0",
            t(),
            0.5,
            [-0.25, -0.25, 3.0],
            [-0.25, -0.25, -3.0],
            Kind::Vertex,
        ),
        (
            "vertex.hit",
            "slanted onto vertex 2",
            t(),
            0.5,
            [-1.0, 5.0, 2.0],
            [0.0, 4.0, -1.0],
            Kind::Vertex,
        ),
        (
            "vertex.miss.no-real-roots",
            "down 0.75 diagonally away from vertex 0",
            t(),
            0.5,
            [-0.625, -0.625, 3.0],
            [-0.625, -0.625, -3.0],
            Kind::None,
        ),
        (
            "vertex.miss.before-start",
            "starts against vertex 0 and moves away from it",
            t(),
            0.5,
            [-0.25, -0.25, 0.125],
            [-3.0, -3.0, 0.125],
            Kind::None,
        ),
        (
            "vertex.miss.beyond-end",
            "stops above vertex 0",
            t(),
            0.5,
            [-0.25, -0.25, 3.0],
            [-0.25, -0.25, 1.0],
            Kind::None,
        ),
        (
            "end.exact-hit",
            "touches edge 0 exactly at the end (worked example 4)",
            t(),
            0.625,
            [2.0, -0.375, 3.0],
            [2.0, -0.375, 0.5],
            Kind::Edge,
        ),
        (
            "tie.edge-end",
            "down onto the end v1 of edge 0: edge and vertex at the same α",
            t(),
            0.5,
            [4.0, -0.25, 3.0],
            [4.0, -0.25, -3.0],
            Kind::Edge,
        ),
        (
            "tie.shared-edge.planar",
            "down onto the diagonal of a square of two triangles",
            quad(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "tie.shared-edge.cube",
            "down onto the cube's edge x = 1, z = 1 (worked example 5)",
            cube(),
            0.5,
            [1.25, 0.125, 3.0],
            [1.25, 0.125, -3.0],
            Kind::Edge,
        ),
        (
            "tie.shared-vertex",
            "straight down onto a pyramid's apex",
            pyramid(),
            0.5,
            [0.0, 0.0, 3.0],
            [0.0, 0.0, -3.0],
            Kind::Vertex,
        ),
        (
            "tie.kind-order",
            "straight down onto vertex 0 of T: face, edges 0 and 2 and vertex 0 at one α",
            t(),
            0.5,
            [0.0, 0.0, 3.0],
            [0.0, 0.0, -3.0],
            Kind::Face,
        ),
        (
            "tie.across-kinds",
            "down onto a floor (triangle 1) where the top edge of a fin below it (triangle 0) lies",
            fin_under_floor(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "tie.feature-order",
            "at height 0.375 < ρ toward vertex 0 along the bisector: edges 0 and 2 at β = 0.8",
            t(),
            0.625,
            [1.5, 1.5, 0.375],
            [0.25, 0.25, 0.375],
            Kind::Edge,
        ),
        (
            "tie.cube-corner",
            "diagonally at the cube's corner (1, 1, 1)",
            cube(),
            0.5,
            [3.0, 3.0, 3.0],
            [0.0, 0.0, 0.0],
            Kind::Vertex,
        ),
        (
            "tie.cube-corner",
            "diagonally at the cube's corner (-1, 1, -1)",
            cube(),
            0.25,
            [-2.0, 2.0, -2.0],
            [0.0, 0.0, 0.0],
            Kind::Vertex,
        ),
        (
            "normal.shallow-convex-edge",
            "straight down onto a ridge whose faces meet at 14.25°",
            shallow_ridge(),
            0.5,
            [0.0, 0.5, 3.0],
            [0.0, 0.5, -3.0],
            Kind::Edge,
        ),
        (
            "normal.flat-edge",
            "straight down onto the diagonal shared by two coplanar triangles",
            quad(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "normal.flat-edge",
            "slanted across the diagonal, landing on it at (0.5, 0.5)",
            quad(),
            0.5,
            [0.0, 1.0, 2.5],
            [1.0, 0.0, -1.5],
            Kind::Face,
        ),
        (
            "grazing.face-hit",
            "descends 2^-9 over a run of 2 onto the face",
            t(),
            0.5,
            [0.5, 1.0, 0.5009765625],
            [2.5, 1.0, 0.4990234375],
            Kind::Face,
        ),
        (
            "grazing.edge-tangent",
            "down exactly ρ beside edge 0",
            t(),
            0.5,
            [2.0, -0.5, 3.0],
            [2.0, -0.5, -3.0],
            Kind::Edge,
        ),
        (
            "margin.face-hit",
            "worked example 1 with ε = 0.125",
            tm(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "margin.edge-miss",
            "down 0.4375 beside edge 0: within r = 0.5, beyond ρ = 0.375",
            tm(),
            0.5,
            [2.0, -0.4375, 3.0],
            [2.0, -0.4375, -3.0],
            Kind::None,
        ),
        (
            "margin.vertex-hit",
            "down by vertex 0 with ε = 0.125",
            tm(),
            0.5,
            [-0.25, -0.125, 3.0],
            [-0.25, -0.125, -3.0],
            Kind::Vertex,
        ),
        (
            "facing.non-strict",
            "in the plane toward edge 0 (n·d = 0)",
            t(),
            0.5,
            [2.0, -3.0, 0.0],
            [2.0, -0.25, 0.0],
            Kind::Edge,
        ),
        (
            "facing.strict",
            "the same in-plane path under the strict rule",
            ts(),
            0.5,
            [2.0, -3.0, 0.0],
            [2.0, -0.25, 0.0],
            Kind::None,
        ),
        (
            "facing.strict",
            "straight down onto the face under the strict rule",
            ts(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "degenerate.skipped",
            "down onto triangle T, listed after two degenerate triangles",
            with_degenerate(),
            0.5,
            [1.0, 1.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
        (
            "degenerate.skipped",
            "up at T's edge 0 from behind, where a zero-area triangle lies",
            with_degenerate(),
            0.5,
            [2.0, -0.25, -3.0],
            [2.0, -0.25, 3.0],
            Kind::None,
        ),
        (
            "mesh.closest-hit",
            "down onto a platform (triangle 1) over a floor listed first (triangle 0)",
            platform_over_floor(),
            0.5,
            [0.25, 0.5, 3.0],
            [0.25, 0.5, -3.0],
            Kind::Face,
        ),
        (
            "mesh.closest-hit",
            "slanted onto the platform, the floor below it listed first",
            platform_over_floor(),
            0.5,
            [-0.5, 0.0, 3.0],
            [1.0, 1.0, -3.0],
            Kind::Face,
        ),
    ];
    // Cells far apart in space and in index, both sides of every halving
    // of the triangle list: triangles 162, 317, 860, 1720, 2471 and 2968.
    for (what, (i, j, upper)) in [
        ("down onto cell (1, 2), triangle 162", (1, 2, false)),
        ("down onto cell (38, 3), triangle 317", (38, 3, true)),
        ("down onto cell (30, 10), triangle 860", (30, 10, false)),
        ("down onto cell (20, 21), triangle 1720", (20, 21, false)),
        ("down onto cell (35, 30), triangle 2471", (35, 30, true)),
        ("down onto cell (4, 37), triangle 2968", (4, 37, false)),
    ] {
        let (p0, p1) = onto_terrain(i, j, upper);
        specs.push(("mesh.large", what, terrain(), 0.125, p0, p1, Kind::Face));
    }
    let mut out: Vec<Case> = Vec::with_capacity(specs.len());
    for (frame, (rule, what, scene, radius, p0, p1, kind)) in specs.into_iter().enumerate() {
        let index = out.iter().filter(|c| c.rule == rule).count();
        out.push(Case {
            rule,
            index,
            what,
            scene,
            query: CaseQuery::Sweep(SweepMsg {
                frame: frame as u64,
                ball: 0,
                radius,
                p0,
                p1,
            }),
            kind,
        });
    }
    let first = out.len() as u64;
    out.extend(super::contact_cases::contact_cases(first));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{Feature, Mesh, Options, Outcome, Sweep, sweep_mesh};

    /// The core's outcome of `case` under the rules.
    fn outcome(case: &Case) -> Outcome {
        let mesh = Mesh::new(case.scene.vertices.clone(), &case.scene.triangles).expect("mesh");
        let s = case.sweep().expect("a sweep case");
        sweep_mesh(
            &mesh,
            &Sweep::new(s.p0, s.p1, s.radius),
            &Options::default(),
        )
        .expect("sweep")
    }

    fn of_rule(rule: &str) -> Vec<Case> {
        let chosen: Vec<Case> = cases().into_iter().filter(|c| c.rule == rule).collect();
        assert!(!chosen.is_empty(), "no case of {rule}");
        chosen
    }

    #[test]
    fn the_closest_hit_is_the_later_listed_triangle() {
        for case in of_rule("mesh.closest-hit") {
            let hit = outcome(&case).hit.expect("a hit");
            assert_eq!(
                (hit.triangle, hit.feature),
                (1, Feature::Face),
                "{}",
                case.id()
            );
            // Triangle 0 alone is hit too, later: the case tells them apart.
            let mut alone = case.clone();
            alone.scene.triangles.truncate(1);
            let later = outcome(&alone).hit.expect("the floor is on the path");
            assert!(later.alpha > hit.alpha, "{}", case.id());
        }
    }

    #[test]
    fn the_large_mesh_is_hit_where_each_case_says() {
        let chosen = of_rule("mesh.large");
        assert!(chosen.len() >= 6);
        assert_eq!(chosen[0].scene.triangles.len(), 3200);
        let mut below_half = 0;
        for case in &chosen {
            let hit = outcome(case).hit.expect("a hit");
            assert_eq!(hit.feature, Feature::Face, "{}", case.id());
            assert!(
                case.what.ends_with(&format!("triangle {}", hit.triangle)),
                "{}: hits triangle {}",
                case.id(),
                hit.triangle
            );
            below_half += usize::from(hit.triangle < 1600);
        }
        assert!(below_half >= 2 && chosen.len() - below_half >= 2);
    }

    #[test]
    fn the_near_edge_contacts_are_within_half_a_percent_of_the_altitude() {
        for case in of_rule("face.near-edge") {
            let hit = outcome(&case).hit.expect("a hit");
            assert_eq!(hit.feature, Feature::Face, "{}", case.id());
            // Triangle T: altitudes 4 (edges 0 and 2) and 2√2 (edge 1).
            let c = hit.contact;
            let weights = [(4.0 - c.x - c.y) / 4.0, c.x / 4.0, c.y / 4.0];
            let least = weights.iter().copied().fold(f64::INFINITY, f64::min);
            assert!(least > 1e-4 && least < 5e-3, "{}: {weights:?}", case.id());
        }
    }

    #[test]
    fn the_ridge_is_a_tie_whose_faces_meet_between_5_and_30_degrees() {
        for case in of_rule("normal.shallow-convex-edge") {
            let mesh = Mesh::new(case.scene.vertices.clone(), &case.scene.triangles).expect("mesh");
            let [a, b] = [0, 1].map(|t| mesh.triangle_by_index(t).expect("triangle").normal);
            let degrees = a.dot(&b).acos().to_degrees();
            assert!(degrees > 10.0 && degrees < 20.0, "{degrees}°");
            let hit = outcome(&case).hit.expect("a hit");
            assert_eq!((hit.triangle, hit.feature), (0, Feature::Edge(2)));
            assert!((hit.normal - nalgebra::Vector3::z()).norm() < 1e-12);
        }
    }
}
