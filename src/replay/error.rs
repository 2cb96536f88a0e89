//! Why an event of a trace cannot be replayed.

use thiserror::Error;

use crate::core::{MeshError, SweepError};
use crate::trace::TraceError;

/// An event the replay cannot use.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// A scene's mesh is invalid.
    #[error("scene message {index}: {cause}")]
    Mesh {
        /// Index of the scene message.
        index: u64,
        /// What is wrong.
        cause: MeshError,
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
    #[error("frame {frame}, ball {ball} (message {index}): {cause}")]
    Sweep {
        /// Frame.
        frame: u64,
        /// Ball.
        ball: u32,
        /// Index of the sweep message.
        index: u64,
        /// What is wrong.
        cause: SweepError,
    },
    /// The margin the options impose on every scene (an engine's declared
    /// margin, `--margin`) is not smaller than a sweep's radius: a fault of
    /// that setting, not of the trace (every ball that small fails alike).
    #[error(
        "frame {frame}, ball {ball} (message {index}): the margin {} given instead of the scene's must be smaller than the ball's radius {}",
        crate::numbers::Shortest(*.margin),
        crate::numbers::Shortest(*.radius)
    )]
    MarginOverride {
        /// Frame.
        frame: u64,
        /// Ball.
        ball: u32,
        /// Index of the sweep message.
        index: u64,
        /// The margin given.
        margin: f64,
        /// The sweep's radius.
        radius: f64,
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
