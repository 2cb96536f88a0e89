//! Traces: MCAP files holding a scene, ball sweeps and expected outcomes.
//!
//! The messages are [`SceneMsg`], [`SweepMsg`] and [`OutcomeMsg`] (their
//! JSON Schemas [`SCENE_SCHEMA_JSON`](schemas::SCENE_SCHEMA_JSON), [`SWEEP_SCHEMA_JSON`](schemas::SWEEP_SCHEMA_JSON),
//! [`OUTCOME_SCHEMA_JSON`](schemas::OUTCOME_SCHEMA_JSON)), and the contact queries [`ContactMsg`] with an
//! engine's answers [`ContactsMsg`]. [`TraceReader`] streams a trace from any
//! `Read`, [`TraceWriter`] (or [`write_trace_file`], [`PendingTrace`])
//! records one, in either message [`Encoding`] (JSON or CBOR);
//! [`validate_scene`](validate::validate_scene), [`validate_sweep`](validate::validate_sweep) and [`validate_outcome`](validate::validate_outcome) are the
//! message checks both share, [`ExpectedSource`] the record of who computed
//! the expectations, [`collect_info`](info::collect_info) summarises a trace for
//! `sweeptrace info`, [`prefetch`] moves a reader to a thread of its
//! own, and [`foxglove_output`](sniff::foxglove_output) tells a Foxglove file written by `replay
//! --foxglove` from a trace. The format is described in `docs/TRACE_FORMAT.md`.
//!
//! The entry points are named here; the public submodules hold the rest of
//! the public items, each under its own module's name ([`info`], [`prefetch`](mod@prefetch), [`schemas`], [`sniff`], [`source`], [`validate`]);
//! the other submodules are private.

mod cbor;
mod encoding;
mod error;
pub mod info;
mod lengths;
mod messages;
pub mod prefetch;
mod read;
pub mod schemas;
pub mod sniff;
pub mod source;
pub mod validate;
mod write;

pub(crate) use cbor::Deserializer as CborDeserializer;
pub use encoding::Encoding;
pub use error::{MessageAt, TraceError};
pub use messages::{
    ContactMsg, ContactPointMsg, ContactsMsg, EXPECTED_TOPIC, OUTCOME_SCHEMA, OutcomeMsg,
    SCENE_SCHEMA, SCENE_TOPIC, SWEEP_SCHEMA, SWEEP_TOPIC, SceneMsg, SweepMsg,
};
pub use read::{
    ChannelStats, EventBody, EventHeader, ReadLimits, ReadStats, TraceEvent, TraceReader,
};
pub(crate) use schemas::SCHEMA_ENCODING;
pub use source::ExpectedSource;
pub(crate) use validate::{frame_of_message, parse_message_as};
pub(crate) use validate::{validate_contact, validate_contacts};
pub(crate) use write::library_string;
pub use write::{
    PendingTrace, TraceWriter, default_write_options, write_trace_file,
    write_trace_file_with_encoding,
};
