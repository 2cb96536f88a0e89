//! Traces: MCAP files holding a scene, ball sweeps and expected outcomes.
//!
//! The messages are [`SceneMsg`], [`SweepMsg`] and [`OutcomeMsg`] (their
//! JSON Schemas [`SCENE_SCHEMA_JSON`], [`SWEEP_SCHEMA_JSON`],
//! [`OUTCOME_SCHEMA_JSON`]), and the contact queries [`ContactMsg`] with an
//! engine's answers [`ContactsMsg`]. [`TraceReader`] streams a trace from any
//! `Read`, [`TraceWriter`] (or [`write_trace_file`], [`PendingTrace`])
//! records one, in either message [`Encoding`] (JSON or CBOR);
//! [`validate_scene`], [`validate_sweep`] and [`validate_outcome`] are the
//! message checks both share, [`ExpectedSource`] the record of who computed
//! the expectations, [`collect_info`] summarises a trace for
//! `sweeptrace info`, [`prefetch`] moves a reader to a thread of its
//! own, and [`foxglove_output`] tells a Foxglove file written by `replay
//! --foxglove` from a trace. The format is described in `docs/TRACE_FORMAT.md`.
//!
//! The submodules are private: every public item is named once, here.

mod cbor;
mod encoding;
mod error;
mod info;
mod lengths;
mod messages;
mod prefetch;
mod read;
mod schemas;
mod sniff;
mod source;
mod validate;
mod write;

pub(crate) use cbor::Deserializer as CborDeserializer;
pub use encoding::Encoding;
pub use error::{MessageAt, TraceError};
pub use info::{SceneSummary, TraceInfo, collect_info, render_info_json, render_info_text};
pub use messages::{
    ContactMsg, ContactPointMsg, ContactsMsg, EXPECTED_TOPIC, OUTCOME_SCHEMA, OutcomeMsg,
    SCENE_SCHEMA, SCENE_TOPIC, SWEEP_SCHEMA, SWEEP_TOPIC, SceneMsg, SweepMsg,
};
pub use prefetch::{DEFAULT_PREFETCH_CHUNK, DEFAULT_PREFETCH_DEPTH, Prefetched, prefetch};
pub use read::{
    ChannelStats, EventBody, EventHeader, ReadLimits, ReadStats, TraceEvent, TraceReader,
};
pub(crate) use schemas::SCHEMA_ENCODING;
pub use schemas::{OUTCOME_SCHEMA_JSON, SCENE_SCHEMA_JSON, SWEEP_SCHEMA_JSON};
pub use sniff::{FOXGLOVE_METADATA_NAME, foxglove_output};
pub use source::{
    EXPECTED_SOURCE_METADATA, ExpectedSource, MAX_NAME_BYTES, MAX_SETTING_VALUE_BYTES,
    MAX_SETTINGS, sweeptrace_source,
};
pub use validate::{
    FieldProblem, parse_message, validate_outcome, validate_scene, validate_sweep,
    validate_triangle,
};
pub(crate) use validate::{frame_of_message, parse_message_as};
pub(crate) use validate::{validate_contact, validate_contacts};
pub(crate) use write::library_string;
pub use write::{
    PendingTrace, TraceWriter, default_write_options, write_trace_file,
    write_trace_file_with_encoding,
};
