//! Regression testing on top of replay: a trace's `/expected` outcomes are
//! the test case.
//!
//! - [`compare`](mod@compare): an outcome against its expectation, field
//!   by field ([`compare()`], [`Tolerances`]);
//! - [`judge`](mod@judge): the one judgement of a sweep's answer against its
//!   expectation ([`agreement`], [`agreement_of`]): match, tie, or
//!   divergence, excused only when a named perturbation within the
//!   rounding budget reproduces it; shared by `check`, `check --engine`,
//!   `diff`, `conform` and the viewer;
//! - [`decision`](mod@decision): the decision line of a sweep in words, and
//!   whether it diverges (used by the viewer and the Foxglove output);
//! - [`explain`](mod@explain): why a divergent sweep came out as it did;
//! - [`check`](mod@check): a whole trace checked ([`check_file`]; the
//!   traces of a suite found by [`find_traces`]), and
//!   [`render_text`] / [`render_json`] for its report;
//! - [`ghost`](mod@ghost): ghost contacts, edge or vertex contacts on an
//!   internal flat or concave place whose normal leans off the faces
//!   ([`judge_ghost`]), counted into `check`'s report beside it;
//! - [`junit`](mod@junit): check's reports as JUnit XML and GitHub Actions
//!   annotations, for CI systems;
//! - [`config`]: `check`'s suite configuration, the `sweeptrace.toml`
//!   files beside the traces, resolved key by key with where each setting
//!   came from ([`config::resolve`]);
//! - [`diff`](mod@diff): two traces, or one under two configurations;
//! - [`bless`](mod@bless): a trace's expectations rewritten from the core;
//! - [`repro`]: one sweep taken out of its trace, bit-exactly: a minimal
//!   trace and a Rust test.

pub mod bless;
pub mod check;
pub mod compare;
pub mod config;
pub mod decision;
pub mod diff;
mod discovery;
pub mod engine_check;
pub mod explain;
pub mod ghost;
mod ghost_count;
pub mod infer;
pub mod judge;
pub mod junit;
mod render;
pub mod repro;

pub use bless::{BlessError, BlessSummary, bless_bytes, bless_file};
pub use check::{
    CheckOptions, DEFAULT_MAX_DETAILS, Divergence, Judged, KindChange, MAX_LISTED_TUNNELS, Status,
    TraceReport, TunnelReport, check_events, check_events_judged, check_file, check_reader,
    divergence_details, find_traces, frames_around, judge_against_core,
};
pub use compare::{
    DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE, DEFAULT_NORMAL_TOLERANCE_DEGREES, Field,
    FieldDiff, FieldSet, Tolerances, angle_degrees, compare,
};
pub use diff::{DiffReport, FirstDifference, Side, diff};
pub use engine_check::{
    Against, EngineCheck, check_file_with_engine, judge_answer_against_expected,
};
pub use explain::{ExpectedTest, expected_tests, explain_outcome, explained_records};
pub use ghost::{
    GHOST_DEGREES, GhostContact, GhostJudgement, GhostLine, GhostPlace, ghost_point, judge_ghost,
};
pub use infer::{Inferred, Spread, infer};
pub use judge::{Agreement, Perturbation, Reproduced, agreement, agreement_of, perturbations};
pub use render::{
    Sides, divergence_line, render_divergence, render_divergence_as, render_json, render_text,
    sides_of, value_text, value_text_exact, values_text,
};
pub use repro::{HexInputs, ReproCase, ReproError, SweepInputs, TraceSweep, find_sweep};
