//! Rounding as an excuse: the perturbations of one input of a sweep within
//! its rounding budget ([`Perturbation`]), and the search for the smallest
//! ones under which the core gives each side's answer ([`Reproduced`]), at
//! double precision (the fragility band) or single precision (the f32
//! budget, spent once).

use std::fmt;

use serde::Serialize;

use crate::core::explain::num;
use crate::core::options::FRAGILE_ULPS;
use crate::core::{Mesh, Options, Sweep, SweptPath};
use crate::replay::SweepResult;
use crate::trace::OutcomeMsg;

use super::compare::Tolerances;
use super::precision::{F32_UNIT, Sensitivity};
use super::reference::Decision;
use crate::conventions::Precision;

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

/// The magnitudes of the perturbations by backward error, in units of
/// `u₃₂ · S`: the powers of two up to the budget (1, 2, 4, 8, 16 at single
/// precision's), and the budget itself when it is not one.
fn budget_perturbation_units(budget: f64) -> Vec<f64> {
    let mut units: Vec<f64> = std::iter::successors(Some(1.0_f64), |k| Some(k * 2.0))
        .take_while(|k| *k <= budget)
        .collect();
    if units.last() != Some(&budget) {
        units.push(budget);
    }
    units
}

/// The perturbations of a sweep whose rounding unit is `u`, smallest first
/// (each magnitude over every input, lower before higher).
#[cfg(test)]
pub(super) fn perturbations(u: f64) -> impl Iterator<Item = Perturbation> {
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
    Some(SweptPath::against(mesh, sweep, options).ok()?.rounding())
}

/// The arithmetic a divergence is excused in: what a perturbation of the
/// inputs may cost, and how a perturbed decision is asked to accept an
/// answer.
#[derive(Clone, Copy)]
pub(super) enum Rounding<'a> {
    /// Double precision: perturbations of the sweep's rounding unit up to
    /// the fragility band; the perturbed decision accepts an answer within
    /// the tolerances.
    F64(&'a Tolerances),
    /// By backward error: perturbations of `u₃₂ · S` up to the budget
    /// `c` (single precision's 16, or a declared accuracy); a perturbation
    /// of `k` units leaves `c - k` for the widening of the continuous
    /// fields (the budget is spent once).
    F32 {
        fixed: &'a Tolerances,
        sensitivity: Option<&'a Sensitivity>,
        budget: f64,
    },
}

impl Rounding<'_> {
    /// What the unit `u` of the perturbations is (from the sweep's own
    /// rounding unit), their magnitudes and the arithmetic's name.
    fn steps(self, sweep_unit: f64) -> (f64, Vec<f64>, Precision) {
        match self {
            Rounding::F64(_) => (sweep_unit, PERTURBATION_UNITS.to_vec(), Precision::F64),
            Rounding::F32 { budget, .. } => (
                sweep_unit / f64::EPSILON * F32_UNIT,
                budget_perturbation_units(budget),
                Precision::F32,
            ),
        }
    }

    /// The whole budget, in the units of the perturbations (at `f64`, no
    /// widening is spent: 0).
    fn budget(self) -> f64 {
        match self {
            Rounding::F64(_) => 0.0,
            Rounding::F32 { budget, .. } => budget,
        }
    }

    /// The budget spent when `decision`, under a perturbation of `k`
    /// units, accepts `answer`; `None` when it does not.
    fn accepts(self, decision: &Decision, answer: &OutcomeMsg, k: f64) -> Option<f64> {
        match self {
            Rounding::F64(tol) => decision.accepts(answer, tol, None).then_some(k),
            Rounding::F32 {
                fixed,
                sensitivity,
                budget,
            } => {
                // A sweep the core misses has no hit to bound the fields
                // by: the perturbed decision's hit does.
                let own = sensitivity
                    .is_none()
                    .then(|| decision.sensitivity())
                    .flatten();
                widening_needed(
                    decision,
                    answer,
                    fixed,
                    sensitivity.or(own.as_ref()),
                    budget - k,
                )
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
pub(super) fn reproduce(
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
                    .unwrap_or(if own.is_some() {
                        rounding.budget()
                    } else {
                        0.0
                    });
                *side = Some((None, spent));
            }
        }
    }
    for p in perturbations_of(u, &units) {
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
        decision.accepts(answer, &tol, None)
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
