//! Iterators over a whole trace: sequential ([`replay_events`]) and with
//! the core queries of each batch in parallel ([`replay_events_parallel`]).

use std::collections::VecDeque;
use std::sync::Arc;

use crate::trace::{EventBody, TraceError, TraceEvent};

use super::replayer::{ComputedSweep, compute_sweep};
use super::{Replay, ReplayError, ReplayEvent, ReplayOptions, ReplaySummary};

/// Replays a stream of trace events (a [`crate::trace::TraceReader`], or
/// events built in memory).
pub fn replay_events<I>(events: I, options: ReplayOptions) -> ReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    ReplayIter {
        events,
        replay: Some(Replay::new(options)),
        tail: VecDeque::new(),
        summary: None,
    }
}

/// The iterator of [`replay_events`]: results in trace order, errors where
/// they occur. After a trace error (the reader stops there) the results held
/// back are still yielded; after an invalid scene or sweep the replay goes
/// on, and the caller decides whether to stop.
pub struct ReplayIter<I> {
    events: I,
    replay: Option<Replay>,
    tail: VecDeque<ReplayEvent>,
    summary: Option<ReplaySummary>,
}

impl<I> ReplayIter<I> {
    /// The counts so far; final once the iterator returned `None`.
    pub fn summary(&self) -> ReplaySummary {
        match (&self.summary, &self.replay) {
            (Some(s), _) => s.clone(),
            (None, Some(r)) => r.summary().clone(),
            (None, None) => ReplaySummary::default(),
        }
    }

    /// The engine, while the input lasts.
    pub fn replay(&self) -> Option<&Replay> {
        self.replay.as_ref()
    }
}

impl<I> Iterator for ReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    type Item = Result<ReplayEvent, ReplayError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.tail.pop_front() {
                return Some(Ok(e));
            }
            let replay = self.replay.as_mut()?;
            if let Some(e) = replay.next_event() {
                return Some(Ok(e));
            }
            match self.events.next() {
                Some(Ok(event)) => {
                    if let Err(err) = replay.push(event) {
                        return Some(Err(err));
                    }
                }
                Some(Err(err)) => {
                    self.finish();
                    return Some(Err(ReplayError::from(err)));
                }
                None => self.finish(),
            }
        }
    }
}

impl<I> ReplayIter<I> {
    fn finish(&mut self) {
        if let Some(replay) = self.replay.take() {
            let (events, summary) = replay.finish();
            self.tail.extend(events);
            self.summary = Some(summary);
        }
    }
}

/// Replays a stream of trace events like [`replay_events`], with the core
/// queries of each batch of `batch_events` events run in parallel on `pool`
/// (rayon's global pool when `None`). The results, their order, the errors
/// and the summary are those of [`replay_events`]: only the independent
/// part of each sweep (the query, [`compute_sweep`]) runs in parallel; the
/// bookkeeping goes through the same [`Replay`] in trace order.
///
/// A batch ends before a scene message, so every sweep of a batch is
/// against the scene in force at its start. Memory is bounded by one batch
/// of events and their results (plus the frame whose results are held back
/// for its `/expected` messages), whatever the trace's length.
pub fn replay_events_parallel<I>(
    events: I,
    options: ReplayOptions,
    batch_events: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
) -> ParallelReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    ParallelReplayIter {
        events,
        replay: Some(Replay::new(options)),
        out: VecDeque::new(),
        held_scene: None,
        summary: None,
        batch_events: batch_events.max(1),
        pool,
    }
}

/// The iterator of [`replay_events_parallel`].
pub struct ParallelReplayIter<I> {
    events: I,
    replay: Option<Replay>,
    out: VecDeque<Result<ReplayEvent, ReplayError>>,
    /// A scene message that ended the previous batch.
    held_scene: Option<TraceEvent>,
    summary: Option<ReplaySummary>,
    batch_events: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl<I> ParallelReplayIter<I> {
    /// The counts so far; final once the iterator returned `None`.
    pub fn summary(&self) -> ReplaySummary {
        match (&self.summary, &self.replay) {
            (Some(s), _) => s.clone(),
            (None, Some(r)) => r.summary().clone(),
            (None, None) => ReplaySummary::default(),
        }
    }
}

impl<I> ParallelReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    /// Reads, computes and pushes one batch; its results go to `out`.
    fn run_batch(&mut self) {
        let Some(replay) = self.replay.as_mut() else {
            return;
        };
        let mut batch: Vec<TraceEvent> = Vec::with_capacity(self.batch_events.min(1 << 16));
        batch.extend(self.held_scene.take());
        let mut end: Option<Option<TraceError>> = None;
        while batch.len() < self.batch_events {
            match self.events.next() {
                Some(Ok(event)) => {
                    let is_scene = |e: &TraceEvent| matches!(e.body, EventBody::Scene(_));
                    if is_scene(&event) && batch.iter().any(|e| !is_scene(e)) {
                        self.held_scene = Some(event);
                        break;
                    }
                    batch.push(event);
                }
                Some(Err(err)) => {
                    end = Some(Some(err));
                    break;
                }
                None => {
                    end = Some(None);
                    break;
                }
            }
        }

        // Leading scenes first, so the sweeps see the scene in force.
        let scenes = batch
            .iter()
            .take_while(|e| matches!(e.body, EventBody::Scene(_)))
            .count();
        let rest = batch.split_off(scenes);
        for event in batch {
            let result = replay.push(event);
            drain(replay, result, &mut self.out);
        }

        let scene = replay.current_scene().cloned();
        let options = *replay.options();
        let compute = |event: &TraceEvent| match (&event.body, &scene) {
            (EventBody::Sweep(sweep), Some(scene)) if options.wants(sweep.frame, sweep.ball) => {
                Some(compute_sweep(scene, sweep, event.header.index, &options))
            }
            _ => None,
        };
        let computed: Vec<Option<Result<ComputedSweep, ReplayError>>> = {
            use rayon::prelude::*;
            let run = || rest.par_iter().with_min_len(16).map(compute).collect();
            match &self.pool {
                Some(pool) => pool.install(run),
                None => run(),
            }
        };
        for (event, computed) in rest.into_iter().zip(computed) {
            let result = match event.body {
                EventBody::Sweep(sweep) => replay.sweep_computed(event.header, sweep, computed),
                body => replay.push(TraceEvent {
                    header: event.header,
                    body,
                }),
            };
            drain(replay, result, &mut self.out);
        }

        match end {
            None => {}
            Some(err) => {
                if let Some(err) = err {
                    self.out.push_back(Err(ReplayError::from(err)));
                }
                if let Some(replay) = self.replay.take() {
                    let (events, summary) = replay.finish();
                    self.out.extend(events.into_iter().map(Ok));
                    self.summary = Some(summary);
                }
            }
        }
    }
}

/// Moves the outcome of one push and what it made ready to `out`, in the
/// order [`ReplayIter`] yields them.
fn drain(
    replay: &mut Replay,
    result: Result<(), ReplayError>,
    out: &mut VecDeque<Result<ReplayEvent, ReplayError>>,
) {
    if let Err(err) = result {
        out.push_back(Err(err));
    }
    while let Some(e) = replay.next_event() {
        out.push_back(Ok(e));
    }
}

impl<I> Iterator for ParallelReplayIter<I>
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    type Item = Result<ReplayEvent, ReplayError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(e) = self.out.pop_front() {
                return Some(e);
            }
            self.replay.as_ref()?;
            self.run_batch();
        }
    }
}
