//! The recording engine's configuration, inferred from its expectations.
//!
//! When a trace's expectations fail, the first question is whether the
//! engine that recorded them ran with another margin or facing rule than
//! the scene declares. The expectations answer it:
//!
//! - an expected **face** hit at `α` on a triangle with front normal `n`
//!   gives the engine's detection radius directly: the face test hits when
//!   the centre is `ρ` above the plane, `ρ = h0 + α (n · d)` (that is
//!   `h0 - α (h0 - h1)`), with `h0 = n · (p0 - a)`; hence its margin
//!   `ε = r - ρ`. Each face hit is one estimate; the report gives their
//!   spread and takes the simplest decimal within it (so rounding noise of
//!   `1e-16` reads as margin 0);
//! - an expected hit on a triangle with `n · d = 0` exactly (moving
//!   parallel to its plane) is only possible with the `non_strict` rule;
//!   hits with `n · d < 0` are consistent with both rules, which are then
//!   both replayed and the one matching more expectations is kept; a hit
//!   with `n · d > 0` (back-facing) fits neither and is counted.
//!
//! The trace is then replayed with what was inferred and the expectations
//! that match (as `check` judges them: [`agreement`]) are counted.

use std::sync::Arc;

use serde::Serialize;

use crate::core::explain::num;
use crate::core::{Facing, Kind, Options, Sweep, sweep_mesh};
use crate::replay::{SceneState, SweepResult};
use crate::trace::OutcomeMsg;

use crate::judge::Tolerances;
use crate::judge::{Agreement, agreement};

/// How many compared sweeps (the first ones) the inference of the
/// recording engine's configuration looks at and replays, so that a
/// check's memory stays bounded whatever the trace's length.
pub const MAX_INFERENCE_SWEEPS: usize = 100_000;

/// One compared sweep, kept by `check` for the inference.
#[derive(Clone, Debug)]
pub struct ComparedSweep {
    /// The scene it was replayed against.
    pub scene: Arc<SceneState>,
    /// Frame.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// The sweep.
    pub sweep: Sweep,
    /// Its expectation.
    pub expected: OutcomeMsg,
    /// The triangle of the replayed outcome, when it is a face hit (used
    /// when an expected face hit names no triangle).
    pub replayed_face: Option<u32>,
}

/// Minimum, median and maximum of the margin estimates.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// Smallest estimate.
    pub min: f64,
    /// Median estimate.
    pub median: f64,
    /// Largest estimate.
    pub max: f64,
}

/// What `check` inferred about the recording engine's configuration.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Inferred {
    /// Expected face hits whose triangle is known: one margin estimate each.
    pub face_hits: u64,
    /// The inferred margin `ε`: the simplest decimal within the estimates'
    /// spread. `None` when there is no estimate, or the estimates are not a
    /// valid margin (`ε < 0`, or not below every radius).
    pub margin: Option<f64>,
    /// The spread of the estimates (when there are any).
    pub margin_spread: Option<Spread>,
    /// The margin replayed with: the inferred one, or `None` for each
    /// scene's own.
    pub replayed_margin: Option<f64>,
    /// The inferred facing rule (the one replayed with).
    pub facing: Facing,
    /// Whether the facing rule is implied by an expected hit (`n · d = 0`
    /// exactly) rather than chosen by replaying both.
    pub facing_implied: bool,
    /// Expected hits on a triangle the path moves parallel to (`n · d = 0`).
    pub parallel_hits: u64,
    /// Expected hits on a triangle the path moves away from (`n · d > 0`):
    /// no facing rule of SEMANTICS.md allows them.
    pub back_facing_hits: u64,
    /// The first frame of a parallel hit, when there is one.
    pub parallel_frame: Option<u64>,
    /// The first frame of a back-facing hit, when there is one.
    pub back_facing_frame: Option<u64>,
    /// Expectations that match (or name a member of the tie set) when the
    /// trace is replayed with what was inferred.
    pub matches: u64,
    /// Expectations compared: the first
    /// [`MAX_INFERENCE_SWEEPS`] of the
    /// trace at most.
    pub compared: u64,
    /// With the other facing rule, when both were replayed: how many match.
    pub other_facing_matches: Option<u64>,
}

impl Inferred {
    /// The report in words: one line on what was inferred, one on how many
    /// expectations match with it.
    pub fn lines(&self) -> Vec<String> {
        let margin = match (self.margin, &self.margin_spread) {
            (Some(m), Some(s)) => format!(
                "margin {m} (from {} expected face hit{}: ε min {}, median {}, max {})",
                self.face_hits,
                if self.face_hits == 1 { "" } else { "s" },
                num(s.min),
                num(s.median),
                num(s.max)
            ),
            (None, Some(s)) if self.face_hits == 1 => format!(
                "no valid margin (the 1 expected face hit gives ε = {}: not 0 ≤ ε < r; the \
                 scenes' margins kept)",
                num(s.median)
            ),
            (None, Some(s)) => format!(
                "no valid margin (the {} expected face hits give ε from {} to {}, median {}: \
                 not 0 ≤ ε < r; the scenes' margins kept)",
                self.face_hits,
                num(s.min),
                num(s.max),
                num(s.median)
            ),
            _ => "no margin (no expected face hit names its triangle; the scenes' margins kept)"
                .to_string(),
        };
        let facing = if self.facing_implied {
            format!(
                "facing {} (an expected hit with n·d = 0, frame {})",
                self.facing,
                self.parallel_frame.unwrap_or_default()
            )
        } else {
            let replayed = match self.other_facing_matches {
                Some(n) if n == self.matches => "both match as many when replayed".to_string(),
                Some(n) => format!("this one matches more when replayed ({n} with the other)"),
                None => String::new(),
            };
            format!(
                "facing {} (no expected hit with n·d = 0: both rules fit the hits; {replayed})",
                self.facing
            )
        };
        let mut lines = vec![format!("inferred engine configuration: {margin}, {facing}")];
        if self.back_facing_hits > 0 {
            lines.push(format!(
                "{} back-facing (n·d > 0, first at frame {}): no facing rule allows {}; the \
                 convention sides = \"two\" (both sides collide) does",
                match self.back_facing_hits {
                    1 => "1 expected hit is".to_string(),
                    n => format!("{n} expected hits are"),
                },
                self.back_facing_frame.unwrap_or_default(),
                crate::numbers::verb(self.back_facing_hits, "it", "them")
            ));
        }
        let with_margin = match self.replayed_margin {
            Some(m) => format!("margin {m}"),
            None => "the scenes' margins".to_string(),
        };
        lines.push(format!(
            "expectations match with {with_margin} and facing {}: {} of {}{}",
            self.facing,
            self.matches,
            self.compared,
            if self.compared as usize >= MAX_INFERENCE_SWEEPS {
                " (the first ones of the trace)"
            } else {
                ""
            }
        ));
        lines
    }
}

/// The simplest decimal within `tolerance` of `median`: 0, or the median
/// rounded to the fewest decimal places.
fn simplest(median: f64, tolerance: f64) -> f64 {
    if median.abs() <= tolerance {
        return 0.0;
    }
    for places in 0..=17 {
        let scale = 10f64.powi(places);
        let candidate = (median * scale).round() / scale;
        if (candidate - median).abs() <= tolerance {
            return candidate;
        }
    }
    median
}

fn median(sorted: &[f64]) -> f64 {
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

/// Counts the expectations that match when every sweep is replayed with
/// `margin` (or its scene's) and `facing`.
fn count_matches(
    compared: &[ComparedSweep],
    margin: Option<f64>,
    facing: Facing,
    tol: &Tolerances,
) -> u64 {
    // Each sweep is judged against its scene with these options; consecutive
    // sweeps of one scene share the copy.
    let mut scene: Option<(&Arc<SceneState>, Arc<SceneState>)> = None;
    compared
        .iter()
        .filter(|c| {
            let replayed = match &scene {
                Some((of, replayed)) if Arc::ptr_eq(of, &c.scene) => replayed.clone(),
                _ => {
                    let options = Options {
                        margin: margin.unwrap_or(c.scene.options.margin),
                        facing,
                        ..c.scene.options
                    };
                    let replayed = Arc::new(SceneState {
                        options,
                        ..SceneState::clone(&c.scene)
                    });
                    scene = Some((&c.scene, replayed.clone()));
                    replayed
                }
            };
            let Ok(outcome) = sweep_mesh(&replayed.mesh, &c.sweep, &replayed.options) else {
                return false;
            };
            let result = SweepResult {
                frame: c.frame,
                ball: c.ball,
                log_time_nanos: 0,
                index: 0,
                scene: replayed,
                sweep: c.sweep,
                outcome,
                records: Vec::new(),
                skipped: Default::default(),
                expected: Some(c.expected),
                tunnels: Vec::new(),
            };
            matches!(
                agreement(&c.expected, &result, tol),
                Agreement::Match | Agreement::Tie
            )
        })
        .count() as u64
}

/// Infers the configuration from `compared` (see the module
/// documentation); `None` when nothing was compared.
pub fn infer(compared: &[ComparedSweep], tol: &Tolerances) -> Option<Inferred> {
    let first = compared.first()?;
    let mut estimates: Vec<f64> = Vec::new();
    let (mut parallel_hits, mut back_facing_hits) = (0u64, 0u64);
    let (mut parallel_frame, mut back_facing_frame) = (None, None);
    let mut smallest_radius = f64::INFINITY;
    for c in compared {
        smallest_radius = smallest_radius.min(c.sweep.radius);
        let e = &c.expected;
        if e.kind == Kind::None {
            continue;
        }
        let named = e.triangle.flatten();
        let triangle = match (e.kind, named) {
            (_, Some(t)) => Some(t),
            (Kind::Face, None) => c.replayed_face,
            _ => None,
        };
        let Some(t) = triangle.and_then(|t| c.scene.mesh.triangle_by_index(t)) else {
            continue;
        };
        let d = c.sweep.p1 - c.sweep.p0;
        let normal_dot_d = t.normal.dot(&d);
        if normal_dot_d == 0.0 {
            parallel_hits += 1;
            parallel_frame = parallel_frame.or(Some(c.frame));
        } else if normal_dot_d > 0.0 {
            back_facing_hits += 1;
            back_facing_frame = back_facing_frame.or(Some(c.frame));
        }
        if e.kind == Kind::Face {
            let h0 = t.normal.dot(&(c.sweep.p0 - t.vertices[0]));
            let rho = h0 + e.alpha * normal_dot_d;
            let epsilon = c.sweep.radius - rho;
            if epsilon.is_finite() {
                estimates.push(epsilon);
            }
        }
    }
    estimates.sort_by(f64::total_cmp);
    let (margin, margin_spread) = match (estimates.first(), estimates.last()) {
        (Some(&min), Some(&max)) => {
            let med = median(&estimates);
            let tolerance = (max - min).max(1e-9 * smallest_radius);
            let m = simplest(med, tolerance);
            let valid = m >= 0.0 && m < smallest_radius;
            (
                valid.then_some(m),
                Some(Spread {
                    min,
                    median: med,
                    max,
                }),
            )
        }
        _ => (None, None),
    };
    let scene_facing = first.scene.options.facing;
    let (facing, facing_implied, matches, other_facing_matches) = if parallel_hits > 0 {
        let n = count_matches(compared, margin, Facing::NonStrict, tol);
        (Facing::NonStrict, true, n, None)
    } else {
        let other = match scene_facing {
            Facing::NonStrict => Facing::Strict,
            Facing::Strict => Facing::NonStrict,
        };
        let own = count_matches(compared, margin, scene_facing, tol);
        let alternative = count_matches(compared, margin, other, tol);
        if alternative > own {
            (other, false, alternative, Some(own))
        } else {
            (scene_facing, false, own, Some(alternative))
        }
    };
    Some(Inferred {
        face_hits: estimates.len() as u64,
        margin,
        margin_spread,
        replayed_margin: margin,
        facing,
        facing_implied,
        parallel_hits,
        back_facing_hits,
        parallel_frame,
        back_facing_frame,
        matches,
        compared: compared.len() as u64,
        other_facing_matches,
    })
}
