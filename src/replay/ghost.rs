//! Ghost contacts: an edge or vertex contact inside a smooth or hollow part
//! of the mesh whose normal leans away from the faces there (see
//! docs/SEMANTICS.md, "Ghost contacts").
//!
//! A ball rolling across the seam between two coplanar triangles touches the
//! seam's edge; an engine that reports the geometric contact normal there
//! (instead of the faces' normal, as the course's rule does) pushes the ball
//! up off the floor: the "bump" of an internal edge. [`judge_ghost`] flags an
//! outcome (a recorded expectation or an engine's answer) that is an edge
//! contact on an internal [`EdgeClass::Flat`] or [`EdgeClass::Concave`]
//! edge, or a vertex contact at a vertex whose edges are all flat or
//! concave, whose normal is more than [`GHOST_DEGREES`] from the nearest
//! front normal of the triangles meeting there.

use std::fmt;

use nalgebra::Vector3;
use serde::Serialize;

use crate::core::explain::num;
use crate::core::topology::{EdgeClass, Topology};
use crate::core::{Kind, Mesh};
use crate::trace::OutcomeMsg;

/// The default angle, in degrees, between an edge or vertex contact's
/// normal and the nearest adjacent face's normal above which the contact
/// is a ghost contact. The course's rule gives exactly a face normal (or
/// the average of the normals of the triangles hit at once, which on a
/// flat seam is the face normal again), so any engine following it stays
/// far below; a normal tilted by a degree already lifts a ball rolling at
/// a metre per second by more than a centimetre per second.
pub const GHOST_DEGREES: f64 = 1.0;

/// Where a ghost contact is: an internal edge or a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GhostPlace {
    /// An internal flat edge (a seam between coplanar triangles).
    Flat,
    /// An internal concave edge (a valley).
    Concave,
    /// A vertex whose every edge is flat or concave.
    Vertex,
}

/// One ghost contact: which outcome, where, and how far its normal leans.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct GhostContact {
    /// Frame of the sweep.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// `log_time` of the sweep, in nanoseconds.
    pub log_time_nanos: u64,
    /// The contact's triangle (input index).
    pub triangle: u32,
    /// Its feature (edge or vertex 0..2 of the triangle).
    pub feature: u8,
    /// `edge` or `vertex`.
    pub kind: Kind,
    /// What kind of place it is.
    pub place: GhostPlace,
    /// The angle, in degrees, between the outcome's normal and the nearest
    /// adjacent front normal.
    pub angle_degrees: f64,
    /// The outcome's normal, as given.
    pub normal: [f64; 3],
    /// The adjacent front normal nearest it.
    pub face_normal: [f64; 3],
    /// For an edge: the other triangle sharing it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub neighbour: Option<u32>,
    /// Whether the outcome is an engine's answer (`check --engine
    /// --against expected`) rather than the trace's expectation. Only in
    /// the JSON when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub answer: bool,
    /// For an edge: whether its two triangles share it by position only,
    /// through different vertex indices (an engine that finds a triangle's
    /// neighbours by vertex index, as Jolt's `MeshShape` does, sees a
    /// boundary there, an active edge). Only in the JSON when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub unwelded: bool,
}

/// What [`judge_ghost`] makes of one outcome.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GhostJudgement {
    /// Not an edge or vertex contact on an internal flat or concave place
    /// (or the scene has no topology, or no such triangle).
    NotApplicable,
    /// On such a place, but without a normal: cannot be judged.
    NoNormal,
    /// On such a place, its normal within the threshold.
    Fine,
    /// A ghost contact.
    Ghost(GhostContact),
}

/// The unit front normal of `triangle`, turned over when the topology
/// calls it flipped (so that the normals around a place agree).
fn oriented_normal(mesh: &Mesh, topology: &Topology, triangle: u32) -> Option<Vector3<f64>> {
    let n = mesh.triangle_by_index(triangle)?.normal;
    Some(if topology.flipped().binary_search(&triangle).is_ok() {
        -n
    } else {
        n
    })
}

/// The angle between two vectors, in degrees (`b` of unit length).
fn angle_degrees(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

/// Judges `outcome` (an expectation or an answer for a sweep against
/// `mesh` with its `topology` (a scene's, [`super::SceneState`]), logged
/// at `log_time_nanos`) for a ghost contact, with the
/// threshold `degrees`. `rule_normal` is the core's own normal for the
/// sweep: the rules' average over its tie set (which at the end of a seam
/// takes in the triangles around the vertex), never a ghost.
pub fn judge_ghost(
    mesh: &Mesh,
    topology: &Topology,
    outcome: &OutcomeMsg,
    log_time_nanos: u64,
    rule_normal: Option<&Vector3<f64>>,
    degrees: f64,
) -> GhostJudgement {
    use GhostJudgement::{Fine, Ghost, NoNormal, NotApplicable};
    let (Some(Some(triangle)), Some(Some(feature))) = (outcome.triangle, outcome.feature) else {
        return NotApplicable;
    };
    let (place, neighbour, triangles): (GhostPlace, Option<u32>, Vec<u32>) = match outcome.kind {
        Kind::Edge => {
            let Some(edge) = topology.triangle_edge(triangle, feature) else {
                return NotApplicable;
            };
            let place = match edge.class {
                EdgeClass::Flat => GhostPlace::Flat,
                EdgeClass::Concave => GhostPlace::Concave,
                _ => return NotApplicable,
            };
            let triangles: Vec<u32> = edge.triangles().collect();
            let neighbour = triangles.iter().copied().find(|&t| t != triangle);
            (place, neighbour, triangles)
        }
        Kind::Vertex => {
            let Some(v) = topology.triangle_vertex(triangle, feature) else {
                return NotApplicable;
            };
            if !topology.vertex_is_flat_or_concave(v) {
                return NotApplicable;
            }
            let mut triangles: Vec<u32> = topology
                .edges_at(v)
                .flat_map(|e| e.triangles().collect::<Vec<_>>())
                .collect();
            triangles.sort_unstable();
            triangles.dedup();
            (GhostPlace::Vertex, None, triangles)
        }
        Kind::None | Kind::Face => return NotApplicable,
    };
    let Some(Some(normal)) = outcome.normal else {
        return NoNormal;
    };
    let given = Vector3::from(normal);
    if !(given.iter().all(|c| c.is_finite()) && given.norm() > 0.0) {
        return NoNormal;
    }
    let nearest = triangles
        .iter()
        .filter_map(|&t| oriented_normal(mesh, topology, t))
        .map(|n| (angle_degrees(&given, &n), n))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let Some((angle, face_normal)) = nearest else {
        return NotApplicable;
    };
    if angle <= degrees || rule_normal.is_some_and(|n| angle_degrees(&given, n) <= degrees) {
        return Fine;
    }
    // Shared by position only: the two triangles' vertex indices differ.
    let unwelded = outcome.kind == Kind::Edge
        && neighbour.is_some_and(|n| {
            let indices = |t: u32| {
                mesh.triangle_by_index(t).map(|t| {
                    let mut v = t.vertex_indices;
                    v.sort_unstable();
                    v
                })
            };
            match (mesh.triangle_by_index(triangle), indices(n)) {
                (Some(t), Some(other)) => {
                    let e = feature as usize;
                    let (a, b) = (t.vertex_indices[e], t.vertex_indices[(e + 1) % 3]);
                    !(other.binary_search(&a).is_ok() && other.binary_search(&b).is_ok())
                }
                _ => false,
            }
        });
    Ghost(GhostContact {
        frame: outcome.frame,
        ball: outcome.ball,
        log_time_nanos,
        triangle,
        feature,
        kind: outcome.kind,
        place,
        angle_degrees: angle,
        normal,
        face_normal: (face_normal + Vector3::zeros()).into(),
        neighbour,
        answer: false,
        unwelded,
    })
}

impl fmt::Display for GhostContact {
    /// `frame 12, ball 0: edge 17.2, an internal flat edge shared with
    /// triangle 18: the expected normal is 14.3° from the faces' normal (0,
    /// 0, 1) — a ball rolling across this seam would be bumped`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = if self.kind == Kind::Vertex {
            "vertex"
        } else {
            "edge"
        };
        write!(
            f,
            "frame {}, ball {}: {kind} {}.{}, ",
            self.frame, self.ball, self.triangle, self.feature
        )?;
        let (place, faces, consequence) = match self.place {
            GhostPlace::Flat => (
                "an internal flat edge",
                "the faces' normal",
                "a ball rolling across this seam would be bumped",
            ),
            GhostPlace::Concave => (
                "an internal concave edge",
                "the nearer face's normal",
                "a ball rolling into this valley would be pushed off both faces",
            ),
            GhostPlace::Vertex => (
                "a vertex whose every edge is flat or concave",
                "the nearest face's normal",
                "a ball rolling over this vertex would be bumped",
            ),
        };
        f.write_str(place)?;
        if let Some(n) = self.neighbour {
            write!(f, " shared with triangle {n}")?;
        }
        let [x, y, z] = self.face_normal;
        write!(
            f,
            ": the {} normal is {:.1}° from {faces} ({}, {}, {}) — {consequence}",
            if self.answer { "engine's" } else { "expected" },
            self.angle_degrees,
            num(x),
            num(y),
            num(z)
        )?;
        if self.unwelded {
            f.write_str(
                " (the two triangles share this edge by position only, through different vertex indices: \
                 an engine that finds neighbours by index, as Jolt's MeshShape does, sees a boundary here; \
                 weld the mesh's vertices)",
            )?;
        }
        Ok(())
    }
}

impl GhostContact {
    /// The short label the viewers draw at the contact: `ghost contact
    /// 10.0°: edge 17.2 is internal and flat` (the rest of the story is in
    /// [`GhostContact`]'s `Display`, the sentence `check` writes).
    pub fn label(&self) -> String {
        let (kind, what) = match self.place {
            GhostPlace::Flat => ("edge", "is internal and flat"),
            GhostPlace::Concave => ("edge", "is internal and concave"),
            GhostPlace::Vertex => ("vertex", "has only flat or concave edges"),
        };
        format!(
            "ghost contact {:.1}°: {kind} {}.{} {what}",
            self.angle_degrees, self.triangle, self.feature
        )
    }

    /// The `ghost` field of a `replay --outcomes` line (see
    /// [`GhostLine`]).
    pub(crate) fn line(&self) -> GhostLine<'_> {
        GhostLine(self)
    }
}

/// A ghost contact as the `ghost` field of a `replay --outcomes` line:
/// its fields without those the line has already (`frame`, `ball`) or that
/// say nothing there (`log_time_nanos`, `answer`), then `text`, the
/// sentence `check` writes after `ghost contact: `.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GhostLine<'a>(pub &'a GhostContact);

impl Serialize for GhostLine<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap as _;
        let g = self.0;
        let mut m = s.serialize_map(Some(9))?;
        m.serialize_entry("triangle", &g.triangle)?;
        m.serialize_entry("feature", &g.feature)?;
        m.serialize_entry("kind", &g.kind)?;
        m.serialize_entry("place", &g.place)?;
        m.serialize_entry("angle_degrees", &g.angle_degrees)?;
        m.serialize_entry("normal", &g.normal)?;
        m.serialize_entry("face_normal", &g.face_normal)?;
        m.serialize_entry("neighbour", &g.neighbour)?;
        m.serialize_entry("text", &g.to_string())?;
        m.end()
    }
}
