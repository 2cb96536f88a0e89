//! A replay as an MCAP file for [Foxglove](https://foxglove.dev): Foxglove's
//! own schemas, JSON-encoded, each channel's JSON Schema embedded in its
//! schema record (self-contained, no `$ref`), so Foxglove (and any MCAP
//! reader) needs nothing else to show it.
//!
//! Channels, all in the frame [`FRAME_ID`], every message at the `log_time`
//! of the trace message it comes from:
//!
//! | topic | schema | what |
//! |---|---|---|
//! | [`MESH_TOPIC`] | `foxglove.SceneUpdate` | the scene's mesh (triangle list, edges by class, defects with labels), once per scene |
//! | [`BALLS_TOPIC`] | `foxglove.SceneUpdate` | per sweep, entity `ball/{ball}`: the ball at `p0`, at the contact, at `p1` |
//! | [`SWEEPS_TOPIC`] | `foxglove.SceneUpdate` | per sweep, entity `sweep/{ball}`: the path, and the swept sphere (radius ρ) at the contact |
//! | [`CONTACTS_TOPIC`] | `foxglove.SceneUpdate` | per sweep, entity `contact/{ball}`: the contact point and the reported normal (deleted at a miss) |
//! | [`EXPECTED_TOPIC`] | `foxglove.SceneUpdate` | per sweep, entity `expected/{ball}`: the expected ball, contact and normal where the sweep diverges (deleted elsewhere) |
//! | [`CONTACT_QUERIES_TOPIC`] | `foxglove.SceneUpdate` | per contact query (`/contact`), entity `contact_query/{ball}`: each answered contact and its normal, marked as `check` judges it (agrees, a problem, a ghost contact), the expected normal beside a differing one, the places left out; written only when the trace has queries |
//! | [`GHOSTS_TOPIC`] | `foxglove.SceneUpdate` | per sweep, entity `ghost/{ball}`: where the expected outcome is a ghost contact, a marker at it, the expected and the faces' normals and one label (deleted elsewhere) |
//! | [`DECISIONS_TOPIC`] | `foxglove.Log` | per sweep, the decision in words; WARNING where `check` fails it |
//! | [`CONTACT_DECISIONS_TOPIC`] | `foxglove.Log` | per contact query, its judgement in words (the counts, each problem and ghost contact); WARNING where `check` fails it; written only when the trace has queries |
//! | [`NUMBERS_TOPIC`] | `sweeptrace.SweepNumbers` | per sweep, `α` and the decisive test's numbers, for the Plot panel |
//!
//! Inside (the submodules are private; every public item is named once,
//! here):
//! - `schemas`: the embedded JSON Schemas ([`SCENE_UPDATE_SCHEMA_JSON`],
//!   [`LOG_SCHEMA_JSON`], [`SWEEP_NUMBERS_SCHEMA_JSON`]);
//! - `messages`: the messages as serde types;
//! - `convert`: pure functions from a scene or a sweep's result to each
//!   channel's message (the decision text is
//!   [`crate::judge::decision_line`]'s and `check`'s, shared with the viewer);
//! - `writer`: [`FoxgloveWriter`] over any `Write + Seek`, and
//!   [`FoxgloveFile`], written under a temporary name and renamed.

mod contacts;
mod convert;
mod messages;
mod schemas;
mod writer;

pub use convert::rotation_from_x;
pub use messages::Quaternion;
pub use schemas::{LOG_SCHEMA_JSON, SCENE_UPDATE_SCHEMA_JSON, SWEEP_NUMBERS_SCHEMA_JSON};
pub use writer::{
    FoxgloveCounts, FoxgloveError, FoxgloveFile, FoxgloveOptions, FoxgloveWriter, write_options,
};

/// The fixed frame of every entity (choose it as the 3D panel's display
/// frame).
pub const FRAME_ID: &str = "world";
/// The mesh.
pub const MESH_TOPIC: &str = "/mesh";
/// The balls.
pub const BALLS_TOPIC: &str = "/balls";
/// The sweeps.
pub const SWEEPS_TOPIC: &str = "/sweeps";
/// The contacts and normals.
pub const CONTACTS_TOPIC: &str = "/contacts";
/// The expected outcomes where a sweep diverges.
pub const EXPECTED_TOPIC: &str = "/expected_outcome";
/// The contact queries, judged.
pub const CONTACT_QUERIES_TOPIC: &str = "/contact_queries";
/// The contact queries' judgements (Log).
pub const CONTACT_DECISIONS_TOPIC: &str = "/contact_decisions";
/// The ghost contacts of the expected outcomes.
pub const GHOSTS_TOPIC: &str = "/ghosts";
/// The decisions (Log).
pub const DECISIONS_TOPIC: &str = "/decisions";
/// The numbers (Plot).
pub const NUMBERS_TOPIC: &str = "/numbers";
/// Name of the metadata record (`trace`: the trace's file name, `writer`).
pub const METADATA_NAME: &str = crate::trace::sniff::FOXGLOVE_METADATA_NAME;
