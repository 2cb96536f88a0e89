//! The conventions an engine's answers imply (`check --infer-config`):
//! each convention is tried on every trace, in a fixed order, and kept when
//! fewer sweeps fail with it than without; what it changed is its evidence.
//! The keys not kept are tried once more after the first pass (a
//! convention may fit only together with one tried after it), and the
//! accuracy is calibrated last.
//! The result is a `sweeptrace.toml` with an `[engine]` table whose every
//! value carries its evidence in a comment.
//!
//! The trial order puts precision first: an engine in single precision
//! differs from the exact rules on most sweeps, which hides what the other
//! conventions change until rounding is judged as rounding. The margin
//! comes from [`super::infer::Inferred`] (the margin every trace's face hits
//! imply); the facing rule is tried both ways; both sides after the
//! initial overlap.
//!
//! Inference never makes a run pass by itself: it prints a file, and the
//! check that uses it judges as strictly as any other.

use std::fmt::Write as _;

use crate::conventions::NormalRule;
use crate::core::{InitialOverlap, Sides};

use super::report::TraceReport;
use crate::conventions::Precision;
use crate::conventions::TieRule;
use crate::conventions::{Accuracy, EngineConventions, F32_BUDGET, FacingRule, MarginRule};

/// What a check of every trace under some conventions came to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trial {
    /// Sweeps that fail.
    pub failing: u64,
    /// Sweeps compared.
    pub compared: u64,
    /// Contact queries whose answers disagree with the core's contact set
    /// (ghost contacts aside: no convention makes them right).
    pub contact_failing: u64,
    /// Contact queries compared.
    pub contact_compared: u64,
    /// Differences within single precision, and the largest backward error.
    pub precision: u64,
    /// The largest backward error among them.
    pub max_backward_error: f64,
    /// The largest among those where only α, the contact or the normal
    /// differ (the engine's accuracy on the values).
    pub max_value_backward_error: f64,
    /// Their 99th percentile (nearest rank; 0 when there are none).
    pub p99_value_backward_error: f64,
    /// Answers that name another member of a tie.
    pub tie_members: u64,
    /// The margins the traces' face hits imply (one per trace that has one).
    pub margins: Vec<f64>,
    /// Traces that could not be checked.
    pub errors: u64,
}

impl Trial {
    /// The trial of `reports`.
    pub fn of(reports: &[TraceReport]) -> Trial {
        let mut t = Trial::default();
        let mut values: Vec<f64> = reports
            .iter()
            .filter_map(|r| r.within_precision.as_ref())
            .flat_map(|w| w.value_backward_errors.iter().copied())
            .collect();
        t.p99_value_backward_error = super::check::percentile(&mut values, 0.99);
        for r in reports {
            t.failing += r.divergent;
            t.compared += r.compared;
            t.contact_failing += r.contacts.divergent;
            t.contact_compared += r.contacts.compared;
            if let Some(within) = &r.within_precision {
                t.precision += within.count;
                t.max_backward_error = t.max_backward_error.max(within.max_backward_error);
                t.max_value_backward_error = t
                    .max_value_backward_error
                    .max(within.max_value_backward_error);
            }
            t.tie_members += r.tie_members;
            if let Some(m) = r.inferred.as_ref().and_then(|i| i.margin) {
                t.margins.push(m);
            }
            t.errors += u64::from(!r.errors.is_empty());
        }
        t
    }

    /// The answers that fail, sweeps and contact queries: what a convention
    /// must lower to be kept.
    pub fn failing_answers(&self) -> u64 {
        self.failing + self.contact_failing
    }

    /// How many fewer answers fail here than in `before`, in words:
    /// `3 fewer sweeps fail` when the contact queries are the same.
    fn fewer_than(&self, before: &Trial) -> String {
        // The sweeps' words are kept as they were ("1 fewer sweeps fail").
        let change = |was: u64, now: u64, what: &str| {
            if now <= was {
                format!("{} fewer {what}", was - now)
            } else {
                format!("{} more {what}", now - was)
            }
        };
        let queries = |was: u64, now: u64| {
            let noun = if was.abs_diff(now) == 1 {
                "contact query"
            } else {
                "contact queries"
            };
            change(was, now, noun)
        };
        let sweeps = change(before.failing, self.failing, "sweeps");
        if self.contact_failing == before.contact_failing {
            format!("{sweeps} fail")
        } else if self.failing == before.failing {
            let verb = if before.contact_failing.abs_diff(self.contact_failing) == 1 {
                "fails"
            } else {
                "fail"
            };
            format!(
                "{} {verb}",
                queries(before.contact_failing, self.contact_failing)
            )
        } else {
            format!(
                "{sweeps} and {} fail",
                queries(before.contact_failing, self.contact_failing)
            )
        }
    }

    /// The counts, for the progress lines: `N of M compared sweeps fail`,
    /// and the contact queries' when there are some.
    pub fn counts(&self) -> String {
        let mut s = format!("{} of {} compared sweeps", self.failing, self.compared);
        if self.contact_compared > 0 {
            let _ = write!(
                s,
                " and {} of {} contact queries",
                self.contact_failing, self.contact_compared
            );
        }
        s.push_str(" fail");
        s
    }
}

/// One candidate change of the conventions.
type Change = Box<dyn Fn(EngineConventions) -> EngineConventions>;

/// One inferred value with its evidence.
#[derive(Clone, Debug, PartialEq)]
pub struct Evidence {
    /// The key of the `[engine]` table.
    pub key: &'static str,
    /// The value, as TOML writes it.
    pub value: String,
    /// Why, in words.
    pub because: String,
}

/// The conventions inferred, with the evidence for each declared one and
/// the failing counts before and after.
#[derive(Clone, Debug, PartialEq)]
pub struct InferredConventions {
    /// The conventions.
    pub conventions: EngineConventions,
    /// The evidence for each value that differs from the rules.
    pub evidence: Vec<Evidence>,
    /// The trial under the rules.
    pub under_rules: Trial,
    /// The trial under the inferred conventions.
    pub under_inferred: Trial,
}

/// Infers the conventions: `check` runs every trace under the conventions
/// it is given and returns the trial, or an error (a fault of the engine,
/// a trace that cannot be checked), which ends the inference: a trial that
/// did not see every sweep is no evidence.
pub fn infer_conventions<E>(
    mut check: impl FnMut(&EngineConventions) -> Result<Trial, E>,
) -> Result<InferredConventions, E> {
    let rules = EngineConventions::default();
    let under_rules = check(&rules)?;
    let mut best = rules;
    let mut best_trial = under_rules.clone();
    let mut evidence: Vec<Evidence> = Vec::new();
    // Each candidate: the conventions with one key changed, and the words
    // of its evidence from the trial before and with it.
    let mut candidates: Vec<(&'static str, Change)> = vec![(
        "precision",
        Box::new(|c| EngineConventions {
            precision: Precision::F32,
            ..c
        }),
    )];
    if let Some(margin) = common_margin(&under_rules.margins) {
        candidates.push((
            "margin",
            Box::new(move |c| EngineConventions {
                margin: MarginRule::Fixed(margin),
                ..c
            }),
        ));
    }
    candidates.extend([
        (
            "facing",
            Box::new(|c| EngineConventions {
                facing: FacingRule::NonStrict,
                ..c
            }) as Change,
        ),
        (
            "facing",
            Box::new(|c| EngineConventions {
                facing: FacingRule::Strict,
                ..c
            }),
        ),
        (
            "initial_overlap",
            Box::new(|c| EngineConventions {
                initial_overlap: InitialOverlap::Alpha0,
                ..c
            }),
        ),
        // Then whatever the direction (Rapier's stopAtPenetration): kept
        // only when more answers fit it than `alpha0`.
        (
            "initial_overlap",
            Box::new(|c| EngineConventions {
                initial_overlap: InitialOverlap::Alpha0Always,
                ..c
            }),
        ),
        // After the initial overlap: a two-sided engine that also reports
        // starts in contact (Jolt) fits two sides only once those starts
        // are hits.
        (
            "sides",
            Box::new(|c| EngineConventions {
                sides: Sides::Two,
                ..c
            }),
        ),
        // Active edges first: it is the contact normal where the two can
        // differ only on flat and concave edges, and where the traces hold
        // no hit there the two fit alike (the evidence says so).
        (
            "normal",
            Box::new(|c| EngineConventions {
                normal: NormalRule::ActiveEdges,
                ..c
            }),
        ),
        (
            "normal",
            Box::new(|c| EngineConventions {
                normal: NormalRule::Contact,
                ..c
            }),
        ),
        (
            "ties",
            Box::new(|c| EngineConventions {
                ties: TieRule::Any,
                ..c
            }),
        ),
        // Or a start within ρ only where the path goes deeper, judged at the
        // contact point (Rapier's stopAtPenetration false): tried after the
        // ties, kept only when more answers fit it than the value kept so
        // far. Before the ties are declared, an engine that names any member
        // of an α = 0 tie (Jolt) fails as many of its starts under
        // `alpha0` as this leaves out, and the count could not tell them
        // apart.
        (
            "initial_overlap",
            Box::new(|c| EngineConventions {
                initial_overlap: InitialOverlap::Alpha0Deeper,
                ..c
            }),
        ),
    ]);
    // Two passes: a convention that helps only together with one tried
    // after it (Rapier's two sides, which fit once any member of a tie may
    // be named) is kept on the second. The second pass tries only the keys
    // the first did not declare.
    // Then the accuracy is calibrated; when it is coarser than single
    // precision, every key is tried again under it (an engine's
    // convention hidden by its solver's accuracy shows once that is held
    // apart: Rapier's starts while leaving, alpha0_always), pass after
    // pass while one changes something (at most three).
    let mut declared_in_first: Vec<&'static str> = Vec::new();
    let mut changed = true;
    for pass in 0..5 {
        if pass >= 3 && !changed {
            break;
        }
        changed = false;
        if pass == 1 {
            declared_in_first = evidence.iter().map(|e| e.key).collect();
        }
        if pass == 2 {
            let Some((accuracy, trial, because)) = calibrate(&mut check, &best, &best_trial)?
            else {
                break;
            };
            best = EngineConventions {
                accuracy: Some(accuracy),
                ..best
            };
            best_trial = trial;
            evidence.push(Evidence {
                key: "accuracy",
                value: accuracy.to_string(),
                because,
            });
            if accuracy.units() <= F32_BUDGET {
                break;
            }
        }
        for (key, change) in &candidates {
            let key = *key;
            if pass == 1 && declared_in_first.contains(&key) {
                continue;
            }
            let trying = change(best);
            if trying == best {
                continue;
            }
            let trial = check(&trying)?;
            if trial.errors > best_trial.errors
                || trial.failing_answers() >= best_trial.failing_answers()
            {
                if key == "normal"
                    && pass < 2
                    && trial.failing_answers() == best_trial.failing_answers()
                    && let Some(e) = evidence.iter_mut().find(|e| e.key == "normal")
                {
                    e.because.push_str(&format!(
                        " (normal = \"{}\" fits as well: no answer here tells them apart)",
                        trying.normal
                    ));
                }
                continue;
            }
            let fixed = best_trial.failing_answers() - trial.failing_answers();
            let fewer = trial.fewer_than(&best_trial);
            let because = match key {
                "precision" => format!(
                    "{} answers differ from the exact rules by no more than single precision \
                 explains (largest backward error {} u32 units of the sweep's scale); {fewer}",
                    trial.precision,
                    crate::core::explain::num(trial.max_backward_error)
                ),
                "margin" => format!(
                    "the face hits of every trace imply this margin; {fewer} with it than with \
                 each scene's own"
                ),
                "facing" => {
                    format!("{fewer} with it than with each scene's rule")
                }
                "sides" => format!(
                    "{fixed} answers hit triangles from behind (n·d > 0) as from the front, with \
                 the normal -n"
                ),
                "initial_overlap" if trying.initial_overlap == InitialOverlap::Alpha0Always => {
                    format!(
                        "answers are hits at α = 0 where the ball starts within ρ of the mesh, \
                     moving away from it too; {fewer} than {}",
                        if best.initial_overlap.is_rules() {
                            "under the rules".to_string()
                        } else {
                            format!("with \"{}\"", best.initial_overlap)
                        }
                    )
                }
                "initial_overlap" if trying.initial_overlap == InitialOverlap::Alpha0Deeper => {
                    format!(
                        "answers are hits at α = 0 where the ball starts within ρ of the mesh \
                     and its path closes in on the contact point, none where it leaves an \
                     edge or a vertex it overlaps; {fewer} than {}",
                        if best.initial_overlap.is_rules() {
                            "under the rules".to_string()
                        } else {
                            format!("with \"{}\"", best.initial_overlap)
                        }
                    )
                }
                "initial_overlap" => format!(
                    "{fixed} answers are hits at α = 0 where the ball starts within ρ of the mesh"
                ),
                "normal" => format!(
                    "{fewer}: the answers give the contact normal{}",
                    if trying.normal == NormalRule::ActiveEdges {
                        " at active edges and vertices, the face normal at flat and concave ones"
                    } else {
                        " at edges and vertices"
                    }
                ),
                "ties" => {
                    format!("{fixed} answers name a member of a tie with that member's own normal")
                }
                _ => fewer,
            };
            evidence.retain(|e: &Evidence| e.key != key);
            best = trying;
            changed = true;
            best_trial = trial;
            let value = best
                .declared()
                .into_iter()
                .find(|(k, _)| *k == key)
                .map_or_else(String::new, |(_, v)| v);
            evidence.push(Evidence {
                key,
                value,
                because,
            });
        }
    }
    Ok(InferredConventions {
        conventions: best,
        evidence,
        under_rules,
        under_inferred: best_trial,
    })
}

/// The widest budget calibration looks through, in units of `u₃₂ · S`
/// (`2¹⁸`, inputs moved by 1.6 % of the scale: Rapier's GJK/EPA, whose
/// relative tolerance is about 1e-3, needs `2¹⁷`): an engine coarser than
/// that is not calibrated, its differences stay failures.
const WIDEST_BUDGET: f64 = 262_144.0;

/// The accuracy the answers showed, when they are judged by backward
/// error (`best` declares `precision = "f32"`): the largest backward error
/// among the answers whose kind, triangle and feature agree (the values'),
/// doubled and rounded up to a power of two, at least 1. Below single
/// precision's 16 for an engine better than its budget (so that a later
/// bias it does not show today fails), above it for a solver coarser than
/// its arithmetic (looked for up to [`WIDEST_BUDGET`] only when sweeps fail
/// at 16, and kept only when fewer fail). `None` when it would be 16, or
/// nothing differs, or it fits worse.
fn calibrate<E>(
    check: &mut impl FnMut(&EngineConventions) -> Result<Trial, E>,
    best: &EngineConventions,
    best_trial: &Trial,
) -> Result<Option<(Accuracy, Trial, String)>, E> {
    if best.budget() != Some(F32_BUDGET) {
        return Ok(None);
    }
    let (measured, coarser) = if best_trial.failing > 0 {
        let wide = check(&EngineConventions {
            accuracy: Some(Accuracy::new(WIDEST_BUDGET)),
            ..*best
        })?;
        if wide.failing < best_trial.failing && wide.errors <= best_trial.errors {
            (wide, true)
        } else {
            (best_trial.clone(), false)
        }
    } else {
        (best_trial.clone(), false)
    };
    // Known good at single precision: every answer's worst. Coarser: the
    // 99th percentile, the worst 1 % left to fail and be looked at (a
    // solver's outliers are not its accuracy).
    let worst = if coarser {
        measured.p99_value_backward_error
    } else {
        measured.max_value_backward_error
    };
    if !(worst > 0.0 && worst.is_finite()) {
        return Ok(None);
    }
    let units = (2.0 * worst).log2().ceil().exp2().max(1.0);
    if units == F32_BUDGET || (coarser && units <= F32_BUDGET) || units > WIDEST_BUDGET {
        return Ok(None);
    }
    let accuracy = Accuracy::new(units);
    let trial = check(&EngineConventions {
        accuracy: Some(accuracy),
        ..*best
    })?;
    if trial.errors > best_trial.errors
        || trial.failing > best_trial.failing
        || trial.failing_answers() > best_trial.failing_answers()
    {
        return Ok(None);
    }
    let because = if units < F32_BUDGET {
        format!(
            "calibrated: the answers' largest backward error on α, the contact and the \
             normal is {} u32 units of the sweep's scale; held to twice that, rounded up to a \
             power of two, instead of single precision's {F32_BUDGET}, so that a later bias \
             beyond it fails (infer again from a build known to be good)",
            crate::core::explain::num(worst)
        )
    } else {
        format!(
            "{} answers differ by more than single precision explains, 99 % of them by at \
             most {} u32 units of the sweep's scale: the engine's solver is coarser than its \
             arithmetic; held to twice that, rounded up to a power of two, {} fewer sweeps \
             fail (the rest are beyond it: look at them)",
            trial.precision.saturating_sub(best_trial.precision),
            crate::core::explain::num(worst),
            best_trial.failing - trial.failing
        )
    };
    Ok(Some((accuracy, trial, because)))
}

/// The margin every estimate agrees on (to 1e-9), if they do.
fn common_margin(margins: &[f64]) -> Option<f64> {
    let first = *margins.first()?;
    margins
        .iter()
        .all(|m| (m - first).abs() <= 1e-9)
        .then_some(first)
}

impl InferredConventions {
    /// The `sweeptrace.toml` these conventions make: a header saying where
    /// it came from and what it changes, then the `[engine]` table, each
    /// value with its evidence. Valid TOML that `check` reads back.
    pub fn to_toml(&self, source: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# The conventions {source} implies, inferred by");
        let _ = writeln!(s, "# `sweeptrace check --infer-config`.");
        let _ = writeln!(
            s,
            "# Under the rules: {} of {} compared sweeps fail; under these conventions: {}.",
            self.under_rules.failing, self.under_rules.compared, self.under_inferred.failing
        );
        if self.under_rules.contact_compared > 0 {
            let _ = writeln!(
                s,
                "# Contact queries: {} of {} fail under the rules; under these conventions: {}.",
                self.under_rules.contact_failing,
                self.under_rules.contact_compared,
                self.under_inferred.contact_failing
            );
        }
        let _ = writeln!(
            s,
            "# Check again with this file: inference never makes a run pass by itself."
        );
        let _ = writeln!(s, "[engine]");
        if self.evidence.is_empty() {
            let _ = writeln!(
                s,
                "# No convention fits better than the rules (docs/SEMANTICS.md)."
            );
        }
        for e in &self.evidence {
            let _ = writeln!(s, "# {}", e.because);
            let _ = writeln!(s, "{} = {}", e.key, e.value);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fake suite: each convention fixes a known number of sweeps.
    fn suite(c: &EngineConventions) -> Result<Trial, String> {
        let mut failing = 100;
        if c.precision == Precision::F32 {
            failing -= 60;
        }
        if c.initial_overlap == InitialOverlap::Alpha0 {
            failing -= 20;
        }
        if c.normal == NormalRule::ActiveEdges {
            failing -= 5;
        }
        if c.normal == NormalRule::Contact {
            failing -= 3;
        }
        if c.sides == Sides::Two {
            failing -= 7;
        }
        Ok(Trial {
            failing,
            compared: 1000,
            precision: if c.precision == Precision::F32 { 60 } else { 0 },
            max_backward_error: 2.0,
            margins: vec![0.0, 0.0],
            ..Trial::default()
        })
    }

    #[test]
    fn keeps_what_fixes_sweeps_and_says_why() {
        let inferred = infer_conventions(suite).expect("no fault");
        let c = inferred.conventions;
        assert_eq!(c.precision, Precision::F32);
        assert_eq!(c.initial_overlap, InitialOverlap::Alpha0);
        assert_eq!(c.normal, NormalRule::ActiveEdges);
        assert_eq!(c.sides, Sides::Two);
        assert!(!inferred.to_toml("e").contains("fits as well"));
        // The margin and the tie rule change nothing in this suite.
        assert_eq!((c.margin, c.ties), (MarginRule::Scene, TieRule::Rule));
        assert_eq!(inferred.under_inferred.failing, 8);
        let toml = inferred.to_toml("the engine");
        assert!(toml.contains("precision = \"f32\""), "{toml}");
        assert!(toml.contains("# 20 answers are hits at α = 0"), "{toml}");
        assert!(
            toml.contains("# 7 answers hit triangles from behind")
                && toml.contains("sides = \"two\""),
            "{toml}"
        );
        let parsed: toml::Table = toml::from_str(&toml).expect("valid TOML");
        assert!(parsed.contains_key("engine"));
    }

    #[test]
    fn a_one_sided_engine_keeps_one_side() {
        // Both sides make sweeps fail (hits where the engine sees none):
        // the rules' `one` stays, and a default is not printed.
        let inferred = infer_conventions(|c| {
            Ok::<_, String>(Trial {
                failing: if c.sides == Sides::Two { 40 } else { 10 },
                compared: 100,
                ..Trial::default()
            })
        })
        .expect("no fault");
        assert_eq!(inferred.conventions.sides, Sides::One);
        assert!(!inferred.to_toml("x").contains("sides"));
    }

    #[test]
    fn an_engine_of_the_rules_gets_an_empty_table() {
        let inferred = infer_conventions(|_| {
            Ok::<_, String>(Trial {
                failing: 0,
                compared: 10,
                ..Trial::default()
            })
        })
        .expect("no fault");
        assert!(inferred.conventions.is_rules());
        assert!(inferred.to_toml("x").contains("No convention fits better"));
    }

    /// Issue 43: a fault in any trial (here the third) ends the inference
    /// with that fault; no conventions come of it.
    #[test]
    fn a_fault_in_a_trial_is_the_result() {
        let mut trials = 0;
        let result = infer_conventions(|c| {
            trials += 1;
            if trials == 3 {
                return Err("the engine exited with status 3".to_string());
            }
            suite(c)
        });
        assert_eq!(
            result.map(|i| i.conventions),
            Err("the engine exited with status 3".to_string())
        );
        assert_eq!(trials, 3, "no trial after the fault");
    }
}
