//! The recording's side of the replay pipeline
//! ([`crate::replay::run_pipeline`]): the [`Logger`] as a
//! [`BatchRecorder`]. For each batch it works out what each sweep's ball
//! showed before it (in trace order), builds the rows of runs of up to
//! [`PREPARE_GROUP_SWEEPS`] consecutive sweeps on the workers, and logs
//! scenes and rows in trace order.

use std::collections::VecDeque;
use std::ops::Range;

use rayon::prelude::*;
use thiserror::Error;

use crate::replay::{BatchRecorder, PipelineEvent as Event, ReplayEvent, sweep_of};

use super::{
    Logger, PREPARE_GROUP_SWEEPS, PrepareOptions, PreparedSweeps, RecordError,
    RecordingStreamError, Shown, prepare_sweeps_into, rows,
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

/// A batch's plan: the runs of consecutive sweeps, what each sweep's ball
/// showed before it, and emptied buffers to reuse.
pub struct Plan {
    options: PrepareOptions,
    groups: Vec<Range<usize>>,
    before: Vec<Shown>,
    spares: Vec<PreparedSweeps>,
}

/// A batch's rows: each run's, with the index of its first sweep.
pub struct Prepared(VecDeque<(usize, PreparedSweeps)>);

impl BatchRecorder for Logger {
    type Plan = Plan;
    type Prepared = Prepared;
    type Error = LogError;

    fn plan(&mut self, batch: &[Event], pool: &rayon::ThreadPool) -> Plan {
        let options = self.prepare_options();
        // Runs of consecutive sweeps: the rows of each run are built on one
        // worker.
        let groups = sweep_runs(batch);
        // What each sweep shows, in parallel; then, in order, what its
        // ball's previous sweep (perhaps in another run) showed.
        let nows: Vec<(u32, Shown)> = pool.install(|| {
            batch
                .par_iter()
                .filter_map(sweep_of)
                .map(|r| (r.ball, rows::shown_of(r, &options)))
                .collect()
        });
        let mut shown = self.shown_before_given(nows).into_iter();
        let before = batch
            .iter()
            .map(|e| match sweep_of(e) {
                Some(_) => shown.next().unwrap_or_default(),
                None => Shown::default(),
            })
            .collect();
        let spares = groups.iter().map(|_| self.spare_prepared()).collect();
        Plan {
            options,
            groups,
            before,
            spares,
        }
    }

    fn prepare(plan: Plan, batch: &[Event]) -> Prepared {
        let Plan {
            options,
            groups,
            before,
            spares,
        } = plan;
        let rows: Vec<PreparedSweeps> = groups
            .par_iter()
            .zip(spares)
            .map(|(g, mut p)| {
                prepare_sweeps_into(
                    &mut p,
                    batch[g.clone()].iter().filter_map(sweep_of),
                    &before[g.clone()],
                    &options,
                );
                p
            })
            .collect();
        Prepared(groups.iter().map(|g| g.start).zip(rows).collect())
    }

    fn record(
        &mut self,
        index: usize,
        event: &Event,
        prepared: &mut Prepared,
    ) -> Result<(), LogError> {
        match event {
            Ok(ReplayEvent::Scene(scene)) => {
                self.log_scene(scene).map_err(|cause| LogError::Scene {
                    scene: scene.number,
                    cause,
                })
            }
            Ok(ReplayEvent::Sweep(result)) => {
                self.saw_frame(result.frame)
                    .map_err(|cause| LogError::Sweeps {
                        frame: result.frame,
                        cause: cause.into(),
                    })?;
                if prepared.0.front().is_some_and(|(start, _)| *start == index)
                    && let Some((_, rows)) = prepared.0.pop_front()
                {
                    self.log_prepared(rows).map_err(|cause| LogError::Sweeps {
                        frame: result.frame,
                        cause,
                    })?;
                }
                Ok(())
            }
            Err(_) => Ok(()),
        }
    }
}

/// The runs of consecutive sweeps of `batch`, each at most
/// [`PREPARE_GROUP_SWEEPS`] long.
fn sweep_runs(batch: &[Event]) -> Vec<Range<usize>> {
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
