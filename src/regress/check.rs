//! Regression checking: the core's outcomes compared with a trace's
//! `/expected` channel.
//!
//! [`check_events`] replays a whole trace (the same [`crate::replay`]
//! engine as `replay`) and returns a [`TraceReport`]: a [`Status`], the
//! counts, and the first divergences in detail ([`Divergence`]), each with
//! the explanation of what the core found and of the test that would have
//! produced the expected result (see [`super::compare()`] for the rule).
//! [`super::render_text`] and [`super::render_json`] are pure functions of
//! a report.
//!
//! Explanations are computed only for the divergences kept in detail, by
//! running the explained query over every triangle
//! ([`crate::core::Broadphase::Exhaustive`]): the fast path stays fast on
//! passing traces.

use std::collections::BTreeMap;

use crate::core::Feature;
use crate::replay::{ReplayError, ReplayEvent, ReplayOptions, SweepResult};
use crate::trace::{EXPECTED_TOPIC, OutcomeMsg, TraceError, TraceEvent, TraceReader};

use super::compare::{FieldDiff, Tolerances};
use super::conventions::EngineConventions;
use super::explain::{expected_tests, explain_outcome, explained_records};
use super::ghost_count::count_ghosts;
use super::infer::{ComparedSweep, MAX_INFERENCE_SWEEPS, infer};
use super::judge::{Agreement, agreement};
use super::report::{
    Divergence, Judged, KindChange, MAX_DIVERGENT_FRAMES, MAX_ERRORS, MAX_LISTED_TUNNELS,
    TraceReport, TunnelReport,
};
use super::repro::SweepInputs;

/// Default number of divergences described in detail per trace.
pub const DEFAULT_MAX_DETAILS: usize = 3;

/// Options of a check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckOptions {
    /// Tolerances of the comparison.
    pub tolerances: Tolerances,
    /// How many divergences are described in detail.
    pub max_details: usize,
    /// Whether a divergence on a fragile decision fails the check too.
    pub strict: bool,
    /// Whether a tunnel fails the check (the default: it is a bug of the
    /// recording engine, whatever the expectations say).
    pub fail_on_tunnel: bool,
    /// Whether a ghost contact fails the check (the default; see
    /// [`judge_ghost`](crate::replay::judge_ghost)).
    pub fail_on_ghost: bool,
    /// The angle, in degrees, above which an edge or vertex contact on an
    /// internal flat or concave place is a ghost contact
    /// ([`crate::replay::GHOST_DEGREES`] by default).
    pub ghost_degrees: f64,
    /// Whether divergences also give their inputs as hexadecimal floating
    /// point ([`Divergence::inputs_hex`]).
    pub hex: bool,
    /// The replay's options (frames, ball, overrides). `explain` and
    /// `detail` are ignored: the check runs the fast query and explains
    /// only the detailed divergences.
    pub replay: ReplayOptions,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            tolerances: Tolerances::default(),
            max_details: DEFAULT_MAX_DETAILS,
            strict: false,
            fail_on_tunnel: true,
            fail_on_ghost: true,
            ghost_degrees: crate::replay::GHOST_DEGREES,
            hex: false,
            replay: ReplayOptions::default(),
        }
    }
}

/// Checks a trace read from any [`std::io::Read`].
pub fn check_reader<R: std::io::Read>(
    reader: R,
    name: &str,
    options: &CheckOptions,
) -> TraceReport {
    check_trace(TraceReader::new(reader, name), name, options)
}

/// Checks the trace `reader` reads (see [`check_reader`]).
fn check_trace<R: std::io::Read>(
    mut reader: TraceReader<R>,
    name: &str,
    options: &CheckOptions,
) -> TraceReport {
    let (mut report, _) = check_stream(reader.by_ref(), name, options, |result| {
        judge_against_core(result, &options.tolerances)
    });
    report.has_expected_channel = reader.stats().channels.contains_key(EXPECTED_TOPIC);
    report.expected_source = reader.expected_source().cloned();
    report
}

/// The judgement of `check`: the sweep's expectation against the core's
/// outcome ([`agreement`]); `None` when the sweep has no expectation.
pub fn judge_against_core(result: &SweepResult, tolerances: &Tolerances) -> Option<Judged> {
    let expected = result.expected?;
    Some(Judged {
        agreement: agreement(&expected, result, tolerances),
        expected,
        got: result.outcome_msg(),
        got_is_core: true,
    })
}

/// Checks a trace given as a stream of events. `has_expected_channel` is
/// set from the events (true when any `/expected` message was seen);
/// [`check_reader`] sets it from the file's channels instead.
pub fn check_events<I>(events: I, name: &str, options: &CheckOptions) -> TraceReport
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    check_events_judged(events, name, options, |result| {
        judge_against_core(result, &options.tolerances)
    })
}

/// [`check_events`] with another judgement of each replayed sweep (`check
/// --engine --against expected` compares an engine's answers with the
/// trace's expectations): the counts, details and report are the same.
pub fn check_events_judged<I, J>(
    events: I,
    name: &str,
    options: &CheckOptions,
    judge: J,
) -> TraceReport
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
    J: FnMut(&SweepResult) -> Option<Judged>,
{
    let (mut report, saw_expected) = check_stream(events, name, options, judge);
    report.has_expected_channel = saw_expected;
    report
}

/// The check of a stream of events with `judge`, except whether the trace
/// has an `/expected` channel (`has_expected_channel` is left false: each
/// caller sets it once, from what it knows); returns the report and whether
/// any `/expected` message was seen.
pub(crate) fn check_stream<I, J>(
    events: I,
    name: &str,
    options: &CheckOptions,
    mut judge: J,
) -> (TraceReport, bool)
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
    J: FnMut(&SweepResult) -> Option<Judged>,
{
    let mut saw_expected = false;
    let events = events.inspect(|e| {
        if matches!(e, Ok(TraceEvent::Expected { .. })) {
            saw_expected = true;
        }
    });
    let replay_options = ReplayOptions {
        explain: None,
        ..options.replay
    };
    let mut report = TraceReport {
        trace: name.to_string(),
        sweeps: 0,
        compared: 0,
        divergent: 0,
        ties: 0,
        fragile_divergent: 0,
        fragile_by_reason: BTreeMap::new(),
        fragile_divergences: Vec::new(),
        strict: options.strict,
        precision_divergent: 0,
        max_backward_error: 0.0,
        conventions: EngineConventions::of(&options.tolerances, &options.replay),
        tunnels: 0,
        tunnels_by_kind: BTreeMap::new(),
        tunnel_details: Vec::new(),
        fail_on_tunnel: options.fail_on_tunnel,
        ghosts: 0,
        ghost_contacts: Vec::new(),
        ghosts_unjudged: 0,
        fail_on_ghost: options.fail_on_ghost,
        ghost_degrees: options.ghost_degrees,
        sweeps_without_expectation: 0,
        expectations_without_sweep: 0,
        expectations: 0,
        has_expected_channel: false,
        by_kind: BTreeMap::new(),
        divergences: Vec::new(),
        divergent_frames: Vec::new(),
        errors: Vec::new(),
        incomplete: false,
        tolerances: options.tolerances,
        inferred: None,
        engine: None,
        expected_source: None,
    };
    let mut compared: Vec<ComparedSweep> = Vec::new();
    let mut replay = crate::replay::replay_events(events, replay_options);
    for event in replay.by_ref() {
        match event {
            Ok(ReplayEvent::Scene(_)) => {}
            Ok(ReplayEvent::Sweep(result)) => {
                report.sweeps += 1;
                for t in &result.tunnels {
                    report.tunnels += 1;
                    *report.tunnels_by_kind.entry(t.kind).or_default() += 1;
                    if report.tunnel_details.len() < MAX_LISTED_TUNNELS {
                        report.tunnel_details.push(TunnelReport {
                            frame: result.frame,
                            ball: result.ball,
                            log_time_nanos: result.log_time_nanos,
                            tunnel: t.clone(),
                        });
                    }
                }
                let Some(judged) = judge(&result) else {
                    report.sweeps_without_expectation += 1;
                    continue;
                };
                let expected = &judged.expected;
                report.compared += 1;
                count_ghosts(&mut report, &result, &judged, options.ghost_degrees);
                // Kept for the inference of the engine's configuration; the
                // first ones only, so memory stays bounded on long traces.
                if judged.got_is_core && compared.len() < MAX_INFERENCE_SWEEPS {
                    compared.push(ComparedSweep {
                        scene: result.scene.clone(),
                        frame: result.frame,
                        ball: result.ball,
                        sweep: result.sweep,
                        expected: *expected,
                        replayed_face: result
                            .outcome
                            .hit
                            .filter(|h| h.feature == Feature::Face)
                            .map(|h| h.triangle),
                    });
                }
                let (fields, fragile, reproduced, backward_error) = match judged.agreement {
                    Agreement::Match => continue,
                    Agreement::Tie => {
                        report.ties += 1;
                        continue;
                    }
                    Agreement::Precision {
                        fields,
                        backward_error,
                        reproduced,
                    } => (
                        fields,
                        result.outcome.fragile,
                        reproduced,
                        Some(backward_error),
                    ),
                    Agreement::Diverges {
                        fields,
                        fragile,
                        reproduced,
                    } => (fields, fragile, reproduced, None),
                };
                let got = judged.got;
                let details = |fields| {
                    let mut d = divergence_details(&result, *expected, got, fields, options.hex);
                    d.reproduced = reproduced;
                    d.backward_error = backward_error;
                    d
                };
                if let Some(error) = backward_error {
                    report.precision_divergent += 1;
                    report.max_backward_error = report.max_backward_error.max(error);
                    if !options.strict {
                        continue;
                    }
                } else if reproduced.is_some() {
                    report.fragile_divergent += 1;
                    for reason in fragile.iter() {
                        *report.fragile_by_reason.entry(reason).or_default() += 1;
                    }
                    if !options.strict {
                        if report.fragile_divergences.len() < options.max_details {
                            report.fragile_divergences.push(details(fields));
                        }
                        continue;
                    }
                }
                report.divergent += 1;
                *report
                    .by_kind
                    .entry(KindChange {
                        expected: expected.kind,
                        got: got.kind,
                    })
                    .or_default() += 1;
                if report.divergent_frames.len() < MAX_DIVERGENT_FRAMES {
                    report.divergent_frames.push(result.frame);
                }
                if report.divergences.len() < options.max_details {
                    report.divergences.push(details(fields));
                }
            }
            Err(err) => {
                if matches!(&err, ReplayError::Trace(e) if e.is_truncation()) {
                    report.incomplete = true;
                }
                if report.errors.len() < MAX_ERRORS {
                    report.errors.push(crate::error_text::full_text(&err));
                }
            }
        }
    }
    let summary = replay.summary();
    drop(replay);
    // A --frames or --ball filter that keeps no sweep compares nothing: an
    // error naming what the trace has, as `replay` gives.
    let selection = summary.selection(&options.replay);
    if selection.is_nothing() && report.errors.len() < MAX_ERRORS {
        report.errors.push(selection.to_string());
    }
    report.expectations_without_sweep = summary.expected_unmatched;
    report.expectations = summary.expected_matched + summary.expected_unmatched;
    if report.divergent + report.fragile_divergent > 0 {
        report.inferred = infer(&compared, &options.tolerances);
    }
    (report, saw_expected)
}

/// A divergent sweep explained as `check` reports it (render it with
/// [`super::render_divergence`]): `fields` are the fields that differ
/// between `expected` and `got` (the sweep's outcome); the core's tests are
/// run again with every record kept. `hex` adds the inputs in hexadecimal.
pub fn divergence_details(
    result: &SweepResult,
    expected: OutcomeMsg,
    got: OutcomeMsg,
    fields: Vec<FieldDiff>,
    hex: bool,
) -> Divergence {
    let records = explained_records(result);
    let inputs = SweepInputs::of(&result.sweep, result.options());
    Divergence {
        inputs,
        inputs_hex: hex.then(|| inputs.hex()),
        frame: result.frame,
        ball: result.ball,
        log_time_nanos: result.log_time_nanos,
        fields,
        expected,
        got,
        fragile: result.outcome.fragile,
        reproduced: None,
        names_tie_member: false,
        backward_error: None,
        margin: result.options().margin,
        facing: result.options().facing,
        got_explanation: explain_outcome(&result.outcome, &records),
        expected_tests: expected_tests(
            &expected,
            &result.outcome,
            &records,
            Some(&result.scene),
            result.sweep.radius - result.options().margin,
        ),
    }
}

/// A frame range around the first failures: from `before` frames before
/// the first divergent frame (or the first tunnel, or the sweep before a
/// tunnel between sweeps) to `after` frames after the last divergence kept
/// in detail (or the first, when none is kept in detail) and the first
/// tunnel. `None` when there is neither a divergence nor a tunnel.
pub fn frames_around(
    r: &TraceReport,
    before: u64,
    after: u64,
) -> Option<crate::replay::FrameRange> {
    let kept = r.divergences.len().max(1);
    let divergent = r.divergent_frames.iter().take(kept).copied();
    let tunnel = r.tunnel_details.first().map(|t| t.frame).into_iter().chain(
        r.tunnel_details
            .first()
            .and_then(|t| t.tunnel.previous_frame),
    );
    let frames: Vec<u64> = divergent.chain(tunnel).collect();
    let first = frames.iter().copied().min()?;
    let last = frames.iter().copied().max().unwrap_or(first);
    Some(crate::replay::FrameRange {
        start: Some(first.saturating_sub(before)),
        end: Some(last.saturating_add(after).saturating_add(1)),
    })
}

/// Checks the trace file at `path`; a file that cannot be opened is a
/// report with [`Status::Error`].
pub fn check_file(path: &std::path::Path, options: &CheckOptions) -> TraceReport {
    let name = path.display().to_string();
    if let Some(text) = crate::sim::obj_instead_of_trace(path) {
        let mut report = check_events(std::iter::empty(), &name, options);
        report.add_error(text);
        return report;
    }
    match std::fs::File::open(path) {
        Ok(file) => check_trace(
            TraceReader::new_indexed(std::io::BufReader::with_capacity(1 << 16, file), &name),
            &name,
            options,
        ),
        Err(err) => {
            let mut report = check_events(std::iter::empty(), &name, options);
            report.add_error(format!("{name}: cannot open: {err}"));
            report
        }
    }
}
