//! `check`'s ghost contacts: each judged sweep's expectation, and an
//! engine's answer when it is not the core's outcome, judged with
//! [`judge_ghost`] and counted into the trace's report.

use crate::replay::SweepResult;

use super::report::{Ghosts, Judged};
use crate::replay::ghost::{GhostJudgement, judge_ghost};

/// How many ghost contacts a report lists, one line each.
pub const MAX_LISTED_GHOSTS: usize = 10;

/// Counts the ghost contacts of one judged sweep into `ghosts` (the first
/// [`MAX_LISTED_GHOSTS`] kept in detail), with its threshold
/// [`Ghosts::degrees`].
pub(super) fn count_ghosts(ghosts: &mut Ghosts, result: &SweepResult, judged: &Judged) {
    // The expectation, and an engine's answer when it is not
    // the core's outcome, judged for ghost contacts whatever
    // the compared fields.
    let answer = (!judged.got_is_core).then_some(&judged.got);
    for (outcome, is_answer) in [(Some(&judged.expected), false), (answer, true)] {
        let Some(outcome) = outcome else { continue };
        match judge_ghost(
            &result.scene.mesh,
            &result.scene.topology,
            outcome,
            result.log_time_nanos,
            result.outcome.hit.as_ref().map(|h| &h.normal),
            ghosts.degrees,
        ) {
            GhostJudgement::Ghost(mut g) => {
                ghosts.count += 1;
                if ghosts.contacts.len() < MAX_LISTED_GHOSTS {
                    g.answer = is_answer;
                    ghosts.contacts.push(g);
                }
            }
            GhostJudgement::NoNormal => ghosts.unjudged += 1,
            // An edge or vertex contact that does not say where it is (no
            // triangle or feature) cannot be placed, so cannot be judged.
            GhostJudgement::NotApplicable if unplaced(outcome) => ghosts.unjudged += 1,
            GhostJudgement::Fine | GhostJudgement::NotApplicable => {}
        }
    }
}

/// Whether `outcome` is an edge or vertex contact without its triangle or
/// its feature.
fn unplaced(outcome: &crate::trace::OutcomeMsg) -> bool {
    matches!(
        outcome.kind,
        crate::core::Kind::Edge | crate::core::Kind::Vertex
    ) && !matches!(
        (outcome.triangle, outcome.feature),
        (Some(Some(_)), Some(Some(_)))
    )
}
