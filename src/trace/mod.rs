//! Traces: MCAP files holding a scene, ball sweeps and expected outcomes.
//!
//! [`read`] streams a trace from any `Read`, [`write`](mod@write) records one,
//! in either message [`encoding`] (JSON, or CBOR through [`cbor`]),
//! [`validate`] holds the message checks both share, [`source`] the record
//! of who computed the expectations, and [`info`] summarises
//! a trace for `sweeptrace info`. The format is described in
//! `docs/TRACE_FORMAT.md`.

pub mod cbor;
pub mod encoding;
pub mod error;
pub mod info;
mod lengths;
pub mod messages;
pub mod prefetch;
pub mod read;
pub mod schemas;
pub mod source;
pub mod validate;
pub mod write;

pub use encoding::Encoding;
pub use error::{MessageAt, TraceError};
pub use read::{ReadLimits, ReadStats, TraceEvent, TraceReader};
pub use source::{EXPECTED_SOURCE_METADATA, ExpectedSource};
pub use write::{PendingTrace, TraceWriter, write_trace_file, write_trace_file_with_encoding};
