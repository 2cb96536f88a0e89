//! Replay: trace events in, one explained result per sweep out.
//!
//! [`Replay`] is push-based: feed it the events of a trace in order
//! ([`Replay::scene`], [`Replay::sweep`], [`Replay::expected`]) and take the
//! finished [`ReplayEvent`]s with [`Replay::next_event`]; [`Replay::finish`]
//! flushes what is still held and returns the [`ReplaySummary`]. [`replay_events`]
//! wraps any iterator of trace events into an iterator of results.
//!
//! A sweep's result is held back until a sweep of another frame (or a new
//! scene, or the end) arrives, so that an `/expected` message logged just
//! after its sweep is still attached to it.
//!
//! Each result also says whether the ball's centre went through a triangle
//! front to back ([`Tunnel`](tunnel::Tunnel)): during the sweep, or since the ball's
//! previous sweep ([`Replay`] keeps where each ball's last sweep left it),
//! and whether its contact is a ghost contact: an edge or vertex contact
//! on an internal flat or concave place whose normal leans off the faces
//! ([`judge_ghost`](ghost::judge_ghost)).
//!
//! Nothing here knows about the viewer: `viz` turns results into a Rerun
//! recording, `check`-like commands compare [`SweepResult::outcome_msg`]
//! with [`SweepResult::expected`].

mod error;
pub mod ghost;
mod iter;
mod normals;
mod options;
mod pipeline;
mod primary;
mod replayer;
mod selection;
pub mod story;
mod summary;
pub mod tunnel;

pub use error::ReplayError;
pub(crate) use ghost::GhostLine;
pub use iter::{ParallelReplayIter, ReplayIter, replay_events, replay_events_parallel};
pub use normals::SceneNormals;
pub use options::{DEFAULT_BATCH_EVENTS, Detail, FrameRange, ReplayOptions};
#[cfg(feature = "viewer")]
pub(crate) use pipeline::sweep_of;
pub use pipeline::{
    BatchRecorder, Event as PipelineEvent, NoRecorder, PipelineOptions, run_pipeline,
    run_pipeline_unrecorded,
};
pub use primary::{CollectPrimary, primary_records};
pub use replayer::{Replay, ReplayEvent, SceneState, SweepResult, feature_class};
pub use selection::{Selection, SweepExtent};
pub use story::{SweepStory, explain_sweep};
pub use summary::{ReplaySummary, TunnelAt};
