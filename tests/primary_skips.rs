//! `--detail primary` tests what the fast query tests: the candidates it
//! skips (back-facing, plane out of reach) are counted by reason, the
//! nearest miss is chosen among the tested ones, and the decision line says
//! how many were skipped. `candidates` keeps testing every candidate.
//! Pinned on the sample trace `traces/record_terrain.mcap`.

use std::path::Path;

use libtest_mimic::Trial;
use sweeptrace::core::record::{Skip, Verdict};
use sweeptrace::judge::Tolerances;
use sweeptrace::judge::decision_line;
use sweeptrace::replay::{
    Detail, ReplayEvent, ReplayOptions, ReplaySummary, SweepResult, replay_events,
};
use sweeptrace::trace::TraceReader;

use crate::{ensure, trial};

pub fn tests() -> Vec<Trial> {
    vec![trial!(primary_counts_skipped_candidates_by_reason)]
}

/// Candidates of the sample terrain trace skipped at `primary`.
const BACK_FACING: u64 = 5680;
/// The same, for the plane out of reach.
const OUT_OF_REACH: u64 = 3812;

fn replay(detail: Detail) -> anyhow::Result<(Vec<SweepResult>, ReplaySummary)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_terrain.mcap");
    let bytes = std::fs::read(&path)?;
    let options = ReplayOptions {
        explain: Some(detail),
        ..ReplayOptions::default()
    };
    let mut it = replay_events(
        TraceReader::new(bytes.as_slice(), "record_terrain.mcap"),
        options,
    );
    let mut out = Vec::new();
    for e in it.by_ref() {
        if let ReplayEvent::Sweep(r) = e? {
            out.push(*r);
        }
    }
    Ok((out, it.summary()))
}

fn primary_counts_skipped_candidates_by_reason() -> anyhow::Result<()> {
    let (primary, at_primary) = replay(Detail::Primary)?;
    let (candidates, at_candidates) = replay(Detail::Candidates)?;
    ensure!(primary.len() == candidates.len(), "different sweeps");
    let skipped = at_primary.skipped;
    let got = (
        skipped.get(Skip::BackFacing),
        skipped.get(Skip::PlaneOutOfReach),
    );
    ensure!(
        got == (BACK_FACING, OUT_OF_REACH),
        "skipped (back-facing, out of reach) {got:?}, pinned ({BACK_FACING}, {OUT_OF_REACH})"
    );
    ensure!(
        at_candidates.skipped.is_empty(),
        "candidates skipped {:?}",
        at_candidates.skipped
    );
    // Every skipped candidate is one triangle's seven tests not run.
    let tests = |s: &ReplaySummary| Verdict::ALL.iter().map(|&v| s.verdicts.get(v)).sum::<u64>();
    ensure!(
        tests(&at_primary) + 7 * skipped.total() == tests(&at_candidates),
        "{} tests at primary + 7 × {} skipped != {} at candidates",
        tests(&at_primary),
        skipped.total(),
        tests(&at_candidates)
    );
    let mut lines = 0;
    let mut first_miss = None;
    let mut first_rejected = None;
    for (p, c) in primary.iter().zip(&candidates) {
        ensure!(
            p.outcome == c.outcome,
            "frame {} ball {}: outcomes differ",
            p.frame,
            p.ball
        );
        ensure!(c.skipped.is_empty(), "a sweep at candidates skipped some");
        let (line, _) = decision_line(p, p.decisive_record(), &Tolerances::default());
        let says = line.contains("candidates skipped") || line.contains("candidate skipped");
        ensure!(
            says == (!p.outcome.is_hit() && !p.skipped.is_empty()),
            "frame {} ball {}: {line}",
            p.frame,
            p.ball
        );
        lines += usize::from(says);
        if says && line.contains("rejected") && first_rejected.is_none() {
            first_rejected = Some(line.clone());
        }
        if says && first_miss.is_none() {
            first_miss = Some(line);
        }
    }
    let first_miss = first_miss.unwrap_or_default();
    let first_rejected = first_rejected.unwrap_or_default();
    ensure!(
        (lines, first_miss.as_str(), first_rejected.as_str())
            == (SKIP_LINES, FIRST_MISS_LINE, FIRST_REJECTED_LINE),
        "{lines} lines name skips; the first:\n{first_miss}\nthe first with a nearest miss:\n{first_rejected}"
    );
    Ok(())
}

/// Decision lines that name skipped candidates (the misses with some).
const SKIP_LINES: usize = 852;
/// The decision line of the trace's first miss with skipped candidates.
const FIRST_MISS_LINE: &str = "frame 56 ball 1: no collision; 7 out-of-reach candidates skipped";
/// The first whose nearest miss is one of the tested candidates.
const FIRST_REJECTED_LINE: &str = "frame 62 ball 1: no collision; closest candidate rejected: \
    face 2643: h0 = 0.88644, h1 = 0.75911, n·d = -0.12733, β = (h0 - ρ)/-(n·d) = 0.67888 in [0, 1], \
    touch point barycentric (-0.21313, -0.43492, 1.64805) outside the triangle: none; \
    3 out-of-reach candidates skipped";
