//! Checking another engine directly: the engine runs as a child process
//! and answers the sweeps of a trace over its standard input and output, in
//! JSON lines (the protocol of `docs/ENGINE_PROTOCOL.md`).
//!
//! - [`EngineCommand`]: the command line that starts the engine;
//! - [`EngineSession`]: the running engine: a
//!   writer thread feeding its stdin, a reader thread parsing its stdout,
//!   the last lines of its stderr kept for the error messages, a timeout on
//!   every answer;
//! - [`EngineAnswers`]: a trace's events with the engine's answers put in
//!   as each sweep's expectation, pipelined (up to
//!   [`EngineOptions::window`] sweeps in flight), so that `check`'s whole
//!   machinery (comparison, ties, fragility, reports) judges them.
//!
//! Every fault of the engine is an [`EngineError`] naming the engine and,
//! where there is one, the sweep: it does not start, exits early (with its
//! last stderr lines), prints a line that is not an outcome, answers
//! another sweep than the one due, or does not answer in time.

// An engine's error carries its command, the line and its last stderr
// lines; it happens once per run, so its size does not matter.
#![allow(clippy::result_large_err)]

mod answers;
mod command;
mod error;
mod process;
pub mod protocol;

pub use answers::{AnswerSink, EngineAnswers, EngineRun};
pub use command::EngineCommand;
pub use error::EngineError;
pub use process::EngineSession;

use std::time::Duration;

/// Default time an engine has to answer the next sweep.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(10);
/// Default number of sweeps sent ahead of the engine's answers.
pub const DEFAULT_WINDOW: usize = 1024;
/// How many of the engine's last stderr lines are kept for error messages.
pub const STDERR_TAIL_LINES: usize = 10;

/// How an engine is run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineOptions {
    /// The longest wait for the next answer (and for the engine to exit
    /// once its input is closed) before the engine is stopped and the
    /// run fails with [`EngineError::Timeout`].
    pub timeout: Duration,
    /// How many sweeps may be sent before their answers are read (at
    /// least 1): the pipeline that keeps a fast engine busy.
    pub window: usize,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions {
            timeout: DEFAULT_TIMEOUT,
            window: DEFAULT_WINDOW,
        }
    }
}

/// What an engine's answers are compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Against {
    /// The core's outcomes: the answers are the sweeps' expectations.
    #[default]
    Core,
    /// The trace's `/expected` channel: the answers are compared with it
    /// (ties and fragility are the core's decision's).
    Expected,
}

impl Against {
    /// `core` or `expected`.
    pub fn as_str(self) -> &'static str {
        match self {
            Against::Core => "core",
            Against::Expected => "expected",
        }
    }
}

/// Checks the trace at `path` against a running engine: the engine answers
/// every sweep ([`EngineAnswers`]) and the answers are judged by an
/// ordinary check ([`crate::regress::check_events_judged`]): with
/// [`Against::Core`] they are the expectations and the core's outcomes
/// are compared with them (the trace's `/expected` is not used); with
/// [`Against::Expected`] they are compared with the trace's `/expected`
/// ([`judge_answer_against_expected`]). Either way the report counts and
/// explains the differences, with ties and fragile decisions as `check`
/// treats them.
///
/// `Err` only when the engine cannot be started; any later fault of the
/// engine is an error of the report (what was answered before it is
/// reported too).
pub fn check_file_with_engine(
    path: &std::path::Path,
    command: &EngineCommand,
    engine: EngineOptions,
    against: Against,
    options: &crate::regress::CheckOptions,
) -> Result<crate::regress::TraceReport, EngineError> {
    let name = path.display().to_string();
    let engine_check = crate::regress::EngineCheck {
        command: command.text.clone(),
        against: against.as_str(),
    };
    let file = match std::fs::File::open(path) {
        Ok(file) => file,
        Err(_) => {
            let mut report = crate::regress::check_file(path, options);
            report.engine = Some(engine_check);
            return Ok(report);
        }
    };
    let session = EngineSession::start(command, engine)?;
    let mut reader =
        crate::trace::TraceReader::new(std::io::BufReader::with_capacity(1 << 16, file), &name);
    let (mut report, run) = match against {
        Against::Core => {
            let mut answers = EngineAnswers::new(reader.by_ref(), session, engine.window);
            let report = crate::regress::check_events(answers.by_ref(), &name, options);
            (report, answers.finish())
        }
        Against::Expected => {
            let sink = AnswerSink::default();
            let mut answers = EngineAnswers::keeping_expectations(
                reader.by_ref(),
                session,
                engine.window,
                sink.clone(),
            );
            let report =
                crate::regress::check_events_judged(answers.by_ref(), &name, options, |result| {
                    let answer = sink.borrow_mut().remove(&(result.frame, result.ball))?;
                    judge_answer_against_expected(result, answer, &options.tolerances)
                });
            (report, answers.finish())
        }
    };
    report.engine = Some(engine_check);
    report.has_expected_channel = match against {
        Against::Core => true,
        Against::Expected => reader
            .stats()
            .channels
            .contains_key(crate::trace::messages::EXPECTED_TOPIC),
    };
    if let Some(error) = run.error {
        if error.cannot_start() {
            return Err(error);
        }
        report.add_error(error.to_string());
    }
    Ok(report)
}

/// The trace's expectation of a sweep against an engine's answer to it:
/// equal fields are a match; answers that differ only in which member of
/// the core's tie set they name (kind, triangle, feature, and that member's
/// own contact) are a tie; otherwise a divergence, fragile when the core's
/// decision is. `None` when the sweep has no expectation.
pub fn judge_answer_against_expected(
    result: &crate::replay::SweepResult,
    answer: crate::trace::messages::OutcomeMsg,
    tolerances: &crate::regress::Tolerances,
) -> Option<crate::regress::Judged> {
    use crate::regress::{Agreement, Field, Judged, compare, explained_records};
    let expected = result.expected?;
    let fields = compare(&expected, &answer, tolerances);
    let agreement = if fields.is_empty() {
        Agreement::Match
    } else {
        let only_choice = fields.iter().all(|f| {
            matches!(
                f.field,
                Field::Kind | Field::Triangle | Field::Feature | Field::Contact
            )
        });
        let ties = if only_choice {
            result.outcome.tie_set(&explained_records(result))
        } else {
            Vec::new()
        };
        let names_member = |o: &crate::trace::messages::OutcomeMsg| {
            ties.iter()
                .any(|t| t.matches(o.kind, o.triangle, o.feature))
        };
        if only_choice && names_member(&expected) && names_member(&answer) {
            Agreement::Tie
        } else {
            Agreement::Diverges {
                fields,
                fragile: result.outcome.fragile,
            }
        }
    };
    Some(Judged {
        expected,
        got: answer,
        agreement,
        got_is_core: false,
    })
}
