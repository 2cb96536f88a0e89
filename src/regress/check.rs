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

use serde::{Serialize, Serializer};

use crate::core::{Facing, Feature, FragileReason, Kind};

use crate::replay::{
    ReplayError, ReplayEvent, ReplayOptions, SweepResult, Tunnel, TunnelAt, TunnelKind,
};
use crate::trace::{EXPECTED_TOPIC, OutcomeMsg, TraceError, TraceEvent, TraceReader};

use super::compare::{FieldDiff, Tolerances};
pub use super::discovery::find_traces;
use super::explain::{ExpectedTest, expected_tests, explain_outcome, explained_records};
use super::ghost::GhostContact;
pub use super::ghost_count::MAX_LISTED_GHOSTS;
use super::ghost_count::count_ghosts;
use super::infer::{ComparedSweep, Inferred, infer};
use super::judge::{Agreement, agreement};
use super::repro::{HexInputs, SweepInputs};

/// Default number of divergences described in detail per trace.
pub const DEFAULT_MAX_DETAILS: usize = 3;
/// How many tunnels a report lists, one line each.
pub const MAX_LISTED_TUNNELS: usize = 10;

/// A tunnel found in a trace: a ball's centre went through a triangle from
/// its front to its back, during a sweep or between two of its sweeps (see
/// [`crate::replay::Tunnel`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TunnelReport {
    /// Frame of the sweep.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// `log_time` of the sweep, in nanoseconds.
    pub log_time_nanos: u64,
    /// The tunnel: kind, triangle, point, fraction, from, to,
    /// previous_frame.
    #[serde(flatten)]
    pub tunnel: Tunnel,
}

impl TunnelReport {
    /// One line for people: frame, ball, triangle, where.
    pub fn line(&self) -> String {
        TunnelAt {
            frame: self.frame,
            ball: self.ball,
            tunnel: self.tunnel.clone(),
        }
        .to_string()
    }
}

/// One sweep whose outcome differs from its expectation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Divergence {
    /// Frame.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// `log_time` of the sweep, in nanoseconds.
    pub log_time_nanos: u64,
    /// The fields that differ.
    pub fields: Vec<FieldDiff>,
    /// The expectation.
    pub expected: OutcomeMsg,
    /// The core's outcome.
    pub got: OutcomeMsg,
    /// Why the core's decision is fragile (empty when robust).
    pub fragile: crate::core::Fragility,
    /// When the decision is fragile and rounding explains the divergence:
    /// the perturbation of the inputs under which the core gives each
    /// side's answer (absent otherwise: a fragile decision does not excuse
    /// an answer no rounding gives).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reproduced: Option<super::judge::Reproduced>,
    /// Whether the expectation names another member of the core's tie set
    /// (a failure only where the tie order must be followed exactly:
    /// `conform`). Only in the JSON when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub names_tie_member: bool,
    /// The sweep's inputs, exactly (shortest round-trip decimals in the
    /// JSON): with them the core makes the same decision.
    pub inputs: SweepInputs,
    /// The inputs as hexadecimal floating point (`check --hex`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inputs_hex: Option<HexInputs>,
    /// The margin and facing rule the core used.
    pub margin: f64,
    /// The facing rule the core used.
    pub facing: Facing,
    /// The tests that decided the core's outcome, in words: the primary
    /// test and the other hits at the same `α`, or the nearest miss.
    pub got_explanation: Vec<String>,
    /// The tests that would have produced the expected result (none when the
    /// expectation is `none`, or names no triangle).
    pub expected_tests: Vec<ExpectedTest>,
}

/// The status of one trace.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    strum::IntoStaticStr,
    strum::Display,
)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every expectation matched, and no tunnel was found (or tunnels do
    /// not fail the check).
    #[strum(serialize = "ok")]
    Ok,
    /// At least one sweep diverged, or a tunnel was found.
    #[strum(serialize = "FAIL")]
    Fail,
    /// Nothing to compare: no `/expected` channel, or no expectation matches
    /// a sweep. Never a pass.
    #[strum(serialize = "NO EXPECTATIONS")]
    NoExpectations,
    /// The trace could not be (fully) checked.
    #[strum(serialize = "ERROR")]
    Error,
}

impl Status {
    /// `ok`, `FAIL`, `NO EXPECTATIONS`, `ERROR`.
    pub fn as_str(self) -> &'static str {
        self.into()
    }
}

impl TraceReport {
    /// Records something that could not be checked (the report becomes
    /// [`Status::Error`]).
    pub fn add_error(&mut self, message: String) {
        if self.errors.len() < MAX_ERRORS {
            self.errors.push(message);
        }
    }

    /// The verdict, from the counts: [`Status::Error`] when anything could
    /// not be checked; [`Status::Fail`] on a divergence (or a tunnel that
    /// fails the check); [`Status::NoExpectations`] when nothing was
    /// compared; otherwise [`Status::Ok`].
    pub fn status(&self) -> Status {
        if !self.errors.is_empty() {
            Status::Error
        } else if self.divergent > 0 || self.fails_on_tunnels() || self.fails_on_ghosts() {
            Status::Fail
        } else if self.compared == 0 {
            Status::NoExpectations
        } else {
            Status::Ok
        }
    }

    /// Whether tunnels were found and fail the check.
    pub fn fails_on_tunnels(&self) -> bool {
        self.tunnels > 0 && self.fail_on_tunnel
    }

    /// Whether ghost contacts were found and fail the check.
    pub fn fails_on_ghosts(&self) -> bool {
        self.ghosts > 0 && self.fail_on_ghost
    }
}

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
    /// [`judge_ghost`](super::judge_ghost)).
    pub fail_on_ghost: bool,
    /// The angle, in degrees, above which an edge or vertex contact on an
    /// internal flat or concave place is a ghost contact
    /// ([`super::GHOST_DEGREES`] by default).
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
            ghost_degrees: super::ghost::GHOST_DEGREES,
            hex: false,
            replay: ReplayOptions::default(),
        }
    }
}

/// The result of checking one trace. Its verdict is [`TraceReport::status`]
/// (in the JSON, `status` after `trace`).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct TraceReport {
    /// The trace's name (its path as given).
    pub trace: String,
    /// Sweeps replayed.
    pub sweeps: u64,
    /// Sweeps compared with an expectation.
    pub compared: u64,
    /// Sweeps whose outcome differs from its expectation (on a robust
    /// decision; with `strict`, on any decision). These fail the check.
    pub divergent: u64,
    /// Sweeps whose expectation names another member of the replayed
    /// decision's tie set: an equally valid answer to the rules, counted
    /// as a match.
    pub ties: u64,
    /// Sweeps that diverge on a fragile decision in a way rounding
    /// explains: a perturbation of the inputs within the rounding budget
    /// makes the core give the expected answer
    /// ([`Divergence::reproduced`]). They fail the check only with
    /// `strict`, where they are also counted in `divergent`. A divergence
    /// on a fragile decision that no perturbation reproduces is counted in
    /// `divergent`.
    pub fragile_divergent: u64,
    /// Fragile divergences by reason (one sweep can have several).
    pub fragile_by_reason: BTreeMap<FragileReason, u64>,
    /// The first fragile divergences, in detail (without `strict`).
    pub fragile_divergences: Vec<Divergence>,
    /// Whether fragile divergences fail the check (`--strict`).
    pub strict: bool,
    /// Tunnels found: a ball's centre through a triangle, front to back,
    /// during a sweep or between two sweeps of the ball. They fail the
    /// check unless `fail_on_tunnel` is off.
    pub tunnels: u64,
    /// Tunnels by kind.
    pub tunnels_by_kind: BTreeMap<TunnelKind, u64>,
    /// The first tunnels (at most [`MAX_LISTED_TUNNELS`]), in trace order.
    pub tunnel_details: Vec<TunnelReport>,
    /// Whether tunnels fail the check.
    pub fail_on_tunnel: bool,
    /// Ghost contacts found: expectations (or an engine's answers) that are
    /// edge or vertex contacts on an internal flat or concave place with a
    /// normal more than `ghost_degrees` from the faces' there
    /// ([`judge_ghost`](super::judge_ghost)), whatever the compared fields. They fail the
    /// check unless `fail_on_ghost` is off.
    pub ghosts: u64,
    /// The first ghost contacts (at most [`MAX_LISTED_GHOSTS`]), in trace
    /// order.
    pub ghost_contacts: Vec<GhostContact>,
    /// Edge or vertex contacts that cannot be judged for ghost contacts:
    /// on such a place but without a normal, or without the triangle or
    /// feature that places them.
    pub ghosts_unjudged: u64,
    /// Whether ghost contacts fail the check.
    pub fail_on_ghost: bool,
    /// The ghost contacts' threshold, in degrees.
    pub ghost_degrees: f64,
    /// Replayed sweeps without an expectation.
    pub sweeps_without_expectation: u64,
    /// Expectations that match no replayed sweep (or arrived after theirs was
    /// complete, or repeat one).
    pub expectations_without_sweep: u64,
    /// `/expected` messages read (matched or not).
    pub expectations: u64,
    /// Whether the trace has an `/expected` channel at all.
    pub has_expected_channel: bool,
    /// Divergent sweeps by the kinds of the expectation and of the outcome
    /// it is compared with.
    pub by_kind: BTreeMap<KindChange, u64>,
    /// The first divergences, in detail (at most `max_details`).
    pub divergences: Vec<Divergence>,
    /// Frames of the first divergent sweeps (up to 100), in trace order.
    pub divergent_frames: Vec<u64>,
    /// What could not be checked: read errors, invalid scenes or sweeps.
    pub errors: Vec<String>,
    /// Whether the trace ends early (it is truncated): the sweeps before
    /// the end were checked. Only in the JSON when true.
    pub incomplete: bool,
    /// The tolerances used.
    pub tolerances: Tolerances,
    /// When expectations fail: the recording engine's margin and facing
    /// rule as its expectations imply them, and how many expectations
    /// match when the trace is replayed with them ([`Inferred`]).
    pub inferred: Option<Inferred>,
    /// When a running engine was checked (`check --engine`): its command
    /// and what its answers were compared with.
    pub engine: Option<super::engine_check::EngineCheck>,
    /// Who computed the trace's `/expected` outcomes, as its
    /// `sweeptrace.expected_source` record says (`null` when it does not).
    /// With `check --engine` and `against` `core` the report's
    /// expectations are the engine's answers instead (`engine`).
    pub expected_source: Option<crate::trace::ExpectedSource>,
}

/// The kinds of a divergent sweep's expectation and of the outcome it is
/// compared with; written `expected -> got` (`face -> edge`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct KindChange {
    /// The expectation's kind.
    pub expected: Kind,
    /// The compared outcome's kind.
    pub got: Kind,
}

impl std::fmt::Display for KindChange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} -> {}", self.expected, self.got)
    }
}

impl Serialize for KindChange {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

/// Counts by key, listed by the keys' names in alphabetical order: the
/// order of the report's text and of its JSON objects.
pub(crate) fn counts_by_name<K: std::fmt::Display>(
    counts: &BTreeMap<K, u64>,
) -> Vec<(String, u64)> {
    let mut named: Vec<(String, u64)> = counts.iter().map(|(k, n)| (k.to_string(), *n)).collect();
    named.sort();
    named
}

/// A count map written as a JSON object whose keys are the names, in
/// alphabetical order.
fn serialize_by_name<K, S>(counts: &BTreeMap<K, u64>, serializer: S) -> Result<S::Ok, S::Error>
where
    K: std::fmt::Display,
    S: Serializer,
{
    serializer.collect_map(counts_by_name(counts))
}

/// The JSON of a report: its fields in declaration order, with the
/// computed [`TraceReport::status`] after `trace`.
impl Serialize for TraceReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Json<'a> {
            trace: &'a str,
            status: Status,
            sweeps: u64,
            compared: u64,
            divergent: u64,
            ties: u64,
            fragile_divergent: u64,
            #[serde(serialize_with = "serialize_by_name")]
            fragile_by_reason: &'a BTreeMap<FragileReason, u64>,
            fragile_divergences: &'a [Divergence],
            strict: bool,
            tunnels: u64,
            #[serde(serialize_with = "serialize_by_name")]
            tunnels_by_kind: &'a BTreeMap<TunnelKind, u64>,
            tunnel_details: &'a [TunnelReport],
            fail_on_tunnel: bool,
            ghosts: u64,
            ghost_contacts: &'a [GhostContact],
            ghosts_unjudged: u64,
            fail_on_ghost: bool,
            ghost_degrees: f64,
            sweeps_without_expectation: u64,
            expectations_without_sweep: u64,
            expectations: u64,
            has_expected_channel: bool,
            #[serde(serialize_with = "serialize_by_name")]
            by_kind: &'a BTreeMap<KindChange, u64>,
            divergences: &'a [Divergence],
            divergent_frames: &'a [u64],
            errors: &'a [String],
            #[serde(skip_serializing_if = "std::ops::Not::not")]
            incomplete: bool,
            tolerances: &'a Tolerances,
            #[serde(skip_serializing_if = "Option::is_none")]
            inferred: &'a Option<Inferred>,
            #[serde(skip_serializing_if = "Option::is_none")]
            engine: &'a Option<super::engine_check::EngineCheck>,
            expected_source: &'a Option<crate::trace::ExpectedSource>,
        }
        // Every field, named: a new field does not compile until it is
        // written here too.
        let TraceReport {
            trace,
            sweeps,
            compared,
            divergent,
            ties,
            fragile_divergent,
            fragile_by_reason,
            fragile_divergences,
            strict,
            tunnels,
            tunnels_by_kind,
            tunnel_details,
            fail_on_tunnel,
            ghosts,
            ghost_contacts,
            ghosts_unjudged,
            fail_on_ghost,
            ghost_degrees,
            sweeps_without_expectation,
            expectations_without_sweep,
            expectations,
            has_expected_channel,
            by_kind,
            divergences,
            divergent_frames,
            errors,
            incomplete,
            tolerances,
            inferred,
            engine,
            expected_source,
        } = self;
        Json {
            trace,
            status: self.status(),
            sweeps: *sweeps,
            compared: *compared,
            divergent: *divergent,
            ties: *ties,
            fragile_divergent: *fragile_divergent,
            fragile_by_reason,
            fragile_divergences,
            strict: *strict,
            tunnels: *tunnels,
            tunnels_by_kind,
            tunnel_details,
            fail_on_tunnel: *fail_on_tunnel,
            ghosts: *ghosts,
            ghost_contacts,
            ghosts_unjudged: *ghosts_unjudged,
            fail_on_ghost: *fail_on_ghost,
            ghost_degrees: *ghost_degrees,
            sweeps_without_expectation: *sweeps_without_expectation,
            expectations_without_sweep: *expectations_without_sweep,
            expectations: *expectations,
            has_expected_channel: *has_expected_channel,
            by_kind,
            divergences,
            divergent_frames,
            errors,
            incomplete: *incomplete,
            tolerances,
            inferred,
            engine,
            expected_source,
        }
        .serialize(serializer)
    }
}

/// How many compared sweeps (the first ones) the inference of the
/// recording engine's configuration looks at and replays, so that a
/// check's memory stays bounded whatever the trace's length.
pub const MAX_INFERENCE_SWEEPS: usize = 100_000;

/// How many divergent frames a report lists.
const MAX_DIVERGENT_FRAMES: usize = 100;
/// How many errors a report keeps.
const MAX_ERRORS: usize = 20;

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

/// One sweep judged: its expectation, the outcome it is compared with,
/// and how they agree.
#[derive(Clone, Debug, PartialEq)]
pub struct Judged {
    /// The expectation.
    pub expected: OutcomeMsg,
    /// What it is compared with (the core's outcome, or an engine's answer).
    pub got: OutcomeMsg,
    /// How they agree.
    pub agreement: Agreement,
    /// Whether `got` is the core's outcome (the inference of the recording
    /// engine's configuration replays the core, so it runs only then).
    pub got_is_core: bool,
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
                let (fields, fragile, reproduced) = match judged.agreement {
                    Agreement::Match => continue,
                    Agreement::Tie => {
                        report.ties += 1;
                        continue;
                    }
                    Agreement::Diverges {
                        fields,
                        fragile,
                        reproduced,
                    } => (fields, fragile, reproduced),
                };
                let got = judged.got;
                let details = |fields| {
                    let mut d = divergence_details(&result, *expected, got, fields, options.hex);
                    d.reproduced = reproduced;
                    d
                };
                if reproduced.is_some() {
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
        margin: result.options().margin,
        facing: result.options().facing,
        got_explanation: explain_outcome(&result.outcome, &records),
        expected_tests: expected_tests(&expected, &result.outcome, &records, Some(&result.scene)),
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
