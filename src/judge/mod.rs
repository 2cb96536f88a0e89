//! The judge: one engine's answer for one sweep against the core's.
//!
//! - comparison: an outcome against its expectation, field by field
//!   ([`compare()`], [`Tolerances`]);
//! - judgement: the one judgement of a sweep's answer against its
//!   expectation ([`agreement`], [`agreement_of`]): match, tie, or
//!   divergence, excused only when a named perturbation within the
//!   rounding budget reproduces it; shared by `check`, `check --engine`,
//!   `diff`, `conform` and the viewer;
//! - the single-precision sensitivity of an answer ([`Sensitivity`](precision::Sensitivity));
//! - where the conventions an engine declares act on the replay and the
//!   judge ([`crate::conventions::EngineConventions`]);
//! - the decision line of a sweep in words, and whether it diverges
//!   ([`decision_line`], [`divergence()`]; used by the viewer and the
//!   Foxglove output);
//! - why a divergent sweep came out as it did ([`explain_outcome`]), the
//!   known mistakes it matches ([`known_mistake`](mistakes::known_mistake)) and the conventions its
//!   failures hint at ([`ConventionHints`]);
//! - one divergent sweep as every report shows it ([`Divergence`](divergence::Divergence),
//!   [`divergence_details`](divergence::divergence_details), [`render_divergence_as`](divergence::render_divergence_as));
//! - one sweep's inputs, bit-exactly ([`SweepInputs`](inputs::SweepInputs));
//! - an engine's contacts for one contact query against the core's contact
//!   set (`judge_contacts`, its [`ContactVerdict`]).
//!
//! The judge depends on the core, the trace messages and the replay only;
//! running a folder of traces is the suite's job ([`crate::suite`]).
//!
//! The entry points are named here; the public submodules hold the rest of
//! the public items, each under its own module's name ([`divergence`](mod@divergence), [`inputs`], [`mistakes`], [`perturbation`], [`precision`]);
//! the other submodules are private.

mod agreement;
mod compare;
pub mod contact_marks;
mod contact_pairing;
mod contacts;
mod decision;
pub mod divergence;
mod explain;
mod hints;
pub mod inputs;
pub mod mistakes;
pub mod perturbation;
pub mod precision;
mod reference;

pub use agreement::{Agreement, agreement, agreement_of};
pub use compare::{
    ContactAxis, DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE,
    DEFAULT_NORMAL_TOLERANCE_DEGREES, Field, FieldDiff, FieldSet, Tolerances, angle_degrees,
    compare,
};
pub(crate) use contact_pairing::{ContactPairing, PairedContacts};
pub(crate) use contacts::write_contact_verdict;
pub use contacts::{ContactProblem, ContactTolerances, ContactVerdict};
pub(crate) use decision::write_decision_line;
#[cfg(feature = "viewer")]
pub(crate) use decision::write_divergence_line;
pub use decision::{decision_line, divergence};
pub use explain::ExpectedTest;
pub(crate) use explain::{expected_tests, explain_outcome, explained_records};
pub use hints::ConventionHints;
