//! The decision line: one sentence per sweep, and whether the sweep
//! diverges from the trace's expectation (by [`crate::judge::agreement`],
//! the judgement `check` uses: ties are matches, and a divergence on a
//! fragile decision is not a failure, as in `check` without `--strict`).

use std::fmt::{self, Write as _};

use crate::core::explain::{Num, write_describe};
use crate::core::record::TestRecord;
use crate::judge::{Agreement, FieldDiff, Tolerances, agreement};
use crate::replay::SweepResult;

/// The fields in which the sweep's outcome differs from the trace's expected
/// outcome when `check` counts the sweep as a failure (empty when it
/// matches, ties, diverges on a fragile decision in a way a perturbation of
/// the inputs reproduces, or has no expectation).
pub fn divergence(r: &SweepResult, tolerances: &Tolerances) -> Vec<FieldDiff> {
    let Some(expected) = &r.expected else {
        return Vec::new();
    };
    match agreement(expected, r, tolerances) {
        Agreement::Diverges {
            fields,
            reproduced: None,
            ..
        } => fields,
        Agreement::Diverges { .. }
        | Agreement::Precision { .. }
        | Agreement::Match
        | Agreement::Tie => Vec::new(),
    }
}

/// The text line of one sweep, and whether it diverges from the trace's
/// expected outcome (by [`divergence`] with `tolerances`).
pub fn decision_line(
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    tolerances: &Tolerances,
) -> (String, bool) {
    let mut s = String::new();
    let diffs = divergence(r, tolerances);
    write_decision_line(&mut s, r, decisive, &diffs);
    (s, !diffs.is_empty())
}

/// Appends [`decision_line`]'s line to `s`; `diffs` are the sweep's
/// [`divergence`].
pub fn write_decision_line(
    s: &mut String,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    diffs: &[FieldDiff],
) {
    let o = &r.outcome;
    let _ = write!(s, "frame {} ball {}: ", r.frame, r.ball);
    if o.is_hit() {
        let _ = write!(
            s,
            "{} collision at α = {} (triangle {}, feature {})",
            o.kind(),
            Num(o.travelled()),
            OrDash(o.hit.map(|h| h.triangle)),
            OrDash(o.hit.and_then(|h| h.feature.index()))
        );
        if let Some(t) = decisive {
            s.push_str(" — ");
            let _ = write_describe(s, t);
        }
    } else {
        s.push_str("no collision");
        match decisive {
            Some(t) => {
                s.push_str("; closest candidate rejected: ");
                let _ = write_describe(s, t);
            }
            None if r.records.is_empty() && r.skipped.is_empty() => {
                s.push_str(" (no triangle's box comes within ρ of the path)")
            }
            None => {}
        }
        // At `primary` the nearest miss is the nearest of the tested
        // candidates: say how many were skipped untested, and why.
        if !r.skipped.is_empty() {
            let _ = write!(s, "; {}", r.skipped.words());
        }
    }
    if !o.fragile.is_robust() {
        let _ = write!(s, " [fragile decision: {}]", o.fragile);
    }
    if let (false, Some(e)) = (diffs.is_empty(), &r.expected) {
        s.push_str(" [differs from the expected outcome in ");
        write_fields(s, diffs);
        let _ = write!(s, "; expected {} at α = {}]", e.kind, Num(e.alpha));
    }
    for t in &r.tunnels {
        let _ = write!(s, " [tunnel: through triangle {} ", t.triangle);
        match t.previous_frame {
            Some(p) => {
                let _ = write!(s, "since the sweep of frame {p}]");
            }
            None => s.push_str("during the sweep]"),
        }
    }
}

/// The line of the `divergences` log: what was expected, what was found,
/// which fields differ.
#[cfg(feature = "viewer")]
pub fn write_divergence_line(s: &mut String, r: &SweepResult, diffs: &[FieldDiff]) {
    let o = &r.outcome;
    let _ = write!(s, "frame {} ball {}: ", r.frame, r.ball);
    write_fields(s, diffs);
    s.push_str(if diffs.len() == 1 {
        " differs"
    } else {
        " differ"
    });
    if let Some(e) = &r.expected {
        let _ = write!(s, ": expected {} at α = {}", e.kind, Num(e.alpha));
        if let (Some(Some(t)), Some(Some(f))) = (e.triangle, e.feature) {
            let _ = write!(s, " (triangle {t}, feature {f})");
        }
    }
    let _ = write!(s, ", replayed {} at α = {}", o.kind(), Num(o.travelled()));
    if let Some(h) = o.hit
        && let Some(f) = h.feature.index()
    {
        let _ = write!(s, " (triangle {}, feature {f})", h.triangle);
    }
    let _ = write!(
        s,
        " (margin {}, facing {})",
        Num(r.options().margin),
        r.options().facing
    );
    // A known limitation of engines, named as `check` names it.
    if let Some(e) = &r.expected {
        let records = super::explain::explained_records(r);
        let rho = r.sweep.radius - r.options().margin;
        let tests = super::explain::expected_tests(e, &r.outcome, &records, Some(&r.scene), rho);
        if let Some(named) = super::explain::limitation(r, e, &tests) {
            let _ = write!(s, "; named: {named}");
        }
    }
}

fn write_fields(s: &mut String, diffs: &[FieldDiff]) {
    for (i, d) in diffs.iter().enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        s.push_str(d.field.as_str());
    }
}

/// A number, or `-` for `None`.
struct OrDash<T>(Option<T>);

impl<T: fmt::Display> fmt::Display for OrDash<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Some(v) => v.fmt(f),
            None => f.write_str("-"),
        }
    }
}
