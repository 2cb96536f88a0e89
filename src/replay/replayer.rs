//! The push-based replay state machine: scenes built into meshes, each
//! sweep run through the core, `/expected` outcomes attached to their sweep.

use std::collections::{HashMap, VecDeque};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::conventions::{EngineConventions, MarginRule};
use crate::core::explain::nearest_miss;
use crate::core::record::{CollectRecords, Observer, SkipCounts, TestRecord, VerdictCounts};
use crate::core::topology::{EdgeClass, Topology};
use crate::core::{
    Broadphase, Feature, Mesh, Options, Outcome, Sweep, SweepError, sweep_mesh, sweep_mesh_with,
};
use crate::trace::{EventBody, EventHeader, OutcomeMsg, SceneMsg, SweepMsg, TraceEvent};

use super::normals::SceneNormals;
use super::primary::CollectPrimary;
use super::tunnel::{BallEnds, Tunnel, TunnelScene, sweep_end, tunnel_during_sweep};
use super::{Detail, ReplayError, ReplayOptions, ReplaySummary};

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
    /// The mesh's topology: its edges by class and its defects, built once
    /// per scene from the same message as [`SceneState::mesh`].
    pub topology: Topology,
    /// The options in force: the scene's margin and facing unless overridden.
    pub options: Options,
    /// Which normal a hit reports, and the scene's active edges when that
    /// depends on them.
    pub normals: SceneNormals,
    /// The run's conventions, whole ([`super::ReplayOptions::conventions`]):
    /// the reference answer was computed under them (`options`, `normals`),
    /// and an answer is judged under their precision and tie rule.
    pub conventions: EngineConventions,
}

impl SceneState {
    /// The class of the edge `outcome` hit, or for a vertex hit the class
    /// of the vertex (see [`feature_class`]); `None` for a face hit or a
    /// miss.
    pub fn hit_class(&self, outcome: &Outcome) -> Option<EdgeClass> {
        let hit = outcome.hit.as_ref()?;
        feature_class(&self.topology, hit.triangle, hit.feature)
    }

    /// What a tunnel of a ball of `radius` is judged against: the mesh, its
    /// topology and `ρ = radius − margin`.
    pub(crate) fn tunnel_scene(&self, radius: f64) -> TunnelScene<'_> {
        TunnelScene {
            mesh: &self.mesh,
            topology: &self.topology,
            rho: radius - self.options.margin,
        }
    }
}

/// The class of feature `feature` of `triangle`: an edge's
/// own class; for a vertex, the most telling class of its edges, in the
/// order `non_manifold`, `boundary`, `convex`, `concave`, `flat` (a vertex
/// is `flat` only when every edge at it is); `None` for a face, or a
/// feature the topology does not have.
pub fn feature_class(topology: &Topology, triangle: u32, feature: Feature) -> Option<EdgeClass> {
    match feature {
        Feature::Face => None,
        Feature::Edge(i) => topology.triangle_edge_class(triangle, i),
        Feature::Vertex(i) => {
            let v = topology.triangle_vertex(triangle, i)?;
            let rank = |c: EdgeClass| match c {
                EdgeClass::NonManifold => 0,
                EdgeClass::Boundary => 1,
                EdgeClass::Convex => 2,
                EdgeClass::Concave => 3,
                EdgeClass::Flat => 4,
            };
            topology
                .edges_at(v)
                .map(|e| e.class)
                .min_by_key(|&c| rank(c))
        }
    }
}

/// Two states are equal when they come from the same scene message with the
/// same options: the mesh is built from that message.
impl PartialEq for SceneState {
    fn eq(&self, other: &SceneState) -> bool {
        self.number == other.number
            && self.index == other.index
            && self.log_time_nanos == other.log_time_nanos
            && self.name == other.name
            && self.options == other.options
            && self.normals == other.normals
            && self.conventions == other.conventions
    }
}

/// The result of one sweep.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SweepResult {
    /// Frame number.
    pub frame: u64,
    /// Ball number.
    pub ball: u32,
    /// `log_time` of the sweep message, in nanoseconds.
    pub log_time_nanos: u64,
    /// Index of the sweep message in the trace.
    pub index: u64,
    /// The scene it was swept against (the one its
    /// [`ReplayEvent::Scene`] announced, shared).
    pub scene: Arc<SceneState>,
    /// The sweep.
    pub sweep: Sweep,
    /// The core's outcome.
    pub outcome: Outcome,
    /// The test records kept at the chosen [`Detail`] (empty when not
    /// explained). With [`Detail::Primary`] the first record is the primary
    /// test, or the nearest miss.
    pub records: Vec<TestRecord>,
    /// The candidate triangles the explained query skipped without testing
    /// them, by reason: at [`Detail::Primary`], what the fast query skips
    /// (its records, and the nearest miss, cover the tested ones only);
    /// empty at the other details, which test every candidate.
    pub skipped: SkipCounts,
    /// The trace's `/expected` outcome for this `(frame, ball)`, if any.
    pub expected: Option<OutcomeMsg>,
    /// Where the ball's centre went through a triangle front to back, in
    /// the order it happened: between its previous sweep and this one, then
    /// during this one (empty when it did not; see [`Tunnel`]).
    pub tunnels: Vec<Tunnel>,
}

impl SweepResult {
    /// The outcome as the record of SEMANTICS.md (every field present).
    pub fn outcome_msg(&self) -> OutcomeMsg {
        OutcomeMsg::from_outcome(self.frame, self.ball, &self.outcome)
    }

    /// The line `replay --outcomes` writes: the outcome record, then the
    /// additive fields `fragile` (the reasons the decision is fragile, `[]`
    /// when it is robust; see [`crate::core::FragileReason`]) and `tunnel`
    /// (the first of [`SweepResult::tunnels`], `null` when there is none),
    /// and for an edge or vertex hit `edge_class`, the class of the edge
    /// (or vertex, [`feature_class`]) hit (`null` otherwise), and `ghost`
    /// ([`SweepResult::ghost`] as a [`super::GhostLine`], `null`
    /// when the expected outcome is not a ghost contact).
    pub fn outcome_line(&self) -> Result<String, serde_json::Error> {
        #[derive(serde::Serialize)]
        struct Line<'a> {
            #[serde(flatten)]
            outcome: OutcomeMsg,
            fragile: crate::core::Fragility,
            tunnel: Option<&'a Tunnel>,
            edge_class: Option<EdgeClass>,
            ghost: Option<super::GhostLine<'a>>,
        }
        let ghost = self.ghost();
        serde_json::to_string(&Line {
            outcome: self.outcome_msg(),
            fragile: self.outcome.fragile,
            tunnel: self.tunnels.first(),
            edge_class: self.scene.hit_class(&self.outcome),
            ghost: ghost.as_ref().map(|g| g.line()),
        })
    }

    /// The expected outcome as a ghost contact, when it is one: judged as
    /// `check` judges it ([`crate::replay::ghost::judge_ghost`], with the core's
    /// normal for the sweep as the rule's and the default threshold
    /// [`super::ghost::GHOST_DEGREES`]).
    pub fn ghost(&self) -> Option<crate::replay::ghost::GhostContact> {
        let expected = self.expected.as_ref()?;
        match crate::replay::ghost::judge_ghost(
            &self.scene.mesh,
            &self.scene.topology,
            expected,
            self.log_time_nanos,
            self.outcome.hit.as_ref().map(|h| &h.normal),
            super::ghost::GHOST_DEGREES,
        ) {
            super::ghost::GhostJudgement::Ghost(g) => Some(g),
            _ => None,
        }
    }

    /// Where the viewers mark the ghost contact `g` of this sweep: at the
    /// expected contact; without one, at the core's contact; without a hit, a
    /// detection radius from the ball's centre at the expected α, against the
    /// expected normal.
    pub(crate) fn ghost_point(&self, g: &crate::replay::ghost::GhostContact) -> [f64; 3] {
        let r = self;
        if let Some(Some(c)) = r.expected.as_ref().and_then(|e| e.contact) {
            return c;
        }
        if let Some(h) = &r.outcome.hit {
            return h.contact.coords.into();
        }
        let alpha = r.expected.as_ref().map_or(1.0, |e| {
            if e.alpha.is_finite() {
                e.alpha.clamp(0.0, 1.0)
            } else {
                1.0
            }
        });
        let center = r.sweep.p0 + (r.sweep.p1 - r.sweep.p0) * alpha;
        let n = nalgebra::Vector3::from(g.normal).normalize();
        (center.coords - n * r.rho()).into()
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

    /// The options used: those of its scene.
    pub fn options(&self) -> &Options {
        &self.scene.options
    }

    /// The detection radius `ρ = r - ε`.
    pub fn rho(&self) -> f64 {
        self.sweep.radius - self.options().margin
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

/// The replay state machine (push-based; see the module documentation).
#[derive(Debug)]
pub struct Replay {
    options: ReplayOptions,
    scene: Option<Arc<SceneState>>,
    /// Results held until their frame is complete.
    pending: Vec<SweepResult>,
    /// `/expected` messages that arrived before their sweep.
    early_expected: HashMap<(u64, u32), OutcomeMsg>,
    ready: VecDeque<ReplayEvent>,
    summary: ReplaySummary,
    /// Where each ball's last replayed sweep left it.
    ends: BallEnds,
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
            summary: ReplaySummary::default(),
            ends: BallEnds::default(),
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
    pub fn scene(&mut self, header: EventHeader, scene: SceneMsg) -> Result<(), ReplayError> {
        let EventHeader {
            log_time_nanos,
            index,
        } = header;
        let start = Instant::now();
        self.release_pending();
        let SceneMsg {
            name,
            vertices,
            triangles,
            margin,
            facing,
        } = scene;
        // From the message, before the mesh takes its vertices. The two
        // check their input alike, so the mesh's error is the one reported.
        let topology = Topology::new(&vertices, &triangles);
        let mesh =
            Mesh::new(vertices, &triangles).map_err(|cause| ReplayError::Mesh { index, cause })?;
        let topology = topology.map_err(|cause| ReplayError::Mesh { index, cause })?;
        let options = self.options.core_options(margin, facing);
        let normals = SceneNormals::new(self.options.conventions.normal, &mesh, &topology);
        let number = self.summary.scenes;
        self.summary.scenes += 1;
        self.summary.degenerate_triangles += mesh.degenerate().len();
        let state = Arc::new(SceneState {
            number,
            index,
            log_time_nanos,
            name,
            mesh,
            topology,
            options,
            normals,
            conventions: self.options.conventions,
        });
        self.scene = Some(state.clone());
        // A jump across a change of scene is not a move through a surface.
        self.ends.clear();
        self.ready.push_back(ReplayEvent::Scene(state));
        self.summary.elapsed += start.elapsed();
        Ok(())
    }

    /// A `/sweep` message.
    pub fn sweep(&mut self, header: EventHeader, msg: SweepMsg) -> Result<(), ReplayError> {
        self.summary.seen.add(msg.frame, msg.ball);
        if self.pending.first().is_some_and(|p| p.frame != msg.frame) {
            self.release_pending();
        }
        if !self.wanted(msg.frame, msg.ball) {
            self.summary.filtered_out += 1;
            // Where this sweep left the ball is not computed.
            self.ends.forget(msg.ball);
            self.early_expected.remove(&(msg.frame, msg.ball));
            return Ok(());
        }
        let Some(scene) = self.scene.clone() else {
            return Err(ReplayError::NoScene {
                frame: msg.frame,
                index: header.index,
            });
        };
        let computed = compute_sweep(&scene, &msg, header.index, &self.options);
        self.commit(header, msg, &scene, computed?);
        Ok(())
    }

    /// A `/sweep` message whose core query already ran ([`compute_sweep`]
    /// against [`Replay::current_scene`], or `None` when the sweep is
    /// filtered out or comes before any scene): the same as
    /// [`Replay::sweep`] without the query. Used by [`super::replay_events_parallel`].
    pub(crate) fn sweep_computed(
        &mut self,
        header: EventHeader,
        msg: SweepMsg,
        computed: Option<Result<ComputedSweep, ReplayError>>,
    ) -> Result<(), ReplayError> {
        let Some(computed) = computed else {
            return self.sweep(header, msg);
        };
        self.summary.seen.add(msg.frame, msg.ball);
        if self.pending.first().is_some_and(|p| p.frame != msg.frame) {
            self.release_pending();
        }
        let Some(scene) = self.scene.clone() else {
            return Err(ReplayError::NoScene {
                frame: msg.frame,
                index: header.index,
            });
        };
        self.commit(header, msg, &scene, computed?);
        Ok(())
    }

    /// Whether a sweep passes the frame and ball filters.
    fn wanted(&self, frame: u64, ball: u32) -> bool {
        self.options.wants(frame, ball)
    }

    fn commit(
        &mut self,
        header: EventHeader,
        msg: SweepMsg,
        scene: &Arc<SceneState>,
        computed: ComputedSweep,
    ) {
        let ComputedSweep {
            sweep,
            outcome,
            records,
            verdicts,
            skipped,
            during,
            elapsed,
        } = computed;
        let start = Instant::now();
        let mut tunnels = Vec::new();
        tunnels.extend(self.ends.jump(
            msg.ball,
            scene.number,
            &scene.tunnel_scene(sweep.radius),
            &sweep.p0,
        ));
        tunnels.extend(during);
        self.ends.set(
            msg.ball,
            msg.frame,
            scene.number,
            sweep_end(&sweep, &outcome),
        );
        for t in &tunnels {
            self.summary.tunnel(msg.frame, msg.ball, t);
        }
        self.summary.verdicts += verdicts;
        self.summary.skipped += skipped;
        let expected = self.early_expected.remove(&(msg.frame, msg.ball));
        if expected.is_some() {
            self.summary.expected_matched += 1;
        }
        self.summary.sweeps += 1;
        self.summary.elapsed += elapsed + start.elapsed();
        *self.summary.outcomes.entry(outcome.kind()).or_default() += 1;
        if !outcome.fragile.is_robust() {
            self.summary.fragile += 1;
            for reason in outcome.fragile.iter() {
                *self.summary.fragile_by_reason.entry(reason).or_default() += 1;
            }
        }
        self.pending.push(SweepResult {
            frame: msg.frame,
            ball: msg.ball,
            log_time_nanos: header.log_time_nanos,
            index: header.index,
            scene: Arc::clone(scene),
            sweep,
            outcome,
            records,
            skipped,
            expected,
            tunnels,
        });
    }

    /// Any trace event.
    pub fn push(&mut self, event: TraceEvent) -> Result<(), ReplayError> {
        match event.body {
            EventBody::Scene(scene) => self.scene(event.header, scene),
            EventBody::Sweep(sweep) => self.sweep(event.header, sweep),
            EventBody::Expected(outcome) => {
                self.expected(outcome);
                Ok(())
            }
            // Contact queries are judged apart from the sweeps (`check`,
            // the recording's contacts); the replay of sweeps counts them.
            EventBody::Contact(_) => {
                self.summary.contact_queries += 1;
                Ok(())
            }
            EventBody::ExpectedContacts(_) => Ok(()),
        }
    }

    /// An `/expected` message.
    pub fn expected(&mut self, outcome: OutcomeMsg) {
        if !self.options.wants(outcome.frame, outcome.ball) {
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
    pub fn finish(mut self) -> (Vec<ReplayEvent>, ReplaySummary) {
        self.release_pending();
        self.summary.expected_unmatched += self.early_expected.len() as u64;
        (self.ready.into_iter().collect(), self.summary)
    }

    /// The counts so far.
    pub fn summary(&self) -> &ReplaySummary {
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
    verdicts: VerdictCounts,
    skipped: SkipCounts,
    /// The tunnel during the sweep, if any.
    during: Option<Tunnel>,
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
    let err = |cause| match cause {
        // The margin was given (not the scene's): the setting's fault.
        SweepError::MarginNotBelowRadius { margin, radius }
            if options.conventions.margin != MarginRule::Scene =>
        {
            ReplayError::MarginOverride {
                frame: msg.frame,
                ball: msg.ball,
                index,
                margin,
                radius,
            }
        }
        cause => ReplayError::Sweep {
            frame: msg.frame,
            ball: msg.ball,
            index,
            cause,
        },
    };
    let mut verdicts = VerdictCounts::default();
    let mut skipped = SkipCounts::default();
    let (outcome, records) = if let Some(detail) = options.explain {
        let broadphase = match detail {
            Detail::All => Broadphase::Exhaustive,
            Detail::Primary | Detail::Candidates => Broadphase::Bvh,
        };
        match detail {
            Detail::Primary => {
                // Only what `primary_records` keeps is kept: the hits and
                // the nearest miss so far, not every record; the candidates
                // the fast query skips are counted, not tested.
                let mut collect = CollectPrimary::default();
                let outcome = explained(scene, &sweep, broadphase, &mut collect).map_err(err)?;
                verdicts = collect.verdict_counts();
                skipped = collect.skip_counts();
                let records = collect.into_primary_records(&outcome);
                (outcome, records)
            }
            Detail::Candidates | Detail::All => {
                let mut collect = CollectRecords::default();
                let outcome = explained(scene, &sweep, broadphase, &mut collect).map_err(err)?;
                verdicts = collect.records.iter().map(TestRecord::verdict).collect();
                (outcome, collect.records)
            }
        }
    } else {
        (
            sweep_mesh(&scene.mesh, &sweep, &scene.options).map_err(err)?,
            Vec::new(),
        )
    };
    let outcome = scene.normals.apply(&sweep, outcome);
    let during = tunnel_during_sweep(&scene.tunnel_scene(sweep.radius), &sweep, &outcome);
    Ok(ComputedSweep {
        sweep,
        outcome,
        records,
        verdicts,
        skipped,
        during,
        elapsed: start.elapsed(),
    })
}

/// The explained query of `sweep` against `scene` with `observer`.
fn explained<O: Observer>(
    scene: &SceneState,
    sweep: &Sweep,
    broadphase: Broadphase,
    observer: &mut O,
) -> Result<Outcome, crate::core::SweepError> {
    sweep_mesh_with(&scene.mesh, sweep, &scene.options, broadphase, observer)
}
