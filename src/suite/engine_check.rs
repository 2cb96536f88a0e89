//! `check --engine`: a trace's sweeps answered by a running engine (the
//! protocol client of [`crate::engine`]) and judged by the one judgement
//! ([`crate::judge`]), in an ordinary check's report.

// An engine's error carries its command, the line and its last stderr
// lines; it happens once per run, so its size does not matter.
#![allow(clippy::result_large_err)]

use crate::engine::{
    AnswerSink, EngineAnswers, EngineCommand, EngineError, EngineOptions, EngineSession,
};
use crate::replay::SweepResult;
use crate::trace::{EXPECTED_TOPIC, ExpectedSource, OutcomeMsg, TraceEvent, TraceReader};

use super::check::{CheckOptions, check_file, check_stream, judge_against_core};
use super::contact_check::ContactMode;
use super::report::{Against, EngineCheck, Judged, TraceReport};
use crate::judge::Tolerances;
use crate::judge::agreement_of;

/// Checks the trace at `path` against a running engine: the engine answers
/// every sweep ([`EngineAnswers`]) and the answers are judged by an
/// ordinary check ([`check_events_judged`](super::check::check_events_judged)): with [`Against::Core`] they
/// are the expectations and the core's outcomes are compared with them
/// (the trace's `/expected` is not used); with [`Against::Expected`] they
/// are compared with the trace's `/expected` ([`judge_answer_against_expected`]).
/// Either way the report counts and explains the differences, with ties
/// and fragile decisions judged as `check` judges them.
///
/// `Err` only when the engine cannot be started; any later fault of the
/// engine is an error of the report (what was answered before it is
/// reported too).
pub fn check_file_with_engine(
    path: &std::path::Path,
    command: &EngineCommand,
    engine: EngineOptions,
    against: Against,
    options: &CheckOptions,
) -> Result<TraceReport, EngineError> {
    let name = path.display().to_string();
    let engine_check = EngineCheck {
        command: command.text.clone(),
        against,
    };
    let file = match std::fs::File::open(path) {
        Ok(file) => file,
        Err(_) => {
            // The same report as `check` gives for a file it cannot open.
            let mut report = check_file(path, options);
            report.engine = Some(engine_check);
            return Ok(report);
        }
    };
    let session = EngineSession::start(command, engine)?;
    let mut reader =
        TraceReader::new_indexed(std::io::BufReader::with_capacity(1 << 16, file), &name);
    let (mut report, run) = match against {
        Against::Core => {
            let mut answers = EngineAnswers::new(reader.by_ref(), session, engine.window)
                .with_contacts(engine.contacts);
            let contacts = if engine.contacts {
                ContactMode::JudgeEngine
            } else {
                ContactMode::NotAsked
            };
            let (report, _) = check_stream(answers.by_ref(), &name, options, contacts, |result| {
                judge_against_core(result, &options.tolerances)
            });
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
            let (report, _) = check_stream(
                answers.by_ref(),
                &name,
                options,
                ContactMode::NotAsked,
                |result| {
                    let answer = sink.borrow_mut().remove(&(result.frame, result.ball))?;
                    judge_answer_against_expected(result, answer, &options.tolerances)
                },
            );
            (report, answers.finish())
        }
    };
    report.engine = Some(engine_check);
    // The recorded paths' tunnels are the trace's, not the engine's.
    if report.tunnels.count > 0 {
        report.tunnels.of_the_recording = true;
        report.tunnels.fail = false;
    }
    report.expected_source = reader.expected_source().cloned();
    report.expectations.has_channel = match against {
        Against::Core => true,
        Against::Expected => reader.stats().channels.contains_key(EXPECTED_TOPIC),
    };
    if let Some(error) = run.error {
        if error.cannot_start() {
            return Err(error);
        }
        report.add_error(error.to_string());
    }
    Ok(report)
}

/// The trace's expectation of a sweep against an engine's answer to it,
/// judged by the one judgement ([`agreement_of`]): a match; a tie when both
/// are answers the core's decision accepts (its primary, or another member
/// of its tie set with that member's own contact); otherwise a divergence,
/// excused as fragile only when a perturbation of the inputs gives each
/// side's answer. `None` when the sweep has no expectation.
pub fn judge_answer_against_expected(
    result: &SweepResult,
    answer: OutcomeMsg,
    tolerances: &Tolerances,
) -> Option<Judged> {
    let expected = result.expected?;
    Some(Judged {
        agreement: agreement_of(&expected, &answer, result, tolerances),
        expected,
        got: answer,
        got_is_core: false,
    })
}

/// One engine's answers to one trace, kept to be judged again
/// ([`record_engine_answers`]): `--infer-config` judges the same answers
/// under many conventions, and an engine does not answer differently for
/// them, so it runs once per trace instead of once per trial.
#[derive(Clone, Debug)]
pub struct RecordedAnswers {
    /// The trace's events, the engine's answers as its expectations (the
    /// trace's own `/expected` left out).
    events: Vec<TraceEvent>,
    /// The trace's expectations' source, as its reader found it.
    expected_source: Option<ExpectedSource>,
    /// The engine's command, as the report names it.
    command: String,
    /// Whether the engine answered the contact queries too
    /// (`--engine-contacts`): its answers are then among the events.
    contacts: bool,
}

/// Runs the engine over the trace at `path` once and keeps its answers;
/// `Ok(None)` when the run did not end cleanly (the file cannot be
/// opened, a trace error, a fault of the engine): then judge with
/// [`check_file_with_engine`], whose report says what went wrong. `Err`
/// only when the engine cannot be started.
pub fn record_engine_answers(
    path: &std::path::Path,
    command: &EngineCommand,
    engine: EngineOptions,
) -> Result<Option<RecordedAnswers>, EngineError> {
    let name = path.display().to_string();
    let Ok(file) = std::fs::File::open(path) else {
        return Ok(None);
    };
    let session = EngineSession::start(command, engine)?;
    let mut reader =
        TraceReader::new_indexed(std::io::BufReader::with_capacity(1 << 16, file), &name);
    let mut answers =
        EngineAnswers::new(reader.by_ref(), session, engine.window).with_contacts(engine.contacts);
    let mut events = Vec::new();
    for event in answers.by_ref() {
        match event {
            Ok(event) => events.push(event),
            Err(_) => return Ok(None),
        }
    }
    if let Some(error) = answers.finish().error {
        if error.cannot_start() {
            return Err(error);
        }
        return Ok(None);
    }
    Ok(Some(RecordedAnswers {
        events,
        expected_source: reader.expected_source().cloned(),
        command: command.text.clone(),
        contacts: engine.contacts,
    }))
}

/// The report of [`check_file_with_engine`] against the core for the
/// answers `recorded` kept (the same judgement, without running the
/// engine again): `name` is the trace's.
pub fn check_recorded_answers(
    recorded: &RecordedAnswers,
    name: &str,
    options: &CheckOptions,
) -> TraceReport {
    let events = recorded.events.iter().cloned().map(Ok);
    let contacts = if recorded.contacts {
        ContactMode::JudgeEngine
    } else {
        ContactMode::NotAsked
    };
    let (mut report, _) = check_stream(events, name, options, contacts, |result| {
        judge_against_core(result, &options.tolerances)
    });
    report.engine = Some(EngineCheck {
        command: recorded.command.clone(),
        against: Against::Core,
    });
    if report.tunnels.count > 0 {
        report.tunnels.of_the_recording = true;
        report.tunnels.fail = false;
    }
    report.expected_source = recorded.expected_source.clone();
    report.expectations.has_channel = true;
    report
}
