//! A replay's scenes and sweeps as Foxglove messages: pure functions, one
//! per channel, from [`SceneState`] and [`SweepResult`].

use std::fmt::Write as _;

use nalgebra::UnitQuaternion;

use super::FRAME_ID;
use super::messages::{
    ArrowPrimitive, Color, DeletionType, FaceNumbers, KeyValuePair, LinePrimitive, LineType, Log,
    LogLevel, Point3, Pose, QuadraticNumbers, Quaternion, SceneEntity, SceneEntityDeletion,
    SceneUpdate, SpherePrimitive, SweepNumbers, TextPrimitive, Time, TriangleListPrimitive,
    Vector3,
};
use crate::core::SweepHit;
use crate::core::explain::label;
use crate::core::record::TestRecord;
use crate::core::topology::{DefectKind, EdgeClass};
use crate::judge::divergence::{divergence_details, render_divergence};
use crate::judge::{FieldDiff, write_decision_line};
use crate::palette::{
    BOUNDARY_EDGE_COLOR, CONCAVE_EDGE_COLOR, CONTACT_BALL_COLOR, CONVEX_EDGE_COLOR, DEFECT_COLOR,
    EXPECTED_COLOR, FACE_NORMAL_COLOR, FLAT_EDGE_COLOR, GHOST_COLOR, HIT_COLOR,
    MAX_DRAWN_DEFECT_LABELS, MESH_COLOR, NON_MANIFOLD_EDGE_COLOR, NORMAL_COLOR, P0_COLOR, P1_COLOR,
    SWEEP_COLOR,
};
use crate::replay::{SceneState, SweepResult};
use strum::IntoEnumIterator as _;

/// The id of the mesh entity on [`super::MESH_TOPIC`]: one id for every
/// scene, so a new scene replaces the previous mesh.
pub const MESH_ENTITY: &str = "mesh";

/// Thickness of the path line, in screen pixels.
const LINE_PIXELS: f64 = 2.0;

/// Height of a defect's label, in screen pixels.
const DEFECT_FONT_PIXELS: f64 = 14.0;

/// The id of the entity of the mesh's edges of `class` on
/// [`super::MESH_TOPIC`]: `mesh/edges/flat`, ...
pub fn edges_entity(class: EdgeClass) -> String {
    format!("{MESH_ENTITY}/edges/{class}")
}

/// The id of the entity of the mesh's defects of `kind` on
/// [`super::MESH_TOPIC`]: `mesh/defects/flipped`, ...
pub fn defects_entity(kind: DefectKind) -> String {
    format!("{MESH_ENTITY}/defects/{kind}")
}

/// The colour and the line thickness (screen pixels) of the mesh's edges
/// of `class`: flat edges faint and thin, convex and concave in colours of
/// their own, boundary and non-manifold edges loud and thick.
fn edge_style(class: EdgeClass) -> ([u8; 4], f64) {
    match class {
        EdgeClass::Flat => (FLAT_EDGE_COLOR, 1.0),
        EdgeClass::Convex => (CONVEX_EDGE_COLOR, 2.0),
        EdgeClass::Concave => (CONCAVE_EDGE_COLOR, 2.0),
        EdgeClass::Boundary => (BOUNDARY_EDGE_COLOR, 3.5),
        EdgeClass::NonManifold => (NON_MANIFOLD_EDGE_COLOR, 4.5),
    }
}

/// An 8-bit RGBA color as Foxglove's `[0, 1]` channels.
pub fn color(rgba: [u8; 4]) -> Color {
    let [r, g, b, a] = rgba.map(|c| f64::from(c) / 255.0);
    Color { r, g, b, a }
}

fn point(p: &nalgebra::Point3<f64>) -> Point3 {
    Point3 {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

fn at(p: &nalgebra::Point3<f64>) -> Pose {
    Pose {
        position: Vector3 {
            x: p.x,
            y: p.y,
            z: p.z,
        },
        orientation: Quaternion::IDENTITY,
    }
}

fn identity() -> Pose {
    at(&nalgebra::Point3::origin())
}

pub(super) fn sphere(
    center: &nalgebra::Point3<f64>,
    radius: f64,
    rgba: [u8; 4],
) -> SpherePrimitive {
    let diameter = 2.0 * radius;
    SpherePrimitive {
        pose: at(center),
        size: Vector3 {
            x: diameter,
            y: diameter,
            z: diameter,
        },
        color: color(rgba),
    }
}

/// The rotation taking +x (an arrow's direction at identity) to `direction`
/// (identity for a zero vector; half a turn about z for -x).
pub fn rotation_from_x(direction: &nalgebra::Vector3<f64>) -> Quaternion {
    let q = if direction.norm() > 0.0 {
        UnitQuaternion::rotation_between(&nalgebra::Vector3::x(), direction).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), std::f64::consts::PI)
        })
    } else {
        UnitQuaternion::identity()
    };
    let q = q.quaternion();
    Quaternion {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    }
}

/// An arrow from `tail` along the unit vector `direction`, `length` long.
pub(super) fn arrow(
    tail: &nalgebra::Point3<f64>,
    direction: &nalgebra::Vector3<f64>,
    length: f64,
    rgba: [u8; 4],
) -> ArrowPrimitive {
    ArrowPrimitive {
        pose: Pose {
            position: at(tail).position,
            orientation: rotation_from_x(direction),
        },
        shaft_length: 0.75 * length,
        shaft_diameter: 0.08 * length,
        head_length: 0.25 * length,
        head_diameter: 0.2 * length,
        color: color(rgba),
    }
}

fn line(
    points: Vec<Point3>,
    indices: Vec<u32>,
    line_type: LineType,
    thickness_pixels: f64,
    rgba: [u8; 4],
) -> LinePrimitive {
    LinePrimitive {
        line_type,
        pose: identity(),
        thickness: thickness_pixels,
        scale_invariant: true,
        points,
        color: color(rgba),
        colors: Vec::new(),
        indices,
    }
}

pub(super) fn key_value(key: &str, value: impl ToString) -> KeyValuePair {
    KeyValuePair {
        key: key.to_string(),
        value: value.to_string(),
    }
}

/// A deletion of the entity `id` of a topic, for entities earlier than `time`.
fn delete(time: Time, id: String) -> SceneEntityDeletion {
    SceneEntityDeletion {
        timestamp: time,
        deletion_type: DeletionType::MatchingId,
        id,
    }
}

/// The scene's mesh, on [`super::MESH_TOPIC`], replacing every entity of
/// the previous scene's (lifetime zero: they stay until the next scene,
/// frame-locked to [`FRAME_ID`]): the entity [`MESH_ENTITY`] with the
/// triangles as a triangle list over the mesh's vertices (degenerate
/// triangles left out, as the core leaves them out); an entity per class
/// of edge the mesh has ([`edges_entity`]) with those edges as a line list
/// in the class's colour; an entity per kind of defect the mesh has
/// ([`defects_entity`]) with a marker and a label at each defect
/// (`flipped triangle 812`; listed in its metadata instead when the scene
/// has more than [`MAX_DRAWN_DEFECT_LABELS`]).
pub fn mesh_update(scene: &SceneState) -> SceneUpdate {
    let time = Time::from_nanos(scene.log_time_nanos);
    let mesh = &scene.mesh;
    let points: Vec<Point3> = mesh.vertices().iter().map(point).collect();
    // In input order (the mesh may hold its triangles in another).
    let mut ordered: Vec<(u32, [u32; 3])> = mesh
        .triangles()
        .iter()
        .map(|t| (t.index, t.vertex_indices))
        .collect();
    ordered.sort_unstable_by_key(|(index, _)| *index);
    let triangles: Vec<[u32; 3]> = ordered.into_iter().map(|(_, v)| v).collect();
    let topology = &scene.topology;
    let new_entity = |id: String| {
        let mut entity = SceneEntity::new(time, FRAME_ID, id);
        entity.frame_locked = true;
        entity
    };
    let mut entity = new_entity(MESH_ENTITY.to_string());
    let counts = topology.edge_counts();
    entity.metadata = vec![
        key_value("scene", scene.number),
        key_value("name", scene.name.as_deref().unwrap_or("")),
        key_value("triangles", triangles.len()),
        key_value("degenerate triangles left out", mesh.degenerate().len()),
        key_value("margin", scene.options.margin),
        key_value("facing", scene.options.facing),
    ];
    entity
        .metadata
        .extend(EdgeClass::iter().map(|c| key_value(&format!("{c} edges"), counts.of(c))));
    entity
        .metadata
        .push(key_value("defects", topology.defects().len()));
    entity.triangles = vec![TriangleListPrimitive {
        pose: identity(),
        points: points.clone(),
        color: color(MESH_COLOR),
        colors: Vec::new(),
        indices: triangles.iter().flatten().copied().collect(),
    }];
    let mut entities = vec![entity];
    let (lo, hi) = mesh.bounds();
    // (A mesh without a usable triangle has no extent: a small marker.)
    let marker_radius = Some(0.005 * (hi - lo).norm())
        .filter(|r| r.is_finite() && *r > 0.0)
        .unwrap_or(0.01);
    for class in EdgeClass::iter() {
        // Every edge of the class once, by its (welded) vertices.
        let indices: Vec<u32> = topology
            .edges()
            .iter()
            .filter(|e| e.class == class && e.vertices.iter().all(|&v| (v as usize) < points.len()))
            .flat_map(|e| e.vertices)
            .collect();
        if indices.is_empty() {
            continue;
        }
        let (rgba, pixels) = edge_style(class);
        let mut entity = new_entity(edges_entity(class));
        entity.metadata = vec![
            key_value("class", class),
            key_value("edges", indices.len() / 2),
        ];
        entity.lines = vec![line(
            points.clone(),
            indices,
            LineType::LineList,
            pixels,
            rgba,
        )];
        entities.push(entity);
    }
    let draw_labels = topology.defects().len() <= MAX_DRAWN_DEFECT_LABELS;
    for kind in DefectKind::iter() {
        let mut entity = new_entity(defects_entity(kind));
        let mut listed = Vec::new();
        for (n, d) in topology
            .defects()
            .iter()
            .filter(|d| d.kind == kind)
            .enumerate()
        {
            if !draw_labels {
                listed.push(key_value(&format!("{kind} {n}"), d));
                continue;
            }
            let [x, y, z] = d.position;
            let position = Vector3 { x, y, z };
            let pose = Pose {
                position,
                orientation: Quaternion::IDENTITY,
            };
            entity.texts.push(TextPrimitive {
                pose,
                billboard: true,
                font_size: DEFECT_FONT_PIXELS,
                scale_invariant: true,
                color: color(DEFECT_COLOR),
                text: d.to_string(),
            });
        }
        if entity.texts.is_empty() && listed.is_empty() {
            continue;
        }
        // A marker at each: a sphere of a hundredth of the mesh's extent.
        let markers: Vec<SpherePrimitive> = topology
            .defects()
            .iter()
            .filter(|d| d.kind == kind)
            .map(|d| sphere(&d.position.into(), marker_radius, DEFECT_COLOR))
            .collect();
        entity.spheres = markers;
        entity.metadata = vec![
            key_value("kind", kind),
            key_value("defects", entity.spheres.len()),
        ];
        entity.metadata.extend(listed);
        entities.push(entity);
    }
    SceneUpdate {
        // The previous scene's edges and defects of a class or kind this
        // one lacks would stay otherwise.
        deletions: vec![SceneEntityDeletion {
            timestamp: time,
            deletion_type: DeletionType::All,
            id: String::new(),
        }],
        entities,
    }
}

/// Clears every entity of a per-sweep topic at a new scene (the balls of
/// the previous scene are gone).
pub fn clear_update(time: Time) -> SceneUpdate {
    SceneUpdate {
        deletions: vec![SceneEntityDeletion {
            timestamp: time,
            deletion_type: DeletionType::All,
            id: String::new(),
        }],
        entities: Vec::new(),
    }
}

/// Where the ball's centre is at `alpha` of its path (`alpha` clamped to
/// `[0, 1]`).
fn center_at(r: &SweepResult, alpha: f64) -> nalgebra::Point3<f64> {
    let alpha = if alpha.is_finite() {
        alpha.clamp(0.0, 1.0)
    } else {
        1.0
    };
    r.sweep.p0 + (r.sweep.p1 - r.sweep.p0) * alpha
}

/// The ball of a sweep, on [`super::BALLS_TOPIC`]: entity `ball/{ball}`
/// with the ball (radius r) at `p0`, at the contact when something is hit,
/// and at `p1`.
pub fn ball_update(r: &SweepResult) -> SceneUpdate {
    let time = Time::from_nanos(r.log_time_nanos);
    let radius = r.sweep.radius;
    let mut entity = SceneEntity::new(time, FRAME_ID, format!("ball/{}", r.ball));
    entity.metadata = sweep_metadata(r);
    entity.spheres.push(sphere(&r.sweep.p0, radius, P0_COLOR));
    if r.outcome.is_hit() {
        entity.spheres.push(sphere(
            &center_at(r, r.outcome.travelled()),
            radius,
            CONTACT_BALL_COLOR,
        ));
    }
    entity.spheres.push(sphere(&r.sweep.p1, radius, P1_COLOR));
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

fn sweep_metadata(r: &SweepResult) -> Vec<KeyValuePair> {
    vec![
        key_value("frame", r.frame),
        key_value("ball", r.ball),
        key_value("kind", r.outcome.kind()),
        key_value("alpha", r.outcome.travelled()),
    ]
}

/// The sweep, on [`super::SWEEPS_TOPIC`]: entity `sweep/{ball}` with the
/// path `p0 → p1` and, when something is hit, the swept sphere at the
/// contact at the detection radius ρ = r - ε.
pub fn sweep_update(r: &SweepResult) -> SceneUpdate {
    let time = Time::from_nanos(r.log_time_nanos);
    let mut entity = SceneEntity::new(time, FRAME_ID, format!("sweep/{}", r.ball));
    entity.metadata = sweep_metadata(r);
    entity.lines.push(line(
        vec![point(&r.sweep.p0), point(&r.sweep.p1)],
        Vec::new(),
        LineType::LineStrip,
        LINE_PIXELS,
        SWEEP_COLOR,
    ));
    if r.outcome.is_hit() {
        let mut rho = sphere(
            &center_at(r, r.outcome.travelled()),
            r.rho().max(0.0),
            SWEEP_COLOR,
        );
        rho.color.a = 0.25;
        entity.spheres.push(rho);
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// The contact point and the reported normal, on
/// [`super::CONTACTS_TOPIC`]: entity `contact/{ball}`, or its deletion when
/// the sweep hits nothing.
pub fn contact_update(r: &SweepResult) -> SceneUpdate {
    let time = Time::from_nanos(r.log_time_nanos);
    let id = format!("contact/{}", r.ball);
    let Some(SweepHit {
        contact, normal, ..
    }) = r.outcome.hit
    else {
        return SceneUpdate {
            deletions: vec![delete(time, id)],
            entities: Vec::new(),
        };
    };
    let size = marker_size(r);
    let mut entity = SceneEntity::new(time, FRAME_ID, id);
    entity.metadata = sweep_metadata(r);
    entity.spheres.push(sphere(&contact, 0.1 * size, HIT_COLOR));
    entity
        .arrows
        .push(arrow(&contact, &normal, 1.5 * size, NORMAL_COLOR));
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// The length unit of the markers: the ball's radius (not zero).
fn marker_size(r: &SweepResult) -> f64 {
    r.sweep.radius.max(1e-3)
}

/// The expected outcome where the sweep diverges from it (`diverges`), on
/// [`super::EXPECTED_TOPIC`]: entity `expected/{ball}` with the ball at the
/// expected `α` and the expected contact and normal, when the expectation
/// has them; otherwise the deletion of that entity.
pub fn expected_update(r: &SweepResult, diverges: bool) -> SceneUpdate {
    let time = Time::from_nanos(r.log_time_nanos);
    let id = format!("expected/{}", r.ball);
    let expected = match &r.expected {
        Some(e) if diverges => e,
        _ => {
            return SceneUpdate {
                deletions: vec![delete(time, id)],
                entities: Vec::new(),
            };
        }
    };
    let size = marker_size(r);
    let mut entity = SceneEntity::new(time, FRAME_ID, id);
    entity.metadata = vec![
        key_value("frame", r.frame),
        key_value("ball", r.ball),
        key_value("expected kind", expected.kind),
        key_value("expected alpha", expected.alpha),
    ];
    let mut ball = sphere(
        &center_at(r, expected.alpha),
        r.sweep.radius,
        EXPECTED_COLOR,
    );
    ball.color.a = 0.4;
    entity.spheres.push(ball);
    if let Some(Some(c)) = expected.contact {
        let c = nalgebra::Point3::from(c);
        entity.spheres.push(sphere(&c, 0.1 * size, EXPECTED_COLOR));
        if let Some(Some(n)) = expected.normal {
            let n = nalgebra::Vector3::from(n);
            if n.norm() > 0.0 {
                entity
                    .arrows
                    .push(arrow(&c, &n.normalize(), 1.5 * size, EXPECTED_COLOR));
            }
        }
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// Height of a ghost contact's label, in screen pixels.
const GHOST_FONT_PIXELS: f64 = 14.0;

/// The ghost contact of the sweep's expected outcome
/// ([`SweepResult::ghost`]), on [`super::GHOSTS_TOPIC`]: entity
/// `ghost/{ball}` with a marker where it is
/// ([`SweepResult::ghost_point`]), two arrows from there, the expected
/// (ghost) normal and the faces' normal, one label (`ghost contact 10.0°:
/// edge 0.2 is internal and flat`) and `check`'s sentence in the metadata;
/// otherwise the deletion of that entity.
pub fn ghost_update(r: &SweepResult) -> SceneUpdate {
    let time = Time::from_nanos(r.log_time_nanos);
    let id = format!("ghost/{}", r.ball);
    let Some(g) = r.ghost() else {
        return SceneUpdate {
            deletions: vec![delete(time, id)],
            entities: Vec::new(),
        };
    };
    let size = marker_size(r);
    let at = nalgebra::Point3::from(r.ghost_point(&g));
    let mut entity = SceneEntity::new(time, FRAME_ID, id);
    entity.metadata = vec![
        key_value("frame", r.frame),
        key_value("ball", r.ball),
        key_value("ghost contact", g),
    ];
    entity.spheres.push(sphere(&at, 0.15 * size, GHOST_COLOR));
    for (n, rgba) in [(g.normal, GHOST_COLOR), (g.face_normal, FACE_NORMAL_COLOR)] {
        let n = nalgebra::Vector3::from(n);
        if n.norm() > 0.0 {
            entity
                .arrows
                .push(arrow(&at, &n.normalize(), 2.0 * size, rgba));
        }
    }
    let [x, y, z] = g.normal;
    let n = nalgebra::Vector3::new(x, y, z).normalize() * (2.2 * size);
    entity.texts.push(TextPrimitive {
        pose: Pose {
            position: Vector3 {
                x: at.x + n.x,
                y: at.y + n.y,
                z: at.z + n.z,
            },
            orientation: Quaternion::IDENTITY,
        },
        billboard: true,
        font_size: GHOST_FONT_PIXELS,
        scale_invariant: true,
        color: color(GHOST_COLOR),
        text: g.label(),
    });
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// The decision of a sweep as a Log line, on [`super::DECISIONS_TOPIC`]:
/// the viewer's decision line; for a sweep that `check` counts as a
/// divergence (`diffs`, from [`crate::judge::divergence`]) also
/// `check`'s report of it ([`render_divergence`]). Level WARNING when
/// `check` fails the sweep (a divergence or a tunnel), INFO otherwise.
/// `name` is `ball N`, `file` the trace's file name.
pub fn decision_log(
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    diffs: &[FieldDiff],
    trace_name: &str,
) -> Log {
    let mut message = String::new();
    write_decision_line(&mut message, r, decisive, diffs);
    if let (false, Some(expected)) = (diffs.is_empty(), &r.expected) {
        let details = divergence_details(r, *expected, r.outcome_msg(), diffs.to_vec(), false);
        let _ = write!(message, "\n{}", render_divergence(&details, ""));
        while message.ends_with('\n') {
            message.pop();
        }
    }
    let failed = !diffs.is_empty() || !r.tunnels.is_empty();
    Log {
        timestamp: Time::from_nanos(r.log_time_nanos),
        level: if failed {
            LogLevel::Warning
        } else {
            LogLevel::Info
        },
        message,
        name: format!("ball {}", r.ball),
        file: trace_name.to_string(),
        line: 0,
    }
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The sweep's numbers for the Plot panel, on [`super::NUMBERS_TOPIC`]:
/// `α`, and the decisive test's quadratic (edge, vertex) or plane distances
/// (face); `failed` as in [`decision_log`].
pub fn sweep_numbers(
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    diffs: &[FieldDiff],
) -> SweepNumbers {
    let quadratic = |a: f64, b: f64, c: f64, discriminant: f64, roots: Option<(f64, f64)>| {
        let (s0, s1) = roots.unzip();
        QuadraticNumbers {
            a: finite(a),
            b: finite(b),
            c: finite(c),
            discriminant: finite(discriminant),
            s0: s0.and_then(finite),
            s1: s1.and_then(finite),
        }
    };
    let (quadratic, face) = match decisive {
        Some(TestRecord::Edge(e)) => (
            Some(quadratic(e.a, e.b, e.c, e.discriminant, e.roots)),
            None,
        ),
        Some(TestRecord::Vertex(v)) => (
            Some(quadratic(v.a, v.b, v.c, v.discriminant, v.roots)),
            None,
        ),
        Some(TestRecord::Face(f)) => (
            None,
            Some(FaceNumbers {
                h0: finite(f.h0),
                h1: finite(f.h1),
                beta: f.beta.and_then(finite),
            }),
        ),
        None => (None, None),
    };
    SweepNumbers {
        timestamp: Time::from_nanos(r.log_time_nanos),
        frame: r.frame,
        ball: r.ball,
        alpha: r.outcome.travelled(),
        kind: r.outcome.kind().as_str(),
        failed: u8::from(!diffs.is_empty() || !r.tunnels.is_empty()),
        fragile: u8::from(!r.outcome.fragile.is_robust()),
        expected_alpha: r.expected.as_ref().and_then(|e| finite(e.alpha)),
        test: decisive.map(label),
        quadratic,
        face,
    }
}
