//! The suite: regression testing over traces, on top of the judge
//! ([`crate::judge`]); a trace's `/expected` outcomes are the test case.
//!
//! - a whole trace checked ([`check_file`]; the traces of a suite found by
//!   [`find_traces`](discovery::find_traces)), and [`render_text`] / [`render_json`] for its report;
//! - ghost contacts (judged by [`crate::replay::ghost::judge_ghost`]) counted into
//!   `check`'s report;
//! - check's reports as JUnit XML and GitHub Actions annotations, for CI
//!   systems ([`check_junit`], [`github_annotations`]);
//! - `check`'s suite configuration, the `sweeptrace.toml` files beside the
//!   traces, resolved key by key with where each setting came from
//!   ([`resolve`](config::resolve), [`settings_for`](config::settings_for));
//! - two traces, or one under two configurations ([`diff()`](diff::diff()),
//!   [`render_diff_text`](diff::render_diff_text));
//! - a trace's expectations rewritten from the core ([`bless_file`](bless::bless_file));
//! - one sweep taken out of its trace, bit-exactly: a minimal trace and a
//!   Rust test ([`find_sweep`](repro::find_sweep), [`ReproCase`](repro::ReproCase)).
//!
//! The entry points are named here; the public submodules hold the rest of
//! the public items, each under its own module's name ([`bless`], [`config`], [`diff`](mod@diff), [`discovery`], [`engine_check`], [`infer`], [`infer_conventions`](mod@infer_conventions), [`report`], [`repro`]);
//! the other submodules are private.

pub mod bless;
mod check;
pub mod config;
mod contact_check;
pub mod contact_diff;
pub mod diff;
pub mod discovery;
pub mod engine_check;
mod ghost_count;
pub mod infer;
pub mod infer_conventions;
mod junit;
mod render;
pub mod report;
pub mod repro;

pub use check::{
    CheckOptions, DEFAULT_MAX_DETAILS, check_events, check_file, check_reader, frames_around,
};
pub use contact_check::ContactsReport;
pub use junit::{check_junit, github_annotations};
pub use render::{render_json, render_text};
pub use report::{Status, TraceReport};
