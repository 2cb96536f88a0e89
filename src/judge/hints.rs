//! The engine conventions a failing check sees without being told: each
//! failing sweep whose difference one convention of docs/ENGINES.md
//! explains is counted under it, and the report says so and how to
//! declare it. Cheap and per sweep, on failures only; `check
//! --infer-config` is the thorough search (it re-runs the check under each
//! convention) and writes the table.

use std::fmt::Write as _;

use serde::Serialize;

use crate::conventions::NormalRule;
use crate::core::{Kind, Options, SweptPath, initial_contacts};
use crate::replay::SweepResult;
use crate::trace::OutcomeMsg;

use super::agreement::agreement_at;
use super::compare::{Field, FieldDiff, Tolerances, angle_degrees};
use crate::conventions::EngineConventions;

/// Failing sweeps a convention would explain, by convention. A sweep is
/// counted under the first that explains it, in this order.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct ConventionHints {
    /// Answers at `α = 0` where the ball starts within its radius of the
    /// mesh and the rules see no collision: `initial_overlap = "alpha0"`.
    #[serde(rename = "initial_overlap")]
    pub starts_within_radius: u64,
    /// Edge and vertex answers whose only difference is the normal, which
    /// is the contact normal (centre minus contact): `normal = "contact"`.
    pub normal: u64,
    /// Answers within single precision's backward error:
    /// `precision = "f32"`.
    pub precision: u64,
}

impl ConventionHints {
    /// Whether no failing sweep looked like a convention.
    pub fn is_empty(&self) -> bool {
        self.total() == 0
    }

    /// How many failing sweeps looked like one.
    pub fn total(&self) -> u64 {
        self.starts_within_radius + self.normal + self.precision
    }

    /// Counts one failing sweep under the first undeclared convention
    /// that explains `expected` (the engine's answer or the trace's
    /// expectation) against `got` (`got_is_core`: the core's outcome).
    pub(crate) fn observe(
        &mut self,
        result: &SweepResult,
        (expected, got, got_is_core): (&OutcomeMsg, &OutcomeMsg, bool),
        fields: &[FieldDiff],
        tol: &Tolerances,
        declared: &EngineConventions,
    ) {
        let rules = EngineConventions::default();
        if declared.initial_overlap == rules.initial_overlap && starts_in_contact(result, expected)
        {
            self.starts_within_radius += 1;
        } else if declared.normal == NormalRule::Face
            && is_contact_normal(result, expected, fields, tol)
        {
            self.normal += 1;
        } else if declared.budget().is_none() {
            let judged = agreement_at(
                (expected, got, got_is_core),
                result,
                tol,
                Some(crate::conventions::F32_BUDGET),
            );
            if !judged.fails(false) {
                self.precision += 1;
            }
        }
    }

    /// The report's line, naming each convention, its count and its key.
    pub fn line(&self) -> String {
        let mut parts = Vec::new();
        let mut part = |n: u64, what: &str, key: &str| {
            if n > 0 {
                parts.push(format!("{n} {what} ({key})"));
            }
        };
        part(
            self.starts_within_radius,
            "hits at α = 0 where the ball starts within its radius",
            "initial_overlap = \"alpha0\"",
        );
        part(
            self.normal,
            "contact normals at edges and vertices",
            "normal = \"contact\"",
        );
        part(
            self.precision,
            "within single precision",
            "precision = \"f32\"",
        );
        let mut s = String::new();
        let _ = write!(
            s,
            "{} like engine conventions, not bugs: {}; declare them in an [engine] table of sweeptrace.toml (docs/ENGINES.md), or let `check --infer-config` write it",
            crate::numbers::counted(self.total(), "failing sweep looks", "failing sweeps look"),
            parts.join(", ")
        );
        s
    }
}

/// Whether `expected` is a hit at `α = 0` for a ball that starts within
/// its radius `r` of a triangle (any margin), which the rules do not call
/// a collision (they find none, or a later one).
fn starts_in_contact(result: &SweepResult, expected: &OutcomeMsg) -> bool {
    if expected.alpha != 0.0 || expected.kind == Kind::None {
        return false;
    }
    let options = Options {
        margin: 0.0,
        ..result.scene.options
    };
    SweptPath::new(&result.sweep, &options)
        .is_ok_and(|path| !initial_contacts(&result.scene.mesh, &path, &options).is_empty())
}

/// Whether only the normal differs, on an edge or vertex answer, and the
/// answer's normal is the contact normal at its own contact.
fn is_contact_normal(
    result: &SweepResult,
    expected: &OutcomeMsg,
    fields: &[FieldDiff],
    tol: &Tolerances,
) -> bool {
    if !matches!(expected.kind, Kind::Edge | Kind::Vertex)
        || fields.iter().any(|f| f.field != Field::Normal)
    {
        return false;
    }
    let (Some(normal), Some(contact)) = (expected.normal.flatten(), expected.contact.flatten())
    else {
        return false;
    };
    let sweep = &result.sweep;
    let centre = sweep.p0 + (sweep.p1 - sweep.p0) * expected.alpha;
    let towards = centre - nalgebra::Point3::from(contact);
    towards.norm() > 0.0
        && angle_degrees(normal, towards.normalize().into())
            .is_some_and(|a| a <= tol.normal_degrees)
}
