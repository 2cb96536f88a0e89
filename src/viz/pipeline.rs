//! The replay's output pipeline: the one implementation used by the
//! `replay` command and by the replay benchmark, so the benchmark measures
//! the program users run.
//!
//! Events are taken from the replay in bounded batches. For each batch, in
//! parallel on the given pool: every sweep's outcome line (JSON) and, in runs
//! of up to [`PREPARE_GROUP_SWEEPS`] consecutive sweeps, the recording's rows.
//! Then, in trace order: scenes and prepared rows go to the [`Logger`], and
//! each event with its outcome line to the caller. Memory is bounded by one
//! batch of events and their rows, whatever the trace's length.

use std::ops::Range;

use rayon::prelude::*;
use thiserror::Error;

use crate::replay::{DEFAULT_BATCH_EVENTS, ReplayError, ReplayEvent, SweepResult};

use super::{
    Logger, PREPARE_GROUP_SWEEPS, PreparedSweeps, RecordError, RecordingStreamError, Shown,
    prepare_sweeps_into,
};

/// Logging to the recording failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum LogError {
    /// Logging a scene's mesh.
    #[error("logging scene {scene}: {}", crate::error_text::full_text(.cause))]
    Scene {
        /// [`crate::replay::SceneState::number`] of the scene.
        scene: usize,
        /// The SDK's error.
        cause: RecordingStreamError,
    },
    /// Logging the rows of a run of sweeps.
    #[error("logging the frames from {frame}: {}", crate::error_text::full_text(.cause))]
    Sweeps {
        /// Frame of the run's first sweep.
        frame: u64,
        /// What failed.
        cause: RecordError,
    },
}

/// What the pipeline produces besides the recording.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PipelineOptions {
    /// Serialize every sweep's outcome as one JSON line (on the workers).
    pub outcome_lines: bool,
    /// Events per batch ([`DEFAULT_BATCH_EVENTS`] when 0).
    pub batch_events: usize,
}

/// The result of a sweep event.
fn sweep_of(event: &Result<ReplayEvent, ReplayError>) -> Option<&SweepResult> {
    match event {
        Ok(ReplayEvent::Sweep(result)) => Some(result),
        _ => None,
    }
}

/// Runs every event of `events` through the pipeline (see the module
/// documentation) and hands each one, in trace order, to `each` with its
/// outcome line (`None` when lines are not asked for, or for scenes and
/// errors). Stops at the first error of `each` or of the logger; errors of
/// the replay itself are handed to `each`, which decides.
pub fn run_pipeline<I, E>(
    events: &mut I,
    pool: &rayon::ThreadPool,
    mut logger: Option<&mut Logger>,
    options: PipelineOptions,
    mut each: impl FnMut(Result<ReplayEvent, ReplayError>, Option<String>) -> Result<(), E>,
) -> Result<(), E>
where
    I: Iterator<Item = Result<ReplayEvent, ReplayError>>,
    E: From<LogError>,
{
    let batch_events = match options.batch_events {
        0 => DEFAULT_BATCH_EVENTS,
        n => n,
    };
    let prepare_options = logger.as_ref().map(|l| l.prepare_options());
    let mut batch = Vec::with_capacity(batch_events);
    loop {
        batch.clear();
        batch.extend(events.by_ref().take(batch_events));
        if batch.is_empty() {
            return Ok(());
        }
        // Runs of consecutive sweeps: the rows of each run are built on one
        // worker.
        let groups: Vec<Range<usize>> = match prepare_options {
            Some(_) => sweep_runs(&batch),
            None => Vec::new(),
        };
        // What each sweep's ball showed before it (sequential: it depends
        // on the ball's previous sweep, perhaps in another run).
        let before: Vec<Shown> = match (logger.as_mut(), &prepare_options) {
            (Some(l), Some(prepare_options)) => {
                // What each sweep shows, in parallel; then, in order, what
                // its ball's previous sweep showed.
                let nows: Vec<(u32, Shown)> = pool.install(|| {
                    batch
                        .par_iter()
                        .filter_map(sweep_of)
                        .map(|r| (r.ball, Shown::of(r, prepare_options)))
                        .collect()
                });
                let mut shown = l.shown_before_given(nows).into_iter();
                batch
                    .iter()
                    .map(|e| match sweep_of(e) {
                        Some(_) => shown.next().unwrap_or_default(),
                        None => Shown::default(),
                    })
                    .collect()
            }
            _ => Vec::new(),
        };
        // Emptied buffers of earlier runs, reused.
        let spares: Vec<PreparedSweeps> = match logger.as_mut() {
            Some(l) => groups.iter().map(|_| l.spare_prepared()).collect(),
            None => Vec::new(),
        };
        let (lines, prepared): (Vec<Option<String>>, Vec<PreparedSweeps>) = pool.install(|| {
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
                || {
                    let Some(prepare_options) = &prepare_options else {
                        return Vec::new();
                    };
                    groups
                        .par_iter()
                        .zip(spares)
                        .map(|(g, mut p)| {
                            prepare_sweeps_into(
                                &mut p,
                                batch[g.clone()].iter().filter_map(sweep_of),
                                &before[g.clone()],
                                prepare_options,
                            );
                            p
                        })
                        .collect()
                },
            )
        });
        let mut lines = lines.into_iter();
        let mut prepared = groups.iter().map(|g| g.start).zip(prepared).peekable();
        for (i, event) in batch.drain(..).enumerate() {
            let line = lines.next().flatten();
            if let Some(l) = logger.as_mut() {
                match &event {
                    Ok(ReplayEvent::Scene(scene)) => {
                        l.log_scene(scene).map_err(|cause| LogError::Scene {
                            scene: scene.number,
                            cause,
                        })?;
                    }
                    Ok(ReplayEvent::Sweep(result)) => {
                        if let Some((_, rows)) = prepared.next_if(|(start, _)| *start == i) {
                            l.log_prepared(rows).map_err(|cause| LogError::Sweeps {
                                frame: result.frame,
                                cause,
                            })?;
                        }
                    }
                    Err(_) => {}
                }
            }
            each(event, line)?;
        }
    }
}

/// The runs of consecutive sweeps of `batch`, each at most
/// [`PREPARE_GROUP_SWEEPS`] long.
fn sweep_runs(batch: &[Result<ReplayEvent, ReplayError>]) -> Vec<Range<usize>> {
    let mut groups: Vec<Range<usize>> = Vec::new();
    for (i, event) in batch.iter().enumerate() {
        if !matches!(event, Ok(ReplayEvent::Sweep(_))) {
            continue;
        }
        match groups.last_mut() {
            Some(g) if g.end == i && g.len() < PREPARE_GROUP_SWEEPS => g.end += 1,
            _ => groups.push(i..i + 1),
        }
    }
    groups
}
