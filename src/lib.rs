//! sweeptrace: replay recorded ball trajectories through a swept-sphere vs
//! triangle-mesh collision core and explain, frame by frame, why each
//! collision was or was not found.
//!
//! # Write a trace, check it, read it back
//!
//! An engine records its scene, its sweeps and the outcomes it computed
//! (its *expectations*); `check` (here [`check_reader`]) replays the sweeps
//! through the core and judges each expectation:
//!
//! ```
//! use sweeptrace::{
//!     CheckOptions, EventBody, Facing, Kind, OutcomeMsg, SceneMsg, Status, SweepMsg,
//!     TraceReader, TraceWriter, check_reader,
//! };
//!
//! let scene = SceneMsg {
//!     name: Some("triangle".into()),
//!     vertices: vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
//!     triangles: vec![[0, 1, 2]],
//!     margin: 0.0,
//!     facing: Facing::NonStrict,
//! };
//! let sweep = SweepMsg { frame: 0, ball: 0, radius: 0.5, p0: [1.0, 1.0, 3.0], p1: [1.0, 1.0, -3.0] };
//! // The engine's answer: a face hit at α = 5/12 on triangle 0 (fields left
//! // unset, such as the contact, are not compared).
//! let answer = OutcomeMsg::hit(0, 0, 5.0 / 12.0, Kind::Face).triangle(0).normal([0.0, 0.0, 1.0]);
//!
//! let mut writer = TraceWriter::new(std::io::Cursor::new(Vec::new()))?;
//! writer.scene(0, &scene)?;
//! writer.sweep(1, &sweep)?;
//! writer.expected(2, &answer)?;
//! let bytes = writer.finish()?.into_inner();
//!
//! let report = check_reader(bytes.as_slice(), "example.mcap", &CheckOptions::default());
//! assert_eq!(report.status(), Status::Ok);
//!
//! let mut sweeps = 0;
//! for event in TraceReader::new(bytes.as_slice(), "example.mcap") {
//!     if let EventBody::Sweep(sweep) = event?.body {
//!         assert_eq!(sweep.radius, 0.5);
//!         sweeps += 1;
//!     }
//! }
//! assert_eq!(sweeps, 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # The public surface
//!
//! - The collision core: [`sweep_mesh`] (fast) and [`sweep_mesh_with`] (every
//!   test's record handed to an [`Observer`]) over a [`Mesh`], with the
//!   [`Sweep`] and [`Options`]; the result is an [`Outcome`]; [`sweep_ties`]
//!   adds its tie set.
//! - Traces: the messages [`SceneMsg`], [`SweepMsg`], [`OutcomeMsg`];
//!   [`TraceWriter`] / [`write_trace_file`] to record (in JSON or CBOR,
//!   the [`Encoding`]), [`TraceReader`] to read (any `Read`, either
//!   encoding), their events [`TraceEvent`] and errors [`TraceError`].
//! - Replay: [`replay_events`] turns trace events into explained results.
//! - Regression: [`check_file`] / [`check_reader`] judge a trace's
//!   expectations with the core ([`CheckOptions`] in, a [`TraceReport`]
//!   out); [`agreement`] is the one judgement of an answer, [`compare()`]
//!   the field-by-field comparison under it.
//!
//! Embedding the core and the trace writer needs no command-line crates:
//! build with `default-features = false` (the `viewer` feature adds the
//! Rerun recording, `cli` the binary's dependencies).
//!
//! Start reading at [`core`] (the collision tests), then [`trace`],
//! [`replay`], [`judge`], [`suite`]; [`sim`] holds the built-in scenes and the
//! simulation behind `record`.

#![warn(missing_docs)]

pub mod atomic;
pub mod conform;
pub mod conventions;
pub mod core;
pub mod engine;
pub mod error_text;
pub mod foxglove;
pub mod fuzzing;
pub mod judge;
pub mod junit;
pub mod numbers;
pub(crate) mod palette;
pub mod replay;
pub mod sim;
pub mod suite;
pub mod trace;
#[cfg(feature = "viewer")]
pub mod viz;

pub use crate::core::record::{CollectRecords, NoObserver, Observer};
pub use crate::core::topology::{Defect, DefectKind, EdgeClass, EdgeCounts, Topology};
pub use crate::core::{
    Facing, Feature, InitialOverlap, Kind, Mesh, MeshError, Options, Outcome, Sides, Sweep,
    SweepError, SweepHit, Tie, sweep_mesh, sweep_mesh_with, sweep_ties,
};
pub use crate::judge::{Agreement, Tolerances, agreement, compare};
pub use crate::replay::{ReplayOptions, replay_events};
pub use crate::suite::{CheckOptions, Status, TraceReport, check_file, check_reader};
pub use crate::trace::{
    Encoding, EventBody, ExpectedSource, OutcomeMsg, SceneMsg, SweepMsg, TraceError, TraceEvent,
    TraceReader, TraceWriter, write_trace_file, write_trace_file_with_encoding,
};

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// docs/LIBRARY.md's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../docs/LIBRARY.md")]
pub struct LibraryDoctests;
