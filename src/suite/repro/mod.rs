//! Reproducing one sweep outside its trace: its inputs bit-exactly
//! ([`SweepInputs`](crate::judge::inputs::SweepInputs)), the sweep found in a trace ([`find_sweep`]), and a
//! minimal case ([`ReproCase`]): that sweep, the triangles within its
//! reach, its expectation, written as a trace of its own and as a Rust
//! test against the public API.
//!
//! Numbers are written so that they read back to the same bits: Rust's
//! `{}`/`{:?}` of an `f64` is the shortest decimal that round-trips, and
//! [`crate::numbers::hex_float`] writes the exact binary value.

mod case;
mod find;
mod rust_test;

pub use case::ReproCase;
pub use find::{ReproError, TraceSweep, find_sweep};
