//! The conformance cases: small scenes and one sweep each, grouped by the
//! rule of docs/SEMANTICS.md they exercise. Every number is exact in
//! binary where the rule's boundary matters, so the rules, not rounding,
//! decide.

use crate::core::{Facing, Kind};
use crate::sim::scenes;
use crate::trace::{SceneMsg, SweepMsg};

/// One case: a scene, a sweep, and the kind the core decides (checked by
/// the test suite, so a case cannot silently stop testing its rule).
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
    /// The sweep (its frame is the case's number in the suite, ball 0).
    pub sweep: SweepMsg,
    /// The kind of the core's outcome.
    pub kind: Kind,
}

impl Case {
    /// `rule/index`, the name `conform --case` takes.
    pub fn id(&self) -> String {
        format!("{}/{}", self.rule, self.index)
    }
}

/// Triangle T of the worked examples.
fn triangle_t(margin: f64, facing: Facing) -> SceneMsg {
    scene(
        "triangle_t",
        vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        vec![[0, 1, 2]],
        margin,
        facing,
    )
}

fn scene(
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
fn quad() -> SceneMsg {
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

/// Every case, in the order of [`RULES`](super::RULES), numbered as frames from 0.
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
    let specs: Vec<Spec> = vec![
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
    ];
    let mut out: Vec<Case> = Vec::with_capacity(specs.len());
    for (frame, (rule, what, scene, radius, p0, p1, kind)) in specs.into_iter().enumerate() {
        let index = out.iter().filter(|c| c.rule == rule).count();
        out.push(Case {
            rule,
            index,
            what,
            scene,
            sweep: SweepMsg {
                frame: frame as u64,
                ball: 0,
                radius,
                p0,
                p1,
            },
            kind,
        });
    }
    out
}
