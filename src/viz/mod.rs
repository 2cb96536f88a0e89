//! The Rerun recording of a replay: the only module that imports `rerun`.
//!
//! [`Logger`] turns [`crate::replay::ReplayEvent`]s into entities (see
//! `paths` for every path) on two timelines: `frame` (sequence, the
//! sweep's frame) and `time` (the trace's `log_time`; never the wall clock).
//! The default timelines `log_time` and `log_tick` of the SDK are switched
//! off, and the recording id is derived from the trace and the options
//! ([`recording_id`]), so the same trace and options give the same content.
//!
//! The files, by job:
//!
//! - `ids`: recording ids ([`recording_id`], [`IdHasher`]);
//! - `recording`: [`Recording`], a recording from its opening (a file, a
//!   viewer, or both) to its finish, the one path every caller takes;
//! - `logger`: [`Logger`], and [`prepare_sweeps`] which builds a run of
//!   sweeps' rows on a worker thread;
//! - `rows`: the rows of one sweep (ball, sweep, contact, primary feature,
//!   expected outcome, plots, status, text); `edge_frame`: its edge tests in
//!   their standard frames;
//! - the decision line, and whether a sweep diverges, are
//!   [`crate::judge::decision_line`] (shared with the Foxglove output);
//! - `convert`: conversions to Rerun types, colors and sizes;
//! - `blueprint`: the default layouts, with fixed ids; `columns`: rows
//!   buffered as typed columns and sent as chunks (both use SDK internals
//!   pinned to Rerun 0.36.3); `spill`: for a recording file, the buffered
//!   rows kept in a temporary file and sent in long chunks;
//! - `contacts`: a trace's contact queries, judged as `check` judges them
//!   and drawn ([`draw_contacts`]);
//! - `paths`: every entity path.

mod blueprint;
mod columns;
mod contacts;
mod convert;
mod edge_frame;
mod ids;
mod logger;
mod out;
mod paths;
mod pipeline;
mod recording;
mod rows;
pub mod rrd_file;
mod spill;

use rerun::RecordingStreamBuilder;

pub use contacts::{DrawContactsError, draw_contacts};
pub use ids::{IdHasher, recording_id};
pub use logger::{
    DEFAULT_FLUSH_BYTES, DEFAULT_FLUSH_ROWS, Logger, LoggerOptions, PreparedSweeps,
    SPILL_FLUSH_BYTES, prepare_sweeps,
};
pub(crate) use logger::{PREPARE_GROUP_SWEEPS, prepare_sweeps_into};
pub use out::{PrepareOptions, Shown};
pub use pipeline::LogError;
pub use recording::{FinishedRecording, Recording, RecordingError, RecordingTarget, Viewer};
pub use rerun::RecordingStreamError;
pub use spill::{MAX_CHUNK_BYTES, MAX_CHUNK_ROWS};

/// Application id of every recording.
pub const APPLICATION_ID: &str = "sweeptrace";
/// Name of the sequence timeline holding the frame number.
pub const FRAME_TIMELINE: &str = "frame";
/// Name of the timeline holding the trace's `log_time`.
pub const TIME_TIMELINE: &str = "time";
/// At most this many edge tests of one sweep get a standardized edge frame
/// (the one that explains the decision first, then hits, then the nearest
/// misses).
pub const MAX_EDGE_FRAMES: usize = 16;
/// `log_time` values at or above this (2001-09-09 as nanoseconds since the
/// Unix epoch) are shown as timestamps; smaller ones as durations since the
/// recording's start.
pub const TIMESTAMP_THRESHOLD_NANOS: u64 = 1_000_000_000_000_000_000;

/// Bytes of chunks the recording stream holds in its queues before the
/// logger waits for its sink (the SDK's `max_bytes_in_flight`, split over
/// its three channels; its default is 100 MiB, which a sink slower than the
/// logger fills, whatever the trace's length).
pub const MAX_BYTES_IN_FLIGHT: u64 = 16 << 20;

/// A recording stream builder with the project's settings: application id
/// [`APPLICATION_ID`], the given recording id, no recording properties (they
/// would hold the wall-clock start time), at most [`MAX_BYTES_IN_FLIGHT`]
/// in the stream's queues. The logger sends whole chunks, so the batcher's
/// other thresholds do not apply.
pub fn builder(recording_id: &str, name: &str) -> RecordingStreamBuilder {
    RecordingStreamBuilder::new(APPLICATION_ID)
        .recording_id(recording_id.to_string())
        .recording_name(name.to_string())
        .send_properties(false)
        .batcher_config(rerun::log::ChunkBatcherConfig {
            max_bytes_in_flight: MAX_BYTES_IN_FLIGHT,
            ..rerun::log::ChunkBatcherConfig::LOW_LATENCY
        })
}

/// Writing the recording failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RecordError {
    /// The Rerun SDK refused the data.
    #[error("{}", crate::error_text::full_text(.cause))]
    Stream {
        /// The SDK's error.
        cause: RecordingStreamError,
    },
    /// The temporary file that holds the rows until a recording file is
    /// finished (see [`Logger::with_spill`]).
    #[error(
        "{doing} the temporary file of the recording {}: {}",
        recording.display(),
        crate::error_text::full_text(.cause)
    )]
    Spill {
        /// The recording file it is for (it lies in the same directory).
        recording: std::path::PathBuf,
        /// What failed: "creating", "writing", "reading", "emptying".
        doing: &'static str,
        /// The error.
        cause: std::io::Error,
    },
}

impl From<RecordingStreamError> for RecordError {
    fn from(cause: RecordingStreamError) -> RecordError {
        RecordError::Stream { cause }
    }
}

impl From<rerun::log::ChunkError> for RecordError {
    fn from(cause: rerun::log::ChunkError) -> RecordError {
        RecordError::Stream {
            cause: RecordingStreamError::Chunk(cause),
        }
    }
}

impl From<rerun::external::arrow::error::ArrowError> for RecordError {
    fn from(cause: rerun::external::arrow::error::ArrowError) -> RecordError {
        rerun::log::ChunkError::Arrow(cause).into()
    }
}
