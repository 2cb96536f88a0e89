//! The replay engine: trace events in, one explained result per sweep out.
//!
//! [`Replay`] is push-based: feed it the events of a trace in order
//! ([`Replay::scene`], [`Replay::sweep`], [`Replay::expected`]) and take the
//! finished [`ReplayEvent`]s with [`Replay::next_event`]; [`Replay::finish`]
//! flushes what is still held and returns the [`Summary`]. [`replay_events`]
//! wraps any iterator of trace events into an iterator of results.
//!
//! A sweep's result is held back until a sweep of another frame (or a new
//! scene, or the end) arrives, so that an `/expected` message logged just
//! after its sweep is still attached to it.
//!
//! Nothing here knows about the viewer: `viz` turns results into a Rerun
//! recording, `check`-like commands compare [`SweepResult::outcome_msg`]
//! with [`SweepResult::expected`].

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::Arc;
use std::time::{Duration, Instant};

use thiserror::Error;

use crate::core::explain::nearest_miss;
use crate::core::{
    Broadphase, CollectRecords, Facing, Kind, Mesh, MeshError, Options, Outcome, Sweep, SweepError,
    TestRecord, Verdict, sweep_mesh, sweep_mesh_with,
};
use crate::trace::messages::{OutcomeMsg, SceneMsg, SweepMsg};
use crate::trace::{TraceError, TraceEvent};

/// How many test records each sweep keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Detail {
    /// The tests that report the primary collision (the primary test first,
    /// then every other hit tied with it ([`Outcome::ties_with`]), which
    /// share the averaged normal); when
    /// nothing hits, the one test that came nearest
    /// ([`crate::core::explain::miss_distance`]) among the BVH candidates.
    #[default]
    Primary,
    /// Every test of every triangle the BVH visited.
    Candidates,
    /// Every test of every triangle ([`Broadphase::Exhaustive`]).
    All,
}

impl Detail {
    /// The name used on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Detail::Primary => "primary",
            Detail::Candidates => "candidates",
            Detail::All => "all",
        }
    }
}

impl std::fmt::Display for Detail {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Detail {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "primary" => Ok(Detail::Primary),
            "candidates" => Ok(Detail::Candidates),
            "all" => Ok(Detail::All),
            other => Err(format!(
                "unknown detail `{other}` (expected `primary`, `candidates` or `all`)"
            )),
        }
    }
}

/// A half-open range of frames `start..end`; either end may be open.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FrameRange {
    /// First frame included.
    pub start: Option<u64>,
    /// First frame excluded.
    pub end: Option<u64>,
}

impl FrameRange {
    /// Whether `frame` lies in the range.
    pub fn contains(&self, frame: u64) -> bool {
        self.start.is_none_or(|s| frame >= s) && self.end.is_none_or(|e| frame < e)
    }
}

impl std::fmt::Display for FrameRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(s) = self.start {
            write!(f, "{s}")?;
        }
        f.write_str("..")?;
        if let Some(e) = self.end {
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::str::FromStr for FrameRange {
    type Err = String;
    /// `A..B` (A included, B excluded), `A..`, `..B`, `A..=B`, or one frame `A`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bound = |t: &str| -> Result<Option<u64>, String> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(None);
            }
            t.parse::<u64>()
                .map(Some)
                .map_err(|_| format!("`{t}` is not a frame number"))
        };
        let range = if let Some((a, b)) = s.split_once("..=") {
            let end = bound(b)?.ok_or_else(|| format!("`{s}`: `..=` needs an end frame"))?;
            FrameRange {
                start: bound(a)?,
                end: Some(end.saturating_add(1)),
            }
        } else if let Some((a, b)) = s.split_once("..") {
            FrameRange {
                start: bound(a)?,
                end: bound(b)?,
            }
        } else {
            let f = bound(s)?.ok_or_else(|| "empty frame range".to_string())?;
            FrameRange {
                start: Some(f),
                end: Some(f.saturating_add(1)),
            }
        };
        if let (Some(a), Some(b)) = (range.start, range.end)
            && b <= a
        {
            return Err(format!(
                "frame range `{s}` is empty (A..B includes A and excludes B)"
            ));
        }
        Ok(range)
    }
}

/// Options of a replay.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReplayOptions {
    /// Only sweeps whose frame lies in this range.
    pub frames: FrameRange,
    /// Only this ball.
    pub ball: Option<u32>,
    /// Which test records each result keeps.
    pub detail: Detail,
    /// Whether to run the explained query at all. When `false` every sweep
    /// uses the fast [`sweep_mesh`] and results carry no records.
    pub explain: bool,
    /// Overrides every scene's margin `ε`.
    pub margin: Option<f64>,
    /// Overrides every scene's facing rule.
    pub facing: Option<Facing>,
}

/// A scene of the trace, built into a mesh.
#[derive(Clone, Debug)]
pub struct SceneState {
    /// 0 for the trace's first scene, 1 for the next, ...
    pub number: usize,
    /// Index of the scene message in the trace.
    pub index: u64,
    /// `log_time` of the scene message, in nanoseconds.
    pub log_time_nanos: u64,
    /// The scene's name, if it has one.
    pub name: Option<String>,
    /// The mesh.
    pub mesh: Mesh,
    /// The options in force: the scene's margin and facing unless overridden.
    pub options: Options,
}

/// The result of one sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepResult {
    /// Frame number.
    pub frame: u64,
    /// Ball number.
    pub ball: u32,
    /// `log_time` of the sweep message, in nanoseconds.
    pub log_time_nanos: u64,
    /// Index of the sweep message in the trace.
    pub index: u64,
    /// [`SceneState::number`] of the scene it was swept against.
    pub scene: usize,
    /// The sweep.
    pub sweep: Sweep,
    /// The options used.
    pub options: Options,
    /// The core's outcome.
    pub outcome: Outcome,
    /// The test records kept at the chosen [`Detail`] (empty when not
    /// explained). With [`Detail::Primary`] the first record is the primary
    /// test, or the nearest miss.
    pub records: Vec<TestRecord>,
    /// The trace's `/expected` outcome for this `(frame, ball)`, if any.
    pub expected: Option<OutcomeMsg>,
}

impl SweepResult {
    /// The outcome as the record of SEMANTICS.md (every field present).
    pub fn outcome_msg(&self) -> OutcomeMsg {
        OutcomeMsg::from_outcome(self.frame, self.ball, &self.outcome)
    }

    /// The record that decided the sweep: the primary test when something is
    /// hit, otherwise the nearest miss among the kept records.
    pub fn decisive_record(&self) -> Option<&TestRecord> {
        if self.outcome.is_hit() {
            self.records.iter().find(|r| self.outcome.is_reported_by(r))
        } else {
            nearest_miss(&self.records)
        }
    }

    /// The detection radius `ρ = r - ε`.
    pub fn rho(&self) -> f64 {
        self.sweep.radius - self.options.margin
    }
}

/// What the replay produces, in trace order.
#[derive(Clone, Debug)]
pub enum ReplayEvent {
    /// A new scene: every following sweep is against it until the next one.
    Scene(Arc<SceneState>),
    /// One sweep's result.
    Sweep(Box<SweepResult>),
}

/// Counts of a replay.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Scenes read.
    pub scenes: usize,
    /// Degenerate triangles left out, over all scenes.
    pub degenerate_triangles: usize,
    /// Sweeps replayed.
    pub sweeps: u64,
    /// Sweeps skipped by the frame and ball filters.
    pub filtered_out: u64,
    /// Replayed sweeps by the kind of their outcome (`none` included).
    pub outcomes: BTreeMap<Kind, u64>,
    /// Verdicts of every test run by the explained query (over the visited
    /// triangles at `primary`/`candidates`, every triangle at `all`), before
    /// the detail level drops records.
    pub verdicts: BTreeMap<Verdict, u64>,
    /// `/expected` messages attached to a replayed sweep.
    pub expected_matched: u64,
    /// `/expected` messages for a replayed `(frame, ball)` that arrived too
    /// late to be attached, or that match no sweep at all.
    pub expected_unmatched: u64,
    /// Time spent in the collision core and the bookkeeping (not reading).
    pub elapsed: Duration,
}

impl Summary {
    /// Sweeps whose outcome is a collision.
    pub fn collisions(&self) -> u64 {
        self.outcomes
            .iter()
            .filter(|(k, _)| **k != Kind::None)
            .map(|(_, n)| n)
            .sum()
    }

    /// A few lines for people.
    pub fn render(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let kinds = [Kind::Face, Kind::Edge, Kind::Vertex]
            .iter()
            .map(|k| format!("{} {k}", self.outcomes.get(k).copied().unwrap_or(0)))
            .collect::<Vec<_>>()
            .join(", ");
        let _ = writeln!(
            s,
            "{} sweeps replayed ({} filtered out) over {} scene(s): {} collisions ({kinds}), {} without",
            self.sweeps,
            self.filtered_out,
            self.scenes,
            self.collisions(),
            self.outcomes.get(&Kind::None).copied().unwrap_or(0),
        );
        if !self.verdicts.is_empty() {
            let v = self
                .verdicts
                .iter()
                .map(|(v, n)| format!("{v} {n}"))
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(s, "test verdicts: {v}");
        }
        if self.expected_matched + self.expected_unmatched > 0 {
            let _ = writeln!(
                s,
                "expected outcomes: {} attached, {} unmatched",
                self.expected_matched, self.expected_unmatched
            );
        }
        if self.degenerate_triangles > 0 {
            let _ = writeln!(
                s,
                "degenerate triangles left out: {}",
                self.degenerate_triangles
            );
        }
        let _ = writeln!(s, "time in the core: {:.3} s", self.elapsed.as_secs_f64());
        s
    }
}

/// An event the replay cannot use.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// A scene's mesh is invalid.
    #[error("scene message {index}: {source}")]
    Mesh {
        /// Index of the scene message.
        index: u64,
        /// What is wrong.
        source: MeshError,
    },
    /// A sweep came before any scene.
    #[error("sweep of frame {frame} (message {index}) has no scene before it")]
    NoScene {
        /// Frame of the sweep.
        frame: u64,
        /// Index of the sweep message.
        index: u64,
    },
    /// A sweep's values are invalid.
    #[error("frame {frame}, ball {ball} (message {index}): {source}")]
    Sweep {
        /// Frame.
        frame: u64,
        /// Ball.
        ball: u32,
        /// Index of the sweep message.
        index: u64,
        /// What is wrong.
        source: SweepError,
    },
    /// The trace could not be read further.
    /// (Boxed: a trace error is large, and results pass through here.)
    #[error(transparent)]
    Trace(Box<TraceError>),
}

impl From<TraceError> for ReplayError {
    fn from(err: TraceError) -> Self {
        ReplayError::Trace(Box::new(err))
    }
}

/// The replay engine (push-based; see the module documentation).
#[derive(Debug)]
pub struct Replay {
    options: ReplayOptions,
    scene: Option<Arc<SceneState>>,
    /// Results held until their frame is complete.
    pending: Vec<SweepResult>,
    /// `/expected` messages that arrived before their sweep.
    early_expected: HashMap<(u64, u32), OutcomeMsg>,
    ready: VecDeque<ReplayEvent>,
    summary: Summary,
}

impl Replay {
    /// A replay with `options`.
    pub fn new(options: ReplayOptions) -> Replay {
        Replay {
            options,
            scene: None,
            pending: Vec::new(),
            early_expected: HashMap::new(),
            ready: VecDeque::new(),
            summary: Summary::default(),
        }
    }

    /// The options.
    pub fn options(&self) -> &ReplayOptions {
        &self.options
    }

    /// The scene in force, if any.
    pub fn current_scene(&self) -> Option<&Arc<SceneState>> {
        self.scene.as_ref()
    }

    /// A `/scene` message.
    pub fn scene(
        &mut self,
        log_time_nanos: u64,
        index: u64,
        scene: SceneMsg,
    ) -> Result<(), ReplayError> {
        let start = Instant::now();
        self.release_pending();
        let SceneMsg {
            name,
            vertices,
            triangles,
            margin,
            facing,
        } = scene;
        let mesh = Mesh::new(vertices, &triangles)
            .map_err(|source| ReplayError::Mesh { index, source })?;
        let options = Options {
            margin: self.options.margin.unwrap_or(margin),
            facing: self.options.facing.unwrap_or(facing),
        };
        let number = self.summary.scenes;
        self.summary.scenes += 1;
        self.summary.degenerate_triangles += mesh.degenerate().len();
        let state = Arc::new(SceneState {
            number,
            index,
            log_time_nanos,
            name,
            mesh,
            options,
        });
        self.scene = Some(state.clone());
        self.ready.push_back(ReplayEvent::Scene(state));
        self.summary.elapsed += start.elapsed();
        Ok(())
    }

    /// A `/sweep` message.
    pub fn sweep(
        &mut self,
        log_time_nanos: u64,
        index: u64,
        msg: SweepMsg,
    ) -> Result<(), ReplayError> {
        if self.pending.first().is_some_and(|p| p.frame != msg.frame) {
            self.release_pending();
        }
        if !self.wanted(msg.frame, msg.ball) {
            self.summary.filtered_out += 1;
            self.early_expected.remove(&(msg.frame, msg.ball));
            return Ok(());
        }
        let Some(scene) = self.scene.clone() else {
            return Err(ReplayError::NoScene {
                frame: msg.frame,
                index,
            });
        };
        let computed = compute_sweep(&scene, &msg, index, &self.options);
        self.commit(log_time_nanos, index, msg, &scene, computed?);
        Ok(())
    }

    /// A `/sweep` message whose core query already ran ([`compute_sweep`]
    /// against [`Replay::current_scene`], or `None` when the sweep is
    /// filtered out or comes before any scene): the same as
    /// [`Replay::sweep`] without the query. Used by [`replay_events_parallel`].
    pub fn sweep_computed(
        &mut self,
        log_time_nanos: u64,
        index: u64,
        msg: SweepMsg,
        computed: Option<Result<ComputedSweep, ReplayError>>,
    ) -> Result<(), ReplayError> {
        let Some(computed) = computed else {
            return self.sweep(log_time_nanos, index, msg);
        };
        if self.pending.first().is_some_and(|p| p.frame != msg.frame) {
            self.release_pending();
        }
        let Some(scene) = self.scene.clone() else {
            return Err(ReplayError::NoScene {
                frame: msg.frame,
                index,
            });
        };
        self.commit(log_time_nanos, index, msg, &scene, computed?);
        Ok(())
    }

    /// Whether a sweep passes the frame and ball filters.
    fn wanted(&self, frame: u64, ball: u32) -> bool {
        replay_wanted(&self.options, frame, ball)
    }

    fn commit(
        &mut self,
        log_time_nanos: u64,
        index: u64,
        msg: SweepMsg,
        scene: &SceneState,
        computed: ComputedSweep,
    ) {
        let ComputedSweep {
            sweep,
            outcome,
            records,
            verdicts,
            elapsed,
        } = computed;
        for (v, n) in verdicts {
            *self.summary.verdicts.entry(v).or_default() += n;
        }
        let expected = self.early_expected.remove(&(msg.frame, msg.ball));
        if expected.is_some() {
            self.summary.expected_matched += 1;
        }
        self.summary.sweeps += 1;
        self.summary.elapsed += elapsed;
        *self.summary.outcomes.entry(outcome.kind).or_default() += 1;
        self.pending.push(SweepResult {
            frame: msg.frame,
            ball: msg.ball,
            log_time_nanos,
            index,
            scene: scene.number,
            sweep,
            options: scene.options,
            outcome,
            records,
            expected,
        });
    }

    /// Any trace event.
    pub fn push(&mut self, event: TraceEvent) -> Result<(), ReplayError> {
        match event {
            TraceEvent::Scene {
                log_time_nanos,
                index,
                scene,
            } => self.scene(log_time_nanos, index, scene),
            TraceEvent::Sweep {
                log_time_nanos,
                index,
                sweep,
            } => self.sweep(log_time_nanos, index, sweep),
            TraceEvent::Expected {
                log_time_nanos,
                index,
                outcome,
            } => {
                self.expected(log_time_nanos, index, outcome);
                Ok(())
            }
        }
    }

    /// An `/expected` message.
    pub fn expected(&mut self, _log_time_nanos: u64, _index: u64, outcome: OutcomeMsg) {
        if !self.options.frames.contains(outcome.frame)
            || self.options.ball.is_some_and(|b| b != outcome.ball)
        {
            return;
        }
        if let Some(p) = self
            .pending
            .iter_mut()
            .find(|p| p.frame == outcome.frame && p.ball == outcome.ball)
        {
            if p.expected.is_none() {
                self.summary.expected_matched += 1;
            } else {
                self.summary.expected_unmatched += 1;
            }
            p.expected = Some(outcome);
            return;
        }
        if self
            .early_expected
            .insert((outcome.frame, outcome.ball), outcome)
            .is_some()
        {
            self.summary.expected_unmatched += 1;
        }
    }

    /// The next finished event, if any.
    pub fn next_event(&mut self) -> Option<ReplayEvent> {
        self.ready.pop_front()
    }

    /// Releases every held result; returns them with the summary.
    pub fn finish(mut self) -> (Vec<ReplayEvent>, Summary) {
        self.release_pending();
        self.summary.expected_unmatched += self.early_expected.len() as u64;
        (self.ready.into_iter().collect(), self.summary)
    }

    /// The counts so far.
    pub fn summary(&self) -> &Summary {
        &self.summary
    }

    fn release_pending(&mut self) {
        let Some(frame) = self.pending.first().map(|p| p.frame) else {
            return;
        };
        for p in self.pending.drain(..) {
            self.ready.push_back(ReplayEvent::Sweep(Box::new(p)));
        }
        // Expected outcomes of earlier frames can no longer find their sweep.
        let before = self.early_expected.len();
        self.early_expected.retain(|(f, _), _| *f >= frame);
        self.summary.expected_unmatched += (before - self.early_expected.len()) as u64;
    }
}

/// The core's part of one sweep, independent of every other sweep: what
/// [`Replay::sweep_computed`] takes.
#[derive(Clone, Debug)]
pub struct ComputedSweep {
    sweep: Sweep,
    outcome: Outcome,
    records: Vec<TestRecord>,
    verdicts: Vec<(Verdict, u64)>,
    elapsed: Duration,
}

/// Runs the core query of one sweep message against `scene` as a replay
/// with `options` would (the filters are not applied here).
pub fn compute_sweep(
    scene: &SceneState,
    msg: &SweepMsg,
    index: u64,
    options: &ReplayOptions,
) -> Result<ComputedSweep, ReplayError> {
    let start = Instant::now();
    let sweep = Sweep::new(msg.p0, msg.p1, msg.radius);
    let err = |source| ReplayError::Sweep {
        frame: msg.frame,
        ball: msg.ball,
        index,
        source,
    };
    let mut verdicts: Vec<(Verdict, u64)> = Vec::new();
    let (outcome, records) = if options.explain {
        let broadphase = match options.detail {
            Detail::All => Broadphase::Exhaustive,
            Detail::Primary | Detail::Candidates => Broadphase::Bvh,
        };
        let mut collect = CollectRecords::default();
        let outcome = sweep_mesh_with(
            &scene.mesh,
            &sweep,
            &scene.options,
            broadphase,
            &mut collect,
        )
        .map_err(err)?;
        for r in &collect.records {
            let v = r.verdict();
            match verdicts.iter_mut().find(|(w, _)| *w == v) {
                Some((_, n)) => *n += 1,
                None => verdicts.push((v, 1)),
            }
        }
        let records = match options.detail {
            Detail::Primary => primary_records(&outcome, collect.records),
            Detail::Candidates | Detail::All => collect.records,
        };
        (outcome, records)
    } else {
        (
            sweep_mesh(&scene.mesh, &sweep, &scene.options).map_err(err)?,
            Vec::new(),
        )
    };
    Ok(ComputedSweep {
        sweep,
        outcome,
        records,
        verdicts,
        elapsed: start.elapsed(),
    })
}

/// The records of [`Detail::Primary`]: the primary test, then every other
/// hit tied with it ([`Outcome::ties_with`]); when nothing is hit,
/// the nearest miss.
pub fn primary_records(outcome: &Outcome, records: Vec<TestRecord>) -> Vec<TestRecord> {
    if !outcome.is_hit() {
        return nearest_miss(&records).copied().into_iter().collect();
    }
    let mut out: Vec<TestRecord> = records
        .iter()
        .filter(|r| outcome.is_reported_by(r))
        .take(1)
        .copied()
        .collect();
    out.extend(
        records.into_iter().filter(|r| {
            r.alpha().is_some_and(|a| outcome.ties_with(a)) && !outcome.is_reported_by(r)
        }),
    );
    out
}

/// Replays a stream of trace events (a [`crate::trace::TraceReader`], or
/// events built in memory).
pub fn replay_events<I>(events: I, options: ReplayOptions) -> ReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    ReplayIter {
        events,
        replay: Some(Replay::new(options)),
        tail: VecDeque::new(),
        summary: None,
    }
}

/// The iterator of [`replay_events`]: results in trace order, errors where
/// they occur. After a trace error (the reader stops there) the results held
/// back are still yielded; after an invalid scene or sweep the replay goes
/// on, and the caller decides whether to stop.
pub struct ReplayIter<I> {
    events: I,
    replay: Option<Replay>,
    tail: VecDeque<ReplayEvent>,
    summary: Option<Summary>,
}

impl<I> ReplayIter<I> {
    /// The counts so far; final once the iterator returned `None`.
    pub fn summary(&self) -> Summary {
        match (&self.summary, &self.replay) {
            (Some(s), _) => s.clone(),
            (None, Some(r)) => r.summary().clone(),
            (None, None) => Summary::default(),
        }
    }

    /// The engine, while the input lasts.
    pub fn replay(&self) -> Option<&Replay> {
        self.replay.as_ref()
    }
}

impl<I> Iterator for ReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    type Item = Result<ReplayEvent, ReplayError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.tail.pop_front() {
                return Some(Ok(e));
            }
            let replay = self.replay.as_mut()?;
            if let Some(e) = replay.next_event() {
                return Some(Ok(e));
            }
            match self.events.next() {
                Some(Ok(event)) => {
                    if let Err(err) = replay.push(event) {
                        return Some(Err(err));
                    }
                }
                Some(Err(err)) => {
                    self.finish();
                    return Some(Err(ReplayError::from(err)));
                }
                None => self.finish(),
            }
        }
    }
}

impl<I> ReplayIter<I> {
    fn finish(&mut self) {
        if let Some(replay) = self.replay.take() {
            let (events, summary) = replay.finish();
            self.tail.extend(events);
            self.summary = Some(summary);
        }
    }
}

/// Trace events per batch of [`replay_events_parallel`] unless told otherwise.
pub const DEFAULT_BATCH_EVENTS: usize = 4096;

/// Replays a stream of trace events like [`replay_events`], with the core
/// queries of each batch of `batch_events` events run in parallel on `pool`
/// (rayon's global pool when `None`). The results, their order, the errors
/// and the summary are those of [`replay_events`]: only the independent
/// part of each sweep (the query, [`compute_sweep`]) runs in parallel; the
/// bookkeeping goes through the same [`Replay`] in trace order.
///
/// A batch ends before a scene message, so every sweep of a batch is
/// against the scene in force at its start. Memory is bounded by one batch
/// of events and their results (plus the frame whose results are held back
/// for its `/expected` messages), whatever the trace's length.
pub fn replay_events_parallel<I>(
    events: I,
    options: ReplayOptions,
    batch_events: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
) -> ParallelReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    ParallelReplayIter {
        events,
        replay: Some(Replay::new(options)),
        out: VecDeque::new(),
        held_scene: None,
        summary: None,
        batch_events: batch_events.max(1),
        pool,
    }
}

/// The iterator of [`replay_events_parallel`].
pub struct ParallelReplayIter<I> {
    events: I,
    replay: Option<Replay>,
    out: VecDeque<Result<ReplayEvent, ReplayError>>,
    /// A scene message that ended the previous batch.
    held_scene: Option<TraceEvent>,
    summary: Option<Summary>,
    batch_events: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl<I> ParallelReplayIter<I> {
    /// The counts so far; final once the iterator returned `None`.
    pub fn summary(&self) -> Summary {
        match (&self.summary, &self.replay) {
            (Some(s), _) => s.clone(),
            (None, Some(r)) => r.summary().clone(),
            (None, None) => Summary::default(),
        }
    }
}

impl<I> ParallelReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    /// Reads, computes and pushes one batch; its results go to `out`.
    fn run_batch(&mut self) {
        let Some(replay) = self.replay.as_mut() else {
            return;
        };
        let mut batch: Vec<TraceEvent> = Vec::with_capacity(self.batch_events.min(1 << 16));
        batch.extend(self.held_scene.take());
        let mut end: Option<Option<TraceError>> = None;
        while batch.len() < self.batch_events {
            match self.events.next() {
                Some(Ok(event)) => {
                    let is_scene = matches!(event, TraceEvent::Scene { .. });
                    if is_scene && batch.iter().any(|e| !matches!(e, TraceEvent::Scene { .. })) {
                        self.held_scene = Some(event);
                        break;
                    }
                    batch.push(event);
                }
                Some(Err(err)) => {
                    end = Some(Some(err));
                    break;
                }
                None => {
                    end = Some(None);
                    break;
                }
            }
        }

        // Leading scenes first, so the sweeps see the scene in force.
        let scenes = batch
            .iter()
            .take_while(|e| matches!(e, TraceEvent::Scene { .. }))
            .count();
        let rest = batch.split_off(scenes);
        for event in batch {
            let result = replay.push(event);
            drain(replay, result, &mut self.out);
        }

        let scene = replay.current_scene().cloned();
        let options = *replay.options();
        let compute = |event: &TraceEvent| match (event, &scene) {
            (TraceEvent::Sweep { index, sweep, .. }, Some(scene))
                if replay_wanted(&options, sweep.frame, sweep.ball) =>
            {
                Some(compute_sweep(scene, sweep, *index, &options))
            }
            _ => None,
        };
        let computed: Vec<Option<Result<ComputedSweep, ReplayError>>> = {
            use rayon::prelude::*;
            let run = || rest.par_iter().with_min_len(16).map(compute).collect();
            match &self.pool {
                Some(pool) => pool.install(run),
                None => run(),
            }
        };
        for (event, computed) in rest.into_iter().zip(computed) {
            let result = match event {
                TraceEvent::Sweep {
                    log_time_nanos,
                    index,
                    sweep,
                } => replay.sweep_computed(log_time_nanos, index, sweep, computed),
                other => replay.push(other),
            };
            drain(replay, result, &mut self.out);
        }

        match end {
            None => {}
            Some(err) => {
                if let Some(err) = err {
                    self.out.push_back(Err(ReplayError::from(err)));
                }
                if let Some(replay) = self.replay.take() {
                    let (events, summary) = replay.finish();
                    self.out.extend(events.into_iter().map(Ok));
                    self.summary = Some(summary);
                }
            }
        }
    }
}

fn replay_wanted(options: &ReplayOptions, frame: u64, ball: u32) -> bool {
    options.frames.contains(frame) && options.ball.is_none_or(|b| b == ball)
}

/// Moves the outcome of one push and what it made ready to `out`, in the
/// order [`ReplayIter`] yields them.
fn drain(
    replay: &mut Replay,
    result: Result<(), ReplayError>,
    out: &mut VecDeque<Result<ReplayEvent, ReplayError>>,
) {
    if let Err(err) = result {
        out.push_back(Err(err));
    }
    while let Some(e) = replay.next_event() {
        out.push_back(Ok(e));
    }
}

impl<I> Iterator for ParallelReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    type Item = Result<ReplayEvent, ReplayError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.out.pop_front() {
                return Some(e);
            }
            self.replay.as_ref()?;
            self.run_batch();
        }
    }
}
