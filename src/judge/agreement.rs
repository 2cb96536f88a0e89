//! The one judgement of an answer against an expectation for one sweep
//! ([`agreement`], whose documentation says how it judges).

use crate::core::Fragility;
use crate::replay::SweepResult;
use crate::trace::OutcomeMsg;

use super::compare::{Field, FieldDiff, NOT_A_UNIT_VECTOR, Tolerances, compare, differing};
use super::perturbation::{Reproduced, Rounding, reproduce};
use super::precision::Sensitivity;
use super::reference::{Decision, MemberBounds};
use crate::conventions::TieRule;

/// How an answer stands against an expectation: the one judgement.
#[derive(Clone, Debug, PartialEq)]
pub enum Agreement {
    /// Every field the expectation holds matches within the tolerances.
    Match,
    /// Both sides are answers the core's decision accepts: its primary or
    /// another member of its tie set, each with that member's own contact
    /// (a ball touching two faces at once touches them at two points; α
    /// and the averaged normal are the decision's). An equally valid
    /// answer to the rules' tie order, reached by different rounding: not
    /// a divergence (except in `conform`, where the cases are exact and the
    /// rule's choice is the only right answer).
    Tie,
    /// Fields differ, by no more than single-precision arithmetic explains
    /// (declared `precision = "f32"`): the continuous fields within their
    /// backward-error bound ([`super::precision::Sensitivity`]), and any other
    /// difference given by the core under a perturbation of the inputs
    /// within the same budget. Not a failure, except with `strict`.
    Precision {
        /// The fields that differ beyond the fixed tolerances.
        fields: Vec<FieldDiff>,
        /// The backward error, in units of `u₃₂ · S`: the smallest move of
        /// the inputs that explains the difference (at most the budget,
        /// [`crate::conventions::EngineConventions::budget`]).
        backward_error: f64,
        /// When a discrete field differs: the perturbation under which the
        /// core gives each side's answer.
        reproduced: Option<Reproduced>,
    },
    /// Fields differ.
    Diverges {
        /// The fields that differ (when the expectation names a member of
        /// the tie set and the other side is the core's outcome: those that
        /// differ from that member).
        fields: Vec<FieldDiff>,
        /// Why the core's decision is fragile; empty when robust.
        fragile: Fragility,
        /// When the decision is fragile and rounding explains the
        /// divergence: the perturbation of the inputs under which the core
        /// gives each side's answer. `None`: no perturbation does (or the
        /// decision is robust), and the divergence fails.
        reproduced: Option<Reproduced>,
    },
}

impl Agreement {
    /// Whether the sweep diverges (excused or not).
    pub fn is_divergent(&self) -> bool {
        matches!(
            self,
            Agreement::Diverges { .. } | Agreement::Precision { .. }
        )
    }

    /// Whether the sweep diverges only as rounding could have made it: a
    /// fragile decision and a [`Reproduced`] answer.
    pub fn is_excused(&self) -> bool {
        matches!(
            self,
            Agreement::Diverges {
                reproduced: Some(_),
                ..
            } | Agreement::Precision { .. }
        )
    }

    /// Whether the sweep fails a check: a divergence that no perturbation
    /// reproduces, or any divergence when `strict`.
    pub fn fails(&self, strict: bool) -> bool {
        match self {
            Agreement::Diverges { reproduced, .. } => strict || reproduced.is_none(),
            Agreement::Precision { .. } => strict,
            Agreement::Match | Agreement::Tie => false,
        }
    }
}

/// Judges the expectation against the core's outcome of `result` (`check`,
/// `diff`, `conform`, the viewer).
///
/// Three outcomes ([`Agreement`]):
/// - **match**: [`compare`] finds no field that differs;
/// - **tie**: each side is an answer the core's decision accepts: its
///   primary, or another member of its tie set with that member's own
///   kind, triangle, feature and contact (α and the averaged normal are the
///   decision's);
/// - **divergence**, which is *excused as fragile* only when the core's
///   decision is fragile **and** a named perturbation of the sweep's inputs
///   within the rounding budget the fragility reasons are defined by makes
///   the core give each side's answer ([`Reproduced`]). Any other
///   divergence fails, whatever the decision's fragility: a fragile
///   decision does not excuse an answer no rounding gives.
///
/// The perturbations ([`super::perturbation::Perturbation`]) move one input at a time by
/// `k · u`, where `u = ε · S` is the sweep's rounding unit (`S` the scale of
/// [`crate::core::SweptPath`], ε the machine epsilon) and `k` runs over 1, 2⁴, 2⁸, 2¹²
/// and 2¹⁶ = [`crate::core::options::FRAGILE_ULPS`] (the fragility band), both signs: each
/// coordinate of `p0`, of `p1`, of both together (the path moved, which is
/// the mesh moved the other way), and the radius. The first one that
/// reproduces an answer, smallest first, is the one reported.
///
/// The judgement is under the conventions `result` was computed under
/// ([`crate::replay::SceneState::conventions`]): at their precision and
/// accuracy (the backward-error budget), with their tie rule.
pub fn agreement(expected: &OutcomeMsg, result: &SweepResult, tol: &Tolerances) -> Agreement {
    let budget = result.scene.conventions.budget();
    judge(expected, &result.outcome_msg(), true, result, tol, budget)
}

/// Judges `expected` against another answer `got` to the same sweep (an
/// engine's), with the core's decision on `result` as the referee: a tie
/// when both are answers the decision accepts; a divergence excused only
/// when a perturbation gives each side's answer.
pub fn agreement_of(
    expected: &OutcomeMsg,
    got: &OutcomeMsg,
    result: &SweepResult,
    tol: &Tolerances,
) -> Agreement {
    let budget = result.scene.conventions.budget();
    judge(expected, got, false, result, tol, budget)
}

/// The judgement of [`agreement`] (`got` the core's own outcome,
/// `got_is_core`) or [`agreement_of`] with the backward-error `budget`
/// (units of `u₃₂ · S`; `None`: the fixed tolerances) rather than the
/// declared one: what a check under the rules asks of single precision
/// ([`super::ConventionHints`]).
pub(crate) fn agreement_at(
    (expected, got, got_is_core): (&OutcomeMsg, &OutcomeMsg, bool),
    result: &SweepResult,
    tol: &Tolerances,
    budget: Option<f64>,
) -> Agreement {
    judge(expected, got, got_is_core, result, tol, budget)
}

fn judge(
    expected: &OutcomeMsg,
    got: &OutcomeMsg,
    got_is_core: bool,
    result: &SweepResult,
    tol: &Tolerances,
    budget: Option<f64>,
) -> Agreement {
    let fields = compare(expected, got, tol);
    if fields.is_empty() {
        return Agreement::Match;
    }
    let fragile = result.outcome.fragile;
    // By backward error (single precision, or a declared accuracy): the
    // tolerances widened to this sweep's bound at the budget (computed
    // only here, for a sweep that differs).
    let sensitivity =
        budget.and_then(|_| Sensitivity::of(result).map(|s| s.observing(expected, got, tol)));
    let widened = sensitivity.zip(budget).map(|(s, c)| s.widen(tol, c));
    let fixed = tol;
    let tol_judged = widened.as_ref().unwrap_or(tol);
    if let Some(s) = &sensitivity
        && differing(expected, got, tol_judged).is_empty()
    {
        return Agreement::Precision {
            backward_error: s.backward_error(&fields, expected, got),
            fields,
            reproduced: None,
        };
    }
    // Against the core's own outcome, a difference in α or the normal alone
    // cannot be another tie member (the members share the decision's α and
    // averaged normal): no need to run the core again, unless rounding may
    // explain it.
    let values_only = fields
        .iter()
        .all(|f| matches!(f.field, Field::Alpha | Field::Normal));
    if got_is_core
        && values_only
        && fragile.is_robust()
        && budget.is_none()
        && result.scene.conventions.ties == TieRule::Rule
    {
        return Agreement::Diverges {
            fields,
            fragile,
            reproduced: None,
        };
    }
    let Some(decision) = Decision::of(&result.scene, &result.sweep) else {
        return Agreement::Diverges {
            fields,
            fragile,
            reproduced: None,
        };
    };
    let tol = tol_judged;
    // By backward error each tie member is held to its own bound.
    let bounds = budget.map(|budget| MemberBounds {
        fixed,
        budget,
        expected,
        got,
    });
    let on_expected = decision.disagreement(expected, tol, bounds.as_ref());
    let got_refused = !got_is_core && !decision.accepts(got, tol, bounds.as_ref());
    if on_expected.is_none() && !got_refused {
        return Agreement::Tie;
    }
    // Against the core's own outcome, the fields that differ are those
    // from the member of the tie set the expectation names.
    let fields = match (got_is_core, on_expected.as_ref()) {
        (true, Some(named)) => named.clone(),
        _ => fields,
    };
    if let Some(budget) = budget {
        // By backward error: any decision is as fragile as the budget; a
        // perturbation spends part of it, and the rest is what the
        // continuous fields may still differ by.
        let rounding = Rounding::F32 {
            fixed,
            sensitivity: sensitivity.as_ref(),
            budget,
        };
        return match reproduce(
            expected,
            on_expected.is_some(),
            got,
            got_refused,
            result,
            rounding,
        ) {
            Some((r, backward_error)) => Agreement::Precision {
                backward_error,
                fields,
                reproduced: Some(r),
            },
            None => Agreement::Diverges {
                // Against the core's own outcome the fields are already
                // those beyond the bound, from the member of the tie set
                // the expectation names (or the primary).
                fields: if got_is_core && on_expected.is_some() {
                    said_beyond_the_bound(fields)
                } else {
                    beyond_f32_bound(expected, got, tol, fields)
                },
                fragile,
                reproduced: None,
            },
        };
    }
    let reproduced = if fragile.is_robust() {
        None
    } else {
        reproduce(
            expected,
            on_expected.is_some(),
            got,
            got_refused,
            result,
            Rounding::F64(tol),
        )
        .map(|(reproduced, _)| reproduced)
    };
    Agreement::Diverges {
        fields,
        fragile,
        reproduced,
    }
}

/// The fields of a divergence at single precision: those beyond this
/// sweep's backward-error bound (`widened`), each continuous one saying
/// so; the fixed tolerances' `fields` when every difference is discrete.
fn beyond_f32_bound(
    expected: &OutcomeMsg,
    got: &OutcomeMsg,
    widened: &Tolerances,
    fields: Vec<FieldDiff>,
) -> Vec<FieldDiff> {
    let beyond = compare(expected, got, widened);
    if beyond.is_empty() {
        return fields;
    }
    said_beyond_the_bound(beyond)
}

/// `fields`, each continuous one saying that it is beyond this sweep's
/// backward-error bound.
fn said_beyond_the_bound(mut beyond: Vec<FieldDiff>) -> Vec<FieldDiff> {
    for f in &mut beyond {
        if let Some(detail) = f.detail.as_mut()
            && matches!(f.field, Field::Alpha | Field::Normal | Field::Contact)
            && !detail.contains(NOT_A_UNIT_VECTOR)
        {
            detail.push_str(" (beyond the f32 backward-error bound of this sweep)");
        }
    }
    beyond
}
