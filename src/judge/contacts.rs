//! One contact query judged: an engine's contacts (`/expected_contacts`)
//! against the core's contact set for the query (`/contact`), under the
//! engine's declared conventions (SEMANTICS.md, "Contacts").
//!
//! The reference is [`contact_set`]: one contact per triangle within
//! reach. Places reached through several triangles (a welded vertex, a
//! shared edge) are one *place*: an engine that reports the place once,
//! through any of its triangles, has it. Each engine contact is then
//! compared field by field with the reference contact of the triangle it
//! names (only the fields it gives): the feature, the point, the
//! separation and the normal the `normal` convention expects there. A
//! contact on an internal flat or concave place whose normal leans from
//! the faces' is a ghost contact ([`judge_ghost`]), reported as such.
//!
//! Tolerances: the check's contact tolerance for positions and separations
//! and its normal tolerance for normals; under a precision budget (`f32`,
//! or a declared `accuracy`) both widen by the budget in units of
//! `u₃₂ · S`, `S` the query's scale (the largest coordinate of the centre,
//! or the reach), the normal by that distance over the radius. A place or
//! a triangle within that tolerance of the reach may be reported or not.

use std::fmt::Write as _;

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use crate::conventions::EngineConventions;
use crate::core::explain::num;
use crate::core::topology::Topology;
use crate::core::{
    Contact, ContactQuery, Feature, Kind, Mesh, Sides, contact_set, triangle_contact,
};
use crate::replay::SceneNormals;
use crate::replay::ghost::{GhostContact, GhostJudgement, judge_ghost};
use crate::trace::{ContactMsg, ContactPointMsg, ContactsMsg, OutcomeMsg};

use super::Tolerances;
use super::precision::F32_UNIT;

/// The tolerances one contact query is judged with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ContactTolerances {
    /// On the point and the separation (a distance).
    pub position: f64,
    /// On the normal's direction, in degrees.
    pub normal_degrees: f64,
    /// On the normal's length, `| |n| − 1 |`.
    pub normal_length: f64,
}

impl ContactTolerances {
    /// The tolerances of `query` against a mesh of coordinates up to
    /// `mesh_scale`, under the check's `tolerances` and the engine's
    /// `conventions` (see the module's documentation).
    pub fn of(
        query: &ContactQuery,
        mesh_scale: f64,
        tolerances: &Tolerances,
        conventions: &EngineConventions,
    ) -> ContactTolerances {
        let scale = query
            .centre
            .iter()
            .fold(query.reach().max(mesh_scale), |m, c| m.max(c.abs()));
        // A closest point is a few roundings of the centre and the
        // vertices: twice the budget, as for a sweep's contact. The
        // budget is single precision's at least: an `accuracy` calibrated
        // tighter on an engine's sweeps is not its contacts'.
        let units = conventions
            .budget()
            .map(|units| units.max(crate::conventions::F32_BUDGET));
        let widen = units.map_or(0.0, |units| 2.0 * units * F32_UNIT * scale);
        let position = tolerances.contact + widen;
        let normal_radians = tolerances.normal_degrees.to_radians() + widen / query.radius;
        ContactTolerances {
            position,
            normal_degrees: normal_radians.to_degrees(),
            normal_length: normal_radians.max(1e-9),
        }
    }
}

/// What is wrong with an engine's contacts for one query.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "problem", rename_all = "snake_case")]
pub enum ContactProblem {
    /// A place the ball touches that the engine does not report.
    Missing {
        /// Its first triangle (in the reference's order).
        triangle: u32,
        /// `face`, `edge N` or `vertex N`.
        feature: String,
        /// The point.
        point: [f64; 3],
        /// The separation there.
        separation: f64,
    },
    /// A contact with a triangle the ball does not reach.
    Extra {
        /// The triangle.
        triangle: u32,
        /// Its separation from the ball (`None`: the triangle is not in
        /// the scene, or its back faces the centre one-sided).
        separation: Option<f64>,
    },
    /// Another feature than the one whose region holds the point.
    Feature {
        /// The triangle.
        triangle: u32,
        /// The reference's feature.
        expected: String,
        /// The engine's.
        got: String,
    },
    /// The point off the reference's.
    Point {
        /// The triangle.
        triangle: u32,
        /// The reference's point.
        expected: [f64; 3],
        /// The engine's.
        got: [f64; 3],
        /// How far apart.
        distance: f64,
    },
    /// The separation off the reference's.
    Separation {
        /// The triangle.
        triangle: u32,
        /// The reference's separation.
        expected: f64,
        /// The engine's.
        got: f64,
    },
    /// The normal's direction off the one the convention expects.
    Normal {
        /// The triangle.
        triangle: u32,
        /// The feature the reference names.
        feature: String,
        /// The normal the convention expects.
        expected: [f64; 3],
        /// The engine's.
        got: [f64; 3],
        /// The angle between them.
        degrees: f64,
    },
    /// A normal whose length is not 1.
    NormalLength {
        /// The triangle.
        triangle: u32,
        /// Its length.
        length: f64,
    },
}

impl std::fmt::Display for ContactProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |p: &[f64; 3]| format!("({}, {}, {})", num(p[0]), num(p[1]), num(p[2]));
        match self {
            ContactProblem::Missing {
                triangle,
                feature,
                point,
                separation,
            } => write!(
                f,
                "missing: the ball touches triangle {triangle} ({feature}) at {}, separation {}, and the engine reports nothing there",
                v(point),
                num(*separation)
            ),
            ContactProblem::Extra {
                triangle,
                separation: Some(s),
            } => write!(
                f,
                "extra: triangle {triangle} is reported, but it is {} from the ball, beyond the contact distance",
                num(*s)
            ),
            ContactProblem::Extra {
                triangle,
                separation: None,
            } => write!(
                f,
                "extra: triangle {triangle} is reported, but the ball cannot touch it (no such triangle, or its back faces the ball under sides = one)"
            ),
            ContactProblem::Feature {
                triangle,
                expected,
                got,
            } => write!(
                f,
                "feature of triangle {triangle}: {got}, but the point lies in the region of its {expected}"
            ),
            ContactProblem::Point {
                triangle,
                expected,
                got,
                distance,
            } => write!(
                f,
                "point on triangle {triangle}: {} is {} from the closest point {}",
                v(got),
                num(*distance),
                v(expected)
            ),
            ContactProblem::Separation {
                triangle,
                expected,
                got,
            } => write!(
                f,
                "separation from triangle {triangle}: {}, expected {} (|Δ| = {})",
                num(*got),
                num(*expected),
                num((got - expected).abs())
            ),
            ContactProblem::Normal {
                triangle,
                feature,
                expected,
                got,
                degrees,
            } => write!(
                f,
                "normal on triangle {triangle} ({feature}): {} is {degrees:.3}° from the expected {}",
                v(got),
                v(expected)
            ),
            ContactProblem::NormalLength { triangle, length } => write!(
                f,
                "normal on triangle {triangle}: |n| = {}, not a unit vector",
                num(*length)
            ),
        }
    }
}

/// One query's judgement.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ContactVerdict {
    /// Frame of the query.
    pub frame: u64,
    /// Its ball.
    pub ball: u32,
    /// How many contacts the reference has (one per triangle).
    pub reference: usize,
    /// How many the engine reported.
    pub answered: usize,
    /// What is wrong, in the order found (missing places last).
    pub problems: Vec<ContactProblem>,
    /// The engine's ghost contacts.
    pub ghosts: Vec<GhostContact>,
    /// The tolerances used.
    pub tolerances: Option<ContactTolerances>,
}

impl ContactVerdict {
    /// Whether the engine's contacts agree (ghost contacts aside).
    pub fn agrees(&self) -> bool {
        self.problems.is_empty()
    }
}

/// A contact query's judgement: how many contacts each side has (ending
/// the current line), then each problem on a line of its own starting with
/// `indent`.
pub(crate) fn write_contact_verdict(s: &mut String, v: &ContactVerdict, indent: &str) {
    let _ = writeln!(
        s,
        "the core finds {}, the answer has {}",
        crate::numbers::counted(v.reference as u64, "contact", "contacts"),
        v.answered
    );
    for p in &v.problems {
        let _ = writeln!(s, "{indent}{p}");
    }
}

/// What a query is judged against: the scene's mesh, its topology and the
/// normals its `normal` convention expects.
pub(crate) struct ContactScene<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Its topology (places are grouped by its weld).
    pub topology: &'a Topology,
    /// The normal convention over the scene.
    pub normals: &'a SceneNormals,
}

/// A place of the mesh: one for every triangle that reaches it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    Face(u32),
    Edge([u32; 2]),
    Vertex(u32),
    /// A feature the topology does not know (a degenerate neighbour).
    Alone(u32, Feature),
}

fn place_of(topology: &Topology, c: &Contact) -> Place {
    match c.feature {
        Feature::Face => Place::Face(c.triangle),
        Feature::Edge(e) => topology
            .triangle_edge(c.triangle, e)
            .map_or(Place::Alone(c.triangle, c.feature), |edge| {
                Place::Edge(edge.vertices)
            }),
        Feature::Vertex(v) => topology
            .triangle_vertex(c.triangle, v)
            .map_or(Place::Alone(c.triangle, c.feature), Place::Vertex),
    }
}

fn feature_text(kind: Kind, index: Option<u8>) -> String {
    match (kind, index) {
        (Kind::Face, _) | (_, None) => kind.as_str().to_string(),
        (_, Some(i)) => format!("{} {i}", kind.as_str()),
    }
}

/// The point of `triangle`'s feature `kind`/`index` nearest to `p` (the
/// projection on the plane for a face).
fn nearest_on(
    mesh: &Mesh,
    triangle: u32,
    kind: Kind,
    index: Option<u8>,
    p: &Point3<f64>,
) -> Option<Point3<f64>> {
    let t = mesh.triangle_by_index(triangle)?;
    Some(match (kind, index) {
        (Kind::Face, _) => p - t.normal * t.normal.dot(&(p - t.vertices[0])),
        (Kind::Edge, Some(e)) if e < 3 => {
            let frame = &t.edges[e as usize];
            let x = frame.to_edge(p).x.clamp(0.0, frame.length);
            frame.to_world(&Point3::new(x, 0.0, 0.0))
        }
        (Kind::Vertex, Some(v)) if v < 3 => t.vertices[v as usize],
        _ => return None,
    })
}

/// `x ≤ tolerance`, false for NaN.
fn within(x: f64, tolerance: f64) -> bool {
    x <= tolerance
}

fn angle_degrees(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

/// Judges the engine's `answer` to `query` against the reference over
/// `scene`, under `conventions` (its `sides` and precision) and the check's
/// `tolerances`; ghost contacts above `ghost_degrees`.
pub(crate) fn judge_contacts(
    scene: &ContactScene<'_>,
    query: &ContactMsg,
    answer: &ContactsMsg,
    tolerances: &Tolerances,
    conventions: &EngineConventions,
    ghost_degrees: f64,
) -> ContactVerdict {
    let q = ContactQuery {
        centre: Point3::from(query.centre),
        radius: query.radius,
        distance: query.distance,
    };
    // The scale of the computation: the centre and the triangles in reach.
    let near = ContactQuery {
        distance: 2.0 * q.distance + q.radius,
        ..q
    };
    let mesh_scale = contact_set(scene.mesh, &near, Sides::Two)
        .iter()
        .filter_map(|c| scene.mesh.triangle_by_index(c.triangle))
        .flat_map(|t| {
            t.vertices
                .iter()
                .flat_map(|v| [v.x.abs(), v.y.abs(), v.z.abs()])
        })
        .fold(0.0, f64::max);
    let tol = ContactTolerances::of(&q, mesh_scale, tolerances, conventions);
    let sides = conventions.sides;
    let reference = contact_set(scene.mesh, &q, sides);
    let places: Vec<Place> = reference
        .iter()
        .map(|c| place_of(scene.topology, c))
        .collect();
    let mut covered = vec![false; reference.len()];
    let mut verdict = ContactVerdict {
        frame: query.frame,
        ball: query.ball,
        reference: reference.len(),
        answered: answer.contacts.len(),
        tolerances: Some(tol),
        ..ContactVerdict::default()
    };
    for got in &answer.contacts {
        let Some(i) = reference.iter().position(|c| c.triangle == got.triangle) else {
            // Within the tolerance of the reach, a triangle may be reported.
            let wider = ContactQuery {
                distance: q.distance + tol.position,
                ..q
            };
            let triangle = scene.mesh.triangle_by_index(got.triangle);
            if triangle
                .and_then(|t| triangle_contact(t, &wider, sides))
                .is_none()
            {
                let separation = triangle
                    .and_then(|t| {
                        triangle_contact(
                            t,
                            &ContactQuery {
                                distance: f64::MAX,
                                ..q
                            },
                            sides,
                        )
                    })
                    .map(|c| c.separation);
                verdict.problems.push(ContactProblem::Extra {
                    triangle: got.triangle,
                    separation,
                });
            }
            continue;
        };
        let place = places[i];
        for (k, p) in places.iter().enumerate() {
            covered[k] |= *p == place;
        }
        judge_one(
            scene,
            &q,
            &reference[i],
            got,
            &tol,
            ghost_degrees,
            &mut verdict,
        );
    }
    let reported: Vec<u32> = answer
        .contacts
        .iter()
        .map(|c| c.triangle)
        .filter(|t| reference.iter().any(|r| r.triangle == *t))
        .collect();
    let mut missing_places = Vec::new();
    for (k, c) in reference.iter().enumerate() {
        if covered[k] || missing_places.contains(&places[k]) {
            continue;
        }
        missing_places.push(places[k]);
        // Within the tolerance of the reach, a place may be left out.
        if c.separation >= q.distance - tol.position {
            continue;
        }
        // A flat seam (or a vertex among flat edges) is part of the plane
        // its triangles make: an engine that reports one of them has the
        // place (Rapier's FIX_INTERNAL_EDGES drops the neighbour's edge
        // contact there; its normal would be the same face normal).
        if flat_place_reported(scene.topology, places[k], &reported) {
            continue;
        }
        verdict.problems.push(ContactProblem::Missing {
            triangle: c.triangle,
            feature: c.feature.to_string(),
            point: c.point.into(),
            separation: c.separation,
        });
    }
    verdict
}

/// Whether `place` is a flat edge, or a vertex whose every edge is flat,
/// one of whose triangles the engine reported.
fn flat_place_reported(topology: &Topology, place: Place, reported: &[u32]) -> bool {
    use crate::core::topology::EdgeClass;
    match place {
        Place::Edge([a, b]) => topology.edge_between(a, b).is_some_and(|e| {
            e.class == EdgeClass::Flat && e.triangles().any(|t| reported.contains(&t))
        }),
        Place::Vertex(v) => {
            let mut edges = topology.edges_at(v).peekable();
            edges.peek().is_some()
                && topology.edges_at(v).all(|e| e.class == EdgeClass::Flat)
                && edges.any(|e| e.triangles().any(|t| reported.contains(&t)))
        }
        Place::Face(_) | Place::Alone(..) => false,
    }
}

/// One engine contact against the reference contact of its triangle.
fn judge_one(
    scene: &ContactScene<'_>,
    q: &ContactQuery,
    reference: &Contact,
    got: &ContactPointMsg,
    tol: &ContactTolerances,
    ghost_degrees: f64,
    verdict: &mut ContactVerdict,
) {
    let triangle = reference.triangle;
    let expected_kind = reference.feature.kind();
    if let Some(kind) = got.kind {
        let same = kind == expected_kind
            && (got.feature.is_none() || got.feature == reference.feature.index());
        // Another feature as near as the tolerance is a tie at a region's
        // boundary.
        let near = || {
            nearest_on(scene.mesh, triangle, kind, got.feature, &q.centre)
                .is_some_and(|p| (p - reference.point).norm() <= tol.position)
        };
        if !same && !near() {
            verdict.problems.push(ContactProblem::Feature {
                triangle,
                expected: reference.feature.to_string(),
                got: feature_text(kind, got.feature),
            });
        }
    }
    if let Some(point) = got.point {
        let distance = (Point3::from(point) - reference.point).norm();
        if !within(distance, tol.position) {
            verdict.problems.push(ContactProblem::Point {
                triangle,
                expected: reference.point.into(),
                got: point,
                distance,
            });
        }
    }
    if let Some(separation) = got.separation
        && !within((separation - reference.separation).abs(), tol.position)
    {
        verdict.problems.push(ContactProblem::Separation {
            triangle,
            expected: reference.separation,
            got: separation,
        });
    }
    let Some(normal) = got.normal else {
        return;
    };
    let given = Vector3::from(normal);
    let length = given.norm();
    if !within((length - 1.0).abs(), tol.normal_length) {
        verdict
            .problems
            .push(ContactProblem::NormalLength { triangle, length });
    }
    // A ghost contact is reported as one, not as a normal difference.
    let outcome = OutcomeMsg {
        frame: verdict.frame,
        ball: verdict.ball,
        alpha: 0.0,
        kind: expected_kind,
        triangle: Some(Some(triangle)),
        feature: Some(reference.feature.index()),
        normal: Some(Some(normal)),
        contact: Some(Some(reference.point.into())),
    };
    if let GhostJudgement::Ghost(ghost) =
        judge_ghost(scene.mesh, scene.topology, &outcome, 0, None, ghost_degrees)
    {
        verdict.ghosts.push(ghost);
        return;
    }
    let expected = scene.normals.contact_rule_normal(
        triangle,
        reference.feature,
        reference.normal,
        reference.face_normal,
    );
    let degrees = angle_degrees(&given, &expected);
    if !within(degrees, tol.normal_degrees) {
        verdict.problems.push(ContactProblem::Normal {
            triangle,
            feature: reference.feature.to_string(),
            expected: expected.into(),
            got: normal,
            degrees,
        });
    }
}
