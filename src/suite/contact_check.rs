//! `check`'s contact queries: each `/contact` query paired with the
//! `/expected_contacts` of the same frame and ball (in either order, within
//! one scene) and judged against the core's contact set
//! ([`judge_contacts`]), beside the sweeps' replay.

use serde::Serialize;

use crate::judge::{ContactPairing, ContactVerdict};
use crate::replay::ghost::GhostContact;
use crate::trace::{EventBody, TraceEvent};

use super::check::CheckOptions;

/// What `check` reports of a trace's contact queries (`contacts` in the
/// JSON, absent when the trace has none).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ContactsReport {
    /// `/contact` queries read (within the frame and ball selection).
    pub queries: u64,
    /// Queries judged against their `/expected_contacts`.
    pub compared: u64,
    /// Queries whose contacts disagree with the core's.
    pub divergent: u64,
    /// Queries without an answer in their scene.
    pub without_answer: u64,
    /// Answers without a query in their scene.
    pub answers_without_query: u64,
    /// Queries not judged because the answers come from an engine command
    /// that was not asked for contacts (`check --engine` without
    /// `--engine-contacts`, or against the trace's expectations).
    #[serde(skip_serializing_if = "is_zero")]
    pub not_asked: u64,
    /// The first divergent queries, in trace order (as many as the check's
    /// `max_details`).
    pub details: Vec<ContactVerdict>,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl ContactsReport {
    /// Whether the trace had nothing of contacts.
    pub fn is_empty(&self) -> bool {
        self.queries == 0 && self.answers_without_query == 0
    }
}

/// Whether `check_stream` judges the trace's contact answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ContactMode {
    /// Judge them against the core (`check`).
    Judge,
    /// Judge them against the core: they are an engine's answers (`check
    /// --engine --engine-contacts`; its ghost contacts say "the engine's
    /// normal").
    JudgeEngine,
    /// Count the queries only: the answers judged come from an engine
    /// command that is not asked for contacts.
    NotAsked,
}

/// The fold over a trace's events.
pub(crate) struct ContactChecker<'a> {
    options: &'a CheckOptions,
    mode: ContactMode,
    pairing: ContactPairing<'a>,
    report: ContactsReport,
    ghosts: Vec<GhostContact>,
    ghost_count: u64,
}

impl<'a> ContactChecker<'a> {
    pub(crate) fn new(options: &'a CheckOptions, mode: ContactMode) -> Self {
        ContactChecker {
            options,
            mode,
            pairing: ContactPairing::new(
                &options.tolerances,
                &options.replay.conventions,
                options.ghost_degrees,
            ),
            report: ContactsReport::default(),
            ghosts: Vec::new(),
            ghost_count: 0,
        }
    }

    /// One event of the trace (sweeps and expectations pass by).
    pub(crate) fn event(&mut self, event: &TraceEvent) {
        let judged = match &event.body {
            EventBody::Scene(scene) => {
                self.pairing.scene(scene);
                None
            }
            EventBody::Contact(query) => {
                if !self.options.replay.wants(query.frame, query.ball) {
                    return;
                }
                self.report.queries += 1;
                if self.mode == ContactMode::NotAsked {
                    self.report.not_asked += 1;
                    return;
                }
                self.pairing.query(query, event.header.log_time_nanos)
            }
            EventBody::ExpectedContacts(answer) => {
                if self.mode == ContactMode::NotAsked
                    || !self.options.replay.wants(answer.frame, answer.ball)
                {
                    return;
                }
                self.pairing.answer(answer)
            }
            EventBody::Sweep(_) | EventBody::Expected(_) => None,
        };
        if let Some(judged) = judged {
            self.judged(judged.verdict);
        }
    }

    fn judged(&mut self, mut verdict: ContactVerdict) {
        if self.mode == ContactMode::JudgeEngine {
            for ghost in &mut verdict.ghosts {
                ghost.answer = true;
            }
        }
        self.report.compared += 1;
        self.ghost_count += verdict.ghosts.len() as u64;
        for ghost in &verdict.ghosts {
            if self.ghosts.len() < super::ghost_count::MAX_LISTED_GHOSTS {
                self.ghosts.push(*ghost);
            }
        }
        if !verdict.agrees() {
            self.report.divergent += 1;
            if self.report.details.len() < self.options.max_details {
                self.report.details.push(verdict);
            }
        }
    }

    /// The report, the ghost contacts (how many, the first of them) and
    /// the errors.
    pub(crate) fn finish(mut self) -> (ContactsReport, u64, Vec<GhostContact>, Vec<String>) {
        self.pairing.flush();
        self.report.without_answer = self.pairing.without_answer;
        self.report.answers_without_query = self.pairing.answers_without_query;
        let errors = std::mem::take(&mut self.pairing.errors);
        (self.report, self.ghost_count, self.ghosts, errors)
    }
}
