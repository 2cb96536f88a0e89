//! Finding one sweep in a trace, with the scene in force and its
//! expectation, and why it may not be found.

use crate::core::{MeshError, Options, Sweep, SweepError};
use crate::replay::SweepExtent;
use crate::trace::{EventBody, OutcomeMsg, SceneMsg, SweepMsg, TraceError, TraceEvent};

/// Why a sweep could not be taken out of a trace.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReproError {
    /// The trace could not be read up to the sweep.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// No sweep has that frame and ball.
    #[error("{trace} has no sweep of frame {frame}, ball {ball}: it has {seen}")]
    NotFound {
        /// The trace.
        trace: String,
        /// Frame asked for.
        frame: u64,
        /// Ball asked for.
        ball: u32,
        /// Sweeps in the trace.
        sweeps: u64,
        /// The frames and balls of the trace's sweeps.
        seen: SweepExtent,
    },
    /// The sweep has no scene before it.
    #[error("{trace}: the sweep of frame {frame}, ball {ball} has no scene before it")]
    NoScene {
        /// The trace.
        trace: String,
        /// Frame.
        frame: u64,
        /// Ball.
        ball: u32,
    },
    /// The scene is not a valid mesh.
    #[error("{trace}: the scene of frame {frame}: {cause}")]
    Mesh {
        /// The trace.
        trace: String,
        /// Frame.
        frame: u64,
        /// The cause.
        cause: MeshError,
    },
    /// The sweep is invalid.
    #[error("{trace}: the sweep of frame {frame}, ball {ball}: {cause}")]
    Sweep {
        /// The trace.
        trace: String,
        /// Frame.
        frame: u64,
        /// Ball.
        ball: u32,
        /// The cause.
        cause: SweepError,
    },
}

/// One sweep of a trace with the scene in force and its expectation.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceSweep {
    /// The scene in force at the sweep (its margin and facing are the
    /// trace's configuration).
    pub scene: SceneMsg,
    /// The sweep.
    pub sweep: SweepMsg,
    /// Its `log_time`.
    pub log_time_nanos: u64,
    /// The `/expected` outcome matched to it, as `replay` matches them (an
    /// expectation before the sweep, or after it until a sweep of another
    /// frame or a new scene).
    pub expected: Option<OutcomeMsg>,
}

impl TraceSweep {
    /// The options of the scene: its margin and facing rule.
    pub fn options(&self) -> Options {
        Options {
            margin: self.scene.margin,
            facing: self.scene.facing,

            ..Options::default()
        }
    }

    /// The core's sweep.
    pub fn core_sweep(&self) -> Sweep {
        Sweep::new(self.sweep.p0, self.sweep.p1, self.sweep.radius)
    }
}

/// Finds the first sweep of `frame` and `ball` in a trace's events. Stops
/// reading once its expectation can no longer follow. `name` names the
/// trace in errors.
pub fn find_sweep<I>(events: I, name: &str, frame: u64, ball: u32) -> Result<TraceSweep, ReproError>
where
    I: IntoIterator<Item = Result<TraceEvent, TraceError>>,
{
    let mut scene: Option<SceneMsg> = None;
    let mut early: Option<OutcomeMsg> = None;
    let mut found: Option<TraceSweep> = None;
    let mut seen = SweepExtent::default();
    for event in events {
        let event = match event {
            Ok(e) => e,
            // After the sweep, a damaged rest only loses a late expectation.
            Err(_) if found.is_some() => break,
            Err(e) => return Err(e.into()),
        };
        match event.body {
            EventBody::Scene(s) => {
                if found.is_some() {
                    break;
                }
                scene = Some(s);
            }
            EventBody::Sweep(sweep) => {
                seen.add(sweep.frame, sweep.ball);
                if let Some(f) = &found {
                    if sweep.frame != f.sweep.frame {
                        break;
                    }
                    continue;
                }
                if sweep.frame == frame && sweep.ball == ball {
                    let Some(s) = scene.take() else {
                        return Err(ReproError::NoScene {
                            trace: name.to_string(),
                            frame,
                            ball,
                        });
                    };
                    found = Some(TraceSweep {
                        scene: s,
                        sweep,
                        log_time_nanos: event.header.log_time_nanos,
                        expected: early.take(),
                    });
                }
            }
            EventBody::Expected(outcome) => {
                if outcome.frame != frame || outcome.ball != ball {
                    continue;
                }
                match &mut found {
                    Some(f) if f.expected.is_none() => f.expected = Some(outcome),
                    Some(_) => {}
                    None => early = early.or(Some(outcome)),
                }
            }
            EventBody::Contact(_) | EventBody::ExpectedContacts(_) => {}
        }
    }
    found.ok_or_else(|| ReproError::NotFound {
        trace: name.to_string(),
        frame,
        ball,
        sweeps: seen.sweeps,
        seen,
    })
}
