//! The Rerun recording of a replay: the only module that imports `rerun`.
//!
//! [`Logger`] turns [`ReplayEvent`]s into entities (see [`paths`] for every
//! path) on two timelines: `frame` (sequence, the sweep's frame) and `time`
//! (the trace's `log_time`; never the wall clock). The default timelines
//! `log_time` and `log_tick` of the SDK are switched off, and the recording
//! id is derived from the trace and the options ([`recording_id`]), so the
//! same trace and options give the same content. (Rerun's row and chunk ids
//! are still fresh per run, so the bytes of two `.rrd` files differ.)

pub mod blueprint;
mod columns;
pub mod paths;
pub mod pipeline;

use std::collections::BTreeMap;
use std::fmt::{self, Write as _};

use nalgebra::{UnitQuaternion, Vector3};
use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintPanel, Horizontal, SelectionPanel, Spatial3DView, TextLogView, TimePanel,
    TimeSeriesView, Vertical,
};
use rerun::components::{
    AlbedoFactor, ClearIsRecursive, FillMode, HalfSize3D, Length, Position3D, Radius, RotationQuat,
    Scalar, Text, TextLogLevel, Translation3D, TriangleIndices, Vector3D,
};
use rerun::{
    Arrows3D, Capsules3D, Clear, Color, ComponentDescriptor, Ellipsoids3D, LineStrips3D, Mesh3D,
    Points3D, RecordingStream, RecordingStreamBuilder, Scalars, TextLog, Transform3D,
    ViewCoordinates,
};

use crate::core::explain::{Label, Num, miss_distance, write_describe};
use crate::core::{EdgeRecord, TestRecord, Triangle};
use crate::replay::{ReplayEvent, SceneState, SweepResult};
use paths::Entity;

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
/// Built with the SDK's `Blueprint`, which gives the blueprint store and its
/// views random ids; [`Logger::new`] sends the same layout with fixed ids
/// instead ([`blueprint::send_default_blueprint`]).
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
/// Rows are not sent one by one: they are buffered per entity as typed
/// columns (plain values, see `columns`), and sent as one chunk per entity
/// every [`DEFAULT_FLUSH_ROWS`] rows (and by [`Logger::flush`] and
/// [`Logger::finish`]). What the recording holds is what logging each row
/// on its own would give, with ids that depend only on the order of the
/// rows, so the same events give the same chunks.
#[derive(Debug)]
pub struct Logger {
    rec: RecordingStream,
    balls: BTreeMap<u32, BallState>,
    scenes: Vec<std::sync::Arc<SceneState>>,
    max_edge_frames: usize,
    columns: columns::Columns,
    flush_rows: usize,
    /// Emptied [`PreparedSweeps`], handed out again by
    /// [`Logger::spare_prepared`] so that their buffers are reused.
    spare: Vec<PreparedSweeps>,
}

/// At most this many emptied [`PreparedSweeps`] are kept for reuse.
const MAX_SPARE_PREPARED: usize = 16;

/// Rows buffered before the logger sends them (see [`Logger`]).
pub const DEFAULT_FLUSH_ROWS: usize = 1 << 17;

/// Sweeps per [`PreparedSweeps`] that the command and the bench prepare on
/// one worker (runs of consecutive sweeps of a batch, cut at this length).
pub const PREPARE_GROUP_SWEEPS: usize = 1024;

/// What a run of consecutive sweeps logs, built without the logger
/// ([`prepare_sweeps`]), so that runs can be prepared in parallel and logged
/// in order with [`Logger::log_prepared`].
#[derive(Debug, Default)]
pub struct PreparedSweeps {
    columns: columns::Columns,
    /// Per sweep: ball, edge slots used, frame, time.
    sweeps: Vec<(u32, usize, i64, columns::Time)>,
}

impl PreparedSweeps {
    /// Sweeps prepared.
    pub fn len(&self) -> usize {
        self.sweeps.len()
    }

    /// Whether no sweep was prepared.
    pub fn is_empty(&self) -> bool {
        self.sweeps.is_empty()
    }
}

/// Component sets: the rows of one entity with the same set number have the
/// same components (see `columns::Columns::row`).
mod set {
    pub const SPHERES: u8 = 0;
    pub const SWEEP: u8 = 1;
    pub const CONTACT: u8 = 2;
    pub const NORMAL: u8 = 3;
    pub const CLEAR: u8 = 4;
    pub const TRIANGLE: u8 = 5;
    pub const LABELED_STRIP: u8 = 6;
    pub const LABELED_POINT: u8 = 7;
    pub const TRANSFORM: u8 = 8;
    pub const STRIP: u8 = 9;
    pub const CYLINDER: u8 = 10;
    pub const EDGE_POINTS: u8 = 11;
    pub const SCALAR: u8 = 12;
    pub const KIND: u8 = 13;
    pub const TEXT_LOG: u8 = 14;
    /// Plus 1 with roots, plus 2 with xc.
    pub const EDGE_VALUES: u8 = 16;
}

/// Where the rows of one sweep go.
struct Out<'a> {
    columns: &'a mut columns::Columns,
    frame: i64,
    time: columns::Time,
}

impl Out<'_> {
    fn row(&mut self, entity: Entity, set: u8) -> columns::Row<'_> {
        self.columns.row(entity, set, self.frame, self.time)
    }

    fn clear(&mut self, entity: Entity, recursive: bool) {
        self.row(entity, set::CLEAR)
            .put::<ClearIsRecursive>(Clear::descriptor_is_recursive, [recursive.into()]);
    }
}

/// Prepares what [`Logger::log_sweep`] logs for each of `results` (in
/// order): `scenes` holds (at least) the scenes they were swept against,
/// `max_edge_frames` as in [`Logger::with_max_edge_frames`].
pub fn prepare_sweeps<'r>(
    scenes: &[std::sync::Arc<SceneState>],
    results: impl IntoIterator<Item = &'r SweepResult>,
    max_edge_frames: usize,
) -> PreparedSweeps {
    let mut p = PreparedSweeps::default();
    prepare_sweeps_into(&mut p, scenes, results, max_edge_frames);
    p
}

/// [`prepare_sweeps`] into `p` (an empty one, for example from
/// [`Logger::spare_prepared`], whose buffers are reused).
pub fn prepare_sweeps_into<'r>(
    p: &mut PreparedSweeps,
    scenes: &[std::sync::Arc<SceneState>],
    results: impl IntoIterator<Item = &'r SweepResult>,
    max_edge_frames: usize,
) {
    debug_assert!(p.is_empty() && p.columns.rows() == 0);
    for r in results {
        let scene = scenes.iter().find(|s| s.number == r.scene).map(|s| &**s);
        let frame = i64::try_from(r.frame).unwrap_or(i64::MAX);
        let time = time_of(r.log_time_nanos);
        let mut out = Out {
            columns: &mut p.columns,
            frame,
            time,
        };
        let decisive = r.decisive_record().copied();
        sweep_rows(&mut out, r);
        decisive_rows(&mut out, scene, r, decisive.as_ref());
        let edge_slots = edge_frame_rows(&mut out, r, decisive.as_ref(), max_edge_frames);
        plot_rows(&mut out, r, decisive.as_ref());
        text_rows(&mut out, r, decisive.as_ref());
        p.sweeps.push((r.ball, edge_slots, frame, time));
    }
}

/// The `time` timeline's value of a `log_time`.
fn time_of(log_time_nanos: u64) -> columns::Time {
    let clamp = |n: u64| i64::try_from(n).unwrap_or(i64::MAX);
    if log_time_nanos >= TIMESTAMP_THRESHOLD_NANOS {
        columns::Time::Timestamp(clamp(log_time_nanos))
    } else {
        columns::Time::Duration(clamp(log_time_nanos))
    }
}

impl Logger {
    /// Takes over `rec`: switches off the wall-clock timelines, sends the
    /// default blueprint (when `blueprint`) and the static world settings.
    pub fn new(rec: RecordingStream, blueprint: bool) -> Result<Logger, RecordingStreamError> {
        rec.set_log_time_enabled(false);
        rec.set_log_tick_enabled(false);
        if blueprint {
            blueprint::send_default_blueprint(&rec)?;
        }
        let mut logger = Logger {
            rec,
            balls: BTreeMap::new(),
            scenes: Vec::new(),
            max_edge_frames: MAX_EDGE_FRAMES,
            columns: columns::Columns::default(),
            flush_rows: DEFAULT_FLUSH_ROWS,
            spare: Vec::new(),
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

    /// Logs one sweep's result at its frame.
    pub fn log_sweep(&mut self, r: &SweepResult) -> Result<(), RecordingStreamError> {
        let prepared = prepare_sweeps(&self.scenes, [r], self.max_edge_frames);
        self.log_prepared(prepared)
    }

    /// Logs sweeps prepared by [`prepare_sweeps`] (sweeps must be logged in
    /// trace order).
    pub fn log_prepared(&mut self, mut p: PreparedSweeps) -> Result<(), RecordingStreamError> {
        self.columns.append(&mut p.columns);
        // Clear the edge frames a ball used at its previous sweep and no
        // longer uses.
        for (b, edge_slots, frame, time) in p.sweeps.drain(..) {
            let state = self.balls.entry(b).or_default();
            let previous = std::mem::replace(&mut state.edge_slots, edge_slots);
            let mut out = Out {
                columns: &mut self.columns,
                frame,
                time,
            };
            for slot in edge_slots..previous {
                out.clear(Entity::EdgeFrame(b, slot), true);
            }
        }
        if self.spare.len() < MAX_SPARE_PREPARED {
            self.spare.push(p);
        }
        if self.columns.rows() >= self.flush_rows {
            self.flush()?;
        }
        Ok(())
    }

    /// An empty [`PreparedSweeps`] to fill with [`prepare_sweeps_into`]:
    /// one handed back by [`Logger::log_prepared`] (buffers kept) when
    /// there is one.
    pub fn spare_prepared(&mut self) -> PreparedSweeps {
        self.spare.pop().unwrap_or_default()
    }
}

/// The balls, the swept volume, the contact and the normal.
fn sweep_rows(out: &mut Out<'_>, r: &SweepResult) {
    use std::iter::once;
    let b = r.ball;
    let o = &r.outcome;
    let p0 = r.sweep.p0;
    let p1 = r.sweep.p1;
    let d = p1 - p0;
    let rho = r.rho();
    let radius = r.sweep.radius as f32;
    let at_contact = p0 + d * o.alpha;

    // The ball at p0, at the contact (when hit) and at p1.
    let hit = o.is_hit();
    let n = if hit { 3 } else { 2 };
    let contact_center = hit.then(|| f32x3(at_contact.coords));
    let contact_color = hit.then(|| rgba(CONTACT_BALL_COLOR));
    out.row(Entity::Spheres(b), set::SPHERES)
        .put::<HalfSize3D>(
            Ellipsoids3D::descriptor_half_sizes,
            std::iter::repeat_n(HalfSize3D::splat(radius), n),
        )
        .put::<Translation3D>(
            Ellipsoids3D::descriptor_centers,
            once(f32x3(p0.coords))
                .chain(contact_center)
                .chain(once(f32x3(p1.coords)))
                .map(Translation3D::from),
        )
        .put::<Color>(
            Ellipsoids3D::descriptor_colors,
            once(rgba(P0_COLOR))
                .chain(contact_color)
                .chain(once(rgba(P1_COLOR))),
        )
        .put::<FillMode>(Ellipsoids3D::descriptor_fill_mode, [FillMode::Solid])
        .put_texts(Ellipsoids3D::descriptor_labels, |t| {
            t.push("p0");
            if hit {
                t.push_fmt(format_args!("α = {}", Num(o.alpha)));
            }
            t.push("p1");
        });

    // The swept volume at the detection radius.
    let (length, rotation) = capsule_pose(&d);
    out.row(Entity::Sweep(b), set::SWEEP)
        .put::<Length>(Capsules3D::descriptor_lengths, [length.into()])
        .put::<Radius>(Capsules3D::descriptor_radii, [(rho as f32).into()])
        .put::<Translation3D>(
            Capsules3D::descriptor_translations,
            [f32x3(p0.coords).into()],
        )
        .put::<RotationQuat>(Capsules3D::descriptor_quaternions, [rotation.into()])
        .put::<Color>(Capsules3D::descriptor_colors, [rgba(SWEEP_COLOR)])
        .put::<FillMode>(Capsules3D::descriptor_fill_mode, [FillMode::MajorWireframe]);

    // Contact and normal.
    match (o.contact, o.normal) {
        (Some(c), Some(nrm)) => {
            out.row(Entity::Contact(b), set::CONTACT)
                .put::<Position3D>(Points3D::descriptor_positions, [f32x3(c.coords).into()])
                .put::<Radius>(Points3D::descriptor_radii, [((rho * 0.08) as f32).into()])
                .put::<Color>(Points3D::descriptor_colors, [rgba(HIT_COLOR)]);
            out.row(Entity::Normal(b), set::NORMAL)
                .put::<Vector3D>(
                    Arrows3D::descriptor_vectors,
                    [f32x3(nrm * (r.sweep.radius.max(1e-3) * 1.5)).into()],
                )
                .put::<Position3D>(Arrows3D::descriptor_origins, [f32x3(c.coords).into()])
                .put::<Color>(Arrows3D::descriptor_colors, [rgba(NORMAL_COLOR)])
                .put_strs(Arrows3D::descriptor_labels, ["normal"]);
        }
        _ => {
            out.clear(Entity::Contact(b), false);
            out.clear(Entity::Normal(b), false);
        }
    }
}

/// Puts a `LineStrips3D` row: one strip, color, radius and label.
fn labeled_strip(
    out: &mut Out<'_>,
    entity: Entity,
    strip: &[[f32; 3]],
    color: [u8; 4],
    radius: f32,
    label: fmt::Arguments<'_>,
) {
    out.row(entity, set::LABELED_STRIP)
        .put_strip(LineStrips3D::descriptor_strips, strip)
        .put::<Radius>(LineStrips3D::descriptor_radii, [radius.into()])
        .put::<Color>(LineStrips3D::descriptor_colors, [rgba(color)])
        .put_fmt(LineStrips3D::descriptor_labels, label);
}

/// The highlighted triangle, edge or vertex of the decisive test.
fn decisive_rows(
    out: &mut Out<'_>,
    scene: Option<&SceneState>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
) {
    let b = r.ball;
    let scene = scene.filter(|s| s.number == r.scene);
    let triangle =
        decisive.and_then(|t| scene.and_then(|s| s.mesh.triangle_by_index(t.triangle())));
    let (Some(t), Some(test)) = (triangle, decisive) else {
        out.clear(Entity::PrimaryTriangle(b), false);
        out.clear(Entity::PrimaryEdge(b), false);
        out.clear(Entity::PrimaryVertex(b), false);
        return;
    };
    let color = if test.alpha().is_some() {
        HIT_COLOR
    } else {
        MISS_COLOR
    };
    // Lift the highlight a little off the mesh so it is not hidden by it.
    let lift = t.normal * (r.rho() * 0.02);
    let verts: [[f32; 3]; 3] = std::array::from_fn(|i| f32x3(t.vertices[i].coords + lift));
    out.row(Entity::PrimaryTriangle(b), set::TRIANGLE)
        .put::<Position3D>(
            Mesh3D::descriptor_vertex_positions,
            verts.map(Position3D::from),
        )
        .put::<TriangleIndices>(Mesh3D::descriptor_triangle_indices, [[0u32, 1, 2].into()])
        .put::<AlbedoFactor>(
            Mesh3D::descriptor_albedo_factor,
            [albedo([color[0], color[1], color[2], 110]).into()],
        );
    let f = test.feature() as usize % 3;
    let label = Label(test);
    match test {
        TestRecord::Edge(_) => {
            labeled_strip(
                out,
                Entity::PrimaryEdge(b),
                &[verts[f], verts[(f + 1) % 3]],
                color,
                (r.rho() * 0.05) as f32,
                format_args!("{label}"),
            );
            out.clear(Entity::PrimaryVertex(b), false);
        }
        TestRecord::Vertex(_) => {
            out.row(Entity::PrimaryVertex(b), set::LABELED_POINT)
                .put::<Position3D>(Points3D::descriptor_positions, [verts[f].into()])
                .put::<Radius>(
                    Points3D::descriptor_radii,
                    [((r.rho() * 0.12) as f32).into()],
                )
                .put::<Color>(Points3D::descriptor_colors, [rgba(color)])
                .put_fmt(Points3D::descriptor_labels, format_args!("{label}"));
            out.clear(Entity::PrimaryEdge(b), false);
        }
        TestRecord::Face(_) => {
            labeled_strip(
                out,
                Entity::PrimaryEdge(b),
                &[verts[0], verts[1], verts[2], verts[0]],
                color,
                (r.rho() * 0.03) as f32,
                format_args!("{label}"),
            );
            out.clear(Entity::PrimaryVertex(b), false);
        }
    }
}

/// The edge tests in their standard frames; returns how many slots it used.
fn edge_frame_rows(
    out: &mut Out<'_>,
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
        out.row(Entity::EdgeFrame(b, slot), set::TRANSFORM)
            .put::<Translation3D>(Transform3D::descriptor_translation, [f32x3(t).into()])
            .put::<RotationQuat>(
                Transform3D::descriptor_quaternion,
                [
                    rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
                        .into(),
                ],
            );
        edge_values(out, Entity::EdgeFrame(b, slot), e);
        let length = e.length as f32;
        let segment = [[0.0f32, 0.0, 0.0], [length, 0.0, 0.0]];
        let segment_radius = (rho * 0.04) as f32;
        // Only the first slot is labelled: with many slots the labels
        // would hide the world view.
        if slot == 0 {
            labeled_strip(
                out,
                Entity::EdgeSegment(b, slot),
                &segment,
                EDGE_COLOR,
                segment_radius,
                format_args!("edge {}.{} (L = {})", e.triangle, e.edge, Num(e.length)),
            );
        } else {
            strip(
                out,
                Entity::EdgeSegment(b, slot),
                &segment,
                EDGE_COLOR,
                segment_radius,
            );
        }
        // A capsule lies along +z; turn it onto +x (90° about +y).
        let half = std::f32::consts::FRAC_1_SQRT_2;
        out.row(Entity::EdgeCylinder(b, slot), set::CYLINDER)
            .put::<Length>(Capsules3D::descriptor_lengths, [length.into()])
            .put::<Radius>(Capsules3D::descriptor_radii, [(rho as f32).into()])
            .put::<RotationQuat>(
                Capsules3D::descriptor_quaternions,
                [rerun::Quaternion::from_xyzw([0.0, half, 0.0, half]).into()],
            )
            .put::<Color>(Capsules3D::descriptor_colors, [rgba(CYLINDER_COLOR)])
            .put::<FillMode>(Capsules3D::descriptor_fill_mode, [FillMode::MajorWireframe]);
        let p0e = f32x3(e.p0_in_edge.coords);
        let p1e = f32x3(e.p1_in_edge.coords);
        strip(
            out,
            Entity::EdgePath(b, slot),
            &[p0e, p1e],
            PATH_COLOR,
            (rho * 0.03) as f32,
        );
        let mut at_s0 = None;
        if let Some((s0, _)) = e.roots
            && (-1.0..=2.0).contains(&s0)
        {
            let at = e.p0_in_edge + (e.p1_in_edge - e.p0_in_edge) * s0;
            at_s0 = Some((f32x3(at.coords), s0));
        }
        out.row(Entity::EdgePoints(b, slot), set::EDGE_POINTS)
            .put::<Position3D>(
                Points3D::descriptor_positions,
                [p0e, p1e]
                    .into_iter()
                    .chain(at_s0.as_ref().map(|a| a.0))
                    .map(Position3D::from),
            )
            .put::<Radius>(Points3D::descriptor_radii, [((rho * 0.06) as f32).into()])
            .put_texts(Points3D::descriptor_labels, |t| {
                t.push("p0").push("p1");
                if let Some((_, s0)) = at_s0 {
                    t.push_fmt(format_args!("s0 = {}", Num(s0)));
                }
            });
    }
    edges.len()
}

/// Puts a `LineStrips3D` row: one strip, color and radius.
fn strip(out: &mut Out<'_>, entity: Entity, strip: &[[f32; 3]], color: [u8; 4], radius: f32) {
    out.row(entity, set::STRIP)
        .put_strip(LineStrips3D::descriptor_strips, strip)
        .put::<Radius>(LineStrips3D::descriptor_radii, [radius.into()])
        .put::<Color>(LineStrips3D::descriptor_colors, [rgba(color)]);
}

/// A `Scalars` row.
fn scalar(out: &mut Out<'_>, entity: Entity, v: f64) {
    out.row(entity, set::SCALAR)
        .put::<Scalar>(Scalars::descriptor_scalars, [v.into()]);
}

/// The α plot and the decisive test's numbers.
fn plot_rows(out: &mut Out<'_>, r: &SweepResult, decisive: Option<&TestRecord>) {
    let b = r.ball;
    scalar(out, Entity::Alpha(b), r.outcome.alpha);
    out.row(Entity::Alpha(b), set::KIND)
        .put_strs(|| any_value::<Text>("kind"), [r.outcome.kind.as_str()]);
    let mut quadratic = |a: f64, bb: f64, c: f64, disc: f64, roots: Option<(f64, f64)>| {
        let (s0, s1) = roots.unzip();
        for (i, v) in [Some(a), Some(bb), Some(c), Some(disc), s0, s1]
            .into_iter()
            .enumerate()
        {
            if let Some(v) = v.filter(|v| v.is_finite()) {
                scalar(out, Entity::Quadratic(b, i), v);
            }
        }
    };
    match decisive {
        Some(TestRecord::Edge(e)) => quadratic(e.a, e.b, e.c, e.discriminant, e.roots),
        Some(TestRecord::Vertex(v)) => quadratic(v.a, v.b, v.c, v.discriminant, v.roots),
        Some(TestRecord::Face(f)) => {
            for (i, v) in [Some(f.h0), Some(f.h1), f.beta].into_iter().enumerate() {
                if let Some(v) = v.filter(|v| v.is_finite()) {
                    scalar(out, Entity::Face(b, i), v);
                }
            }
        }
        None => {}
    }
}

/// The decision in words.
fn text_rows(out: &mut Out<'_>, r: &SweepResult, decisive: Option<&TestRecord>) {
    let mut row = out.row(Entity::Log, set::TEXT_LOG);
    let mut mismatch = false;
    row.put_texts(TextLog::descriptor_text, |t| {
        t.push_with(|s| mismatch = write_decision_line(s, r, decisive));
    });
    let level = if mismatch {
        TextLogLevel::WARN
    } else if r.outcome.is_hit() {
        TextLogLevel::INFO
    } else {
        TextLogLevel::DEBUG
    };
    row.put_strs(TextLog::descriptor_level, [level]);
}

/// The text line of one sweep, and whether it disagrees with the trace's
/// expected outcome.
pub fn decision_line(r: &SweepResult, decisive: Option<&TestRecord>) -> (String, bool) {
    let mut s = String::new();
    let mismatch = write_decision_line(&mut s, r, decisive);
    (s, mismatch)
}

/// Appends [`decision_line`]'s line to `s`; returns whether it disagrees
/// with the trace's expected outcome.
fn write_decision_line(s: &mut String, r: &SweepResult, decisive: Option<&TestRecord>) -> bool {
    let o = &r.outcome;
    let _ = write!(s, "frame {} ball {}: ", r.frame, r.ball);
    if o.is_hit() {
        let _ = write!(
            s,
            "{} collision at α = {} (triangle {}, feature {})",
            o.kind,
            Num(o.alpha),
            OrDash(o.triangle),
            OrDash(o.feature)
        );
        if let Some(t) = decisive {
            s.push_str(" — ");
            let _ = write_describe(s, t);
        }
    } else {
        s.push_str("no collision");
        match decisive {
            Some(t) => {
                s.push_str("; closest candidate rejected: ");
                let _ = write_describe(s, t);
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
            let _ = write!(s, " [expected {} at α = {}]", e.kind, Num(e.alpha));
        }
    }
    mismatch
}

/// A number, or `-` for `None`.
struct OrDash<T>(Option<T>);

impl<T: fmt::Display> fmt::Display for OrDash<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Some(v) => v.fmt(f),
            None => f.write_str("-"),
        }
    }
}

/// The descriptor `AnyValues::with_component::<C>(name, ..)` gives.
fn any_value<C: rerun::Component>(name: &'static str) -> ComponentDescriptor {
    ComponentDescriptor::partial(name).with_component_type(C::name())
}

/// The numbers of an edge test (as `AnyValues`: test, verdict, length, a,
/// b, c, discriminant, and s0, s1, xc when known).
fn edge_values(out: &mut Out<'_>, entity: Entity, e: &EdgeRecord) {
    let set = set::EDGE_VALUES + u8::from(e.roots.is_some()) + 2 * u8::from(e.xc.is_some());
    let mut row = out.row(entity, set);
    row.put_fmt(
        || any_value::<Text>("test"),
        format_args!("edge {}.{}", e.triangle, e.edge),
    )
    .put_strs(|| any_value::<Text>("verdict"), [e.verdict.as_str()])
    .put::<Scalar>(|| any_value::<Scalar>("length"), [e.length.into()])
    .put::<Scalar>(|| any_value::<Scalar>("a"), [e.a.into()])
    .put::<Scalar>(|| any_value::<Scalar>("b"), [e.b.into()])
    .put::<Scalar>(|| any_value::<Scalar>("c"), [e.c.into()])
    .put::<Scalar>(
        || any_value::<Scalar>("discriminant"),
        [e.discriminant.into()],
    );
    if let Some((s0, s1)) = e.roots {
        row.put::<Scalar>(|| any_value::<Scalar>("s0"), [s0.into()])
            .put::<Scalar>(|| any_value::<Scalar>("s1"), [s1.into()]);
    }
    if let Some(xc) = e.xc {
        row.put::<Scalar>(|| any_value::<Scalar>("xc"), [xc.into()]);
    }
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
