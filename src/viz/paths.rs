//! Every entity path of a replay recording, in one place.
//!
//! ```text
//! world                               view coordinates (right-handed, z up), static
//! world/mesh/{scene}                  Mesh3D of each scene, static
//! world/mesh/{scene}/wireframe        LineStrips3D: every triangle edge once, static
//! world/ball/{ball}/spheres           Ellipsoids3D: the ball at p0, at the contact, at p1
//! world/ball/{ball}/sweep             Capsules3D: the volume swept with radius ρ (wireframe)
//! world/ball/{ball}/contact           Points3D: the contact point
//! world/ball/{ball}/normal            Arrows3D: the reported normal, from the contact
//! world/ball/{ball}/focus             Transform3D: the ball at the decision (at α), scaled
//!                                     to its surroundings; the origin of the view that
//!                                     follows the ball (logged for the followed ball only)
//! world/ball/{ball}/primary/triangle  Mesh3D: the primary (or nearest-miss) triangle
//! world/ball/{ball}/primary/outline   LineStrips3D: its three edges (labelled for a face test)
//! world/ball/{ball}/primary/edge      LineStrips3D: its edge, bold, when the test is an edge test
//! world/ball/{ball}/primary/vertex    Points3D: its vertex, when the test is a vertex test
//! world/ball/{ball}/expected/ball     Ellipsoids3D: the ball at the expected α, when the
//!                                     sweep diverges from the trace's expectation
//! world/ball/{ball}/expected/contact  Points3D: the expected contact (idem)
//! world/ball/{ball}/expected/normal   Arrows3D: the expected normal (idem)
//! world/ball/{ball}/tunnel           Points3D: where the ball's centre went through a
//!                                     triangle front to back (during this sweep or since
//!                                     its previous one), labelled with the triangle
//! world/ball/{ball}/edge/{slot}       Transform3D world_from_edge of one logged edge test,
//!                                     plus its numbers (AnyValues: test, verdict, length,
//!                                     a, b, c, discriminant, s0, s1, xc; s0, s1 and xc
//!                                     empty when the test did not compute them)
//! world/ball/{ball}/edge/{slot}/edge      LineStrips3D (0,0,0)→(L,0,0) in the edge frame
//! world/ball/{ball}/edge/{slot}/cylinder  Capsules3D of radius ρ around the edge
//! world/ball/{ball}/edge/{slot}/path      LineStrips3D p0_in_edge→p1_in_edge
//! world/ball/{ball}/edge/{slot}/points    Points3D p0_in_edge, p1_in_edge, the ball's
//!                                         center at s0 and s1 (when real), xc on the edge
//! world/ball/{ball}/edge/0/axes           Arrows3D: the frame's x, y (front normal), z axes
//! plots/ball/{ball}/alpha             Scalars: the chosen α (AnyValues `kind` alongside)
//! plots/ball/{ball}/quadratic/{a,b,c,discriminant,s0,s1}
//!                                     Scalars of the decisive edge or vertex test
//! plots/ball/{ball}/face/{h0,h1,beta} Scalars of the decisive face test
//! status/ball/{ball}                  Scalars: 0 when the sweep matches its expectation,
//!                                     1 when it diverges (sweeps with an expectation only)
//! status/ball/{ball}/fragile          Scalars: 1 at each fragile decision (absent elsewhere)
//! log                                 TextLog: one line per sweep, the decision in words
//! divergences                         TextLog: one line per divergent sweep and one
//!                                     WARN line per tunnel
//! ```
//!
//! Slot 0 of `edge` is the decisive test when it is an edge test (the
//! primary test, or the nearest miss); when the decision was a face or
//! vertex test (or the nearest miss was one), it is the nearest edge test of
//! the same triangle. The edge-frame view of the default blueprint looks at
//! `world/ball/{followed}/edge/0`.

/// Root of the 3D world.
pub const WORLD: &str = "world";
/// The text log.
pub const LOG: &str = "log";
/// Root of the time-series plots.
pub const PLOTS: &str = "plots";
/// Root of the per-ball divergence status series.
pub const STATUS: &str = "status";
/// The log of divergent sweeps.
pub const DIVERGENCES: &str = "divergences";

/// The static wireframe of scene `scene`.
pub fn wireframe(scene: usize) -> String {
    format!("world/mesh/{scene}/wireframe")
}

/// The view-following transform of one ball.
pub fn focus(ball: u32) -> String {
    format!("world/ball/{ball}/focus")
}

/// The outline of the primary triangle.
pub fn primary_outline(ball: u32) -> String {
    format!("world/ball/{ball}/primary/outline")
}

/// Root of the expected outcome drawn for a divergent sweep.
pub fn expected(ball: u32) -> String {
    format!("world/ball/{ball}/expected")
}

/// The ball at the expected α.
pub fn expected_ball(ball: u32) -> String {
    format!("world/ball/{ball}/expected/ball")
}

/// The expected contact point.
pub fn expected_contact(ball: u32) -> String {
    format!("world/ball/{ball}/expected/contact")
}

/// The expected normal.
pub fn expected_normal(ball: u32) -> String {
    format!("world/ball/{ball}/expected/normal")
}

/// Where the ball's centre went through a triangle.
pub fn tunnel(ball: u32) -> String {
    format!("world/ball/{ball}/tunnel")
}

/// The divergence status series of one ball.
pub fn status(ball: u32) -> String {
    format!("status/ball/{ball}")
}

/// The fragile-decision marks of one ball.
pub fn fragile(ball: u32) -> String {
    format!("status/ball/{ball}/fragile")
}

/// Under [`edge_frame`]: the frame's axes.
pub fn edge_axes(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}/axes")
}

/// The mesh of scene `scene` (0-based).
pub fn mesh(scene: usize) -> String {
    format!("world/mesh/{scene}")
}

/// Root of everything of one ball in the world.
pub fn ball(ball: u32) -> String {
    format!("world/ball/{ball}")
}

/// The ball at p0, at the contact and at p1.
pub fn spheres(ball: u32) -> String {
    format!("world/ball/{ball}/spheres")
}

/// The swept volume.
pub fn sweep(ball: u32) -> String {
    format!("world/ball/{ball}/sweep")
}

/// The contact point.
pub fn contact(ball: u32) -> String {
    format!("world/ball/{ball}/contact")
}

/// The reported normal.
pub fn normal(ball: u32) -> String {
    format!("world/ball/{ball}/normal")
}

/// The highlighted triangle of the decisive test.
pub fn primary_triangle(ball: u32) -> String {
    format!("world/ball/{ball}/primary/triangle")
}

/// The highlighted edge of the decisive test.
pub fn primary_edge(ball: u32) -> String {
    format!("world/ball/{ball}/primary/edge")
}

/// The highlighted vertex of the decisive test.
pub fn primary_vertex(ball: u32) -> String {
    format!("world/ball/{ball}/primary/vertex")
}

/// The standard frame of the `slot`-th logged edge test (a Transform3D).
pub fn edge_frame(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}")
}

/// Under [`edge_frame`]: the edge on +x.
pub fn edge_segment(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}/edge")
}

/// Under [`edge_frame`]: the cylinder of radius ρ around the edge.
pub fn edge_cylinder(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}/cylinder")
}

/// Under [`edge_frame`]: the path in the edge frame.
pub fn edge_path(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}/path")
}

/// Under [`edge_frame`]: p0, p1 (and the center at s0) in the edge frame.
pub fn edge_points(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}/points")
}

/// The chosen α.
pub fn alpha(ball: u32) -> String {
    format!("plots/ball/{ball}/alpha")
}

/// One value of the decisive quadratic: `name` is `a`, `b`, `c`,
/// `discriminant`, `s0` or `s1`.
pub fn quadratic(ball: u32, name: &str) -> String {
    format!("plots/ball/{ball}/quadratic/{name}")
}

/// One value of the decisive face test: `name` is `h0`, `h1` or `beta`.
pub fn face(ball: u32, name: &str) -> String {
    format!("plots/ball/{ball}/face/{name}")
}

/// Names of the quadratic scalars, in order.
pub const QUADRATIC_NAMES: [&str; 6] = ["a", "b", "c", "discriminant", "s0", "s1"];
/// Names of the face scalars, in order.
pub const FACE_NAMES: [&str; 3] = ["h0", "h1", "beta"];

/// A per-frame entity of a sweep, as a small value (the path as a string is
/// built once per entity, by [`Entity::path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Entity {
    Spheres(u32),
    Sweep(u32),
    Contact(u32),
    Normal(u32),
    Focus(u32),
    PrimaryTriangle(u32),
    PrimaryOutline(u32),
    PrimaryEdge(u32),
    PrimaryVertex(u32),
    EdgeFrame(u32, usize),
    EdgeSegment(u32, usize),
    EdgeCylinder(u32, usize),
    EdgePath(u32, usize),
    EdgePoints(u32, usize),
    EdgeAxes(u32, usize),
    Expected(u32),
    ExpectedBall(u32),
    ExpectedContact(u32),
    ExpectedNormal(u32),
    Tunnel(u32),
    Status(u32),
    Fragile(u32),
    Divergences,
    Alpha(u32),
    /// Index into [`QUADRATIC_NAMES`].
    Quadratic(u32, usize),
    /// Index into [`FACE_NAMES`].
    Face(u32, usize),
    Log,
}

impl Entity {
    /// The entity path.
    pub(crate) fn path(self) -> String {
        match self {
            Entity::Spheres(b) => spheres(b),
            Entity::Sweep(b) => sweep(b),
            Entity::Contact(b) => contact(b),
            Entity::Normal(b) => normal(b),
            Entity::Focus(b) => focus(b),
            Entity::PrimaryTriangle(b) => primary_triangle(b),
            Entity::PrimaryOutline(b) => primary_outline(b),
            Entity::PrimaryEdge(b) => primary_edge(b),
            Entity::PrimaryVertex(b) => primary_vertex(b),
            Entity::EdgeFrame(b, s) => edge_frame(b, s),
            Entity::EdgeSegment(b, s) => edge_segment(b, s),
            Entity::EdgeCylinder(b, s) => edge_cylinder(b, s),
            Entity::EdgePath(b, s) => edge_path(b, s),
            Entity::EdgePoints(b, s) => edge_points(b, s),
            Entity::EdgeAxes(b, s) => edge_axes(b, s),
            Entity::Expected(b) => expected(b),
            Entity::ExpectedBall(b) => expected_ball(b),
            Entity::ExpectedContact(b) => expected_contact(b),
            Entity::ExpectedNormal(b) => expected_normal(b),
            Entity::Tunnel(b) => tunnel(b),
            Entity::Status(b) => status(b),
            Entity::Fragile(b) => fragile(b),
            Entity::Divergences => DIVERGENCES.to_string(),
            Entity::Alpha(b) => alpha(b),
            Entity::Quadratic(b, i) => quadratic(b, QUADRATIC_NAMES[i]),
            Entity::Face(b, i) => face(b, FACE_NAMES[i]),
            Entity::Log => LOG.to_string(),
        }
    }
}
