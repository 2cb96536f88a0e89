//! The suite: regression testing over traces, on top of the judge
//! ([`crate::judge`]); a trace's `/expected` outcomes are the test case.
//!
//! - a whole trace checked ([`check_file`]; the traces of a suite found by
//!   [`find_traces`]), and [`render_text`] / [`render_json`] for its report;
//! - ghost contacts (judged by [`crate::replay::judge_ghost`]) counted into
//!   `check`'s report;
//! - check's reports as JUnit XML and GitHub Actions annotations, for CI
//!   systems ([`check_junit`], [`github_annotations`]);
//! - `check`'s suite configuration, the `sweeptrace.toml` files beside the
//!   traces, resolved key by key with where each setting came from
//!   ([`resolve`], [`settings_for`]);
//! - two traces, or one under two configurations ([`diff()`],
//!   [`render_diff_text`]);
//! - a trace's expectations rewritten from the core ([`bless_file`]);
//! - one sweep taken out of its trace, bit-exactly: a minimal trace and a
//!   Rust test ([`find_sweep`], [`ReproCase`]).
//!
//! The submodules are private: every public item is named once, here.

mod bless;
mod check;
mod config;
mod contact_check;
mod diff;
mod discovery;
mod engine_check;
mod ghost_count;
mod infer;
mod infer_conventions;
mod junit;
mod render;
mod report;
mod repro;

pub use bless::{
    BlessEngine, BlessError, BlessOptions, BlessSelection, BlessSummary, bless_bytes, bless_file,
    bless_file_with,
};
pub use check::{
    CheckOptions, DEFAULT_MAX_DETAILS, check_events, check_file, check_reader, frames_around,
};
pub use config::excluded_by;
pub use config::{
    ConfigError, ConfigFile, ConfigFiles, Overrides, Settings, normalize, render_settings_json,
    render_settings_text, resolve, settings_for,
};
pub use contact_check::ContactsReport;
pub use diff::{
    DiffReport, FirstDifference, Side, diff, render_diff_json, render_diff_text, scene_differences,
};
pub use discovery::{Discovered, DiscoveryError, discover, find_traces};
pub use engine_check::{
    RecordedAnswers, check_file_with_engine, check_recorded_answers, record_engine_answers,
};
pub use infer::{Inferred, Spread};
pub use infer_conventions::{Evidence, InferredConventions, Trial, infer_conventions};
pub use junit::{check_junit, github_annotations};
pub use render::{render_json, render_text};
pub use report::{
    Against, Divergences, EngineCheck, Expectations, Fragile, Ghosts, KindChange,
    MAX_LISTED_TUNNELS, MarginFault, Status, TraceReport, TunnelReport, Tunnels, WithinPrecision,
};
pub use repro::{ReproCase, ReproError, TraceSweep, find_sweep};
