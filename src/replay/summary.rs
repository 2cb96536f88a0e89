//! The counts of a replay and their rendering for people.

use std::collections::BTreeMap;
use std::time::Duration;

use crate::core::record::{SkipCounts, VerdictCounts};
use crate::core::{FragileReason, Kind};

use super::ReplayOptions;
use super::selection::{Selection, SweepExtent};
use super::tunnel::{Tunnel, TunnelKind};
use crate::numbers::plural;

/// How many tunnels the summary lists.
pub const LISTED_TUNNELS: usize = 5;

/// A tunnel with the sweep it was found at.
#[derive(Clone, Debug, PartialEq)]
pub struct TunnelAt {
    /// Frame of the sweep.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// The tunnel.
    pub tunnel: Tunnel,
}

impl std::fmt::Display for TunnelAt {
    /// `frame F, ball B: through triangle T during its sweep at (x, y, z)`
    /// (or `between its sweeps of frames P and F`), with `(back to front)`
    /// after the triangle for a flipped one crossed that way and `, through
    /// the flipped triangle 812` (the defect within ρ) at the end.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "frame {}, ball {}: {}",
            self.frame,
            self.ball,
            self.tunnel.sentence(Some(self.frame))
        )
    }
}

/// Counts of a replay.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ReplaySummary {
    /// Scenes read.
    pub scenes: usize,
    /// Degenerate triangles left out, over all scenes.
    pub degenerate_triangles: usize,
    /// Sweeps replayed.
    pub sweeps: u64,
    /// Sweeps skipped by the frame and ball filters.
    pub filtered_out: u64,
    /// The frames and balls of every sweep read, filtered out or not.
    pub seen: SweepExtent,
    /// Replayed sweeps by the kind of their outcome (`none` included).
    pub outcomes: BTreeMap<Kind, u64>,
    /// Verdicts of every test run by the explained query (over the visited
    /// triangles at `primary`/`candidates`, every triangle at `all`), before
    /// the detail level drops records. At `primary` the candidates the fast
    /// query skips are not tested: they are counted in `skipped`.
    pub verdicts: VerdictCounts,
    /// Candidate triangles skipped without a test, by reason (at `primary`
    /// only).
    pub skipped: SkipCounts,
    /// `/expected` messages attached to a replayed sweep.
    pub expected_matched: u64,
    /// `/expected` messages for a replayed `(frame, ball)` that arrived too
    /// late to be attached, or that match no sweep at all.
    pub expected_unmatched: u64,
    /// Time spent in the collision core and the bookkeeping (not reading).
    pub elapsed: Duration,
    /// Replayed sweeps whose decision is fragile (rounding at the level of
    /// the inputs could change it; see [`crate::core::FragileReason`]).
    pub fragile: u64,
    /// Fragile decisions by reason (a decision can have several).
    pub fragile_by_reason: BTreeMap<FragileReason, u64>,
    /// Tunnels found, by kind.
    pub tunnels: BTreeMap<TunnelKind, u64>,
    /// The first tunnels (at most `LISTED_TUNNELS`, 5), in trace order.
    pub first_tunnels: Vec<TunnelAt>,
    /// `/contact` queries read (not replayed as sweeps: `check` judges
    /// them, the recording draws them).
    pub contact_queries: u64,
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

    /// Tunnels found, of every kind.
    pub fn tunnel_count(&self) -> u64 {
        self.tunnels.values().sum()
    }

    /// Counts one tunnel found at `(frame, ball)`.
    pub(crate) fn tunnel(&mut self, frame: u64, ball: u32, tunnel: &Tunnel) {
        *self.tunnels.entry(tunnel.kind).or_default() += 1;
        if self.first_tunnels.len() < LISTED_TUNNELS {
            self.first_tunnels.push(TunnelAt {
                frame,
                ball,
                tunnel: tunnel.clone(),
            });
        }
    }

    /// What the frame and ball filters of `options` (the replay's) kept.
    pub fn selection(&self, options: &ReplayOptions) -> Selection {
        Selection::of(options, &self.seen, self.sweeps)
    }

    /// A few lines for people, ending with the time in the core.
    pub fn render(&self) -> String {
        self.render_timed(None)
    }

    /// A few lines for people, ending with the time the whole run took
    /// (`total`, when given: reading, the core, the outputs) and the time
    /// in the core.
    pub fn render_timed(&self, total: Option<Duration>) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let kinds = [Kind::Face, Kind::Edge, Kind::Vertex]
            .iter()
            .map(|k| format!("{} {k}", self.outcomes.get(k).copied().unwrap_or(0)))
            .collect::<Vec<_>>()
            .join(", ");
        let _ = writeln!(
            s,
            "{} {} replayed ({} filtered out) over {} {}: {} {} ({kinds}), {} without",
            self.sweeps,
            plural(self.sweeps, "sweep"),
            self.filtered_out,
            self.scenes,
            plural(self.scenes as u64, "scene"),
            self.collisions(),
            plural(self.collisions(), "collision"),
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
        if !self.skipped.is_empty() {
            let _ = writeln!(s, "{}, not tested", self.skipped.words());
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
        let tunnels = self.tunnel_count();
        if tunnels > 0 {
            let kinds = self
                .tunnels
                .iter()
                .map(|(k, n)| format!("{n} {k}"))
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(
                s,
                "tunnels (a ball's centre through a triangle, front to back): {tunnels} ({kinds})"
            );
            for t in &self.first_tunnels {
                let _ = writeln!(s, "  {t}");
            }
            if tunnels > self.first_tunnels.len() as u64 {
                let _ = writeln!(
                    s,
                    "  ... {} more",
                    tunnels - self.first_tunnels.len() as u64
                );
            }
        }
        if self.degenerate_triangles > 0 {
            let _ = writeln!(
                s,
                "degenerate triangles left out: {}",
                self.degenerate_triangles
            );
        }
        match total {
            Some(total) => {
                let _ = writeln!(
                    s,
                    "time: {:.3} s in all, {:.3} s of it in the core",
                    total.as_secs_f64(),
                    self.elapsed.as_secs_f64()
                );
            }
            None => {
                let _ = writeln!(s, "time in the core: {:.3} s", self.elapsed.as_secs_f64());
            }
        }
        s
    }
}
