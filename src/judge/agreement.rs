//! The one judgement of an answer against an expectation for one sweep
//! ([`agreement`], whose documentation says how it judges).

use std::fmt;

use nalgebra::Point3;

use serde::Serialize;

use crate::core::explain::num;
use crate::core::{
    Broadphase, EdgeRecord, FRAGILE_ULPS, FaceRecord, Feature, Fragility, InitialOverlap, Mesh,
    Observer, Options, Outcome, Sweep, SweepHit, SweptPath, TestRecord, Tie, VertexRecord,
    initial_contacts, sweep_mesh_with,
};
use crate::replay::{SceneState, SweepResult};
use crate::trace::OutcomeMsg;

use super::compare::Precision;
use super::compare::{Field, FieldDiff, NOT_A_UNIT_VECTOR, TieRule, Tolerances, compare};
use super::precision::{F32_OPERATIONS, F32_UNIT, Sensitivity};

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
    /// backward-error bound ([`super::Sensitivity`]), and any other
    /// difference given by the core under a perturbation of the inputs
    /// within the same budget. Not a failure, except with `strict`.
    Precision {
        /// The fields that differ beyond the fixed tolerances.
        fields: Vec<FieldDiff>,
        /// The backward error, in units of `u₃₂ · S`: the smallest move of
        /// the inputs that explains the difference (at most
        /// [`F32_OPERATIONS`]).
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

/// One change of one input of a sweep, within its rounding budget.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Perturbation {
    /// What moved: `p0.x` … `p1.z`, `path.x` … `path.z` (both ends of the
    /// path by the same amount), or `radius`.
    pub input: &'static str,
    /// By how many rounding units `u` (signed).
    pub units: f64,
    /// By how much, in the scene's length unit (`units · u`, signed).
    pub offset: f64,
}

impl Perturbation {
    /// Applies the perturbation to `sweep`.
    fn apply(&self, sweep: &Sweep) -> Sweep {
        let mut s = *sweep;
        let axis = |name: &str| match name.as_bytes().last() {
            Some(b'x') => 0,
            Some(b'y') => 1,
            _ => 2,
        };
        match self.input.split_once('.') {
            Some(("p0", a)) => s.p0[axis(a)] += self.offset,
            Some(("p1", a)) => s.p1[axis(a)] += self.offset,
            Some((_, a)) => {
                s.p0[axis(a)] += self.offset;
                s.p1[axis(a)] += self.offset;
            }
            None => s.radius += self.offset,
        }
        s
    }
}

/// `p1.z lower by 2^12 u`, `the radius larger by 1 u`, `the whole path
/// (p0 and p1) moved by -2^4 u in y` (`u`: [`Reproduced::rounding_unit`]).
impl fmt::Display for Perturbation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let exponent = self.units.abs().log2().round();
        let size = if exponent == 0.0 {
            "1 u".to_string()
        } else {
            format!("2^{exponent} u")
        };
        let up = self.units > 0.0;
        match self.input.strip_prefix("path.") {
            Some(axis) => write!(
                f,
                "the whole path (p0 and p1) moved by {}{size} in {axis}",
                if up { "+" } else { "-" }
            ),
            None if self.input == "radius" => write!(
                f,
                "the radius {} by {size}",
                if up { "larger" } else { "smaller" }
            ),
            None => write!(
                f,
                "{} {} by {size}",
                self.input,
                if up { "higher" } else { "lower" }
            ),
        }
    }
}

/// How the two sides of a fragile divergence are each an answer of the
/// core: `None` for the core's own decision (its primary or a member of
/// its tie set), or the perturbation under which the core gives it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Reproduced {
    /// The expectation's side.
    pub expected: Option<Perturbation>,
    /// The side compared with it (the core's outcome, or an engine's answer).
    pub got: Option<Perturbation>,
    /// The sweep's rounding unit: `u = ε · S`, or `u₃₂ · S` at single
    /// precision.
    pub rounding_unit: f64,
    /// The arithmetic the rounding unit is of (only in the JSON when not
    /// `f64`).
    #[serde(skip_serializing_if = "Precision::is_f64")]
    pub precision: Precision,
}

impl Reproduced {
    /// In words, naming the two sides `expected` and `got` (`the engine's
    /// answer is what the core gives with p1.z lower by 2^12 u (u = …)`).
    pub fn text(&self, expected: &str, got: &str) -> String {
        let one = |side: &str, p: &Option<Perturbation>| match p {
            Some(p) => format!("{side} is what the core gives with {p}"),
            None => format!("{side} is the core's own decision"),
        };
        let mut s = match (&self.expected, &self.got) {
            (Some(_), None) => one(expected, &self.expected),
            (None, Some(_)) => one(got, &self.got),
            _ => format!(
                "{}, and {}",
                one(expected, &self.expected),
                one(got, &self.got)
            ),
        };
        let unit = match self.precision {
            Precision::F64 => "the sweep's rounding unit",
            Precision::F32 => "single precision's unit u₃₂ · S",
        };
        s.push_str(&format!(" (u = {}, {unit})", num(self.rounding_unit)));
        s
    }

    /// The larger of the two perturbations, in units of `u`.
    pub fn units(&self) -> f64 {
        [self.expected, self.got]
            .iter()
            .flatten()
            .map(|p| p.units.abs())
            .fold(0.0, f64::max)
    }
}

/// The magnitudes of the perturbations, in rounding units: 1, 2⁴, 2⁸, 2¹²,
/// 2¹⁶ (the fragility band, [`FRAGILE_ULPS`]).
const PERTURBATION_UNITS: [f64; 5] = [1.0, 16.0, 256.0, 4096.0, FRAGILE_ULPS];

/// The inputs that are perturbed, one at a time.
const PERTURBED_INPUTS: [&str; 10] = [
    "p0.x", "p0.y", "p0.z", "p1.x", "p1.y", "p1.z", "path.x", "path.y", "path.z", "radius",
];

/// The magnitudes of the perturbations at single precision, in units of
/// `u₃₂ · S`: 1, 2, 4, 8 and [`F32_OPERATIONS`] (the backward-error budget).
const F32_PERTURBATION_UNITS: [f64; 5] = [1.0, 2.0, 4.0, 8.0, F32_OPERATIONS];

/// The perturbations of a sweep whose rounding unit is `u`, smallest first
/// (each magnitude over every input, lower before higher).
#[cfg(test)]
pub fn perturbations(u: f64) -> impl Iterator<Item = Perturbation> {
    perturbations_of(u, &PERTURBATION_UNITS)
}

/// The perturbations by `units` times `u`, smallest first.
fn perturbations_of(u: f64, units: &[f64]) -> impl Iterator<Item = Perturbation> + '_ {
    units.iter().copied().flat_map(move |k| {
        PERTURBED_INPUTS.into_iter().flat_map(move |input| {
            [-k, k].into_iter().map(move |units| Perturbation {
                input,
                units,
                offset: units * u,
            })
        })
    })
}

/// The sweep's rounding unit `u = ε · S` against `mesh` (the scale the
/// core's tests use); `None` when the sweep is invalid.
fn rounding_unit(mesh: &Mesh, sweep: &Sweep, options: &Options) -> Option<f64> {
    let (lo, hi) = mesh.bounds();
    Some(
        SweptPath::new(sweep, options)
            .ok()?
            .with_mesh_scale(&lo, &hi)
            .rounding(),
    )
}

/// Keeps the records of the tests that hit.
#[derive(Default)]
struct Hits(Vec<TestRecord>);

impl Observer for Hits {
    // Triangles whose every test ends back-facing hit nothing.
    const WANTS_RECORDS: bool = false;
    fn face(&mut self, r: &FaceRecord) {
        if r.alpha().is_some() {
            self.0.push(TestRecord::Face(*r));
        }
    }
    fn edge(&mut self, r: &EdgeRecord) {
        if r.alpha().is_some() {
            self.0.push(TestRecord::Edge(*r));
        }
    }
    fn vertex(&mut self, r: &VertexRecord) {
        if r.alpha().is_some() {
            self.0.push(TestRecord::Vertex(*r));
        }
    }
}

/// The core's decision on one sweep under the scene's options and
/// conventions: its outcome and the hits that can be members of its tie
/// set.
struct Decision<'a> {
    scene: &'a SceneState,
    sweep: Sweep,
    outcome: Outcome,
    hits: Vec<TestRecord>,
    /// Under `initial_overlap = alpha0`, when the ball starts in contact:
    /// every initial contact, all tied at `α = 0`.
    initial: Vec<SweepHit>,
}

impl<'a> Decision<'a> {
    fn of(scene: &'a SceneState, sweep: &Sweep) -> Option<Decision<'a>> {
        let mut hits = Hits::default();
        let outcome = sweep_mesh_with(
            &scene.mesh,
            sweep,
            &scene.options,
            Broadphase::Bvh,
            &mut hits,
        )
        .ok()?;
        let initial = if scene.options.initial_overlap == InitialOverlap::Alpha0
            && outcome.hit.is_some_and(|h| h.alpha == 0.0)
        {
            let (lo, hi) = scene.mesh.bounds();
            let path = SweptPath::new(sweep, &scene.options)
                .ok()?
                .with_mesh_scale(&lo, &hi);
            initial_contacts(
                &scene.mesh,
                &path,
                scene.options.facing,
                scene.options.sides,
            )
            .into_iter()
            .map(|(h, _)| h)
            .collect()
        } else {
            Vec::new()
        };
        Some(Decision {
            scene,
            sweep: *sweep,
            outcome: scene.normals.apply(sweep, outcome),
            hits: hits.0,
            initial,
        })
    }

    /// The normal a tie member reports under [`TieRule::Any`]: its own
    /// (its triangle's face normal, or its contact normal where the
    /// scene's normal rule gives that). `back`: the member was hit on its
    /// triangle's back (`sides = two`), whose face normal is `-n`.
    fn member_normal(&self, tie: &Tie, contact: &Point3<f64>, back: bool) -> Option<[f64; 3]> {
        let front = self.scene.mesh.triangle_by_index(tie.triangle)?.normal;
        let face = if back { -front } else { front };
        let alpha = self.outcome.hit.map_or(tie.alpha, |h| h.alpha);
        let n =
            self.scene
                .normals
                .normal(&self.sweep, alpha, tie.triangle, tie.feature, contact, face);
        Some([n.x, n.y, n.z])
    }

    /// `None` when the decision accepts `answer`: it matches the primary,
    /// or another member of the tie set with that member's own contact.
    /// Otherwise the fields that differ: from the first member the answer
    /// names, or from the primary.
    fn disagreement(&self, answer: &OutcomeMsg, tol: &Tolerances) -> Option<Vec<FieldDiff>> {
        let primary = OutcomeMsg::from_outcome(answer.frame, answer.ball, &self.outcome);
        let differ = compare(answer, &primary, tol);
        if differ.is_empty() {
            return None;
        }
        let mut named: Option<Vec<FieldDiff>> = None;
        for r in &self.hits {
            let Some(tie) = Tie::of(r) else { continue };
            if !self.outcome.ties_with(tie.alpha) {
                continue;
            }
            let mut member = primary;
            member.kind = tie.kind();
            member.triangle = Some(Some(tie.triangle));
            member.feature = Some(tie.feature.index());
            member.contact = Some(r.contact().map(|c| [c.x, c.y, c.z]));
            if tol.ties == TieRule::Any
                && let Some(contact) = r.contact()
            {
                member.normal = Some(self.member_normal(&tie, &contact, r.back()));
            }
            let d = compare(answer, &member, tol);
            if d.is_empty() {
                return None;
            }
            if names_tie(answer, &tie) {
                named.get_or_insert(d);
            }
        }
        for h in &self.initial {
            let tie = Tie {
                triangle: h.triangle,
                feature: h.feature,
                alpha: 0.0,
            };
            let mut member = primary;
            member.kind = tie.kind();
            member.triangle = Some(Some(tie.triangle));
            member.feature = Some(tie.feature.index());
            member.contact = Some(Some([h.contact.x, h.contact.y, h.contact.z]));
            if tol.ties == TieRule::Any {
                // An initial contact's normal is its side's (`-n` on a back).
                let back = self
                    .scene
                    .mesh
                    .triangle_by_index(tie.triangle)
                    .is_some_and(|t| t.normal.dot(&h.normal) < 0.0);
                member.normal = Some(self.member_normal(&tie, &h.contact, back));
            }
            let d = compare(answer, &member, tol);
            if d.is_empty() {
                return None;
            }
            if names_tie(answer, &tie) {
                named.get_or_insert(d);
            }
        }
        Some(named.unwrap_or(differ))
    }
}

/// Whether `answer` names `tie`. The trace spells "not given" as an absent
/// field (`None`) and "given as null" as `Some(None)`: a tie is a hit, so a
/// null triangle never names it, nor a null feature an edge or a vertex.
fn names_tie(answer: &OutcomeMsg, tie: &Tie) -> bool {
    let triangle = match answer.triangle {
        None => None,
        Some(None) => return false,
        Some(Some(t)) => Some(t),
    };
    let feature = match answer.feature {
        None => None,
        Some(None) if tie.feature != Feature::Face => return false,
        Some(f) => f,
    };
    tie.matches(answer.kind, triangle, feature)
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
/// The perturbations ([`perturbations`]) move one input at a time by
/// `k · u`, where `u = ε · S` is the sweep's rounding unit (`S` the scale of
/// [`SweptPath`], ε the machine epsilon) and `k` runs over 1, 2⁴, 2⁸, 2¹²
/// and 2¹⁶ = [`FRAGILE_ULPS`] (the fragility band), both signs: each
/// coordinate of `p0`, of `p1`, of both together (the path moved, which is
/// the mesh moved the other way), and the radius. The first one that
/// reproduces an answer, smallest first, is the one reported.
pub fn agreement(expected: &OutcomeMsg, result: &SweepResult, tol: &Tolerances) -> Agreement {
    judge(expected, &result.outcome_msg(), true, result, tol)
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
    judge(expected, got, false, result, tol)
}

fn judge(
    expected: &OutcomeMsg,
    got: &OutcomeMsg,
    got_is_core: bool,
    result: &SweepResult,
    tol: &Tolerances,
) -> Agreement {
    let fields = compare(expected, got, tol);
    if fields.is_empty() {
        return Agreement::Match;
    }
    let fragile = result.outcome.fragile;
    // Single precision: the tolerances widened to this sweep's backward
    // error bound (computed only here, for a sweep that differs).
    let sensitivity = match tol.precision {
        Precision::F64 => None,
        Precision::F32 => Sensitivity::of(result).map(|s| s.observing(expected, got, tol)),
    };
    let widened = sensitivity.map(|s| s.widen(tol, F32_OPERATIONS));
    let fixed = tol;
    let tol_judged = widened.as_ref().unwrap_or(tol);
    if let Some(s) = &sensitivity
        && compare(expected, got, tol_judged).is_empty()
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
        && tol.precision == Precision::F64
        && tol.ties == TieRule::Rule
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
    let on_expected = decision.disagreement(expected, tol);
    let on_got = if got_is_core {
        None
    } else {
        decision.disagreement(got, tol)
    };
    if on_expected.is_none() && on_got.is_none() {
        return Agreement::Tie;
    }
    // Against the core's own outcome, the fields that differ are those
    // from the member of the tie set the expectation names.
    let fields = match (got_is_core, on_expected.as_ref()) {
        (true, Some(named)) => named.clone(),
        _ => fields,
    };
    if tol.precision == Precision::F32 {
        // Single precision: any decision is as fragile as f32's budget; a
        // perturbation spends part of it, and the rest is what the
        // continuous fields may still differ by.
        let rounding = Rounding::F32 {
            fixed,
            sensitivity: sensitivity.as_ref(),
        };
        return match reproduce(
            expected,
            on_expected.is_some(),
            got,
            on_got.is_some(),
            result,
            rounding,
        ) {
            Some((r, backward_error)) => Agreement::Precision {
                backward_error,
                fields,
                reproduced: Some(r),
            },
            None => Agreement::Diverges {
                fields: beyond_f32_bound(expected, got, tol, fields),
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
            on_got.is_some(),
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
    let mut beyond = compare(expected, got, widened);
    if beyond.is_empty() {
        return fields;
    }
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

/// The arithmetic a divergence is excused in: what a perturbation of the
/// inputs may cost, and how a perturbed decision is asked to accept an
/// answer.
#[derive(Clone, Copy)]
enum Rounding<'a> {
    /// Double precision: perturbations of the sweep's rounding unit up to
    /// the fragility band; the perturbed decision accepts an answer within
    /// the tolerances.
    F64(&'a Tolerances),
    /// Single precision: perturbations of `u₃₂ · S` up to
    /// `c` = [`F32_OPERATIONS`] units; a perturbation of `k` units leaves
    /// `c - k` for the widening of the continuous fields (the budget is
    /// spent once).
    F32 {
        fixed: &'a Tolerances,
        sensitivity: Option<&'a Sensitivity>,
    },
}

impl Rounding<'_> {
    /// What the unit `u` of the perturbations is (from the sweep's own
    /// rounding unit), their magnitudes and the arithmetic's name.
    fn steps(self, sweep_unit: f64) -> (f64, &'static [f64], Precision) {
        match self {
            Rounding::F64(_) => (sweep_unit, &PERTURBATION_UNITS, Precision::F64),
            Rounding::F32 { .. } => (
                sweep_unit / f64::EPSILON * F32_UNIT,
                &F32_PERTURBATION_UNITS,
                Precision::F32,
            ),
        }
    }

    /// The budget spent when `decision`, under a perturbation of `k`
    /// units, accepts `answer`; `None` when it does not.
    fn accepts(self, decision: &Decision, answer: &OutcomeMsg, k: f64) -> Option<f64> {
        match self {
            Rounding::F64(tol) => decision.disagreement(answer, tol).is_none().then_some(k),
            Rounding::F32 { fixed, sensitivity } => {
                widening_needed(decision, answer, fixed, sensitivity, F32_OPERATIONS - k)
                    .map(|widening| k + widening)
            }
        }
    }
}

/// The smallest perturbations under which the core gives `expected` (when
/// `expected_open`, i.e. its own decision does not) and `got` (when
/// `got_open`), in the arithmetic `rounding`; `None` unless both are
/// found. With the budget spent: per side, the perturbation plus (at f32)
/// the smallest widening that then accepts the answer; the larger side's.
/// A side the core's own decision accepts costs nothing at f64, and at f32
/// the widening it needs.
fn reproduce(
    expected: &OutcomeMsg,
    expected_open: bool,
    got: &OutcomeMsg,
    got_open: bool,
    result: &SweepResult,
    rounding: Rounding,
) -> Option<(Reproduced, f64)> {
    let sweep_unit = rounding_unit(&result.scene.mesh, &result.sweep, result.options())?;
    let (u, units, precision) = rounding.steps(sweep_unit);
    let answers = [(expected, expected_open), (got, got_open)];
    // Each side: its perturbation (`None`: the core's own decision) and
    // the budget spent in all.
    let mut sides: [Option<(Option<Perturbation>, f64)>; 2] = [None, None];
    if answers.iter().any(|(_, open)| !open) {
        let own = match rounding {
            Rounding::F64(_) => None,
            Rounding::F32 { .. } => Some(Decision::of(&result.scene, &result.sweep)?),
        };
        for (side, (answer, open)) in sides.iter_mut().zip(answers) {
            if !open {
                let spent = own
                    .as_ref()
                    .and_then(|d| rounding.accepts(d, answer, 0.0))
                    .unwrap_or(if own.is_some() { F32_OPERATIONS } else { 0.0 });
                *side = Some((None, spent));
            }
        }
    }
    for p in perturbations_of(u, units) {
        if sides.iter().all(Option::is_some) {
            break;
        }
        let Some(decision) = Decision::of(&result.scene, &p.apply(&result.sweep)) else {
            continue;
        };
        for (side, (answer, _)) in sides.iter_mut().zip(answers) {
            if side.is_none()
                && let Some(spent) = rounding.accepts(&decision, answer, p.units.abs())
            {
                *side = Some((Some(p), spent));
            }
        }
    }
    let [(on_expected, e), (on_got, g)] = [sides[0]?, sides[1]?];
    Some((
        Reproduced {
            expected: on_expected,
            got: on_got,
            rounding_unit: u,
            precision,
        },
        e.max(g),
    ))
}

/// The smallest widening, in units of `u₃₂ · S` up to `budget`, under
/// which `decision` accepts `answer` (its continuous fields compared
/// within [`Sensitivity::widen`] of the fixed tolerances; without a
/// sensitivity, when the core's answer is a miss, the fixed tolerances
/// alone); `None` when the whole budget does not.
fn widening_needed(
    decision: &Decision,
    answer: &OutcomeMsg,
    fixed: &Tolerances,
    s: Option<&Sensitivity>,
    budget: f64,
) -> Option<f64> {
    let accepts = |units: f64| {
        let tol = s.map_or(*fixed, |s| s.widen(fixed, units));
        decision.disagreement(answer, &tol).is_none()
    };
    if budget < 0.0 || !accepts(budget.max(0.0)) {
        return None;
    }
    if accepts(0.0) {
        return Some(0.0);
    }
    let (mut lo, mut hi) = (0.0_f64, budget);
    for _ in 0..24 {
        let mid = 0.5 * (lo + hi);
        if accepts(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perturbations_are_ordered_smallest_first_and_cover_every_input() {
        let all: Vec<Perturbation> = perturbations(1.0).collect();
        assert_eq!(all.len(), 5 * 10 * 2);
        assert!(all.windows(2).all(|w| w[0].units.abs() <= w[1].units.abs()));
        assert_eq!(all[0].input, "p0.x");
        assert_eq!(all[0].units, -1.0);
        assert_eq!(all.last().map(|p| p.units), Some(FRAGILE_ULPS));
    }

    #[test]
    fn a_perturbation_moves_only_its_input() {
        let s = Sweep::new([1.0, 2.0, 3.0], [4.0, 5.0, 6.0], 0.5);
        let p = |input, offset| Perturbation {
            input,
            units: 1.0,
            offset,
        };
        assert_eq!(p("p1.z", 0.25).apply(&s).p1.z, 6.25);
        assert_eq!(p("p1.z", 0.25).apply(&s).p0, s.p0);
        let moved = p("path.y", -1.0).apply(&s);
        assert_eq!((moved.p0.y, moved.p1.y), (1.0, 4.0));
        assert_eq!(p("radius", 0.125).apply(&s).radius, 0.625);
        assert_eq!(p("p0.x", 0.5).to_string(), "p0.x higher by 1 u".to_string());
    }
}
