//! Every entity path of a replay recording, in one place.
//!
//! ```text
//! world                               view coordinates (right-handed, z up), static
//! world/mesh/{scene}                  Mesh3D of each scene, at its first sweep's frame,
//!                                     cleared (with its children) where the next scene shows
//! world/mesh/{scene}/edges/{class}    LineStrips3D: the edges of one class (boundary,
//!                                     convex, flat, concave, non_manifold; see
//!                                     `core::topology::EdgeClass`), a strip each, in the class's
//!                                     colour and width, with the mesh (a class the mesh has no
//!                                     edge of is not logged)
//! world/mesh/{scene}/defects/{kind}   Points3D: the defects of one kind (flipped,
//!                                     crack, t_junction, ...; see `core::topology::DefectKind`),
//!                                     a point at each with one label each
//!                                     ("flipped triangle 812"), with the mesh (a kind the mesh
//!                                     has none of is not logged)
//! world/ball/{ball}                   the sweep, one row per sweep (cleared, with its
//!                                     children, where a new scene shows):
//!                                       Ellipsoids3D: the ball at p0, at the contact, at p1
//!                                       Capsules3D: the volume swept with radius ρ (wireframe)
//!                                       Points3D: the contact point (none when nothing is hit)
//!                                       Arrows3D: the reported normal, from the contact (idem)
//! world/ball/{ball}/focus             Transform3D: the ball at the decision (at α), scaled
//!                                     to its surroundings; the origin of the view that
//!                                     follows the ball (logged for the followed ball only)
//! world/ball/{ball}/primary           the primary (or nearest-miss) triangle:
//!                                       Mesh3D: the triangle, filled
//!                                       LineStrips3D: its three edges (labelled for a face
//!                                       test), then its edge, bold, for an edge test
//!                                       (labelled; the outline's label is then empty)
//!                                       Points3D: its vertex, labelled, for a vertex test
//!                                       (else none)
//! world/ball/{ball}/expected          the expected outcome, when the sweep diverges from
//!                                     the trace's expectation:
//!                                       Ellipsoids3D: the ball at the expected α
//!                                       Points3D: the expected contact (none when the
//!                                       expectation names none)
//!                                       Arrows3D: the expected normal, from that contact
//!                                       (none without a contact or a usable normal)
//! world/ball/{ball}/tunnel            Points3D: where the ball's centre went through a
//!                                     triangle front to back (during this sweep or since
//!                                     its previous one), labelled with the triangle
//! world/ball/{ball}/ghost             a ghost contact, when the sweep's expected outcome is
//!                                     one (see `replay::ghost::judge_ghost`):
//!                                       Points3D: the expected contact, labelled
//!                                       (`ghost contact 10.0°: edge 0.2 is internal and
//!                                       flat`; the label is the expected ball's instead
//!                                       when that one is labelled, so they do not pile up)
//!                                       Arrows3D: the expected (ghost) normal, then the
//!                                       faces' normal, from that point
//! world/ball/{ball}/edge/{slot}       one logged edge test in its standard frame:
//!                                       Transform3D world_from_edge
//!                                       AnyValues: test, verdict, length, a, b, c,
//!                                       discriminant, s0, s1, xc (s0, s1 and xc empty
//!                                       when the test did not compute them)
//!                                     and, in the edge frame:
//!                                       LineStrips3D: the edge (0,0,0)→(L,0,0), then the
//!                                       path p0_in_edge→p1_in_edge
//!                                       Capsules3D: the cylinder of radius ρ around the edge
//!                                       Points3D: p0_in_edge, p1_in_edge, the ball's center
//!                                       at s0 and s1 (when real), xc on the edge
//!                                       Arrows3D: the frame's x, y (front normal), z axes
//!                                       (slot 0 only)
//! plots/ball/{ball}/alpha             Scalars: the chosen α (AnyValues `kind` alongside)
//! plots/ball/{ball}/quadratic         Scalars: A, B, C, discriminant, s0, s1 of the
//!                                     decisive edge or vertex test, a series each (NaN,
//!                                     a break in the line, where a value is missing)
//! plots/ball/{ball}/face              Scalars: h0, h1, β of the decisive face test (idem)
//! status/ball/{ball}                  Scalars: 0 when the sweep matches its expectation,
//!                                     1 when it diverges (sweeps with an expectation only)
//! status/ball/{ball}/fragile          Scalars: 1 at each fragile decision (absent elsewhere)
//! world/ball/{ball}/contacts          a contact query's answer (at the query's frame), one
//!                                     row per query:
//!                                       Points3D: each answered contact, coloured by its
//!                                       verdict, a ghost or a problem labelled
//! world/ball/{ball}/contacts/normals  Arrows3D: each answered contact's normal
//! world/ball/{ball}/contacts/expected Arrows3D: the normal the core expects beside a
//!                                     differing or ghost normal
//! world/ball/{ball}/contacts/missing  Points3D: the places the answer leaves out, labelled
//! plots/contacts/ball/{ball}          Scalars: contacts and ghost contacts of each query
//!                                     (series named, static)
//! log                                 TextLog: one line per sweep, the decision in words
//! divergences                         TextLog: one line per divergent sweep and one
//!                                     WARN line per tunnel and per ghost contact, and one
//!                                     per ghost or problem of a contact query
//! ```
//!
//! What one sweep shows of a ball is on few entities, each with the
//! archetypes of one part of the picture in one row: the rows, not their
//! values, are what a recording's size and speed are made of. A part that
//! a sweep does not show (no contact, no decisive vertex) is logged empty
//! in that row; an entity a sweep does not log at all (no primary
//! triangle, fewer edge tests, no divergence) is cleared at the ball's
//! first sweep without it.
//!
//! Slot 0 of `edge` is the decisive test when it is an edge test (the
//! primary test, or the nearest miss); when the decision was a face or
//! vertex test (or the nearest miss was one), it is the nearest edge test of
//! the same triangle; when there is no decisive test, the nearest recorded
//! edge test, or, when none was recorded and the expectation names a
//! triangle, the expected edge test (run for the recording). The other
//! slots hold the other recorded edge tests, hits first. The edge-frame
//! view of the default blueprint looks at `world/ball/{followed}/edge/0`.

use crate::core::topology::{DefectKind, EdgeClass};

/// Root of the 3D world.
pub const WORLD: &str = "world";
/// The text log.
pub const LOG: &str = "log";
/// Root of the per-ball divergence status series.
pub const STATUS: &str = "status";
/// The log of divergent sweeps.
pub const DIVERGENCES: &str = "divergences";

/// The edges of class `class` of scene `scene`.
pub fn edges(scene: usize, class: EdgeClass) -> String {
    format!("world/mesh/{scene}/edges/{class}")
}

/// The defects of kind `kind` of scene `scene`.
pub fn defects(scene: usize, kind: DefectKind) -> String {
    format!("world/mesh/{scene}/defects/{kind}")
}

/// The mesh of scene `scene` (0-based).
pub fn mesh(scene: usize) -> String {
    format!("world/mesh/{scene}")
}

/// Everything of one ball in the world, and its sweep (the balls, the
/// swept volume, the contact and the normal).
pub fn ball(ball: u32) -> String {
    format!("world/ball/{ball}")
}

/// The view-following transform of one ball.
pub fn focus(ball: u32) -> String {
    format!("world/ball/{ball}/focus")
}

/// The primary triangle, its outline, its decisive edge or vertex.
pub fn primary(ball: u32) -> String {
    format!("world/ball/{ball}/primary")
}

/// The expected outcome drawn for a divergent sweep.
pub fn expected(ball: u32) -> String {
    format!("world/ball/{ball}/expected")
}

/// Where the ball's centre went through a triangle.
pub fn tunnel(ball: u32) -> String {
    format!("world/ball/{ball}/tunnel")
}

/// A ghost contact of the ball's expected outcome.
pub fn ghost(ball: u32) -> String {
    format!("world/ball/{ball}/ghost")
}

/// The standard frame of the `slot`-th logged edge test and what is drawn
/// in it.
pub fn edge_frame(ball: u32, slot: usize) -> String {
    format!("world/ball/{ball}/edge/{slot}")
}

/// The divergence status series of one ball.
pub fn status(ball: u32) -> String {
    format!("status/ball/{ball}")
}

/// The fragile-decision marks of one ball.
pub fn fragile(ball: u32) -> String {
    format!("status/ball/{ball}/fragile")
}

/// The chosen α.
pub fn alpha(ball: u32) -> String {
    format!("plots/ball/{ball}/alpha")
}

/// The numbers of the decisive quadratic, a series each
/// ([`QUADRATIC_NAMES`]).
pub fn quadratic(ball: u32) -> String {
    format!("plots/ball/{ball}/quadratic")
}

/// The numbers of the decisive face test, a series each ([`FACE_NAMES`]).
pub fn face(ball: u32) -> String {
    format!("plots/ball/{ball}/face")
}

/// The contacts an engine answered to the ball's contact query.
pub fn contacts(ball: u32) -> String {
    format!("world/ball/{ball}/contacts")
}

/// The numbers of contacts and ghost contacts of each contact query of
/// the ball, a series each ([`CONTACT_SERIES`]).
pub fn contact_plot(ball: u32) -> String {
    format!("plots/contacts/ball/{ball}")
}

/// The series of [`contact_plot`], in the order of its values.
pub const CONTACT_SERIES: [&str; 2] = ["contacts", "ghost contacts"];

/// The series of [`quadratic`], in the order of its values.
pub const QUADRATIC_NAMES: [&str; 6] = ["A", "B", "C", "discriminant", "s0", "s1"];
/// The series of [`face`], in the order of its values.
pub const FACE_NAMES: [&str; 3] = ["h0", "h1", "β"];

/// A per-frame entity of a sweep, as a small value (the path as a string is
/// built once per entity, by [`Entity::path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Entity {
    Ball(u32),
    Focus(u32),
    Primary(u32),
    EdgeFrame(u32, usize),
    Expected(u32),
    Tunnel(u32),
    Ghost(u32),
    Status(u32),
    Fragile(u32),
    Divergences,
    Alpha(u32),
    Quadratic(u32),
    Face(u32),
    Log,
    Contacts(u32),
    ContactNormals(u32),
    ContactExpected(u32),
    ContactMissing(u32),
    ContactPlot(u32),
}

impl Entity {
    /// The entity path.
    pub(crate) fn path(self) -> String {
        match self {
            Entity::Ball(b) => ball(b),
            Entity::Focus(b) => focus(b),
            Entity::Primary(b) => primary(b),
            Entity::EdgeFrame(b, s) => edge_frame(b, s),
            Entity::Expected(b) => expected(b),
            Entity::Tunnel(b) => tunnel(b),
            Entity::Ghost(b) => ghost(b),
            Entity::Status(b) => status(b),
            Entity::Fragile(b) => fragile(b),
            Entity::Divergences => DIVERGENCES.to_string(),
            Entity::Alpha(b) => alpha(b),
            Entity::Quadratic(b) => quadratic(b),
            Entity::Face(b) => face(b),
            Entity::Log => LOG.to_string(),
            Entity::Contacts(b) => contacts(b),
            Entity::ContactNormals(b) => format!("{}/normals", contacts(b)),
            Entity::ContactExpected(b) => format!("{}/expected", contacts(b)),
            Entity::ContactMissing(b) => format!("{}/missing", contacts(b)),
            Entity::ContactPlot(b) => contact_plot(b),
        }
    }
}
