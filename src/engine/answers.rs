//! A trace's events with an engine's answers as the sweeps' expectations.

use std::cell::RefCell;
use std::collections::{HashMap, VecDeque};
use std::rc::Rc;

use crate::trace::OutcomeMsg;

use crate::trace::{EventBody, TraceError, TraceEvent};

use super::{EngineError, EngineSession};

/// An event waiting to be handed on, in trace order.
enum Queued {
    /// A scene or a read error: handed on as it is.
    Ready(Result<TraceEvent, TraceError>),
    /// A sweep sent to the engine, handed on once its answer is read.
    Sweep(TraceEvent, (u64, u32)),
    /// A contact query sent to the engine, handed on once its answer is
    /// read.
    Contact(TraceEvent, (u64, u32)),
}

/// The events of a trace, with the trace's own `/expected` messages left
/// out and each sweep preceded by the engine's answer to it, as an
/// [`EventBody::Expected`] of that sweep. Scenes and sweeps go to the
/// engine as they are read, up to `window` sweeps ahead of the answers.
///
/// A fault of the engine ends the events (what came before stays valid);
/// [`EngineAnswers::finish`] returns it.
pub struct EngineAnswers<I> {
    input: I,
    session: Option<EngineSession>,
    window: usize,
    queue: VecDeque<Queued>,
    in_flight: usize,
    input_done: bool,
    front_answered: bool,
    error: Option<EngineError>,
    answered: u64,
    trace_expectations: u64,
    /// When set, the answers go here and the trace's expectations pass.
    sink: Option<AnswerSink>,
    /// Whether contact queries are sent to the engine (its answers then
    /// replace the trace's `/expected_contacts`); otherwise they pass with
    /// the trace's own answers.
    contacts: bool,
    /// The trace's own `/expected_contacts`, left out.
    trace_contacts: u64,
}

/// Where [`EngineAnswers::keeping_expectations`] puts the engine's
/// answers, by `(frame, ball)`, for the consumer to take.
pub type AnswerSink = Rc<RefCell<HashMap<(u64, u32), OutcomeMsg>>>;

/// How an engine's run over a trace ended.
#[derive(Debug)]
pub struct EngineRun {
    /// Sweeps the engine answered.
    pub answered: u64,
    /// The trace's own `/expected` messages, left out.
    pub trace_expectations: u64,
    /// The engine's fault, if any: the events ended there.
    pub error: Option<EngineError>,
}

impl<I> EngineAnswers<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    /// The events of `input` answered by `session`, with up to `window`
    /// sweeps in flight (at least 1).
    pub fn new(input: I, session: EngineSession, window: usize) -> Self {
        EngineAnswers {
            input,
            session: Some(session),
            window: window.max(1),
            queue: VecDeque::new(),
            in_flight: 0,
            input_done: false,
            front_answered: false,
            error: None,
            answered: 0,
            trace_expectations: 0,
            sink: None,
            contacts: false,
            trace_contacts: 0,
        }
    }

    /// Sends the trace's contact queries to the engine too, its answers in
    /// place of the trace's `/expected_contacts` (only with
    /// [`EngineAnswers::new`]: compared with the core).
    pub fn with_contacts(mut self, contacts: bool) -> Self {
        self.contacts = contacts && self.sink.is_none();
        self
    }

    /// Like [`EngineAnswers::new`], but the trace's own `/expected`
    /// messages pass unchanged and the engine's answers go into `sink`
    /// instead (each in before its sweep is handed on): to compare the
    /// engine with the trace's expectations.
    pub fn keeping_expectations(
        input: I,
        session: EngineSession,
        window: usize,
        sink: AnswerSink,
    ) -> Self {
        EngineAnswers {
            sink: Some(sink),
            ..EngineAnswers::new(input, session, window)
        }
    }

    /// Ends the run: the engine's input is closed and it must exit cleanly
    /// with nothing more to say. Returns how it went.
    pub fn finish(mut self) -> EngineRun {
        if let Some(session) = self.session.take() {
            let complete = self.input_done && self.queue.is_empty();
            if complete && self.error.is_none() {
                self.error = session.finish().err();
            }
            // Otherwise the events were not all taken: dropping the session
            // stops the engine.
        }
        EngineRun {
            answered: self.answered,
            trace_expectations: self.trace_expectations,
            error: self.error,
        }
    }

    fn fail(&mut self, error: EngineError) -> Option<Result<TraceEvent, TraceError>> {
        self.error = Some(error);
        self.session = None;
        self.queue.clear();
        None
    }

    /// Reads ahead and sends to the engine until `window` sweeps are in
    /// flight or the input ends.
    fn fill(&mut self) -> Result<(), EngineError> {
        let Some(session) = self.session.as_mut() else {
            return Ok(());
        };
        while !self.input_done && self.in_flight < self.window {
            match self.input.next() {
                None => self.input_done = true,
                Some(Ok(event)) => match &event.body {
                    EventBody::Expected(_) => {
                        self.trace_expectations += 1;
                        if self.sink.is_some() {
                            self.queue.push_back(Queued::Ready(Ok(event)));
                        }
                    }
                    EventBody::Contact(query) if self.contacts => {
                        session.send_contact(query)?;
                        let key = (query.frame, query.ball);
                        self.queue.push_back(Queued::Contact(event, key));
                        self.in_flight += 1;
                    }
                    EventBody::ExpectedContacts(_) if self.contacts => self.trace_contacts += 1,
                    // Not asked of the engine: the queries pass with the
                    // trace's own answers (the check counts them as not
                    // judged).
                    EventBody::Contact(_) | EventBody::ExpectedContacts(_) => {
                        self.queue.push_back(Queued::Ready(Ok(event)));
                    }
                    EventBody::Scene(scene) => {
                        session.send_scene(scene)?;
                        self.queue.push_back(Queued::Ready(Ok(event)));
                    }
                    EventBody::Sweep(sweep) => {
                        session.send_sweep(sweep)?;
                        let key = (sweep.frame, sweep.ball);
                        self.queue.push_back(Queued::Sweep(event, key));
                        self.in_flight += 1;
                    }
                },
                Some(Err(e)) => self.queue.push_back(Queued::Ready(Err(e))),
            }
        }
        Ok(())
    }
}

impl<I> Iterator for EngineAnswers<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    type Item = Result<TraceEvent, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.error.is_some() {
            return None;
        }
        if let Err(e) = self.fill() {
            return self.fail(e);
        }
        match self.queue.front()? {
            Queued::Ready(_) => match self.queue.pop_front() {
                Some(Queued::Ready(event)) => Some(event),
                _ => None,
            },
            Queued::Sweep(..) | Queued::Contact(..) if self.front_answered => {
                // Its answer was handed on: now the query itself.
                self.front_answered = false;
                self.in_flight -= 1;
                match self.queue.pop_front() {
                    Some(Queued::Sweep(event, _) | Queued::Contact(event, _)) => Some(Ok(event)),
                    _ => None,
                }
            }
            Queued::Contact(event, key) => {
                let (key, header) = (*key, event.header);
                let session = self.session.as_mut()?;
                match session.next_contacts(key) {
                    Ok(contacts) => {
                        self.front_answered = true;
                        Some(Ok(TraceEvent {
                            header,
                            body: EventBody::ExpectedContacts(contacts),
                        }))
                    }
                    Err(e) => self.fail(e),
                }
            }
            Queued::Sweep(event, key) => {
                let (key, header) = (*key, event.header);
                let session = self.session.as_mut()?;
                match session.next_answer(key) {
                    Ok(outcome) if self.sink.is_some() => {
                        self.answered += 1;
                        if let Some(sink) = &self.sink {
                            sink.borrow_mut().insert(key, outcome);
                        }
                        self.in_flight -= 1;
                        match self.queue.pop_front() {
                            Some(Queued::Sweep(event, _)) => Some(Ok(event)),
                            _ => None,
                        }
                    }
                    Ok(outcome) => {
                        self.front_answered = true;
                        self.answered += 1;
                        Some(Ok(TraceEvent {
                            header,
                            body: EventBody::Expected(outcome),
                        }))
                    }
                    Err(e) => self.fail(e),
                }
            }
        }
    }
}
