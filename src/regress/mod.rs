//! Regression testing on top of replay: a trace's `/expected` outcomes are
//! the test case.
//!
//! - comparison: an outcome against its expectation, field by field
//!   ([`compare()`], [`Tolerances`]);
//! - judgement: the one judgement of a sweep's answer against its
//!   expectation ([`agreement`], [`agreement_of`]): match, tie, or
//!   divergence, excused only when a named perturbation within the
//!   rounding budget reproduces it; shared by `check`, `check --engine`,
//!   `diff`, `conform` and the viewer;
//! - the decision line of a sweep in words, and whether it diverges
//!   ([`decision_line`], [`divergence`]; used by the viewer and the
//!   Foxglove output);
//! - why a divergent sweep came out as it did ([`explain_outcome`]);
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
mod compare;
mod config;
mod conventions;
mod decision;
mod diff;
mod discovery;
mod engine_check;
mod explain;
mod ghost_count;
mod hints;
mod infer;
mod infer_conventions;
mod judge;
mod junit;
mod mistakes;
mod precision;
mod render;
mod report;
mod repro;

pub use bless::{
    BlessEngine, BlessError, BlessOptions, BlessSelection, BlessSummary, bless_bytes, bless_file,
    bless_file_with,
};
pub(crate) use check::divergence_details;
pub use check::{
    CheckOptions, DEFAULT_MAX_DETAILS, check_events, check_file, check_reader, frames_around,
};
pub use compare::{
    DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE, DEFAULT_NORMAL_TOLERANCE_DEGREES, Field,
    FieldDiff, FieldSet, TieRule, Tolerances, angle_degrees, compare,
};
pub use config::excluded_by;
pub use config::{
    ConfigError, ConfigFile, EngineOverrides, EngineSettings, Overrides, Setting, Settings, Source,
    normalize, render_settings_json, render_settings_text, resolve, settings_for,
};
pub use conventions::{EngineConventions, FacingRule, MarginRule};
pub(crate) use decision::write_decision_line;
#[cfg(feature = "viewer")]
pub(crate) use decision::write_divergence_line;
pub use decision::{decision_line, divergence};
pub use diff::{
    DiffReport, FirstDifference, Side, diff, render_diff_json, render_diff_text, scene_differences,
};
pub use discovery::{DiscoveryError, find_traces, foxglove_output};
pub use engine_check::check_file_with_engine;
pub use explain::ExpectedTest;
pub(crate) use explain::{expected_tests, explain_outcome, explained_records};
pub use hints::ConventionHints;
pub use infer::{Inferred, Spread};
pub use infer_conventions::{Evidence, InferredConventions, Trial, infer_conventions};
pub use judge::{Agreement, Perturbation, Reproduced, agreement, agreement_of};
pub use junit::{check_junit, github_annotations};
pub use mistakes::{KNOWN_MISTAKES, Mistake, known_mistake};
pub use precision::{F32_OPERATIONS, F32_UNIT, Precision, Sensitivity};
pub use render::{Sides, render_divergence, render_divergence_as, render_json, render_text};
pub(crate) use render::{divergence_line, values_text};
pub use report::{
    Against, Divergence, Divergences, EngineCheck, Expectations, Fragile, Ghosts, KindChange,
    MAX_LISTED_TUNNELS, Status, TraceReport, TunnelReport, Tunnels, WithinPrecision,
};
pub use repro::{HexInputs, ReproCase, ReproError, SweepInputs, TraceSweep, find_sweep};
