//! The Rerun recording of a replay: the only module that imports `rerun`.
//!
//! [`Logger`] turns [`ReplayEvent`]s into entities (see [`paths`] for every
//! path) on two timelines: `frame` (sequence, the sweep's frame) and `time`
//! (the trace's `log_time`; never the wall clock). The default timelines
//! `log_time` and `log_tick` of the SDK are switched off, and the recording
//! id is derived from the trace and the options ([`recording_id`]), so the
//! same trace and options give the same content. (Rerun's row and chunk ids
//! are still fresh per run, so the bytes of two `.rrd` files differ.)

mod columns;
pub mod paths;

use std::collections::BTreeMap;

use nalgebra::{UnitQuaternion, Vector3};
use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintActivation, BlueprintPanel, Horizontal, SelectionPanel, Spatial3DView,
    TextLogView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{FillMode, TextLogLevel};
use rerun::{
    AnyValues, Arrows3D, AsComponents, Capsules3D, Clear, Color, Ellipsoids3D, LineStrips3D,
    Mesh3D, Points3D, RecordingStream, RecordingStreamBuilder, Scalars, TextLog, Transform3D,
    ViewCoordinates,
};

use crate::core::explain::{describe, miss_distance, num};
use crate::core::{EdgeRecord, TestRecord, Triangle};
use crate::replay::{ReplayEvent, SceneState, SweepResult};

pub use rerun::RecordingStreamError;

/// Application id of every recording.
pub const APPLICATION_ID: &str = "sweeptrace";
/// Name of the sequence timeline holding the frame number.
pub const FRAME_TIMELINE: &str = "frame";
/// Name of the timeline holding the trace's `log_time`.
pub const TIME_TIMELINE: &str = "time";
/// At most this many edge tests of one sweep get a standardized edge frame
/// (the decisive test first, then hits, then the nearest misses).
pub const MAX_EDGE_FRAMES: usize = 16;
/// `log_time` values at or above this (2001-09-09 as nanoseconds since the
/// Unix epoch) are shown as timestamps; smaller ones as durations since the
/// recording's start.
pub const TIMESTAMP_THRESHOLD_NANOS: u64 = 1_000_000_000_000_000_000;

const MESH_COLOR: [u8; 4] = [170, 175, 185, 255];
const P0_COLOR: [u8; 4] = [80, 140, 255, 90];
const P1_COLOR: [u8; 4] = [160, 160, 160, 60];
const CONTACT_BALL_COLOR: [u8; 4] = [255, 140, 0, 140];
const SWEEP_COLOR: [u8; 4] = [120, 170, 255, 255];
const HIT_COLOR: [u8; 4] = [230, 40, 40, 255];
const MISS_COLOR: [u8; 4] = [240, 200, 40, 255];
const NORMAL_COLOR: [u8; 4] = [40, 200, 80, 255];
const EDGE_COLOR: [u8; 4] = [230, 40, 40, 255];
const CYLINDER_COLOR: [u8; 4] = [255, 120, 120, 255];
const PATH_COLOR: [u8; 4] = [80, 140, 255, 255];

/// A recording id that depends only on `parts` (for example the trace's
/// bytes and the options), so replaying the same trace twice gives the same
/// recording id.
pub fn recording_id(parts: &[&[u8]]) -> String {
    let mut h = IdHasher::new();
    for part in parts {
        h.update(&(part.len() as u64).to_le_bytes());
        h.update(part);
    }
    h.finish()
}

/// Streaming hash for [`recording_id`]s: FNV-1a with 128 bits, printed as
/// `sweeptrace-<32 hex digits>`. Not cryptographic; stable across builds.
#[derive(Clone, Copy, Debug)]
pub struct IdHasher(u128);

impl Default for IdHasher {
    fn default() -> Self {
        IdHasher::new()
    }
}

impl IdHasher {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;

    /// An empty hash.
    pub fn new() -> IdHasher {
        IdHasher(Self::OFFSET)
    }

    /// Adds bytes.
    pub fn update(&mut self, bytes: &[u8]) {
        let mut h = self.0;
        for &b in bytes {
            h ^= b as u128;
            h = h.wrapping_mul(Self::PRIME);
        }
        self.0 = h;
    }

    /// The recording id.
    pub fn finish(&self) -> String {
        format!("sweeptrace-{:032x}", self.0)
    }
}

/// A recording stream builder with the project's settings: application id
/// [`APPLICATION_ID`], the given recording id, no recording properties (they
/// would hold the wall-clock start time).
pub fn builder(recording_id: &str, name: &str) -> RecordingStreamBuilder {
    RecordingStreamBuilder::new(APPLICATION_ID)
        .recording_id(recording_id.to_string())
        .recording_name(name.to_string())
        .send_properties(false)
}

/// The default layout: on top the world and the decisive edge in its
/// standard frame, below them the plots (α, the quadratic, the face test),
/// at the bottom the text log; the time panel on the `frame` timeline, the
/// side panels collapsed.
///
/// The SDK gives the blueprint store and its views random ids, so unlike the
/// recording itself the blueprint's ids differ between runs.
pub fn default_blueprint() -> Blueprint {
    let world = Spatial3DView::new("World").with_origin(paths::WORLD);
    let edge = Spatial3DView::new("Edge frame (ball 0, decisive edge)")
        .with_origin(paths::edge_frame(0, 0));
    let alpha = TimeSeriesView::new("α (ball 0)").with_origin(paths::alpha(0));
    let quadratic = TimeSeriesView::new("Quadratic A, B, C, disc, s0, s1 (ball 0)")
        .with_origin(format!("{}/ball/0/quadratic", paths::PLOTS));
    let face = TimeSeriesView::new("Face h0, h1, β (ball 0)")
        .with_origin(format!("{}/ball/0/face", paths::PLOTS));
    let log = TextLogView::new("Decisions").with_origin(paths::LOG);
    Blueprint::new(
        Vertical::new(vec![
            Horizontal::new(vec![world.into(), edge.into()])
                .with_column_shares(vec![3.0, 2.0])
                .into(),
            Horizontal::new(vec![alpha.into(), quadratic.into(), face.into()]).into(),
            log.into(),
        ])
        .with_row_shares(vec![3.0, 1.4, 1.2]),
    )
    .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
    .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
    .with_time_panel(
        TimePanel::new()
            .with_state(PanelState::Collapsed)
            .with_timeline(FRAME_TIMELINE)
            .with_fps(10.0),
    )
}

#[derive(Debug, Default)]
struct BallState {
    /// Edge slots logged at the previous sweep.
    edge_slots: usize,
}

/// Logs replay events to a recording stream.
///
/// Rows are not sent one by one: they are buffered per entity, as columns,
/// and sent as one chunk per entity every [`DEFAULT_FLUSH_ROWS`] rows (and
/// by [`Logger::flush`] and [`Logger::finish`]). What the recording holds is
/// what logging each row on its own would give, with ids that depend only
/// on the order of the rows, so the same events give the same chunks.
#[derive(Debug)]
pub struct Logger {
    rec: RecordingStream,
    balls: BTreeMap<u32, BallState>,
    scenes: Vec<std::sync::Arc<SceneState>>,
    time_origin_nanos: Option<u64>,
    max_edge_frames: usize,
    columns: columns::Columns,
    flush_rows: usize,
}

/// Rows buffered before the logger sends them (see [`Logger`]).
pub const DEFAULT_FLUSH_ROWS: usize = 1 << 14;

/// What one sweep logs, built without the logger ([`prepare_sweep`]), so
/// that many sweeps can be prepared in parallel and logged in order with
/// [`Logger::log_prepared`].
#[derive(Debug)]
pub struct PreparedSweep {
    frame: u64,
    log_time_nanos: u64,
    ball: u32,
    edge_slots: usize,
    rows: Rows,
}

/// The rows of one sweep: entity path and serialized components, in order.
#[derive(Debug, Default)]
struct Rows(Vec<(String, Vec<rerun::SerializedComponentBatch>)>);

impl Rows {
    fn push(&mut self, path: impl Into<String>, value: &dyn rerun::AsComponents) {
        self.0.push((path.into(), value.as_serialized_batches()));
    }
}

/// Prepares what [`Logger::log_sweep`] logs for `r`: `scene` is the scene
/// it was swept against, `max_edge_frames` as in
/// [`Logger::with_max_edge_frames`].
pub fn prepare_sweep(
    scene: Option<&SceneState>,
    r: &SweepResult,
    max_edge_frames: usize,
) -> PreparedSweep {
    let mut rows = Rows::default();
    let decisive = r.decisive_record().copied();
    sweep_rows(&mut rows, r);
    decisive_rows(&mut rows, scene, r, decisive.as_ref());
    let edge_slots = edge_frame_rows(&mut rows, r, decisive.as_ref(), max_edge_frames);
    plot_rows(&mut rows, r, decisive.as_ref());
    text_rows(&mut rows, r, decisive.as_ref());
    PreparedSweep {
        frame: r.frame,
        log_time_nanos: r.log_time_nanos,
        ball: r.ball,
        edge_slots,
        rows,
    }
}

impl Logger {
    /// Takes over `rec`: switches off the wall-clock timelines, sends the
    /// default blueprint (when `blueprint`) and the static world settings.
    pub fn new(rec: RecordingStream, blueprint: bool) -> Result<Logger, RecordingStreamError> {
        rec.set_log_time_enabled(false);
        rec.set_log_tick_enabled(false);
        if blueprint {
            default_blueprint().send(
                &rec,
                BlueprintActivation {
                    make_active: true,
                    make_default: true,
                },
            )?;
        }
        let mut logger = Logger {
            rec,
            balls: BTreeMap::new(),
            scenes: Vec::new(),
            time_origin_nanos: None,
            max_edge_frames: MAX_EDGE_FRAMES,
            columns: columns::Columns::default(),
            flush_rows: DEFAULT_FLUSH_ROWS,
        };
        logger.log_static(paths::WORLD, &ViewCoordinates::RIGHT_HAND_Z_UP())?;
        Ok(logger)
    }

    /// Sets how many rows are buffered before they are sent (at least 1).
    pub fn with_flush_rows(mut self, rows: usize) -> Logger {
        self.flush_rows = rows.max(1);
        self
    }

    /// How many edge tests per sweep get an edge frame.
    pub fn max_edge_frames(&self) -> usize {
        self.max_edge_frames
    }

    /// Sends every buffered row.
    pub fn flush(&mut self) -> Result<(), RecordingStreamError> {
        self.columns.send(&self.rec)
    }

    fn log_static(
        &mut self,
        path: impl Into<String>,
        value: &dyn rerun::AsComponents,
    ) -> Result<(), RecordingStreamError> {
        self.columns
            .send_static(&self.rec, path.into(), value.as_serialized_batches())
    }

    /// Sets how many edge tests per sweep get an edge frame.
    pub fn with_max_edge_frames(mut self, n: usize) -> Logger {
        self.max_edge_frames = n;
        self
    }

    /// The stream.
    pub fn stream(&self) -> &RecordingStream {
        &self.rec
    }

    /// Logs one event.
    pub fn log(&mut self, event: &ReplayEvent) -> Result<(), RecordingStreamError> {
        match event {
            ReplayEvent::Scene(scene) => self.log_scene(scene),
            ReplayEvent::Sweep(result) => self.log_sweep(result),
        }
    }

    /// Sends what is buffered, flushes and hands the stream back (drop it,
    /// and every clone, to finish a file). Use [`Logger::flush`] first to
    /// see an error of the last rows.
    pub fn finish(mut self) -> RecordingStream {
        let _ = self.flush();
        let _ = self.rec.flush_blocking();
        self.rec
    }

    /// Logs a scene's mesh (static, one Mesh3D, flat-shaded).
    pub fn log_scene(
        &mut self,
        scene: &std::sync::Arc<SceneState>,
    ) -> Result<(), RecordingStreamError> {
        let mut triangles: Vec<&Triangle> = scene.mesh.triangles().iter().collect();
        triangles.sort_by_key(|t| t.index);
        let mut positions = Vec::with_capacity(triangles.len() * 3);
        let mut normals = Vec::with_capacity(triangles.len() * 3);
        for t in &triangles {
            for v in &t.vertices {
                positions.push(f32x3(v.coords));
                normals.push(f32x3(t.normal));
            }
        }
        let indices = (0..triangles.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]);
        let mesh = Mesh3D::new(positions)
            .with_vertex_normals(normals)
            .with_triangle_indices(indices)
            .with_albedo_factor(albedo(MESH_COLOR));
        self.log_static(paths::mesh(scene.number), &mesh)?;
        self.scenes.push(scene.clone());
        Ok(())
    }

    /// The `time` timeline's value of a `log_time`.
    fn time_of(&mut self, log_time_nanos: u64) -> columns::Time {
        let clamp = |n: u64| i64::try_from(n).unwrap_or(i64::MAX);
        if log_time_nanos >= TIMESTAMP_THRESHOLD_NANOS {
            columns::Time::Timestamp(clamp(log_time_nanos))
        } else {
            let origin = *self.time_origin_nanos.get_or_insert(0);
            columns::Time::Duration(clamp(log_time_nanos.saturating_sub(origin)))
        }
    }

    /// Logs one sweep's result at its frame.
    pub fn log_sweep(&mut self, r: &SweepResult) -> Result<(), RecordingStreamError> {
        let scene = self.scenes.iter().find(|s| s.number == r.scene).cloned();
        let prepared = prepare_sweep(scene.as_deref(), r, self.max_edge_frames);
        self.log_prepared(prepared)
    }

    /// Logs a sweep prepared by [`prepare_sweep`] (sweeps must be logged in
    /// trace order).
    pub fn log_prepared(&mut self, p: PreparedSweep) -> Result<(), RecordingStreamError> {
        let frame = i64::try_from(p.frame).unwrap_or(i64::MAX);
        let time = self.time_of(p.log_time_nanos);
        for (path, batches) in p.rows.0 {
            self.columns
                .push_row(&self.rec, path, frame, time, batches)?;
        }
        let b = p.ball;
        let state = self.balls.entry(b).or_default();
        let previous = std::mem::replace(&mut state.edge_slots, p.edge_slots);
        for slot in p.edge_slots..previous {
            self.columns.push_row(
                &self.rec,
                paths::edge_frame(b, slot),
                frame,
                time,
                Clear::recursive().as_serialized_batches(),
            )?;
        }
        if self.columns.rows() >= self.flush_rows {
            self.flush()?;
        }
        Ok(())
    }
}

/// The balls, the swept volume, the contact and the normal.
fn sweep_rows(rows: &mut Rows, r: &SweepResult) {
    let b = r.ball;
    let o = &r.outcome;
    let p0 = r.sweep.p0;
    let p1 = r.sweep.p1;
    let d = p1 - p0;
    let rho = r.rho();
    let radius = r.sweep.radius as f32;
    let at_contact = p0 + d * o.alpha;

    // The ball at p0, at the contact (when hit) and at p1.
    let mut centers = vec![f32x3(p0.coords)];
    let mut colors = vec![rgba(P0_COLOR)];
    let mut labels = vec!["p0".to_string()];
    if o.is_hit() {
        centers.push(f32x3(at_contact.coords));
        colors.push(rgba(CONTACT_BALL_COLOR));
        labels.push(format!("α = {}", num(o.alpha)));
    }
    centers.push(f32x3(p1.coords));
    colors.push(rgba(P1_COLOR));
    labels.push("p1".to_string());
    let n = centers.len();
    rows.push(
        paths::spheres(b),
        &Ellipsoids3D::from_centers_and_radii(centers, std::iter::repeat_n(radius, n))
            .with_colors(colors)
            .with_labels(labels)
            .with_fill_mode(FillMode::Solid),
    );

    // The swept volume at the detection radius.
    let (length, rotation) = capsule_pose(&d);
    rows.push(
        paths::sweep(b),
        &Capsules3D::from_lengths_and_radii([length], [rho as f32])
            .with_translations([f32x3(p0.coords)])
            .with_quaternions([rotation])
            .with_colors([rgba(SWEEP_COLOR)])
            .with_fill_mode(FillMode::MajorWireframe),
    );

    // Contact and normal.
    match (o.contact, o.normal) {
        (Some(c), Some(nrm)) => {
            rows.push(
                paths::contact(b),
                &Points3D::new([f32x3(c.coords)])
                    .with_colors([rgba(HIT_COLOR)])
                    .with_radii([(rho * 0.08) as f32]),
            );
            rows.push(
                paths::normal(b),
                &Arrows3D::from_vectors([f32x3(nrm * (r.sweep.radius.max(1e-3) * 1.5))])
                    .with_origins([f32x3(c.coords)])
                    .with_colors([rgba(NORMAL_COLOR)])
                    .with_labels(["normal"]),
            );
        }
        _ => {
            rows.push(paths::contact(b), &Clear::flat());
            rows.push(paths::normal(b), &Clear::flat());
        }
    }
}

/// The highlighted triangle, edge or vertex of the decisive test.
fn decisive_rows(
    rows: &mut Rows,
    scene: Option<&SceneState>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
) {
    let b = r.ball;
    let scene = scene.filter(|s| s.number == r.scene);
    let triangle =
        decisive.and_then(|t| scene.and_then(|s| s.mesh.triangle_by_index(t.triangle())));
    let (Some(t), Some(test)) = (triangle, decisive) else {
        rows.push(paths::primary_triangle(b), &Clear::flat());
        rows.push(paths::primary_edge(b), &Clear::flat());
        rows.push(paths::primary_vertex(b), &Clear::flat());
        return;
    };
    let color = if test.alpha().is_some() {
        HIT_COLOR
    } else {
        MISS_COLOR
    };
    // Lift the highlight a little off the mesh so it is not hidden by it.
    let lift = t.normal * (r.rho() * 0.02);
    let verts: Vec<[f32; 3]> = t.vertices.iter().map(|v| f32x3(v.coords + lift)).collect();
    rows.push(
        paths::primary_triangle(b),
        &Mesh3D::new(verts.clone())
            .with_triangle_indices([[0u32, 1, 2]])
            .with_albedo_factor(albedo([color[0], color[1], color[2], 110])),
    );
    let f = test.feature() as usize % 3;
    match test {
        TestRecord::Edge(_) => {
            rows.push(
                paths::primary_edge(b),
                &LineStrips3D::new([[verts[f], verts[(f + 1) % 3]]])
                    .with_colors([rgba(color)])
                    .with_radii([(r.rho() * 0.05) as f32])
                    .with_labels([crate::core::explain::label(test)]),
            );
            rows.push(paths::primary_vertex(b), &Clear::flat());
        }
        TestRecord::Vertex(_) => {
            rows.push(
                paths::primary_vertex(b),
                &Points3D::new([verts[f]])
                    .with_colors([rgba(color)])
                    .with_radii([(r.rho() * 0.12) as f32])
                    .with_labels([crate::core::explain::label(test)]),
            );
            rows.push(paths::primary_edge(b), &Clear::flat());
        }
        TestRecord::Face(_) => {
            let mut outline = verts.clone();
            outline.push(verts[0]);
            rows.push(
                paths::primary_edge(b),
                &LineStrips3D::new([outline])
                    .with_colors([rgba(color)])
                    .with_radii([(r.rho() * 0.03) as f32])
                    .with_labels([crate::core::explain::label(test)]),
            );
            rows.push(paths::primary_vertex(b), &Clear::flat());
        }
    }
}

/// The edge tests in their standard frames; returns how many slots it used.
fn edge_frame_rows(
    rows: &mut Rows,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    max_edge_frames: usize,
) -> usize {
    let b = r.ball;
    let rho = r.rho();
    let mut edges: Vec<(f64, &EdgeRecord)> = r
        .records
        .iter()
        .filter_map(|t| match t {
            TestRecord::Edge(e) => {
                let rank = if decisive == Some(t) {
                    f64::NEG_INFINITY
                } else if t.alpha().is_some() {
                    -1.0
                } else {
                    miss_distance(t).unwrap_or(f64::INFINITY)
                };
                Some((rank, e))
            }
            _ => None,
        })
        .collect();
    edges.sort_by(|x, y| x.0.total_cmp(&y.0));
    edges.truncate(max_edge_frames);
    for (slot, (_, e)) in edges.iter().enumerate() {
        let world_from_edge = e.frame.world_from_edge();
        let q = world_from_edge.rotation;
        let t = world_from_edge.translation.vector;
        rows.push(
            paths::edge_frame(b, slot),
            &Transform3D::from_translation_rotation(
                f32x3(t),
                rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32]),
            ),
        );
        rows.push(paths::edge_frame(b, slot), &edge_values(e));
        let length = e.length as f32;
        // Only the first slot is labelled: with many slots the labels
        // would hide the world view.
        let mut segment = LineStrips3D::new([[[0.0f32, 0.0, 0.0], [length, 0.0, 0.0]]])
            .with_colors([rgba(EDGE_COLOR)])
            .with_radii([(rho * 0.04) as f32]);
        if slot == 0 {
            segment = segment.with_labels([format!(
                "edge {}.{} (L = {})",
                e.triangle,
                e.edge,
                num(e.length)
            )]);
        }
        rows.push(paths::edge_segment(b, slot), &segment);
        // A capsule lies along +z; turn it onto +x (90° about +y).
        let half = std::f32::consts::FRAC_1_SQRT_2;
        rows.push(
            paths::edge_cylinder(b, slot),
            &Capsules3D::from_lengths_and_radii([length], [rho as f32])
                .with_quaternions([rerun::Quaternion::from_xyzw([0.0, half, 0.0, half])])
                .with_colors([rgba(CYLINDER_COLOR)])
                .with_fill_mode(FillMode::MajorWireframe),
        );
        let p0e = f32x3(e.p0_in_edge.coords);
        let p1e = f32x3(e.p1_in_edge.coords);
        rows.push(
            paths::edge_path(b, slot),
            &LineStrips3D::new([[p0e, p1e]])
                .with_colors([rgba(PATH_COLOR)])
                .with_radii([(rho * 0.03) as f32]),
        );
        let mut points = vec![p0e, p1e];
        let mut labels = vec!["p0".to_string(), "p1".to_string()];
        if let Some((s0, _)) = e.roots
            && (-1.0..=2.0).contains(&s0)
        {
            let at = e.p0_in_edge + (e.p1_in_edge - e.p0_in_edge) * s0;
            points.push(f32x3(at.coords));
            labels.push(format!("s0 = {}", num(s0)));
        }
        rows.push(
            paths::edge_points(b, slot),
            &Points3D::new(points)
                .with_labels(labels)
                .with_radii([(rho * 0.06) as f32]),
        );
    }
    edges.len()
}

/// The α plot and the decisive test's numbers.
fn plot_rows(rows: &mut Rows, r: &SweepResult, decisive: Option<&TestRecord>) {
    let b = r.ball;
    rows.push(paths::alpha(b), &Scalars::single(r.outcome.alpha));
    rows.push(
        paths::alpha(b),
        &AnyValues::default()
            .with_component::<rerun::components::Text>("kind", [r.outcome.kind.as_str()]),
    );
    let mut quadratic = |a: f64, bb: f64, c: f64, disc: f64, roots: Option<(f64, f64)>| {
        let mut values = vec![a, bb, c, disc];
        if let Some((s0, s1)) = roots {
            values.extend([s0, s1]);
        }
        for (name, v) in paths::QUADRATIC_NAMES.iter().zip(values) {
            if v.is_finite() {
                rows.push(paths::quadratic(b, name), &Scalars::single(v));
            }
        }
    };
    match decisive {
        Some(TestRecord::Edge(e)) => quadratic(e.a, e.b, e.c, e.discriminant, e.roots),
        Some(TestRecord::Vertex(v)) => quadratic(v.a, v.b, v.c, v.discriminant, v.roots),
        Some(TestRecord::Face(f)) => {
            for (name, v) in paths::FACE_NAMES
                .iter()
                .zip([Some(f.h0), Some(f.h1), f.beta])
            {
                if let Some(v) = v.filter(|v| v.is_finite()) {
                    rows.push(paths::face(b, name), &Scalars::single(v));
                }
            }
        }
        None => {}
    }
}

/// The decision in words.
fn text_rows(rows: &mut Rows, r: &SweepResult, decisive: Option<&TestRecord>) {
    let (line, mismatch) = decision_line(r, decisive);
    let level = if mismatch {
        TextLogLevel::WARN
    } else if r.outcome.is_hit() {
        TextLogLevel::INFO
    } else {
        TextLogLevel::DEBUG
    };
    rows.push(paths::LOG, &TextLog::new(line).with_level(level));
}

/// The text line of one sweep, and whether it disagrees with the trace's
/// expected outcome.
pub fn decision_line(r: &SweepResult, decisive: Option<&TestRecord>) -> (String, bool) {
    let o = &r.outcome;
    let mut s = format!("frame {} ball {}: ", r.frame, r.ball);
    if o.is_hit() {
        s.push_str(&format!(
            "{} collision at α = {} (triangle {}, feature {})",
            o.kind,
            num(o.alpha),
            o.triangle.map_or("-".into(), |t| t.to_string()),
            o.feature.map_or("-".into(), |f| f.to_string())
        ));
        if let Some(t) = decisive {
            s.push_str(" — ");
            s.push_str(&describe(t));
        }
    } else {
        s.push_str("no collision");
        match decisive {
            Some(t) => {
                s.push_str("; closest candidate rejected: ");
                s.push_str(&describe(t));
            }
            None if r.records.is_empty() => {
                s.push_str(" (no triangle's box comes within ρ of the path)")
            }
            None => {}
        }
    }
    let mut mismatch = false;
    if let Some(e) = &r.expected {
        let alpha_differs = (e.alpha - o.alpha).abs() > 1e-6 || !e.alpha.is_finite();
        if e.kind != o.kind || alpha_differs {
            mismatch = true;
            s.push_str(&format!(" [expected {} at α = {}]", e.kind, num(e.alpha)));
        }
    }
    (s, mismatch)
}

fn edge_values(e: &EdgeRecord) -> AnyValues {
    use rerun::components::{Scalar, Text};
    let mut v = AnyValues::default()
        .with_component::<Text>("test", [format!("edge {}.{}", e.triangle, e.edge)])
        .with_component::<Text>("verdict", [e.verdict.as_str()])
        .with_component::<Scalar>("length", [e.length])
        .with_component::<Scalar>("a", [e.a])
        .with_component::<Scalar>("b", [e.b])
        .with_component::<Scalar>("c", [e.c])
        .with_component::<Scalar>("discriminant", [e.discriminant]);
    if let Some((s0, s1)) = e.roots {
        v = v
            .with_component::<Scalar>("s0", [s0])
            .with_component::<Scalar>("s1", [s1]);
    }
    if let Some(xc) = e.xc {
        v = v.with_component::<Scalar>("xc", [xc]);
    }
    v
}

/// Length and rotation of a capsule (which lies along +z) from the origin
/// along `d`.
fn capsule_pose(d: &Vector3<f64>) -> (f32, rerun::Quaternion) {
    let length = d.norm();
    let q = if length > 0.0 {
        UnitQuaternion::rotation_between(&Vector3::z(), d).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
        })
    } else {
        UnitQuaternion::identity()
    };
    (
        length as f32,
        rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32]),
    )
}

fn f32x3(v: Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn rgba(c: [u8; 4]) -> Color {
    Color::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}

fn albedo(c: [u8; 4]) -> rerun::datatypes::Rgba32 {
    rerun::datatypes::Rgba32::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}
