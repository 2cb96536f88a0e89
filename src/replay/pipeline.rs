//! The replay's output pipeline: the one implementation used by the
//! `replay` command and by the replay benchmark, with or without a
//! recording (a parallel `--outcomes` needs no viewer).
//!
//! Events are taken from the replay in bounded batches. For each batch, in
//! parallel on the given pool: every sweep's outcome line (JSON) and what a
//! [`BatchRecorder`] prepares of the batch (a Rerun recording's rows, built
//! by `viz`). Then, in trace order: each event goes to the recorder and,
//! with its outcome line, to the caller. Memory is bounded by one batch of
//! events and what was prepared of it, whatever the trace's length.

use std::convert::Infallible;

use rayon::prelude::*;

use super::{DEFAULT_BATCH_EVENTS, ReplayError, ReplayEvent, SweepResult};

/// One event of a replay, as the pipeline hands it on.
pub type Event = Result<ReplayEvent, ReplayError>;

/// What the pipeline produces besides what the recorder records.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PipelineOptions {
    /// Serialize every sweep's outcome as one JSON line (on the workers).
    pub outcome_lines: bool,
    /// Events per batch ([`DEFAULT_BATCH_EVENTS`] when 0).
    pub batch_events: usize,
}

/// Something that records a replay batch by batch: its work on a batch is
/// split into a plan (on the caller's thread, in trace order: what depends
/// on earlier batches), the preparation (on the workers, beside the outcome
/// lines) and the recording of each event (in trace order).
pub trait BatchRecorder {
    /// What [`BatchRecorder::plan`] works out of a batch.
    type Plan: Send;
    /// What [`BatchRecorder::prepare`] builds of a batch.
    type Prepared: Send;
    /// Why recording an event failed.
    type Error;

    /// Plans the batch, on the caller's thread (it may use `pool`).
    fn plan(&mut self, batch: &[Event], pool: &rayon::ThreadPool) -> Self::Plan;

    /// Prepares the batch from its plan; runs on the pool, and may use
    /// rayon's parallel iterators.
    fn prepare(plan: Self::Plan, batch: &[Event]) -> Self::Prepared;

    /// Records event `index` of the batch (in trace order, every event
    /// once) from what was prepared.
    fn record(
        &mut self,
        index: usize,
        event: &Event,
        prepared: &mut Self::Prepared,
    ) -> Result<(), Self::Error>;
}

/// The recorder of a pipeline that records nothing: the outcome lines only.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRecorder;

impl BatchRecorder for NoRecorder {
    type Plan = ();
    type Prepared = ();
    type Error = Infallible;

    fn plan(&mut self, _: &[Event], _: &rayon::ThreadPool) {}

    fn prepare(_: (), _: &[Event]) {}

    fn record(&mut self, _: usize, _: &Event, _: &mut ()) -> Result<(), Infallible> {
        Ok(())
    }
}

/// The result of a sweep event.
pub(crate) fn sweep_of(event: &Event) -> Option<&SweepResult> {
    match event {
        Ok(ReplayEvent::Sweep(result)) => Some(result),
        _ => None,
    }
}

/// Runs every event of `events` through the pipeline (see the module
/// documentation), records it with `recorder` (when given) and hands it,
/// in trace order, to `each` with its outcome line (`None` when lines are
/// not asked for, or for scenes and errors). Stops at the first error of
/// `each` or of the recorder; errors of the replay itself are handed to
/// `each`, which decides.
pub fn run_pipeline<I, R, E>(
    events: &mut I,
    pool: &rayon::ThreadPool,
    mut recorder: Option<&mut R>,
    options: PipelineOptions,
    mut each: impl FnMut(Event, Option<String>) -> Result<(), E>,
) -> Result<(), E>
where
    I: Iterator<Item = Event>,
    R: BatchRecorder,
    E: From<R::Error>,
{
    let batch_events = match options.batch_events {
        0 => DEFAULT_BATCH_EVENTS,
        n => n,
    };
    let mut batch = Vec::with_capacity(batch_events);
    loop {
        batch.clear();
        batch.extend(events.by_ref().take(batch_events));
        if batch.is_empty() {
            return Ok(());
        }
        let plan = recorder.as_mut().map(|r| r.plan(&batch, pool));
        let (lines, prepared): (Vec<Option<String>>, Option<R::Prepared>) = pool.install(|| {
            rayon::join(
                || {
                    if !options.outcome_lines {
                        return Vec::new();
                    }
                    batch
                        .par_iter()
                        .with_min_len(64)
                        .map(|event| sweep_of(event).and_then(|r| r.outcome_line().ok()))
                        .collect()
                },
                || plan.map(|plan| R::prepare(plan, &batch)),
            )
        });
        let mut lines = lines.into_iter();
        let mut recording = recorder.as_mut().zip(prepared);
        for (i, event) in batch.drain(..).enumerate() {
            let line = lines.next().flatten();
            if let Some((r, prepared)) = recording.as_mut() {
                r.record(i, &event, prepared)?;
            }
            each(event, line)?;
        }
    }
}

/// [`run_pipeline`] without a recorder: the outcome lines only.
pub fn run_pipeline_unrecorded<I, E>(
    events: &mut I,
    pool: &rayon::ThreadPool,
    options: PipelineOptions,
    each: impl FnMut(Event, Option<String>) -> Result<(), E>,
) -> Result<(), E>
where
    I: Iterator<Item = Event>,
    E: From<Infallible>,
{
    run_pipeline(events, pool, None::<&mut NoRecorder>, options, each)
}
