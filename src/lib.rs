//! sweeptrace: replay recorded ball trajectories through a swept-sphere vs
//! triangle-mesh collision core and explain, frame by frame, why each
//! collision was or was not found.
//!
//! # The public surface
//!
//! - The collision core: [`sweep_mesh`] (fast) and [`sweep_mesh_with`] (every
//!   test's record handed to an [`Observer`]) over a [`Mesh`], with the
//!   [`Sweep`] and [`Options`]; the result is an [`Outcome`].
//! - Traces: [`TraceWriter`] / [`write_trace_file`] to record, [`TraceReader`]
//!   to read (any `Read`), their events [`TraceEvent`].
//! - Replay: [`replay_events`] turns trace events into explained results.
//! - Regression: [`check_file`] / [`check_reader`] compare a trace's
//!   expectations with the core; [`compare()`] is the one comparison rule.
//!
//! Embedding the core and the trace writer needs no command-line crates:
//! build with `default-features = false` (the `viewer` feature adds the
//! Rerun recording, `cli` the binary's dependencies).
//!
//! Start reading at [`core`] (the collision tests), then [`trace`],
//! [`replay`], [`regress`]; [`sim`] holds the built-in scenes and the
//! simulation behind `record`.

#![warn(missing_docs)]

pub mod atomic;
pub mod conform;
pub mod core;
pub mod engine;
pub mod error_text;
pub mod foxglove;
#[doc(hidden)]
pub mod fuzzing;
pub mod junit;
pub mod numbers;
pub mod palette;
pub mod regress;
pub mod replay;
pub mod run;
pub mod sim;
pub mod trace;
#[cfg(feature = "viewer")]
pub mod viz;

pub use crate::core::{
    CollectRecords, Facing, Kind, Mesh, NoObserver, Observer, Options, Outcome, Sweep, sweep_mesh,
    sweep_mesh_with,
};
pub use crate::regress::{Tolerances, check_file, check_reader, compare};
pub use crate::replay::{ReplayOptions, replay_events};
pub use crate::run::RunOutcome;
pub use crate::trace::{TraceEvent, TraceReader, TraceWriter, write_trace_file};

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// docs/LIBRARY.md's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../docs/LIBRARY.md")]
pub struct LibraryDoctests;
