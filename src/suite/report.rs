//! What `check` reports of one trace ([`TraceReport`], its [`Status`]) and
//! of one sweep ([`Judged`], [`Divergence`], [`TunnelReport`]): the types
//! that the check's fold ([`super::check`]), `check --engine`, the ghost
//! count, the inference, the renderers and JUnit share. Nothing here runs
//! a replay.

use std::collections::BTreeMap;

use serde::{Serialize, Serializer};

use crate::core::{FragileReason, Kind};
use crate::replay::TunnelAt;
use crate::replay::ghost::GhostContact;
use crate::replay::tunnel::{Tunnel, TunnelKind};
use crate::trace::OutcomeMsg;

use super::contact_check::ContactsReport;
use super::infer::Inferred;
use crate::conventions::EngineConventions;
use crate::judge::Agreement;
use crate::judge::ConventionHints;
use crate::judge::Tolerances;
use crate::judge::divergence::Divergence;

/// How many tunnels a report lists, one line each.
pub const MAX_LISTED_TUNNELS: usize = 10;
/// A tunnel found in a trace: a ball's centre went through a triangle from
/// its front to its back, during a sweep or between two of its sweeps (see
/// [`crate::replay::tunnel::Tunnel`]).
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
        } else if self.divergent > 0
            || self.contacts.divergent > 0
            || self.fails_on_tunnels()
            || self.fails_on_ghosts()
        {
            Status::Fail
        } else if self.compared == 0 && self.contacts.compared == 0 {
            Status::NoExpectations
        } else {
            Status::Ok
        }
    }

    /// Whether tunnels were found and fail the check.
    pub fn fails_on_tunnels(&self) -> bool {
        self.tunnels.count > 0 && self.tunnels.fail
    }

    /// Whether ghost contacts were found and fail the check.
    pub fn fails_on_ghosts(&self) -> bool {
        self.ghosts.count > 0 && self.ghosts.fail
    }
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

/// What an engine's answers are compared with.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, strum::IntoStaticStr, strum::Display,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Against {
    /// The core's outcomes: the answers are the sweeps' expectations.
    #[default]
    Core,
    /// The trace's `/expected` channel: the answers are compared with it
    /// (ties and fragility are the core's decision's).
    Expected,
}

/// A running engine's part in a check.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct EngineCheck {
    /// The engine's command.
    pub command: String,
    /// [`Against::Core`]: the engine's answers are the expectations and the
    /// core's outcomes are compared with them ("expected" is the engine's
    /// answer, "got" the core's); [`Against::Expected`]: the trace's
    /// `/expected` is the expectation and the engine's answers are compared
    /// with it ("got" is the engine's answer).
    pub against: Against,
}

/// The result of checking one trace. Its verdict is [`TraceReport::status`]
/// (in the JSON, `status` after `trace`).
///
/// Its JSON is flat: each part ([`Fragile`], [`Tunnels`], [`Ghosts`],
/// [`Expectations`], [`Divergences`]) writes its fields beside the
/// report's own, under the names each field's `serde(rename)` gives, in
/// declaration order.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
// The derive writes every field but `trace` into an inherent
// `TraceReport::serialize`; the `Serialize` impl below puts `trace` and
// the computed `status` first.
#[serde(remote = "Self")]
#[non_exhaustive]
pub struct TraceReport {
    /// The trace's name (its path as given).
    #[serde(skip)]
    pub trace: String,
    /// Sweeps replayed.
    pub sweeps: u64,
    /// Sweeps compared with an expectation.
    pub compared: u64,
    /// Sweeps whose outcome differs from its expectation (on a robust
    /// decision; with `strict`, on any decision). These fail the check.
    /// The first of them are in [`TraceReport::divergences`].
    pub divergent: u64,
    /// Sweeps whose expectation names another member of the replayed
    /// decision's tie set: an equally valid answer to the rules, counted
    /// as a match.
    #[serde(rename = "ties")]
    pub tie_members: u64,
    /// Divergences on fragile decisions that rounding explains.
    #[serde(flatten)]
    pub fragile: Fragile,
    /// At single precision (`precision = "f32"`; `None` otherwise, and
    /// then not in the JSON): the differences single-precision rounding
    /// explains.
    #[serde(flatten)]
    pub within_precision: Option<WithinPrecision>,
    /// The engine conventions the check judged by (the `[engine]` table;
    /// only in the JSON when some are declared).
    #[serde(skip_serializing_if = "EngineConventions::is_rules")]
    pub conventions: EngineConventions,
    /// Failing sweeps that an undeclared convention would explain
    /// (`conventions_seen`; only in the JSON when some).
    #[serde(
        rename = "conventions_seen",
        skip_serializing_if = "ConventionHints::is_empty"
    )]
    pub convention_hints: ConventionHints,
    /// Tunnels found.
    #[serde(flatten)]
    pub tunnels: Tunnels,
    /// Ghost contacts found.
    #[serde(flatten)]
    pub ghosts: Ghosts,
    /// The expectations and the sweeps, matched.
    #[serde(flatten)]
    pub expectations: Expectations,
    /// The divergent sweeps (counted in [`TraceReport::divergent`]).
    #[serde(flatten)]
    pub divergences: Divergences,
    /// The contact queries judged (`contacts`, absent when the trace has
    /// none).
    #[serde(skip_serializing_if = "ContactsReport::is_empty")]
    pub contacts: ContactsReport,
    /// What could not be checked: read errors, invalid scenes or sweeps.
    pub errors: Vec<String>,
    /// Whether the trace ends early (it is truncated): the sweeps before
    /// the end were checked. Only in the JSON when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub incomplete: bool,
    /// The tolerances used.
    pub tolerances: Tolerances,
    /// When expectations fail: the recording engine's margin and facing
    /// rule as its expectations imply them, and how many expectations
    /// match when the trace is replayed with them ([`Inferred`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inferred: Option<Inferred>,
    /// When a running engine was checked (`check --engine`): its command
    /// and what its answers were compared with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub engine: Option<EngineCheck>,
    /// Who computed the trace's `/expected` outcomes, as its
    /// `sweeptrace.expected_source` record says (`null` when it does not).
    /// With `check --engine` and `against` `core` the report's
    /// expectations are the engine's answers instead (`engine`).
    pub expected_source: Option<crate::trace::ExpectedSource>,
    /// The margin given instead of the scenes' (an engine's declared
    /// margin) is not smaller than a ball's radius: the check of the trace
    /// stopped at the first such sweep, with one error. A fault of the
    /// setting, which the command line names.
    #[serde(skip)]
    pub margin_fault: Option<MarginFault>,
}

/// A margin given instead of the scenes' that is not smaller than a
/// sweep's radius ([`TraceReport::margin_fault`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct MarginFault {
    /// The margin given.
    pub margin: f64,
    /// The radius of the first sweep it does not fit.
    pub radius: f64,
    /// That sweep's frame.
    pub frame: u64,
    /// That sweep's ball.
    pub ball: u32,
}

impl MarginFault {
    /// The fault of `margin` against the sweep of `ball` at `frame`, of
    /// radius `radius`.
    pub fn new(margin: f64, radius: f64, frame: u64, ball: u32) -> MarginFault {
        MarginFault {
            margin,
            radius,
            frame,
            ball,
        }
    }

    /// The fault a replay error reports, if it is one
    /// ([`ReplayError::MarginOverride`](crate::replay::ReplayError::MarginOverride)).
    pub fn of(err: &crate::replay::ReplayError) -> Option<MarginFault> {
        match *err {
            crate::replay::ReplayError::MarginOverride {
                frame,
                ball,
                margin,
                radius,
                ..
            } => Some(MarginFault {
                margin,
                radius,
                frame,
                ball,
            }),
            _ => None,
        }
    }
}

/// A report's divergences on fragile decisions that rounding explains: a
/// perturbation of the inputs within the rounding budget makes the core
/// give the expected answer ([`Divergence::reproduced`]). They fail the
/// check only with `strict`, where they are also counted in
/// [`TraceReport::divergent`]. A divergence on a fragile decision that no
/// perturbation reproduces is counted in [`TraceReport::divergent`] only.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Fragile {
    /// How many (`fragile_divergent` in the JSON).
    #[serde(rename = "fragile_divergent")]
    pub count: u64,
    /// How many by reason; one sweep can have several (`fragile_by_reason`).
    #[serde(rename = "fragile_by_reason", serialize_with = "serialize_by_name")]
    pub by_reason: BTreeMap<FragileReason, u64>,
    /// The first of them, in detail, without `strict`
    /// (`fragile_divergences`).
    #[serde(rename = "fragile_divergences")]
    pub details: Vec<Divergence>,
    /// Whether they fail the check (`--strict`).
    pub strict: bool,
}

/// A report's sweeps whose answers differ by no more than single-precision
/// rounding explains ([`crate::judge::Agreement::Precision`]). Failures only with
/// `strict`, where they are also counted in [`TraceReport::divergent`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct WithinPrecision {
    /// How many (`precision_divergent` in the JSON).
    #[serde(rename = "precision_divergent")]
    pub count: u64,
    /// The largest backward error among them, in units of `u₃₂ · S`
    /// (`max_backward_error`).
    pub max_backward_error: f64,
    /// The 99th percentile of their backward errors (nearest rank; 0 when
    /// there are none): what the engine needs on all but its worst sweeps
    /// (`p99_backward_error`).
    pub p99_backward_error: f64,
    /// Of the compared sweeps where both sides hit with different `α`
    /// (within the tolerances or not): how many expectations are later
    /// than the core's answer (`alpha_later`)...
    pub alpha_later: u64,
    /// ...and how many earlier (`alpha_earlier`). Rounding errs both ways
    /// about as often; a lopsided balance is a bias of the engine (a late
    /// contact, a penetration skin) or of its arithmetic, which a per-sweep
    /// bound does not see ([`WithinPrecision::lopsided`]).
    pub alpha_earlier: u64,
    /// The largest backward error among those whose kind, triangle and
    /// feature agree with the core's (only α, the contact or the normal
    /// differ): the engine's accuracy on the values, which
    /// `--infer-config` calibrates from. Not in the JSON.
    #[serde(skip)]
    pub max_value_backward_error: f64,
    /// Each of those backward errors, in the order met (for the
    /// percentiles calibration reads). Not in the JSON.
    #[serde(skip)]
    pub value_backward_errors: Vec<f64>,
}

impl WithinPrecision {
    /// How far the balance of later and earlier `α` is from even, in
    /// standard deviations of a fair coin (`(later - earlier) / √n`).
    pub fn balance_z(&self) -> f64 {
        let n = (self.alpha_later + self.alpha_earlier) as f64;
        if n == 0.0 {
            return 0.0;
        }
        (self.alpha_later as f64 - self.alpha_earlier as f64) / n.sqrt()
    }

    /// Whether the balance is lopsided beyond chance: at least 20 differing
    /// hits and five standard deviations from even (a fair coin does that
    /// less than once in a million runs).
    pub fn lopsided(&self) -> bool {
        self.alpha_later + self.alpha_earlier >= 20 && self.balance_z().abs() >= 5.0
    }
}

/// A report's tunnels: a ball's centre through a triangle, front to back,
/// during a sweep or between two sweeps of the ball. They fail the check
/// unless `fail` is off.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Tunnels {
    /// How many (`tunnels` in the JSON).
    #[serde(rename = "tunnels")]
    pub count: u64,
    /// How many by kind (`tunnels_by_kind`).
    #[serde(rename = "tunnels_by_kind", serialize_with = "serialize_by_name")]
    pub by_kind: BTreeMap<TunnelKind, u64>,
    /// The first of them (at most [`MAX_LISTED_TUNNELS`]), in trace order
    /// (`tunnel_details`).
    #[serde(rename = "tunnel_details")]
    pub details: Vec<TunnelReport>,
    /// Whether they fail the check (`fail_on_tunnel`).
    #[serde(rename = "fail_on_tunnel")]
    pub fail: bool,
    /// The sweeps were answered by a running engine (`check --engine`):
    /// the tunnels are the recorded paths' (between sweeps, or where the
    /// reference stops no ball either), the same whatever engine answers,
    /// so they are a note about the trace and never fail the engine's
    /// check. A tunnel the engine's own answers make (a miss where the
    /// reference hits) is a divergence. Only in the JSON when true, that
    /// is when there are tunnels (`tunnels_of_the_recording`).
    #[serde(
        rename = "tunnels_of_the_recording",
        skip_serializing_if = "std::ops::Not::not"
    )]
    pub of_the_recording: bool,
}

/// A report's ghost contacts: expectations (or an engine's answers) that
/// are edge or vertex contacts on an internal flat or concave place with a
/// normal more than `degrees` from the faces' there
/// ([`judge_ghost`](crate::replay::ghost::judge_ghost)), whatever the compared
/// fields. They fail the check unless `fail` is off.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Ghosts {
    /// How many (`ghosts` in the JSON).
    #[serde(rename = "ghosts")]
    pub count: u64,
    /// The first of them (at most ten), in trace order
    /// (`ghost_contacts`).
    #[serde(rename = "ghost_contacts")]
    pub contacts: Vec<GhostContact>,
    /// Edge or vertex contacts on such a place that give no normal, so
    /// cannot be judged (`ghosts_unjudged`).
    #[serde(rename = "ghosts_unjudged")]
    pub unjudged: u64,
    /// Whether they fail the check (`fail_on_ghost`).
    #[serde(rename = "fail_on_ghost")]
    pub fail: bool,
    /// The threshold, in degrees (`ghost_degrees`).
    #[serde(rename = "ghost_degrees")]
    pub degrees: f64,
}

/// A report's expectations and replayed sweeps, matched.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Expectations {
    /// Replayed sweeps without an expectation
    /// (`sweeps_without_expectation` in the JSON).
    #[serde(rename = "sweeps_without_expectation")]
    pub missing: u64,
    /// Expectations that match no replayed sweep (or arrived after theirs
    /// was complete, or repeat one) (`expectations_without_sweep`).
    #[serde(rename = "expectations_without_sweep")]
    pub unmatched: u64,
    /// `/expected` messages read, matched or not (`expectations`).
    #[serde(rename = "expectations")]
    pub read: u64,
    /// Whether the trace has an `/expected` channel at all
    /// (`has_expected_channel`).
    #[serde(rename = "has_expected_channel")]
    pub has_channel: bool,
}

/// A report's divergent sweeps (their count is
/// [`TraceReport::divergent`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Divergences {
    /// How many by the kinds of the expectation and of the outcome it is
    /// compared with (`by_kind` in the JSON).
    #[serde(serialize_with = "serialize_by_name")]
    pub by_kind: BTreeMap<KindChange, u64>,
    /// The first of them, in detail (at most `max_details`)
    /// (`divergences`).
    #[serde(rename = "divergences")]
    pub details: Vec<Divergence>,
    /// Frames of the first of them (up to 100), in trace order
    /// (`divergent_frames`).
    #[serde(rename = "divergent_frames")]
    pub frames: Vec<u64>,
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

/// The JSON of a report: `trace`, the computed [`TraceReport::status`],
/// then the other fields in declaration order, each part's flattened in.
impl Serialize for TraceReport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        /// The report's fields but `trace`, as the derive writes them.
        struct Fields<'a>(&'a TraceReport);
        impl Serialize for Fields<'_> {
            fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                TraceReport::serialize(self.0, serializer)
            }
        }
        #[derive(Serialize)]
        struct Json<'a> {
            trace: &'a str,
            status: Status,
            #[serde(flatten)]
            fields: Fields<'a>,
        }
        Json {
            trace: &self.trace,
            status: self.status(),
            fields: Fields(self),
        }
        .serialize(serializer)
    }
}

/// How many divergent frames a report lists.
pub(crate) const MAX_DIVERGENT_FRAMES: usize = 100;
/// How many errors a report keeps.
pub(crate) const MAX_ERRORS: usize = 20;
