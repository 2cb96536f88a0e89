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

use crate::core::{Feature, Kind};
use crate::replay::{ReplayError, ReplayEvent, ReplayOptions, ReplaySummary, SweepResult};
use crate::trace::{EXPECTED_TOPIC, EventBody, TraceError, TraceEvent, TraceReader};

use super::contact_check::{ContactChecker, ContactMode};
use super::ghost_count::count_ghosts;
use super::infer::{ComparedSweep, MAX_INFERENCE_SWEEPS, infer};
use super::report::{
    Judged, KindChange, MAX_DIVERGENT_FRAMES, MAX_ERRORS, MAX_LISTED_TUNNELS, MarginFault,
    TraceReport, TunnelReport, WithinPrecision,
};
use crate::judge::divergence::divergence_details;
use crate::judge::{Agreement, agreement};
use crate::judge::{Field, Tolerances};

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
    /// [`judge_ghost`](crate::replay::ghost::judge_ghost)).
    pub fail_on_ghost: bool,
    /// The angle, in degrees, above which an edge or vertex contact on an
    /// internal flat or concave place is a ghost contact
    /// ([`crate::replay::ghost::GHOST_DEGREES`] by default).
    pub ghost_degrees: f64,
    /// Whether divergences also give their inputs as hexadecimal floating
    /// point ([`crate::judge::divergence::Divergence::inputs_hex`]).
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
            ghost_degrees: crate::replay::ghost::GHOST_DEGREES,
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
    let (mut report, _) = check_stream(
        reader.by_ref(),
        name,
        options,
        ContactMode::Judge,
        |result| judge_against_core(result, &options.tolerances),
    );
    report.expectations.has_channel = reader.stats().channels.contains_key(EXPECTED_TOPIC);
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

/// Checks a trace given as a stream of events. Whether it has an
/// `/expected` channel ([`super::report::Expectations::has_channel`]) is set from the events (true when any `/expected` message was seen);
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
    let (mut report, saw_expected) = check_stream(events, name, options, ContactMode::Judge, judge);
    report.expectations.has_channel = saw_expected;
    report
}

/// The check of a stream of events with `judge`, except whether the trace
/// has an `/expected` channel (`has_channel` is left false: each caller
/// sets it once, from what it knows); returns the report and whether any
/// `/expected` message was seen. The contact queries are judged beside
/// the sweeps, or only counted (`contacts`).
pub(crate) fn check_stream<I, J>(
    events: I,
    name: &str,
    options: &CheckOptions,
    contacts: ContactMode,
    mut judge: J,
) -> (TraceReport, bool)
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
    J: FnMut(&SweepResult) -> Option<Judged>,
{
    let mut saw_expected = false;
    let mut contact_checker = ContactChecker::new(options, contacts);
    let events = events.inspect(|e| {
        if let Ok(event) = e {
            if matches!(event.body, EventBody::Expected(_)) {
                saw_expected = true;
            }
            contact_checker.event(event);
        }
    });
    let replay_options = ReplayOptions {
        explain: None,
        ..options.replay
    };
    let mut report = ReportBuilder::new(name, options);
    let mut replay = crate::replay::replay_events(events, replay_options);
    for event in replay.by_ref() {
        match event {
            Ok(ReplayEvent::Scene(_)) => {}
            Ok(ReplayEvent::Sweep(result)) => {
                let judged = judge(&result);
                report.sweep(&result, judged);
            }
            // A margin that does not fit the balls fails every sweep
            // alike: one error, and the check of the trace stops.
            Err(err) => match MarginFault::of(&err) {
                Some(fault) => {
                    report.margin_fault(fault);
                    break;
                }
                None => report.error(&err),
            },
        }
    }
    let summary = replay.summary();
    drop(replay);
    let mut report = report.finish(&summary);
    let (contacts, ghost_count, ghosts, errors) = contact_checker.finish();
    report.contacts = contacts;
    report.ghosts.count += ghost_count;
    for ghost in ghosts {
        if report.ghosts.contacts.len() < super::ghost_count::MAX_LISTED_GHOSTS {
            report.ghosts.contacts.push(ghost);
        }
    }
    for error in errors {
        report.add_error(error);
    }
    (report, saw_expected)
}

/// `check`'s fold: one trace's report, built sweep by sweep.
struct ReportBuilder<'a> {
    report: TraceReport,
    options: &'a CheckOptions,
    /// The first sweeps compared with the core's outcome, kept for the
    /// inference of the engine's configuration (the first ones only, so
    /// memory stays bounded on long traces).
    compared: Vec<ComparedSweep>,
    /// Every backward error within single precision, for the report's
    /// percentile (one number a sweep that differs).
    backward_errors: Vec<f64>,
}

impl<'a> ReportBuilder<'a> {
    /// A report of nothing yet, with the check's options in it.
    fn new(name: &str, options: &'a CheckOptions) -> Self {
        let mut report = TraceReport {
            trace: name.to_string(),
            tolerances: options.tolerances,
            ..TraceReport::default()
        };
        report.fragile.strict = options.strict;
        report.within_precision =
            (options.replay.conventions.budget().is_some()).then(WithinPrecision::default);
        report.conventions = options.replay.conventions;
        report.tunnels.fail = options.fail_on_tunnel;
        report.ghosts.fail = options.fail_on_ghost;
        report.ghosts.degrees = options.ghost_degrees;
        ReportBuilder {
            report,
            options,
            compared: Vec::new(),
            backward_errors: Vec::new(),
        }
    }

    /// One replayed sweep: its tunnels, and its judgement (`None` when it
    /// has no expectation).
    fn sweep(&mut self, result: &SweepResult, judged: Option<Judged>) {
        self.report.sweeps += 1;
        let tunnels = &mut self.report.tunnels;
        for t in &result.tunnels {
            tunnels.count += 1;
            *tunnels.by_kind.entry(t.kind).or_default() += 1;
            if tunnels.details.len() < MAX_LISTED_TUNNELS {
                tunnels.details.push(TunnelReport {
                    frame: result.frame,
                    ball: result.ball,
                    log_time_nanos: result.log_time_nanos,
                    tunnel: t.clone(),
                });
            }
        }
        match judged {
            Some(judged) => self.judged(result, judged),
            None => self.report.expectations.missing += 1,
        }
    }

    /// A sweep compared with its expectation: its ghost contacts, and a
    /// match, a tie or a divergence.
    fn judged(&mut self, result: &SweepResult, judged: Judged) {
        self.report.compared += 1;
        if let Some(within) = self.report.within_precision.as_mut()
            && judged.expected.kind != Kind::None
            && judged.got.kind != Kind::None
            && self.options.tolerances.fields.contains(Field::Alpha)
        {
            if judged.expected.alpha > judged.got.alpha {
                within.alpha_later += 1;
            } else if judged.expected.alpha < judged.got.alpha {
                within.alpha_earlier += 1;
            }
        }
        count_ghosts(&mut self.report.ghosts, result, &judged);
        if judged.got_is_core && self.compared.len() < MAX_INFERENCE_SWEEPS {
            self.compared.push(ComparedSweep {
                scene: result.scene.clone(),
                frame: result.frame,
                ball: result.ball,
                sweep: result.sweep,
                expected: judged.expected,
                replayed_face: result
                    .outcome
                    .hit
                    .filter(|h| h.feature == Feature::Face)
                    .map(|h| h.triangle),
            });
        }
        match judged.agreement {
            Agreement::Match => {}
            Agreement::Tie => self.report.tie_members += 1,
            Agreement::Precision { .. } | Agreement::Diverges { .. } => {
                self.diverges(result, judged);
            }
        }
    }

    /// A sweep whose answers differ: within single precision (a backward
    /// error), fragile and explained by rounding (`reproduced`), or a
    /// divergence; the first of each kind in detail.
    fn diverges(&mut self, result: &SweepResult, judged: Judged) {
        let (fields, fragile, reproduced, backward_error) = match judged.agreement {
            Agreement::Match | Agreement::Tie => return,
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
        let details = |fields| {
            let mut d = divergence_details(
                result,
                judged.expected,
                judged.got,
                fields,
                self.options.hex,
            );
            d.reproduced = reproduced;
            d.backward_error = backward_error;
            d
        };
        let report = &mut self.report;
        if let Some(error) = backward_error {
            let within = report
                .within_precision
                .get_or_insert_with(WithinPrecision::default);
            within.count += 1;
            within.max_backward_error = within.max_backward_error.max(error);
            if reproduced.is_none() {
                within.max_value_backward_error = within.max_value_backward_error.max(error);
                within.value_backward_errors.push(error);
            }
            self.backward_errors.push(error);
            if !self.options.strict {
                return;
            }
        } else if reproduced.is_some() {
            report.fragile.count += 1;
            for reason in fragile.iter() {
                *report.fragile.by_reason.entry(reason).or_default() += 1;
            }
            if !self.options.strict {
                if report.fragile.details.len() < self.options.max_details {
                    report.fragile.details.push(details(fields));
                }
                return;
            }
        }
        report.divergent += 1;
        report.convention_hints.observe(
            result,
            (&judged.expected, &judged.got, judged.got_is_core),
            &fields,
            &self.options.tolerances,
            &report.conventions,
        );
        let divergences = &mut report.divergences;
        *divergences
            .by_kind
            .entry(KindChange {
                expected: judged.expected.kind,
                got: judged.got.kind,
            })
            .or_default() += 1;
        if divergences.frames.len() < MAX_DIVERGENT_FRAMES {
            divergences.frames.push(result.frame);
        }
        if divergences.details.len() < self.options.max_details {
            divergences.details.push(details(fields));
        }
    }

    /// A margin given instead of the scenes' that does not fit a ball:
    /// the report's one error.
    fn margin_fault(&mut self, fault: MarginFault) {
        self.report.errors = vec![format!(
            "frame {}, ball {}: the margin {} given instead of the scene's must be smaller than the ball's radius {}",
            fault.frame,
            fault.ball,
            crate::numbers::Shortest(fault.margin),
            crate::numbers::Shortest(fault.radius)
        )];
        self.report.margin_fault = Some(fault);
    }

    /// What the replay could not do.
    fn error(&mut self, err: &ReplayError) {
        if matches!(err, ReplayError::Trace(e) if e.is_truncation()) {
            self.report.incomplete = true;
        }
        if self.report.errors.len() < MAX_ERRORS {
            self.report.errors.push(crate::error_text::full_text(err));
        }
    }

    /// The report, with the replay's count of expectations and, when any
    /// sweep diverged, the inference of the engine's configuration.
    fn finish(mut self, summary: &ReplaySummary) -> TraceReport {
        let report = &mut self.report;
        // A --frames or --ball filter that keeps no sweep compares nothing:
        // an error naming what the trace has, as `replay` gives.
        let selection = summary.selection(&self.options.replay);
        if selection.is_nothing() && report.errors.len() < MAX_ERRORS {
            report.errors.push(selection.to_string());
        }
        report.expectations.unmatched = summary.expected_unmatched;
        report.expectations.read = summary.expected_matched + summary.expected_unmatched;
        if report.divergent + report.fragile.count > 0 {
            report.inferred = infer(&self.compared, &self.options.tolerances);
        }
        if let Some(within) = report.within_precision.as_mut() {
            within.p99_backward_error = percentile(&mut self.backward_errors, 0.99);
        }
        self.report
    }
}

/// The `q` quantile of `values` by nearest rank (0 when empty).
pub(super) fn percentile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    values[rank - 1]
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
    let kept = r.divergences.details.len().max(1);
    let divergent = r.divergences.frames.iter().take(kept).copied();
    let tunnel = r
        .tunnels
        .details
        .first()
        .map(|t| t.frame)
        .into_iter()
        .chain(
            r.tunnels
                .details
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
/// report with [`super::Status::Error`].
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
