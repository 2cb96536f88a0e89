//! sweeptrace: replay recorded ball trajectories through a swept-sphere vs
//! triangle-mesh collision core and explain, frame by frame, why each
//! collision was or was not found.
//!
//! Start with [`core`] (the collision tests) and [`scenes`] (built-in meshes).

pub mod atomic;
pub mod core;
pub mod numbers;
pub mod regress;
pub mod replay;
pub mod report;
pub mod run;
pub mod sim;
pub mod trace;
#[cfg(feature = "viewer")]
pub mod viz;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
