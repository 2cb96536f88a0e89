//! [`Logger`]: replay events into a recording stream, through typed
//! columns; [`prepare_sweeps`] builds the rows of a run of sweeps without
//! the logger, so that runs can be prepared in parallel.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Arc;

use rerun::{
    AsComponents as _, Clear, LineStrips3D, Mesh3D, Points3D, RecordingStream,
    RecordingStreamError, SeriesLines, SeriesPoints, ViewCoordinates,
};
use strum::IntoEnumIterator as _;

use super::blueprint::{self, Layout};
use super::columns;
use super::convert::{
    DEFECT_COLOR, DEFECT_POINTS, MESH_COLOR, SERIES_COLORS, albedo, edge_style, f32x3, rgba,
    ui_points,
};
use super::edge_frame::{choose_edges, edge_frame_rows};
use super::out::{Out, PrepareOptions, Shown};
use super::paths;
use super::rows::{
    self, PLOT_BITS, SweepLabels, ball_row, expected_rows, focus_rows, ghost_rows, plot_entity,
    plot_rows, plot_series, primary_rows, text_rows, transition_rows, tunnel_rows,
};
use super::spill::Spill;
use super::{RecordError, TIMESTAMP_THRESHOLD_NANOS};
use crate::core::mesh::Triangle;
use crate::core::record::EdgeRecord;
use crate::core::topology::{DefectKind, EdgeClass};
use crate::judge::divergence;
use crate::palette::MAX_DRAWN_DEFECT_LABELS;
use crate::replay::{ReplayEvent, SceneState, SweepResult};

/// Rows buffered before the logger sends them (see [`Logger`]); with
/// [`DEFAULT_FLUSH_BYTES`] the bytes usually come first.
pub const DEFAULT_FLUSH_ROWS: usize = 1 << 20;

/// Bytes of buffered rows (times, row numbers, values) at which the logger
/// sends them, whatever their number (see [`Logger`]). The chunks are one
/// per entity and set of components, so the larger the buffer, the more
/// rows each chunk holds, and each chunk costs a fixed overhead in the
/// file besides its rows (schema, footer entry); many balls mean many
/// entities sharing the buffer, hence short chunks. BENCHMARKS.md has the
/// measurements.
pub const DEFAULT_FLUSH_BYTES: usize = 32 << 20;

/// [`DEFAULT_FLUSH_BYTES`] of a logger that spills ([`Logger::with_spill`]):
/// its parts are joined into long chunks at the end, so the buffer's size no
/// longer sets the chunks' length, only how often the buffer is written
/// out (each flush writes one part per entity and set). A smaller buffer
/// means more flushes, a larger one more memory for little speed: 8 MiB
/// saved 10 to 15 MB but cost 2 s of the 11 s of CPU of a 347 k-sweep
/// session (BENCHMARKS.md has the measurements).
pub const SPILL_FLUSH_BYTES: usize = 12 << 20;

/// Sweeps per [`PreparedSweeps`] that the command and the bench prepare on
/// one worker (runs of consecutive sweeps of a batch, cut at this length).
pub const PREPARE_GROUP_SWEEPS: usize = 1024;

/// At most this many emptied [`PreparedSweeps`] are kept for reuse.
const MAX_SPARE_PREPARED: usize = 16;

/// Options of a [`Logger`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoggerOptions {
    /// Whether to send the default layout (blueprint).
    pub blueprint: bool,
    /// What each sweep's rows depend on.
    pub prepare: PrepareOptions,
    /// How long [`Logger::finish`] waits for the stream's sinks (a viewer
    /// that may not be reachable); `None` waits as long as it takes.
    pub flush_timeout: Option<std::time::Duration>,
}

impl Default for LoggerOptions {
    fn default() -> Self {
        LoggerOptions {
            blueprint: true,
            prepare: PrepareOptions::default(),
            flush_timeout: None,
        }
    }
}

/// Logs replay events to a recording stream.
///
/// Rows are not sent one by one: they are buffered per entity as typed
/// columns (plain values, see `columns`), and sent as one chunk per entity
/// when [`DEFAULT_FLUSH_ROWS`] rows or [`DEFAULT_FLUSH_BYTES`] bytes are
/// buffered (and by [`Logger::flush`] and [`Logger::finish`]), so memory
/// is bounded whatever the number of balls and the trace's length. With
/// [`Logger::with_spill`] (a recording file) they go to a temporary file
/// instead and into the recording in long chunks. What the recording holds
/// is what logging each row on its own would give, with ids that depend
/// only on the order of the rows, so the same events give the same chunks.
///
/// The layout sent at the start leads with the followed ball; when some
/// sweep (or contact query) diverged from its expectation, [`Logger::finish`] sends a second
/// one that leads with the divergences and makes it the active one.
#[derive(Debug)]
pub struct Logger {
    rec: RecordingStream,
    /// The balls seen (their plots' styles sent).
    balls: BTreeSet<u32>,
    /// What each ball's last sweep handed to [`Logger::shown_before`] shows.
    shown: BTreeMap<u32, Shown>,
    options: LoggerOptions,
    columns: columns::Columns,
    flush_rows: usize,
    flush_bytes: usize,
    /// Divergent sweeps logged.
    divergent: u64,
    /// Tunnels logged.
    tunnels: u64,
    /// Contact queries drawn that diverge from the core's set or hold a
    /// ghost contact ([`super::draw_contacts`]).
    contact_divergences: u64,
    /// Whether a contact query of the followed ball was drawn (the layout
    /// sent at the end then plots them).
    followed_contacts: bool,
    /// The largest frame of the sweeps logged so far.
    last_frame: Option<u64>,
    /// A scene logged and not yet shown: it is shown at its first sweep's
    /// frame ([`Logger::log_scene`]).
    pending_scene: Option<Arc<SceneState>>,
    /// The scene whose mesh is shown.
    mesh_shown: Option<usize>,
    /// Where buffered rows go until the recording is finished, when it is
    /// a file ([`Logger::with_spill`]).
    spill: Option<Spill>,
    /// Emptied [`PreparedSweeps`], handed out again by
    /// [`Logger::spare_prepared`] so that their buffers are reused.
    spare: Vec<PreparedSweeps>,
}

/// What a run of consecutive sweeps logs, built without the logger
/// ([`prepare_sweeps`]), so that runs can be prepared in parallel and logged
/// in order with [`Logger::log_prepared`].
#[derive(Debug, Default)]
pub struct PreparedSweeps {
    columns: columns::Columns,
    /// The ball of each sweep prepared.
    balls: Vec<u32>,
    divergent: u64,
    tunnels: u64,
    /// Scratch: the edge tests of one sweep.
    edges: Vec<EdgeRecord>,
}

impl PreparedSweeps {
    /// Sweeps prepared.
    pub fn len(&self) -> usize {
        self.balls.len()
    }

    /// Whether no sweep was prepared.
    pub fn is_empty(&self) -> bool {
        self.balls.is_empty()
    }
}

/// Prepares what [`Logger::log_sweep`] logs for each of `results` (in
/// order); `options` are the logger's ([`Logger::prepare_options`]).
pub fn prepare_sweeps<'r>(
    results: impl IntoIterator<Item = &'r SweepResult>,
    before: &[Shown],
    options: &PrepareOptions,
) -> PreparedSweeps {
    let mut p = PreparedSweeps::default();
    prepare_sweeps_into(&mut p, results, before, options);
    p
}

/// [`prepare_sweeps`] into `p` (an empty one, for example from
/// [`Logger::spare_prepared`], whose buffers are reused). `before` holds,
/// for each of `results`, what the previous sweep of its ball left shown
/// ([`Logger::shown_before`]).
pub fn prepare_sweeps_into<'r>(
    p: &mut PreparedSweeps,
    results: impl IntoIterator<Item = &'r SweepResult>,
    before: &[Shown],
    options: &PrepareOptions,
) {
    debug_assert!(p.is_empty() && p.columns.rows() == 0);
    let mut before = before.iter();
    for r in results {
        let frame = i64::try_from(r.frame).unwrap_or(i64::MAX);
        let time = time_of(r.log_time_nanos);
        let before = before.next().copied();
        debug_assert!(before.is_some(), "fewer `before` than results");
        let mut out = Out {
            columns: &mut p.columns,
            frame,
            time,
            before: before.unwrap_or_default(),
        };
        let decisive = r.decisive_record().copied();
        let diffs = divergence(r, &options.tolerances);
        ball_row(&mut out, r);
        let followed = r.ball == options.follow_ball;
        if followed {
            focus_rows(&mut out, r, decisive.as_ref(), !diffs.is_empty());
        }
        let slot0 = choose_edges(&mut p.edges, r, decisive.as_ref(), options.max_edge_frames);
        let expected = r.expected.filter(|_| !diffs.is_empty());
        let ghost = r.ghost();
        let labels = SweepLabels::of(
            r,
            decisive.as_ref(),
            &p.edges,
            slot0,
            followed,
            expected.is_some(),
            ghost.as_ref(),
        );
        let primary = primary_rows(&mut out, r, decisive.as_ref(), labels.primary);
        edge_frame_rows(&mut out, r, &p.edges, labels.slot0.as_deref());
        let plotted = plot_rows(&mut out, r, decisive.as_ref());
        if let Some(e) = &expected {
            expected_rows(&mut out, r, e, labels.expected, ghost.as_ref());
        }
        let expected = expected.is_some();
        text_rows(&mut out, r, decisive.as_ref(), &diffs);
        let tunnel = tunnel_rows(&mut out, r);
        let ghost = ghost_rows(&mut out, r, ghost.as_ref(), labels.ghost);
        // What this sweep drew (`Logger::shown_before` worked out the same
        // for the ball's next sweep).
        let now = Shown::drawn(p.edges.len(), plotted, primary, expected, tunnel, ghost);
        debug_assert!(
            rows::shown_of(r, options) == now,
            "shown_of disagrees with the rows drawn"
        );
        transition_rows(&mut out, r.ball, now);
        p.divergent += u64::from(!diffs.is_empty());
        p.tunnels += r.tunnels.len() as u64;
        p.balls.push(r.ball);
    }
}

/// The static style of ball `b`'s plots of the decisive test's numbers:
/// named series drawn as lines with a marker at each value, so that a value
/// with no neighbour (the lines break where a value stops existing) is
/// still seen.
fn series_styles(
    columns: &mut columns::Columns,
    rec: &RecordingStream,
    b: u32,
) -> Result<(), RecordingStreamError> {
    for bit in 0..PLOT_BITS {
        let entity = plot_entity(b, bit);
        let names = plot_series(bit);
        let colors = || SERIES_COLORS[..names.len()].iter().map(|&c| rgba(c));
        let mut batches = SeriesLines::new()
            .with_names(names.iter().copied())
            .with_colors(colors())
            .as_serialized_batches();
        batches.extend(
            SeriesPoints::new()
                .with_names(names.iter().copied())
                .with_colors(colors())
                .with_marker_sizes([2.5])
                .as_serialized_batches(),
        );
        columns.send_static(rec, entity.path(), batches)?;
    }
    Ok(())
}

/// The edges of `class` of a scene, a segment each, by the positions of
/// their (welded) vertices.
pub(crate) fn edge_strips(scene: &SceneState, class: EdgeClass) -> Vec<[[f32; 3]; 2]> {
    let vertices = scene.mesh.vertices();
    let at = |i: u32| vertices.get(i as usize).map(|p| f32x3(p.coords));
    scene
        .topology
        .edges()
        .iter()
        .filter(|e| e.class == class)
        .filter_map(|e| Some([at(e.vertices[0])?, at(e.vertices[1])?]))
        .collect()
}

/// The `time` timeline's value of a `log_time`.
pub(super) fn time_of(log_time_nanos: u64) -> columns::Time {
    let clamp = |n: u64| i64::try_from(n).unwrap_or(i64::MAX);
    if log_time_nanos >= TIMESTAMP_THRESHOLD_NANOS {
        columns::Time::Timestamp(clamp(log_time_nanos))
    } else {
        columns::Time::Duration(clamp(log_time_nanos))
    }
}

impl Logger {
    /// Takes over `rec`: switches off the wall-clock timelines, sends the
    /// default blueprint (when `blueprint`) and the static world settings;
    /// the other options are the defaults (follows ball 0).
    pub fn new(rec: RecordingStream, blueprint: bool) -> Result<Logger, RecordingStreamError> {
        Logger::with_options(
            rec,
            LoggerOptions {
                blueprint,
                ..LoggerOptions::default()
            },
        )
    }

    /// [`Logger::new`] with every option.
    pub fn with_options(
        rec: RecordingStream,
        options: LoggerOptions,
    ) -> Result<Logger, RecordingStreamError> {
        rec.set_log_time_enabled(false);
        rec.set_log_tick_enabled(false);
        if options.blueprint {
            blueprint::send_blueprint(
                &rec,
                Layout::FollowBall,
                options.prepare.follow_ball,
                false,
            )?;
        }
        let mut logger = Logger {
            rec,
            balls: BTreeSet::new(),
            shown: BTreeMap::new(),
            options,
            columns: columns::Columns::default(),
            flush_rows: DEFAULT_FLUSH_ROWS,
            flush_bytes: DEFAULT_FLUSH_BYTES,
            divergent: 0,
            contact_divergences: 0,
            followed_contacts: false,
            last_frame: None,
            pending_scene: None,
            mesh_shown: None,
            tunnels: 0,
            spill: None,
            spare: Vec::new(),
        };
        logger.log_static(paths::WORLD, &ViewCoordinates::RIGHT_HAND_Z_UP())?;
        // The followed ball's frame has the world's axes (only moved and
        // scaled), so the view that looks from it keeps z up.
        logger.log_static(
            paths::focus(options.prepare.follow_ball),
            &ViewCoordinates::RIGHT_HAND_Z_UP(),
        )?;
        Ok(logger)
    }

    /// Sets how many rows are buffered before they are sent (at least 1).
    pub fn with_flush_rows(mut self, rows: usize) -> Logger {
        self.flush_rows = rows.max(1);
        self
    }

    /// Sets how many bytes of rows are buffered before they are sent (at
    /// least 1).
    pub fn with_flush_bytes(mut self, bytes: usize) -> Logger {
        self.flush_bytes = bytes.max(1);
        self
    }

    /// How many edge tests per sweep get an edge frame.
    pub fn max_edge_frames(&self) -> usize {
        self.options.prepare.max_edge_frames
    }

    /// Sets how many edge tests per sweep get an edge frame.
    pub fn with_max_edge_frames(mut self, n: usize) -> Logger {
        self.options.prepare.max_edge_frames = n;
        self
    }

    /// What [`prepare_sweeps`] needs to prepare rows for this logger.
    pub fn prepare_options(&self) -> PrepareOptions {
        self.options.prepare
    }

    /// Divergent sweeps logged so far.
    pub fn divergent_sweeps(&self) -> u64 {
        self.divergent
    }

    /// Tunnels logged so far.
    pub fn tunnels(&self) -> u64 {
        self.tunnels
    }

    /// Keeps the buffered rows in an anonymous temporary file in `dir`
    /// until the end ([`Logger::send_all`]), and then sends them joined into
    /// long chunks (see `spill`): for a recording that goes to the file
    /// `recording` only (a viewer would see nothing until the end; errors
    /// name `recording`). The temporary file disappears with the process.
    ///
    /// The buffer is then sent at [`SPILL_FLUSH_BYTES`] (call
    /// [`Logger::with_flush_bytes`] after this to choose another bound).
    pub fn with_spill(mut self, dir: &Path, recording: &Path) -> Result<Logger, RecordError> {
        self.spill = Some(Spill::new(dir, recording)?);
        self.flush_bytes = SPILL_FLUSH_BYTES;
        Ok(self)
    }

    /// With [`Logger::with_spill`]: at most `rows` rows per chunk instead
    /// of [`super::MAX_CHUNK_ROWS`] (for tests of the joining; no effect
    /// without a spill).
    pub fn with_spill_chunk_rows(mut self, rows: usize) -> Logger {
        if let Some(spill) = &mut self.spill {
            spill.set_max_rows(rows);
        }
        self
    }

    /// Sends every buffered row (to the temporary file with
    /// [`Logger::with_spill`]).
    pub fn flush(&mut self) -> Result<(), RecordError> {
        match &mut self.spill {
            Some(spill) => {
                self.columns.spill(spill)?;
                // What has a chunk's worth goes out now, while the replay
                // goes on.
                self.columns.send_ready(spill, &self.rec)
            }
            None => Ok(self.columns.send(&self.rec)?),
        }
    }

    /// Sends every row logged so far to the stream, those held in the
    /// temporary file included.
    pub fn send_all(&mut self) -> Result<(), RecordError> {
        self.send_all_with(|_, _| {})
    }

    /// [`Logger::send_all`], telling `progress` the bytes of the temporary
    /// file read back so far and their total (not called without
    /// [`Logger::with_spill`]).
    pub fn send_all_with(&mut self, progress: impl FnMut(u64, u64)) -> Result<(), RecordError> {
        self.flush()?;
        if let Some(spill) = &mut self.spill {
            self.columns.send_spilled(spill, &self.rec, progress)?;
        }
        Ok(())
    }

    pub(super) fn log_static(
        &mut self,
        path: impl Into<String>,
        value: &dyn rerun::AsComponents,
    ) -> Result<(), RecordingStreamError> {
        self.columns
            .send_static(&self.rec, path.into(), value.as_serialized_batches())
    }

    /// Sends one row of `path` at `at` (frame, time) at once.
    fn log_at(
        &mut self,
        path: impl Into<String>,
        value: &dyn rerun::AsComponents,
        (frame, time): (i64, columns::Time),
    ) -> Result<(), RecordingStreamError> {
        self.columns.send_at(
            &self.rec,
            path.into(),
            value.as_serialized_batches(),
            frame,
            time,
        )
    }

    /// The stream.
    pub fn stream(&self) -> &RecordingStream {
        &self.rec
    }

    /// Logs one event.
    pub fn log(&mut self, event: &ReplayEvent) -> Result<(), RecordError> {
        match event {
            ReplayEvent::Scene(scene) => Ok(self.log_scene(scene)?),
            ReplayEvent::Sweep(result) => self.log_sweep(result),
        }
    }

    /// Sends what is buffered, flushes and hands the stream back (drop it,
    /// and every clone, to finish a file). When some sweep diverged from
    /// its expectation (or went through a triangle, or a contact query
    /// diverged or held a ghost contact), first sends the layout that leads
    /// with the divergences, as the active one; when the followed ball's
    /// contact queries were drawn, the layout sent (that one, or the first
    /// again) plots them too. Use [`Logger::send_all`] first to see an
    /// error of the last rows.
    pub fn finish(mut self) -> RecordingStream {
        let _ = self.show_pending_scene(None);
        let _ = self.send_all();
        let diverged = self.divergent + self.tunnels + self.contact_divergences > 0;
        if self.options.blueprint && (diverged || self.followed_contacts) {
            let layout = if diverged {
                Layout::Divergences
            } else {
                Layout::FollowBall
            };
            // Every chunk before the second layout, so that the order of
            // the file's messages does not vary.
            let _ = self.flush_stream();
            let _ = blueprint::send_blueprint(
                &self.rec,
                layout,
                self.options.prepare.follow_ball,
                self.followed_contacts,
            );
        }
        let _ = self.flush_stream();
        self.rec
    }

    /// Flushes the stream to its sinks, within the options' timeout.
    fn flush_stream(&self) -> Result<(), rerun::sink::SinkFlushError> {
        match self.options.flush_timeout {
            Some(timeout) => self.rec.flush_with_timeout(timeout),
            None => self.rec.flush_blocking(),
        }
    }

    /// Notes that a sweep of `frame` is logged next (in trace order): a
    /// scene logged before it and not shown yet is shown at that frame.
    pub(super) fn saw_frame(&mut self, frame: u64) -> Result<(), RecordingStreamError> {
        self.show_pending_scene(Some(frame))?;
        self.last_frame = Some(self.last_frame.map_or(frame, |f| f.max(frame)));
        Ok(())
    }

    /// Logs a scene: its mesh (one Mesh3D, flat-shaded), its edges (one
    /// LineStrips3D per class, every edge once) and its defects (one
    /// Points3D per kind, a label each, drawn when the scene has at most
    /// `MAX_DRAWN_DEFECT_LABELS` of them), from the scene's topology, at the
    /// scene's `log_time` and at the frame of its first sweep, where the
    /// previous scene's are cleared, with what every ball showed (its
    /// sweep, its contacts; not its plots): each frame shows the mesh its
    /// sweeps were tested against (a trace may hold a scene per level, or the same
    /// scene sent again). A scene without sweeps is shown at the frame
    /// after the last sweep (0 before any), when the next scene comes or
    /// the sweeps end ([`Logger::show_pending_scene`]).
    pub fn log_scene(&mut self, scene: &Arc<SceneState>) -> Result<(), RecordingStreamError> {
        self.show_pending_scene(None)?;
        self.pending_scene = Some(Arc::clone(scene));
        Ok(())
    }

    /// Shows the scene logged and not yet shown, if any, at `frame` (its
    /// first sweep's), or without one at the frame after the last sweep.
    pub(super) fn show_pending_scene(
        &mut self,
        frame: Option<u64>,
    ) -> Result<(), RecordingStreamError> {
        let Some(scene) = self.pending_scene.take() else {
            return Ok(());
        };
        let frame = frame.unwrap_or_else(|| self.last_frame.map_or(0, |f| f.saturating_add(1)));
        let when = (
            i64::try_from(frame).unwrap_or(i64::MAX),
            time_of(scene.log_time_nanos),
        );
        if let Some(previous) = self.mesh_shown.replace(scene.number) {
            self.log_at(paths::mesh(previous), &Clear::recursive(), when)?;
            // What the balls showed belongs to the previous scene: a ball
            // absent from this one would keep its last sweep and contacts
            // on the new mesh. Each ball's next sweep draws it again (its
            // rows come after this clear, at this frame too).
            let balls: Vec<u32> = self.balls.iter().copied().collect();
            for b in balls {
                self.log_at(paths::ball(b), &Clear::recursive(), when)?;
            }
        }
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
        self.log_at(paths::mesh(scene.number), &mesh, when)?;

        for class in EdgeClass::iter() {
            let strips = edge_strips(&scene, class);
            if strips.is_empty() {
                continue;
            }
            let (color, radius) = edge_style(class);
            let edges = LineStrips3D::new(strips)
                .with_radii([ui_points(radius)])
                .with_colors([rgba(color)]);
            self.log_at(paths::edges(scene.number, class), &edges, when)?;
        }
        let draw_labels = scene.topology.defects().len() <= MAX_DRAWN_DEFECT_LABELS;
        for kind in DefectKind::iter() {
            let (at, labels): (Vec<[f32; 3]>, Vec<String>) = scene
                .topology
                .defects()
                .iter()
                .filter(|d| d.kind == kind)
                .map(|d| (d.position.map(|c| c as f32), d.to_string()))
                .unzip();
            if at.is_empty() {
                continue;
            }
            let defects = Points3D::new(at)
                .with_radii([ui_points(DEFECT_POINTS)])
                .with_colors([rgba(DEFECT_COLOR)])
                .with_labels(labels)
                .with_show_labels(draw_labels);
            self.log_at(paths::defects(scene.number, kind), &defects, when)?;
        }
        Ok(())
    }

    /// Logs one sweep's result at its frame.
    pub fn log_sweep(&mut self, r: &SweepResult) -> Result<(), RecordError> {
        self.saw_frame(r.frame)?;
        let before = self.shown_before([r]);
        let prepared = prepare_sweeps([r], &before, &self.options.prepare);
        self.log_prepared(prepared)
    }

    /// What the previous sweep of each of `results`' balls left shown, in
    /// order (for [`prepare_sweeps`]); remembers what each shows, so the
    /// results must then be prepared and logged, in this order.
    pub fn shown_before<'r>(
        &mut self,
        results: impl IntoIterator<Item = &'r SweepResult>,
    ) -> Vec<Shown> {
        let nows: Vec<(u32, Shown)> = results
            .into_iter()
            .map(|r| (r.ball, rows::shown_of(r, &self.options.prepare)))
            .collect();
        self.shown_before_given(nows)
    }

    /// [`Logger::shown_before`] of sweeps of the balls `balls` whose rows
    /// show `now` (worked out elsewhere, for example in parallel, with
    /// `rows::shown_of`).
    pub(crate) fn shown_before_given(
        &mut self,
        balls_now: impl IntoIterator<Item = (u32, Shown)>,
    ) -> Vec<Shown> {
        balls_now
            .into_iter()
            .map(|(ball, now)| std::mem::replace(self.shown.entry(ball).or_default(), now))
            .collect()
    }

    /// Logs sweeps prepared by [`prepare_sweeps`] (sweeps must be logged in
    /// trace order).
    pub fn log_prepared(&mut self, mut p: PreparedSweeps) -> Result<(), RecordError> {
        self.columns.append(&mut p.columns);
        self.divergent += std::mem::take(&mut p.divergent);
        self.tunnels += std::mem::take(&mut p.tunnels);
        // (What a ball showed at its previous sweep and no longer shows is
        // cleared among the sweep's rows: `rows::transition_rows`.)
        for b in p.balls.drain(..) {
            if self.balls.insert(b) {
                series_styles(&mut self.columns, &self.rec, b)?;
            }
        }
        if self.spare.len() < MAX_SPARE_PREPARED {
            self.spare.push(p);
        }
        self.flush_if_full()
    }

    /// The buffer of rows, for rows other than sweeps' (see
    /// [`Logger::flush_if_full`]).
    pub(super) fn columns(&mut self) -> &mut columns::Columns {
        &mut self.columns
    }

    /// Counts a contact query of `ball` drawn, `diverges` when it diverges
    /// or holds a ghost contact: with one, the layout that leads with the
    /// divergences' log is the active one; with one of the followed ball,
    /// the layout sent at the end plots its queries ([`Logger::finish`]).
    pub(super) fn count_contact_query(&mut self, ball: u32, diverges: bool) {
        self.contact_divergences += u64::from(diverges);
        self.followed_contacts |= ball == self.options.prepare.follow_ball;
    }

    /// Sends (or spills) the buffer when it holds enough rows or bytes.
    pub(super) fn flush_if_full(&mut self) -> Result<(), RecordError> {
        if self.columns.rows() >= self.flush_rows || self.columns.bytes() >= self.flush_bytes {
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
