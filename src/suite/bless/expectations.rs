//! Blessing's pass 1: the trace replayed (with an engine, its answers
//! alongside, each checked as a writer of `/expected` checks it), and the
//! new expectation of every sweep, by `(frame, ball)` in trace order, with
//! the source record that names where they come from.

use std::collections::{HashMap, VecDeque};

use super::{BlessEngine, BlessError, BlessOptions, BlessSelection};
use crate::engine::{AnswerSink, EngineAnswers, EngineSession};
use crate::replay::{
    ReplayError, ReplayEvent, ReplayOptions, Selection, SweepExtent, SweepResult, replay_events,
};
use crate::trace::source::{MAX_NAME_BYTES, MAX_SETTING_VALUE_BYTES, sweeptrace_source};
use crate::trace::validate::{validate_outcome, validate_triangle};
use crate::trace::{ExpectedSource, OutcomeMsg, TraceReader};

/// What the replay pass found: the expectation to write after every sweep
/// of a trace (`None`: none), by `(frame, ball)` in trace order, and the
/// source of the new expectations.
pub(super) struct Replayed {
    pub(super) outcomes: HashMap<(u64, u32), VecDeque<Option<OutcomeMsg>>>,
    pub(super) source: ExpectedSource,
    pub(super) replaced: Option<ExpectedSource>,
    pub(super) blessed: u64,
    pub(super) kept: u64,
    pub(super) sweeps: u64,
}

/// Pass 1's bookkeeping: each replayed sweep's expectation to write.
#[derive(Default)]
struct Collected {
    outcomes: HashMap<(u64, u32), VecDeque<Option<OutcomeMsg>>>,
    /// The margins and facing rules the scenes were replayed with, in order.
    margins: Vec<String>,
    facings: Vec<String>,
    blessed: u64,
    kept: u64,
    sweeps: u64,
    /// The trace's frames and balls, for a selection that selects none.
    seen: SweepExtent,
}

impl Collected {
    /// Takes one replayed event; `answer` gives the engine's answer to a
    /// sweep, checked (with an engine: every sweep's, selected or not),
    /// else the core's outcome is the new expectation.
    fn event(
        &mut self,
        event: Result<ReplayEvent, ReplayError>,
        name: &str,
        select: &BlessSelection,
        answer: impl FnOnce(&SweepResult) -> Result<Option<OutcomeMsg>, BlessError>,
    ) -> Result<(), BlessError> {
        match event {
            Ok(ReplayEvent::Sweep(r)) => {
                self.sweeps += 1;
                self.seen.add(r.frame, r.ball);
                let answer = answer(&r)?;
                let written = if select.selects(r.frame, r.ball) {
                    self.blessed += 1;
                    Some(answer.unwrap_or_else(|| r.outcome_msg()))
                } else {
                    self.kept += u64::from(r.expected.is_some());
                    r.expected
                };
                self.outcomes
                    .entry((r.frame, r.ball))
                    .or_default()
                    .push_back(written);
            }
            Ok(ReplayEvent::Scene(scene)) => {
                for (list, value) in [
                    (&mut self.margins, scene.options.margin.to_string()),
                    (&mut self.facings, scene.options.facing.to_string()),
                ] {
                    if !list.contains(&value) {
                        list.push(value);
                    }
                }
            }
            Err(cause) => {
                return Err(BlessError::Replay {
                    file: name.to_string(),
                    cause,
                });
            }
        }
        Ok(())
    }
}

/// The engine's answer to the sweep `r`, if it gave one, when the trace
/// can hold it: checked as every writer of `/expected` checks an outcome
/// (its values, and a triangle of the sweep's scene), so that a snapshot
/// is never written that its own reader or writer would refuse.
fn checked_answer(
    answer: Option<OutcomeMsg>,
    r: &SweepResult,
    engine: &BlessEngine,
) -> Result<Option<OutcomeMsg>, BlessError> {
    let Some(answer) = answer else {
        return Ok(None);
    };
    validate_outcome(&answer)
        .and_then(|()| validate_triangle(&answer, r.scene.mesh.triangles().len()))
        .map_err(|problem| BlessError::Answer {
            command: engine.command.text.clone(),
            frame: r.frame,
            ball: r.ball,
            field: problem.field,
            problem: problem.problem,
        })?;
    Ok(Some(answer))
}

/// `text` cut to at most `max` bytes, at a character boundary, with `...`
/// when cut.
fn clipped(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_string();
    }
    let mut end = max.saturating_sub(3);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}...", &text[..end])
}

/// Values in words, the first few of many only (a setting's value is
/// bounded: [`crate::trace::source::MAX_SETTING_VALUE_BYTES`]).
fn listed(values: &[String]) -> String {
    const SHOWN: usize = 8;
    let text = values
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if values.len() > SHOWN {
        format!("{text} and {} more", values.len() - SHOWN)
    } else {
        text
    }
}

pub(super) fn outcomes_of(
    input: &[u8],
    name: &str,
    options: &BlessOptions,
) -> Result<Replayed, BlessError> {
    let replay = ReplayOptions {
        explain: None,
        frames: Default::default(),
        ball: None,
        ..options.replay
    };
    let mut collected = Collected::default();
    let mut reader = TraceReader::new_indexed(std::io::Cursor::new(input), name);
    match &options.engine {
        None => {
            for event in replay_events(reader.by_ref(), replay) {
                collected.event(event, name, &options.select, |_| Ok(None))?;
            }
        }
        Some(engine) => {
            let session = EngineSession::start(&engine.command, engine.options)
                .map_err(|cause| BlessError::Engine { cause })?;
            let sink = AnswerSink::default();
            let mut answers = EngineAnswers::keeping_expectations(
                reader.by_ref(),
                session,
                engine.options.window,
                sink.clone(),
            );
            for event in replay_events(answers.by_ref(), replay) {
                collected.event(event, name, &options.select, |r| {
                    checked_answer(sink.borrow_mut().remove(&(r.frame, r.ball)), r, engine)
                })?;
            }
            if let Some(cause) = answers.finish().error {
                return Err(BlessError::Engine { cause });
            }
        }
    }
    // A selection that selects no sweep would rewrite the trace for
    // nothing: an error naming what the trace holds, as a filter of
    // `check` or `replay` that keeps nothing.
    if collected.blessed == 0
        && let Some(filter) = options.select.text()
    {
        return Err(BlessError::NothingSelected {
            file: name.to_string(),
            selection: Selection::Nothing {
                filter,
                seen: collected.seen,
            },
        });
    }
    let replaced = reader.expected_source().cloned();
    let mut source = match &options.engine {
        None => {
            let source =
                sweeptrace_source(&listed(&collected.margins), &listed(&collected.facings));
            match &options.conventions {
                Some(text) => source.setting("conventions", clipped(text, MAX_SETTING_VALUE_BYTES)),
                None => source,
            }
        }
        Some(engine) => ExpectedSource::new(
            clipped(&engine.name, MAX_NAME_BYTES),
            clipped(&engine.version, MAX_NAME_BYTES),
        )
        .setting(
            "command",
            clipped(&engine.command.text, MAX_SETTING_VALUE_BYTES),
        )
        .setting(
            "blessed_by",
            format!("sweeptrace {}", env!("CARGO_PKG_VERSION")),
        ),
    };
    if options.select != BlessSelection::All {
        let earlier = match &replaced {
            Some(old) if collected.kept > 0 => {
                format!(" from {}", clipped(&old.engine, MAX_NAME_BYTES))
            }
            _ => String::new(),
        };
        source = source.setting(
            "blessed",
            format!(
                "{} of {} sweeps; the other {} keep their expectations{earlier}",
                collected.blessed, collected.sweeps, collected.kept
            ),
        );
    }
    Ok(Replayed {
        outcomes: collected.outcomes,
        source,
        replaced,
        blessed: collected.blessed,
        kept: collected.kept,
        sweeps: collected.sweeps,
    })
}
