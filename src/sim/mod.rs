//! A small ball simulation that records sweeps: balls under gravity through a
//! scene, every move a sweep answered by [`core::sweep_mesh`](crate::core::sweep_mesh).
//!
//! The response is the one of the CS121 physics notes that SEMANTICS.md
//! follows: at a collision at `α` the ball moves to
//! `p0 + α d`, its velocity is reflected about the reported normal with a
//! restitution factor (only when it moves into that normal), it is pushed out
//! along the normal by the margin `ε` plus a tiny [`SimOptions::separation`],
//! and it continues with the rest of the time step. A frame holds at most
//! [`SimOptions::max_substeps`] sweeps per ball; time left after the last one
//! is dropped (the ball stays where it is for the rest of the frame).
//!
//! Frames and times in the trace: every sweep is its own `(frame, ball)`.
//! Sub-step `k` of simulation frame `f` gets trace frame `base(f) + k`, where
//! `base` advances by the number of sub-step rounds frame `f` used (1 when no
//! ball collided), so trace frames are dense and equal simulation frames until
//! the first sub-step. Its log time is `f × time_step` in nanoseconds plus `k`
//! nanoseconds: it grows strictly with the trace frame and stays inside the
//! simulation frame's time window. No wall clock is read.
//!
//! Bounds: the *play volume* is the mesh's bounding box grown on every side
//! by half its diagonal plus four radii. A ball whose centre leaves it, or
//! whose position or velocity stops being finite, is *stopped*: it records no
//! further sweeps, and the summary lists it. Nothing escapes to infinity and
//! no NaN reaches a trace.
//!
//! Determinism: the only randomness is the per-ball jitter, drawn from
//! `ChaCha8Rng` seeded with [`SimOptions::seed`]; the arithmetic is plain
//! IEEE (no `libm` calls), so a seed gives the same sweeps on every platform.

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use thiserror::Error;

use crate::core::{
    ContactQuery, Facing, Kind, Mesh, Options, Sides, Sweep, SweepError, SweepHit, contact_set,
    sweep_mesh,
};
use crate::numbers::{self, Rule};
mod obj;
pub mod scenes;

use crate::trace::{ContactMsg, ContactPointMsg, ContactsMsg, OutcomeMsg, SceneMsg, SweepMsg};
pub use obj::{ObjError, load_obj, obj_from_reader, obj_instead_of_trace};
use scenes::SceneMesh;

/// Largest number of simulation frames.
pub const MAX_FRAMES: u64 = 100_000_000;
/// Largest number of balls.
pub const MAX_BALLS: u32 = 100_000;
/// Largest number of sweeps per ball and frame.
pub const MAX_SUBSTEPS: u32 = 64;
/// Smallest time step, in seconds (1 µs, so sub-step offsets stay inside a frame).
pub const MIN_TIME_STEP: f64 = 1e-6;
/// Largest time step, in seconds.
pub const MAX_TIME_STEP: f64 = 10.0;

/// Parameters of a simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Number of simulation frames.
    pub frames: u64,
    /// Seed of the per-ball jitter.
    pub seed: u64,
    /// Number of balls (they do not collide with each other).
    pub balls: u32,
    /// Radius of every ball.
    pub radius: f64,
    /// Initial position of ball 0's centre.
    pub position: [f64; 3],
    /// Initial velocity of ball 0, units per second.
    pub velocity: [f64; 3],
    /// Balls 1.. start at `position` plus a uniform offset in
    /// `[-position_jitter, position_jitter]` along x and y (not z, so a ball
    /// placed just above a floor stays above it).
    pub position_jitter: f64,
    /// Balls 1.. start with `velocity` plus a uniform offset in
    /// `[-velocity_jitter, velocity_jitter]` along each axis.
    pub velocity_jitter: f64,
    /// Duration of a frame, in seconds.
    pub time_step: f64,
    /// Gravity, units per second squared.
    pub gravity: [f64; 3],
    /// Fraction of the normal speed kept at a bounce, in `[0, 1]`.
    pub restitution: f64,
    /// The margin `ε` of the sweeps (`0 ≤ ε < radius`), written into the scene.
    pub margin: f64,
    /// The facing rule of the sweeps, written into the scene.
    pub facing: Facing,
    /// Largest number of sweeps per ball and frame, `1 ..= MAX_SUBSTEPS`.
    pub max_substeps: u32,
    /// Extra push-out after a collision, beyond the margin, as a fraction of
    /// the radius (default 1e-9): with `ε = 0` it keeps rounding from starting
    /// the next sweep a hair inside `ρ` of the plane just touched, which the
    /// face test would not report.
    pub separation: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            frames: 300,
            seed: 0,
            balls: 1,
            radius: 0.25,
            position: [0.0, 0.0, 3.0],
            velocity: [0.0, 0.0, 0.0],
            position_jitter: 0.0,
            velocity_jitter: 0.0,
            time_step: 1.0 / 60.0,
            gravity: [0.0, 0.0, -9.81],
            restitution: 0.8,
            margin: 0.0,
            facing: Facing::NonStrict,
            max_substeps: 4,
            separation: 1e-9,
        }
    }
}

impl SimOptions {
    /// Checks every parameter; the error names the field.
    pub fn validate(&self) -> Result<(), SimError> {
        let finite = |field: &'static str, v: f64| {
            numbers::check(v, Rule::Finite).map_err(|reason| SimError::Invalid { field, reason })
        };
        finite("radius", self.radius)?;
        for (field, p) in [
            ("position", self.position),
            ("velocity", self.velocity),
            ("gravity", self.gravity),
        ] {
            for v in p {
                finite(field, v)?;
            }
        }
        for (field, v) in [
            ("position_jitter", self.position_jitter),
            ("velocity_jitter", self.velocity_jitter),
            ("time_step", self.time_step),
            ("restitution", self.restitution),
            ("margin", self.margin),
            ("separation", self.separation),
        ] {
            finite(field, v)?;
        }
        let invalid =
            |field: &'static str, reason: String| Err(SimError::Invalid { field, reason });
        numbers::check(self.radius, Rule::Positive).map_err(|reason| SimError::Invalid {
            field: "radius",
            reason,
        })?;
        numbers::check_margin(self.margin, self.radius).map_err(|reason| SimError::Invalid {
            field: "margin",
            reason,
        })?;
        if !(MIN_TIME_STEP..=MAX_TIME_STEP).contains(&self.time_step) {
            return invalid(
                "time_step",
                format!(
                    "must lie in [{MIN_TIME_STEP}, {MAX_TIME_STEP}] seconds, got {}",
                    numbers::Shortest(self.time_step)
                ),
            );
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            return invalid(
                "restitution",
                format!(
                    "must lie in [0, 1], got {}",
                    numbers::Shortest(self.restitution)
                ),
            );
        }
        if self.position_jitter < 0.0 || self.velocity_jitter < 0.0 {
            return invalid("jitter", "must be ≥ 0".into());
        }
        if !(0.0..=1e-3).contains(&self.separation) {
            return invalid(
                "separation",
                format!(
                    "must lie in [0, 1e-3], got {}",
                    numbers::Shortest(self.separation)
                ),
            );
        }
        if self.frames > MAX_FRAMES {
            return invalid(
                "frames",
                format!("at most {MAX_FRAMES}, got {}", self.frames),
            );
        }
        if self.balls == 0 || self.balls > MAX_BALLS {
            return invalid(
                "balls",
                format!("must lie in 1..={MAX_BALLS}, got {}", self.balls),
            );
        }
        if self.max_substeps == 0 || self.max_substeps > MAX_SUBSTEPS {
            return invalid(
                "max_substeps",
                format!("must lie in 1..={MAX_SUBSTEPS}, got {}", self.max_substeps),
            );
        }
        Ok(())
    }

    /// The core options of every sweep.
    pub fn core_options(&self) -> Options {
        Options {
            margin: self.margin,
            facing: self.facing,

            ..Options::default()
        }
    }

    /// The frame duration in nanoseconds.
    pub fn time_step_nanos(&self) -> u64 {
        (self.time_step * 1e9).round() as u64
    }
}

/// A simulation that cannot run.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SimError {
    /// A parameter is out of range.
    #[error("invalid simulation parameter `{field}`: {reason}")]
    Invalid {
        /// The parameter.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The core refused a sweep (cannot happen with validated options; kept
    /// as an error rather than a panic).
    #[error("frame {frame}, ball {ball}: {cause}")]
    Sweep {
        /// Trace frame.
        frame: u64,
        /// Ball.
        ball: u32,
        /// The core's error.
        cause: SweepError,
    },
}

/// One recorded sweep and the outcome the core gave it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    /// Simulation frame (before sub-step numbering).
    pub sim_frame: u64,
    /// Log time of both messages, nanoseconds.
    pub log_time_nanos: u64,
    /// The `/sweep` message.
    pub sweep: SweepMsg,
    /// The `/expected` message.
    pub outcome: OutcomeMsg,
}

impl Event {
    /// The contact query where the event's sweep leaves the ball (its
    /// centre at the sweep's `α`: touching the mesh after a hit, at the
    /// path's end after a miss), with the contact `distance`, and the
    /// core's contacts there as the recording engine's answer (each with
    /// the rules' normal, the face normal on the ball's side).
    pub fn contacts(&self, mesh: &Mesh, distance: f64) -> (ContactMsg, ContactsMsg) {
        let s = &self.sweep;
        let alpha = self.outcome.alpha;
        let centre = [0, 1, 2].map(|k| s.p0[k] + (s.p1[k] - s.p0[k]) * alpha);
        let query = ContactMsg {
            frame: s.frame,
            ball: s.ball,
            radius: s.radius,
            centre,
            distance,
        };
        let set = contact_set(
            mesh,
            &ContactQuery {
                centre: centre.into(),
                radius: s.radius,
                distance,
            },
            Sides::One,
        );
        let answer = ContactsMsg {
            frame: s.frame,
            ball: s.ball,
            contacts: set.iter().map(ContactPointMsg::from_contact).collect(),
        };
        (query, answer)
    }
}

/// Why a ball stopped recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Its centre left the play volume.
    LeftBounds,
    /// Its position or velocity stopped being finite.
    NonFinite,
}

/// A stopped ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stopped {
    /// The ball.
    pub ball: u32,
    /// The last trace frame it recorded.
    pub frame: u64,
    /// Why.
    pub reason: StopReason,
    /// Its last position.
    pub position: [f64; 3],
}

/// Counts of a finished simulation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SimSummary {
    /// Simulation frames run.
    pub sim_frames: u64,
    /// Trace frames used (sub-steps included).
    pub trace_frames: u64,
    /// Sweeps recorded.
    pub sweeps: u64,
    /// Sweeps by outcome kind: face, edge, vertex, none.
    pub face: u64,
    /// Edge collisions.
    pub edge: u64,
    /// Vertex collisions.
    pub vertex: u64,
    /// Misses.
    pub none: u64,
    /// Ball-frames whose sub-steps ran out before the end of the time step
    /// (the rest of that frame was dropped).
    pub truncated: u64,
    /// Balls stopped before the end.
    pub stopped: Vec<Stopped>,
}

impl SimSummary {
    /// Collisions of every kind.
    pub fn collisions(&self) -> u64 {
        self.face + self.edge + self.vertex
    }

    fn count(&mut self, kind: Kind) {
        self.sweeps += 1;
        match kind {
            Kind::Face => self.face += 1,
            Kind::Edge => self.edge += 1,
            Kind::Vertex => self.vertex += 1,
            Kind::None => self.none += 1,
        }
    }
}

/// The `/scene` message of a simulation: the mesh with the options' margin
/// and facing rule.
pub fn scene_message(scene: &SceneMesh, options: &SimOptions) -> SceneMsg {
    SceneMsg {
        name: Some(scene.name.clone()),
        vertices: scene.vertices.clone(),
        triangles: scene.triangles.clone(),
        margin: options.margin,
        facing: options.facing,
    }
}

/// The box a ball's centre must stay in (`min`, `max`).
pub fn play_volume(mesh: &Mesh, radius: f64) -> (Point3<f64>, Point3<f64>) {
    let (lo, hi) = mesh.bounds();
    let pad = 0.5 * (hi - lo).norm() + 4.0 * radius;
    let pad = Vector3::repeat(pad);
    (lo - pad, hi + pad)
}

struct Ball {
    position: Point3<f64>,
    velocity: Vector3<f64>,
    /// Seconds of the current frame still to move.
    remaining: f64,
    active: bool,
}

/// The initial `(position, velocity)` of every ball.
pub fn initial_states(options: &SimOptions) -> Vec<([f64; 3], [f64; 3])> {
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut out = Vec::with_capacity(options.balls as usize);
    for ball in 0..options.balls {
        let mut p = options.position;
        let mut v = options.velocity;
        if ball > 0 {
            for coordinate in p.iter_mut().take(2) {
                *coordinate += jitter(&mut rng, options.position_jitter);
            }
            for axis in v.iter_mut() {
                *axis += jitter(&mut rng, options.velocity_jitter);
            }
        }
        out.push((p, v));
    }
    out
}

fn jitter(rng: &mut ChaCha8Rng, amount: f64) -> f64 {
    // Always draw, so one ball's jitter does not depend on another amount.
    let u: f64 = rng.random::<f64>();
    (2.0 * u - 1.0) * amount
}

/// Runs the simulation on `mesh`, handing every sweep and its outcome to
/// `on_event` in trace order (by trace frame, then ball). Stops at the first
/// error `on_event` returns.
pub fn simulate<E: From<SimError>>(
    mesh: &Mesh,
    options: &SimOptions,
    mut on_event: impl FnMut(&Event) -> Result<(), E>,
) -> Result<SimSummary, E> {
    options.validate()?;
    let core_options = options.core_options();
    let (lo, hi) = play_volume(mesh, options.radius);
    let inside = |p: &Point3<f64>| (0..3).all(|i| p[i] >= lo[i] && p[i] <= hi[i]);
    let gravity = Vector3::from(options.gravity);
    let dt = options.time_step;
    let dt_nanos = options.time_step_nanos();
    let push = options.margin + options.separation * options.radius;
    let mut summary = SimSummary::default();
    let mut balls: Vec<Ball> = initial_states(options)
        .into_iter()
        .map(|(p, v)| Ball {
            position: p.into(),
            velocity: v.into(),
            remaining: 0.0,
            active: true,
        })
        .collect();
    for (index, ball) in balls.iter_mut().enumerate() {
        if !inside(&ball.position) {
            ball.active = false;
            summary.stopped.push(Stopped {
                ball: index as u32,
                frame: 0,
                reason: StopReason::LeftBounds,
                position: ball.position.into(),
            });
        }
    }
    let mut base = 0u64;
    for sim_frame in 0..options.frames {
        for ball in balls.iter_mut().filter(|b| b.active) {
            ball.velocity += gravity * dt;
            ball.remaining = dt;
        }
        let mut rounds = 0u64;
        for k in 0..u64::from(options.max_substeps) {
            let frame = base + k;
            let log_time_nanos = sim_frame.saturating_mul(dt_nanos).saturating_add(k);
            let mut any = false;
            for (index, ball) in balls.iter_mut().enumerate() {
                if !ball.active || ball.remaining <= 0.0 {
                    continue;
                }
                any = true;
                let index = index as u32;
                let p0 = ball.position;
                let p1 = p0 + ball.velocity * ball.remaining;
                let sweep = Sweep {
                    p0,
                    p1,
                    radius: options.radius,
                };
                let outcome =
                    sweep_mesh(mesh, &sweep, &core_options).map_err(|cause| SimError::Sweep {
                        frame,
                        ball: index,
                        cause,
                    })?;
                let event = Event {
                    sim_frame,
                    log_time_nanos,
                    sweep: SweepMsg {
                        frame,
                        ball: index,
                        radius: options.radius,
                        p0: p0.into(),
                        p1: p1.into(),
                    },
                    outcome: OutcomeMsg::from_outcome(frame, index, &outcome),
                };
                on_event(&event)?;
                summary.count(outcome.kind());
                match outcome.hit {
                    Some(SweepHit { alpha, normal, .. }) => {
                        ball.position = p0 + (p1 - p0) * alpha;
                        let into = ball.velocity.dot(&normal);
                        if into < 0.0 {
                            ball.velocity -= normal * ((1.0 + options.restitution) * into);
                        }
                        ball.position += normal * push;
                        ball.remaining *= 1.0 - alpha;
                    }
                    None => {
                        ball.position = p1;
                        ball.remaining = 0.0;
                    }
                }
                let reason = if !(ball.position.iter().all(|v| v.is_finite())
                    && ball.velocity.iter().all(|v| v.is_finite()))
                {
                    Some(StopReason::NonFinite)
                } else if !inside(&ball.position) {
                    Some(StopReason::LeftBounds)
                } else {
                    None
                };
                if let Some(reason) = reason {
                    ball.active = false;
                    let position = if reason == StopReason::NonFinite {
                        p0
                    } else {
                        ball.position
                    };
                    summary.stopped.push(Stopped {
                        ball: index,
                        frame,
                        reason,
                        position: position.into(),
                    });
                }
            }
            if !any {
                break;
            }
            rounds = k + 1;
        }
        for ball in balls.iter_mut().filter(|b| b.active && b.remaining > 0.0) {
            // Out of sub-steps: the rest of the frame is dropped.
            ball.remaining = 0.0;
            summary.truncated += 1;
        }
        base += rounds;
        summary.sim_frames = sim_frame + 1;
        if balls.iter().all(|b| !b.active) {
            break;
        }
    }
    summary.trace_frames = base;
    Ok(summary)
}
