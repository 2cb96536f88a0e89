//! What the replay keeps of a sweep's test records at
//! [`Detail::Primary`](super::Detail::Primary): the primary test and its
//! ties, or the nearest miss ([`primary_records`]), and the observer that
//! keeps only those while the core runs ([`CollectPrimary`]).
//!
//! At `primary` the core tests only what the fast query tests: the
//! candidates it skips (back-facing, plane out of reach) are counted by
//! reason, not tested, so the verdict counts cover the tested candidates
//! and the nearest miss is the nearest among them.

use crate::core::Outcome;
use crate::core::explain::{
    edge_miss_distance, face_miss_distance, nearest_miss, vertex_miss_distance,
};
use crate::core::record::{
    EdgeRecord, FaceRecord, Observer, Skip, SkipCounts, TestRecord, Verdict, VerdictCounts,
    VertexRecord,
};

/// An observer that keeps, of a sweep's records, only what
/// [`primary_records`] can return (every hit; while nothing is hit, the
/// nearest miss so far, [`nearest_miss`]'s first of equals) and counts the
/// verdicts of all: the same answer as collecting every record of the
/// tested candidates, without storing them. It lets the core skip what the
/// fast query skips, and counts those candidates by [`Skip`] reason.
#[derive(Debug, Default)]
pub struct CollectPrimary {
    /// Every hit, in the order the tests ran.
    hits: Vec<TestRecord>,
    /// Whether one of `hits` makes the outcome a hit (one at an `α` below
    /// infinity, as the core's decision counts them).
    found_hit: bool,
    /// The rejected test nearest to a hit so far, with its distance; not
    /// looked for once something is hit (the outcome is then a hit, whose
    /// records are hits).
    nearest: Option<(f64, TestRecord)>,
    /// Tests run, by verdict.
    verdicts: VerdictCounts,
    /// Candidates skipped without a test, by reason.
    skipped: SkipCounts,
}

impl CollectPrimary {
    /// One test's record: its verdict, whether it hit (`alpha`), its
    /// [`miss_distance`](crate::core::explain::miss_distance) and the
    /// record itself, made only when kept.
    #[inline]
    fn keep(
        &mut self,
        verdict: Verdict,
        alpha: Option<f64>,
        distance: impl FnOnce() -> Option<f64>,
        record: impl Fn() -> TestRecord,
    ) {
        self.verdicts.add(verdict);
        if let Some(a) = alpha {
            self.hits.push(record());
            self.found_hit |= a < f64::INFINITY;
        } else if !self.found_hit
            && let Some(d) = distance()
            && self
                .nearest
                .as_ref()
                .is_none_or(|(best, _)| d.total_cmp(best).is_lt())
        {
            self.nearest = Some((d, record()));
        }
    }

    /// The tests run, by verdict.
    pub fn verdict_counts(&self) -> VerdictCounts {
        self.verdicts
    }

    /// The candidates skipped without a test, by reason.
    pub fn skip_counts(&self) -> SkipCounts {
        self.skipped
    }

    /// [`primary_records`] of every record this observer saw.
    pub fn into_primary_records(self, outcome: &Outcome) -> Vec<TestRecord> {
        if outcome.is_hit() {
            // The records `primary_records` keeps of a hit are all hits.
            primary_records(outcome, self.hits)
        } else {
            self.nearest.map(|(_, r)| r).into_iter().collect()
        }
    }
}

impl Observer for CollectPrimary {
    const TESTS_EVERY_CANDIDATE: bool = false;

    #[inline]
    fn skipped(&mut self, _triangle: u32, reason: Skip) {
        self.skipped.add(reason);
    }
    #[inline]
    fn face(&mut self, r: &FaceRecord) {
        self.keep(
            r.verdict,
            r.alpha(),
            || face_miss_distance(r),
            || TestRecord::Face(*r),
        );
    }
    #[inline]
    fn edge(&mut self, r: &EdgeRecord) {
        self.keep(
            r.verdict,
            r.alpha(),
            || edge_miss_distance(r),
            || TestRecord::Edge(*r),
        );
    }
    #[inline]
    fn vertex(&mut self, r: &VertexRecord) {
        self.keep(
            r.verdict,
            r.alpha(),
            || vertex_miss_distance(r),
            || TestRecord::Vertex(*r),
        );
    }
}

/// The records of [`Detail::Primary`](super::Detail::Primary): the primary test, then every other
/// hit tied with it ([`Outcome::ties_with`]); when nothing is hit,
/// the nearest miss.
pub fn primary_records(outcome: &Outcome, records: Vec<TestRecord>) -> Vec<TestRecord> {
    if !outcome.is_hit() {
        return nearest_miss(&records).copied().into_iter().collect();
    }
    let mut out: Vec<TestRecord> = records
        .iter()
        .filter(|r| outcome.is_reported_by(r))
        .take(1)
        .copied()
        .collect();
    out.extend(
        records.into_iter().filter(|r| {
            r.alpha().is_some_and(|a| outcome.ties_with(a)) && !outcome.is_reported_by(r)
        }),
    );
    out
}
