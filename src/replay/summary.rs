//! The counts of a replay and their rendering for people.

use std::collections::BTreeMap;
use std::time::Duration;

use crate::core::{FragileReason, Kind, Verdict};

/// Counts of a replay.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReplaySummary {
    /// Scenes read.
    pub scenes: usize,
    /// Degenerate triangles left out, over all scenes.
    pub degenerate_triangles: usize,
    /// Sweeps replayed.
    pub sweeps: u64,
    /// Sweeps skipped by the frame and ball filters.
    pub filtered_out: u64,
    /// Replayed sweeps by the kind of their outcome (`none` included).
    pub outcomes: BTreeMap<Kind, u64>,
    /// Verdicts of every test run by the explained query (over the visited
    /// triangles at `primary`/`candidates`, every triangle at `all`), before
    /// the detail level drops records.
    pub verdicts: BTreeMap<Verdict, u64>,
    /// `/expected` messages attached to a replayed sweep.
    pub expected_matched: u64,
    /// `/expected` messages for a replayed `(frame, ball)` that arrived too
    /// late to be attached, or that match no sweep at all.
    pub expected_unmatched: u64,
    /// Replayed sweeps whose decision is fragile (rounding at the level of
    /// the inputs could change it; see [`crate::core::FragileReason`]).
    pub fragile: u64,
    /// Fragile decisions by reason (a decision can have several).
    pub fragile_by_reason: BTreeMap<FragileReason, u64>,
    /// Time spent in the collision core and the bookkeeping (not reading).
    pub elapsed: Duration,
}

impl ReplaySummary {
    /// Sweeps whose outcome is a collision.
    pub fn collisions(&self) -> u64 {
        self.outcomes
            .iter()
            .filter(|(k, _)| **k != Kind::None)
            .map(|(_, n)| n)
            .sum()
    }

    /// A few lines for people.
    pub fn render(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let kinds = [Kind::Face, Kind::Edge, Kind::Vertex]
            .iter()
            .map(|k| format!("{} {k}", self.outcomes.get(k).copied().unwrap_or(0)))
            .collect::<Vec<_>>()
            .join(", ");
        let _ = writeln!(
            s,
            "{} sweeps replayed ({} filtered out) over {} scene(s): {} collisions ({kinds}), {} without",
            self.sweeps,
            self.filtered_out,
            self.scenes,
            self.collisions(),
            self.outcomes.get(&Kind::None).copied().unwrap_or(0),
        );
        if !self.verdicts.is_empty() {
            let v = self
                .verdicts
                .iter()
                .map(|(v, n)| format!("{v} {n}"))
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(s, "test verdicts: {v}");
        }
        if self.expected_matched + self.expected_unmatched > 0 {
            let _ = writeln!(
                s,
                "expected outcomes: {} attached, {} unmatched",
                self.expected_matched, self.expected_unmatched
            );
        }
        if self.fragile > 0 {
            let reasons = self
                .fragile_by_reason
                .iter()
                .map(|(r, n)| format!("{} {n}", r.as_str()))
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(
                s,
                "fragile decisions: {} of {} ({reasons})",
                self.fragile, self.sweeps
            );
        }
        if self.degenerate_triangles > 0 {
            let _ = writeln!(
                s,
                "degenerate triangles left out: {}",
                self.degenerate_triangles
            );
        }
        let _ = writeln!(s, "time in the core: {:.3} s", self.elapsed.as_secs_f64());
        s
    }
}
