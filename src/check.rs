//! Regression checking: the core's outcomes compared with a trace's
//! `/expected` channel.
//!
//! [`compare`] compares one outcome with one expectation, field by field,
//! **only over the fields the expectation holds** (an absent field is `None`
//! in [`OutcomeMsg`] and is not compared; a `null` field is `Some(None)` and
//! is compared: it must be null in the outcome too). Discrete fields
//! (`kind`, `triangle`, `feature`) must be equal; the continuous ones are
//! compared within the [`Tolerances`], whose defaults are listed there.
//!
//! [`check_events`] replays a whole trace (the same [`crate::replay`]
//! engine as `replay`) and returns a [`TraceReport`]: a [`Status`], the
//! counts, and the first divergences in detail ([`Divergence`]), each with
//! the explanation of what the core found and of the test that would have
//! produced the expected result. [`render_text`] and [`render_json`] are
//! pure functions of a report.
//!
//! Explanations are computed only for the divergences kept in detail, by
//! running the explained query over every triangle
//! ([`Broadphase::Exhaustive`]): the fast path stays fast on passing traces.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::Arc;

use serde::Serialize;
use serde_json::{Value, json};

use crate::core::explain::{describe, label, nearest_miss, num};
use crate::core::{
    Broadphase, CollectRecords, Kind, Outcome, TestRecord, Verdict, sweep_mesh_with,
};
use crate::replay::{
    ReplayError, ReplayEvent, ReplayOptions, SceneState, SweepResult, primary_records,
};
use crate::trace::messages::{EXPECTED_TOPIC, OutcomeMsg};
use crate::trace::{TraceError, TraceEvent, TraceReader};

/// Default absolute tolerance on `α` (a fraction of the path, unitless).
pub const DEFAULT_ALPHA_TOLERANCE: f64 = 1e-6;
/// Default angular tolerance on the normal, in **degrees**.
pub const DEFAULT_NORMAL_TOLERANCE_DEGREES: f64 = 0.01;
/// Default tolerance on the contact point: a Euclidean distance, in the
/// scene's length unit.
pub const DEFAULT_CONTACT_TOLERANCE: f64 = 1e-6;
/// Default number of divergences described in detail per trace.
pub const DEFAULT_MAX_DETAILS: usize = 3;

/// How far a continuous field may be from its expectation. These are the
/// only tolerances of the comparison; their defaults are the `DEFAULT_*`
/// constants of this module:
///
/// - `alpha`: the absolute difference is at most `alpha` (default `1e-6`);
/// - `normal`: the angle between the two vectors is at most
///   `normal_degrees`, in **degrees** (default `0.01°`);
/// - `contact`: the Euclidean distance is at most `contact`, in the scene's
///   length unit (default `1e-6`).
///
/// `kind`, `triangle` and `feature` are compared exactly.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Tolerances {
    /// Absolute tolerance on `α`.
    pub alpha: f64,
    /// Angular tolerance on the normal, in degrees.
    pub normal_degrees: f64,
    /// Distance tolerance on the contact point.
    pub contact: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            alpha: DEFAULT_ALPHA_TOLERANCE,
            normal_degrees: DEFAULT_NORMAL_TOLERANCE_DEGREES,
            contact: DEFAULT_CONTACT_TOLERANCE,
        }
    }
}

impl Tolerances {
    /// Checks that every tolerance is a finite number `≥ 0`; names the field.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("alpha tolerance", self.alpha),
            ("normal tolerance (degrees)", self.normal_degrees),
            ("contact tolerance", self.contact),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("the {name} must be a finite number ≥ 0, got {v}"));
            }
        }
        Ok(())
    }
}

/// A field of the outcome record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Field {
    /// `kind`.
    Kind,
    /// `triangle`.
    Triangle,
    /// `feature`.
    Feature,
    /// `alpha`.
    Alpha,
    /// `normal`.
    Normal,
    /// `contact`.
    Contact,
}

impl Field {
    /// The field's name in the outcome record.
    pub fn as_str(self) -> &'static str {
        match self {
            Field::Kind => "kind",
            Field::Triangle => "triangle",
            Field::Feature => "feature",
            Field::Alpha => "alpha",
            Field::Normal => "normal",
            Field::Contact => "contact",
        }
    }
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One field that differs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FieldDiff {
    /// The field.
    pub field: Field,
    /// The expected value, as JSON (`null` for null).
    pub expected: Value,
    /// The value the core produced, as JSON.
    pub got: Value,
    /// How far apart, in words (`|Δα| = 0.01 > 1e-6`), when the field is continuous.
    pub detail: Option<String>,
}

fn vec3(v: &Option<[f64; 3]>) -> Value {
    match v {
        Some(v) => json!(v),
        None => Value::Null,
    }
}

/// The angle between two vectors, in degrees; `None` when either has zero
/// or non-finite length.
pub fn angle_degrees(a: [f64; 3], b: [f64; 3]) -> Option<f64> {
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let (na, nb) = (norm(a), norm(b));
    if !(na.is_finite() && nb.is_finite() && na > 0.0 && nb > 0.0) {
        return None;
    }
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let angle = norm(cross).atan2(dot).to_degrees();
    angle.is_finite().then_some(angle)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Compares `got` with `expected` over the fields `expected` holds (see the
/// [module documentation](self)). Returns the fields that differ, in the
/// order kind, triangle, feature, alpha, normal, contact; empty when they
/// match. `frame` and `ball` are not compared (they are the matching key).
/// A NaN anywhere counts as a difference, never as a match.
pub fn compare(expected: &OutcomeMsg, got: &OutcomeMsg, tol: &Tolerances) -> Vec<FieldDiff> {
    let mut out = Vec::new();
    if expected.kind != got.kind {
        out.push(FieldDiff {
            field: Field::Kind,
            expected: json!(expected.kind),
            got: json!(got.kind),
            detail: None,
        });
    }
    if let Some(want) = expected.triangle {
        let have = got.triangle.flatten();
        if want != have {
            out.push(FieldDiff {
                field: Field::Triangle,
                expected: json!(want),
                got: json!(have),
                detail: None,
            });
        }
    }
    // A face has no feature: an expected face hit matches a face hit whatever
    // feature it names (`null`, or the 0 older recordings wrote).
    let both_faces = expected.kind == Kind::Face && got.kind == Kind::Face;
    if let Some(want) = expected.feature.filter(|_| !both_faces) {
        let have = got.feature.flatten();
        if want != have {
            out.push(FieldDiff {
                field: Field::Feature,
                expected: json!(want),
                got: json!(have),
                detail: None,
            });
        }
    }
    let delta = (got.alpha - expected.alpha).abs();
    if delta.is_nan() || delta > tol.alpha {
        out.push(FieldDiff {
            field: Field::Alpha,
            expected: json!(expected.alpha),
            got: json!(got.alpha),
            detail: Some(format!("|Δα| = {} > {}", num(delta), num(tol.alpha))),
        });
    }
    if let Some(want) = expected.normal {
        let have = got.normal.flatten();
        let detail = match (want, have) {
            (None, None) => None,
            (Some(_), None) => Some("expected a normal, got none".to_string()),
            (None, Some(_)) => Some("expected no normal (null), got one".to_string()),
            (Some(w), Some(h)) => match angle_degrees(w, h) {
                None => Some("one of the normals has zero or non-finite length".to_string()),
                Some(a) if a <= tol.normal_degrees => None,
                Some(a) => Some(format!("angle {}° > {}°", num(a), num(tol.normal_degrees))),
            },
        };
        if let Some(detail) = detail {
            out.push(FieldDiff {
                field: Field::Normal,
                expected: vec3(&want),
                got: vec3(&have),
                detail: Some(detail),
            });
        }
    }
    if let Some(want) = expected.contact {
        let have = got.contact.flatten();
        let detail = match (want, have) {
            (None, None) => None,
            (Some(_), None) => Some("expected a contact point, got none".to_string()),
            (None, Some(_)) => Some("expected no contact point (null), got one".to_string()),
            (Some(w), Some(h)) => {
                let d = distance(w, h);
                if d <= tol.contact {
                    None
                } else {
                    Some(format!("distance {} > {}", num(d), num(tol.contact)))
                }
            }
        };
        if let Some(detail) = detail {
            out.push(FieldDiff {
                field: Field::Contact,
                expected: vec3(&want),
                got: vec3(&have),
                detail: Some(detail),
            });
        }
    }
    out
}

/// The test that would have produced the expected result, and why it did not.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExpectedTest {
    /// `edge 12.1`, `face 3`, ...
    pub test: String,
    /// Its record in words (`explain::describe`), or why there is none.
    pub description: String,
    /// Its verdict, when the test ran.
    pub verdict: Option<Verdict>,
    /// Why it did not decide the sweep, in words.
    pub why_not: String,
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
    /// The margin and facing rule the core used.
    pub margin: f64,
    /// The facing rule the core used.
    pub facing: String,
    /// The tests that decided the core's outcome, in words: the primary
    /// test and the other hits at the same `α`, or the nearest miss.
    pub got_explanation: Vec<String>,
    /// The tests that would have produced the expected result (none when the
    /// expectation is `none`, or names no triangle).
    pub expected_tests: Vec<ExpectedTest>,
}

/// The status of one trace.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every expectation matched.
    Ok,
    /// At least one sweep diverged.
    Fail,
    /// Nothing to compare: no `/expected` channel, or no expectation matches
    /// a sweep. Never a pass.
    NoExpectations,
    /// The trace could not be (fully) checked.
    Error,
}

impl Status {
    /// `ok`, `FAIL`, `NO EXPECTATIONS`, `ERROR`.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Fail => "FAIL",
            Status::NoExpectations => "NO EXPECTATIONS",
            Status::Error => "ERROR",
        }
    }

    /// The exit code of a set of statuses: 2 when anything could not be
    /// checked (an error or no expectations), else 1 when a divergence was
    /// found, else 0.
    pub fn exit_code<'a>(statuses: impl IntoIterator<Item = &'a Status>) -> u8 {
        let mut code = 0;
        for s in statuses {
            code = code.max(match s {
                Status::Ok => 0,
                Status::Fail => 1,
                Status::NoExpectations | Status::Error => 2,
            });
        }
        code
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Options of a check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckOptions {
    /// Tolerances of the comparison.
    pub tolerances: Tolerances,
    /// How many divergences are described in detail.
    pub max_details: usize,
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
            replay: ReplayOptions::default(),
        }
    }
}

/// The result of checking one trace.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceReport {
    /// The trace's name (its path as given).
    pub trace: String,
    /// The verdict.
    pub status: Status,
    /// Sweeps replayed.
    pub sweeps: u64,
    /// Sweeps compared with an expectation.
    pub compared: u64,
    /// Sweeps whose outcome differs from its expectation.
    pub divergent: u64,
    /// Replayed sweeps without an expectation.
    pub sweeps_without_expectation: u64,
    /// Expectations that match no replayed sweep (or arrived after theirs was
    /// complete, or repeat one).
    pub expectations_without_sweep: u64,
    /// `/expected` messages read (matched or not).
    pub expectations: u64,
    /// Whether the trace has an `/expected` channel at all.
    pub has_expected_channel: bool,
    /// Divergent sweeps by `(expected kind, got kind)`.
    pub by_kind: BTreeMap<String, u64>,
    /// The first divergences, in detail (at most `max_details`).
    pub divergences: Vec<Divergence>,
    /// Frames of the first divergent sweeps (up to 100), in trace order.
    pub divergent_frames: Vec<u64>,
    /// What could not be checked: read errors, invalid scenes or sweeps.
    pub errors: Vec<String>,
    /// The tolerances used.
    pub tolerances: Tolerances,
}

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
    let mut reader = TraceReader::new(reader, name);
    let mut report = check_events(reader.by_ref(), name, options);
    report.has_expected_channel = reader.stats().channels.contains_key(EXPECTED_TOPIC);
    report.status = status_of(&report);
    report
}

/// Checks a trace given as a stream of events. `has_expected_channel` is
/// set from the events (true when any `/expected` message was seen);
/// [`check_reader`] sets it from the file's channels instead.
pub fn check_events<I>(events: I, name: &str, options: &CheckOptions) -> TraceReport
where
    I: Iterator<Item = Result<TraceEvent, TraceError>>,
{
    let mut saw_expected = false;
    let events = events.inspect(|e| {
        if matches!(e, Ok(TraceEvent::Expected { .. })) {
            saw_expected = true;
        }
    });
    let replay_options = ReplayOptions {
        explain: false,
        ..options.replay
    };
    let mut report = TraceReport {
        trace: name.to_string(),
        status: Status::Ok,
        sweeps: 0,
        compared: 0,
        divergent: 0,
        sweeps_without_expectation: 0,
        expectations_without_sweep: 0,
        expectations: 0,
        has_expected_channel: false,
        by_kind: BTreeMap::new(),
        divergences: Vec::new(),
        divergent_frames: Vec::new(),
        errors: Vec::new(),
        tolerances: options.tolerances,
    };
    let mut scene: Option<Arc<SceneState>> = None;
    let mut replay = crate::replay::replay_events(events, replay_options);
    for event in replay.by_ref() {
        match event {
            Ok(ReplayEvent::Scene(s)) => scene = Some(s),
            Ok(ReplayEvent::Sweep(result)) => {
                report.sweeps += 1;
                let Some(expected) = &result.expected else {
                    report.sweeps_without_expectation += 1;
                    continue;
                };
                report.compared += 1;
                let got = result.outcome_msg();
                let mut fields = compare(expected, &got, &options.tolerances);
                if !fields.is_empty() && expected_is_tied(&result, scene.as_deref(), expected) {
                    // The expectation names another member of the tie set:
                    // an equally valid answer to the rules.
                    fields.retain(|f| {
                        !matches!(f.field, Field::Kind | Field::Triangle | Field::Feature)
                    });
                }
                if fields.is_empty() {
                    continue;
                }
                report.divergent += 1;
                *report
                    .by_kind
                    .entry(format!("{} -> {}", expected.kind, got.kind))
                    .or_default() += 1;
                if report.divergent_frames.len() < MAX_DIVERGENT_FRAMES {
                    report.divergent_frames.push(result.frame);
                }
                if report.divergences.len() < options.max_details {
                    report.divergences.push(divergence(
                        &result,
                        scene.as_deref(),
                        *expected,
                        got,
                        fields,
                    ));
                }
            }
            Err(err) => {
                if report.errors.len() < MAX_ERRORS {
                    report.errors.push(error_text(&err));
                }
            }
        }
    }
    let summary = replay.summary();
    drop(replay);
    report.expectations_without_sweep = summary.expected_unmatched;
    report.expectations = summary.expected_matched + summary.expected_unmatched;
    report.has_expected_channel = saw_expected;
    report.status = status_of(&report);
    report
}

/// Whether the expected kind, triangle and feature name a member of the
/// replayed decision's tie set ([`crate::core::sweep_ties`]).
fn expected_is_tied(
    result: &SweepResult,
    scene: Option<&SceneState>,
    expected: &OutcomeMsg,
) -> bool {
    let Some(scene) = scene else {
        return false;
    };
    crate::core::sweep_ties(&scene.mesh, &result.sweep, &result.options).is_ok_and(|(_, ties)| {
        ties.iter()
            .any(|t| t.matches(expected.kind, expected.triangle, expected.feature))
    })
}

fn error_text(err: &ReplayError) -> String {
    let mut s = err.to_string();
    let mut source = std::error::Error::source(err);
    while let Some(e) = source {
        let text = e.to_string();
        if !s.contains(&text) {
            let _ = write!(s, ": {text}");
        }
        source = e.source();
    }
    s
}

fn status_of(r: &TraceReport) -> Status {
    if !r.errors.is_empty() {
        Status::Error
    } else if r.divergent > 0 {
        Status::Fail
    } else if r.compared == 0 {
        Status::NoExpectations
    } else {
        Status::Ok
    }
}

/// Re-runs a sweep with every test recorded (the same core, every triangle).
pub fn explained_records(result: &SweepResult, scene: &SceneState) -> Vec<TestRecord> {
    let mut collect = CollectRecords::default();
    match sweep_mesh_with(
        &scene.mesh,
        &result.sweep,
        &result.options,
        Broadphase::Exhaustive,
        &mut collect,
    ) {
        Ok(_) => collect.records,
        Err(_) => Vec::new(),
    }
}

/// The records that decided `outcome`, described: the primary test then the
/// other hits tied with it ([`Outcome::ties_with`]); when nothing is
/// hit, the nearest miss.
pub fn explain_outcome(outcome: &Outcome, records: &[TestRecord]) -> Vec<String> {
    if !outcome.is_hit() {
        return match nearest_miss(records) {
            Some(r) => vec![format!("no test hit; nearest miss: {}", describe(r))],
            None => vec!["no test hit (no triangle was tested)".to_string()],
        };
    }
    let decided = primary_records(outcome, records.to_vec());
    let primary = decided.iter().find(|r| outcome.is_reported_by(r));
    primary
        .map(|r| format!("primary: {}", describe(r)))
        .into_iter()
        .chain(
            decided
                .iter()
                .filter(|r| !outcome.is_reported_by(r))
                .take(8)
                .map(|r| format!("also at this α: {}", describe(r))),
        )
        .collect()
}

/// The tests that would have produced `expected`, each with why it did not
/// decide the sweep.
pub fn expected_tests(
    expected: &OutcomeMsg,
    got: &Outcome,
    records: &[TestRecord],
    scene: Option<&SceneState>,
) -> Vec<ExpectedTest> {
    if expected.kind == Kind::None {
        return Vec::new();
    }
    let Some(Some(triangle)) = expected.triangle else {
        // Without a triangle every test of that kind could be the one; name
        // the hits of that kind, if any.
        return records
            .iter()
            .filter(|r| r.kind() == expected.kind && r.verdict() == Verdict::Hit)
            .take(3)
            .map(|r| expected_test(r, expected, got))
            .collect();
    };
    let feature = expected.feature.flatten();
    let found: Vec<&TestRecord> = records
        .iter()
        .filter(|r| {
            r.kind() == expected.kind
                && r.triangle() == triangle
                && (expected.kind == Kind::Face || feature.is_none_or(|f| f == r.feature()))
        })
        .collect();
    if found.is_empty() {
        let test = match (expected.kind, feature) {
            (Kind::Face, _) => format!("face {triangle}"),
            (k, Some(f)) => format!("{k} {triangle}.{f}"),
            (k, None) => format!("{k} {triangle}.*"),
        };
        let why = match scene {
            Some(s) if triangle as usize >= s.mesh.input_triangle_count() => format!(
                "triangle {triangle} does not exist: the scene has {} triangles",
                s.mesh.input_triangle_count()
            ),
            Some(s)
                if s.mesh
                    .degenerate()
                    .iter()
                    .any(|d| d.index == triangle as usize) =>
            {
                format!("triangle {triangle} is degenerate and left out of every test")
            }
            _ => "this test did not run".to_string(),
        };
        return vec![ExpectedTest {
            test,
            description: why.clone(),
            verdict: None,
            why_not: why,
        }];
    }
    found
        .into_iter()
        .map(|r| expected_test(r, expected, got))
        .collect()
}

fn expected_test(r: &TestRecord, expected: &OutcomeMsg, got: &Outcome) -> ExpectedTest {
    let verdict = r.verdict();
    let decides = got.is_reported_by(r);
    let why_not = match r.alpha() {
        None => format!("it reports no collision ({verdict})"),
        Some(a) if decides => format!(
            "it decides the sweep, at α = {} where the expectation has α = {} \
             (was the expectation recorded with another margin or facing rule?)",
            num(a),
            num(expected.alpha)
        ),
        Some(a) if got.is_hit() && !got.ties_with(a) => format!(
            "it hits at α = {}, later than the primary collision at α = {}",
            num(a),
            num(got.alpha)
        ),
        Some(a) if (a - expected.alpha).abs() > 1e-12 && got.is_hit() => format!(
            "it hits at α = {} (expected α = {}); the primary collision is at α = {}",
            num(a),
            num(expected.alpha),
            num(got.alpha)
        ),
        Some(a) if got.is_hit() => format!(
            "it hits at α = {}, as expected, but loses the tie to the primary test \
             (ties go face < edge < vertex, then lower triangle, then lower feature)",
            num(a)
        ),
        Some(a) => format!("it hits at α = {} but the sweep reports none", num(a)),
    };
    ExpectedTest {
        test: label(r),
        description: describe(r),
        verdict: Some(verdict),
        why_not,
    }
}

fn divergence(
    result: &SweepResult,
    scene: Option<&SceneState>,
    expected: OutcomeMsg,
    got: OutcomeMsg,
    fields: Vec<FieldDiff>,
) -> Divergence {
    let records = scene
        .map(|s| explained_records(result, s))
        .unwrap_or_default();
    Divergence {
        frame: result.frame,
        ball: result.ball,
        log_time_nanos: result.log_time_nanos,
        fields,
        expected,
        got,
        margin: result.options.margin,
        facing: result.options.facing.to_string(),
        got_explanation: explain_outcome(&result.outcome, &records),
        expected_tests: expected_tests(&expected, &result.outcome, &records, scene),
    }
}

/// A JSON value in words: numbers as [`num`], null as `null`.
pub fn value_text(v: &Value) -> String {
    match v {
        Value::Null => "null".to_string(),
        Value::String(s) => s.clone(),
        Value::Number(n) => n.as_f64().map(num).unwrap_or_else(|| n.to_string()),
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(value_text).collect::<Vec<_>>().join(", ")
        ),
        other => other.to_string(),
    }
}

/// One divergence in words, several lines, indented by `indent`.
pub fn render_divergence(d: &Divergence, indent: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{indent}frame {}, ball {}: {} differ (margin {}, facing {})",
        d.frame,
        d.ball,
        d.fields
            .iter()
            .map(|f| f.field.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        num(d.margin),
        d.facing
    );
    for f in &d.fields {
        let _ = write!(
            s,
            "{indent}  {}: expected {}, got {}",
            f.field,
            value_text(&f.expected),
            value_text(&f.got)
        );
        if let Some(detail) = &f.detail {
            let _ = write!(s, " ({detail})");
        }
        s.push('\n');
    }
    let _ = writeln!(s, "{indent}  the core found:");
    for line in &d.got_explanation {
        let _ = writeln!(s, "{indent}    {line}");
    }
    if d.expected.kind == Kind::None {
        let _ = writeln!(s, "{indent}  expected no collision");
    } else if d.expected_tests.is_empty() {
        let _ = writeln!(
            s,
            "{indent}  expected a {} collision; no test of that kind hit",
            d.expected.kind
        );
    } else {
        for t in &d.expected_tests {
            let _ = writeln!(s, "{indent}  expected result's test: {}", t.description);
            let _ = writeln!(s, "{indent}    why not: {}", t.why_not);
        }
    }
    s
}

/// One line of a trace's status, then (when it failed) the first
/// divergences in detail.
pub fn render_text(r: &TraceReport) -> String {
    let mut s = String::new();
    let counts = format!(
        "{} sweeps, {} compared, {} without expectation, {} expectations without a sweep",
        r.sweeps, r.compared, r.sweeps_without_expectation, r.expectations_without_sweep
    );
    match r.status {
        Status::Ok => {
            let _ = writeln!(s, "ok {}: {counts}", r.trace);
        }
        Status::Fail => {
            let kinds = r
                .by_kind
                .iter()
                .map(|(k, n)| format!("{k}: {n}"))
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(
                s,
                "FAIL {}: {} of {} compared sweeps diverge ({kinds}); {counts}",
                r.trace, r.divergent, r.compared
            );
            if r.divergences.is_empty()
                && let Some(frame) = r.divergent_frames.first()
            {
                let _ = writeln!(s, "  first divergence: frame {frame}");
            }
            if let Some(first) = r.divergences.first() {
                let _ = writeln!(
                    s,
                    "  first divergence: frame {}, ball {} ({})",
                    first.frame,
                    first.ball,
                    first
                        .fields
                        .iter()
                        .map(|f| f.field.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            for d in &r.divergences {
                s.push_str(&render_divergence(d, "  "));
            }
            if r.divergent as usize > r.divergences.len() {
                let _ = writeln!(
                    s,
                    "  ... {} more divergent sweeps (frames {}{})",
                    r.divergent as usize - r.divergences.len(),
                    r.divergent_frames
                        .iter()
                        .skip(r.divergences.len())
                        .take(20)
                        .map(u64::to_string)
                        .collect::<Vec<_>>()
                        .join(", "),
                    if r.divergent as usize > r.divergences.len() + 20 {
                        ", ..."
                    } else {
                        ""
                    }
                );
            }
        }
        Status::NoExpectations => {
            let why = if !r.has_expected_channel {
                "no /expected channel".to_string()
            } else if r.expectations == 0 {
                "the /expected channel holds no message".to_string()
            } else {
                format!(
                    "none of the {} /expected messages matches a sweep",
                    r.expectations
                )
            };
            let _ = writeln!(s, "NO EXPECTATIONS {}: {why}; {counts}", r.trace);
        }
        Status::Error => {
            let _ = writeln!(
                s,
                "ERROR {}: {}; {counts}, {} diverge",
                r.trace,
                r.errors.first().map(String::as_str).unwrap_or("error"),
                r.divergent
            );
            for e in r.errors.iter().skip(1) {
                let _ = writeln!(s, "  also: {e}");
            }
            for d in &r.divergences {
                s.push_str(&render_divergence(d, "  "));
            }
        }
    }
    s
}

/// The reports as one JSON document: `{"status": ..., "traces": [...]}`
/// (pretty-printed, ending with a newline).
pub fn render_json(reports: &[TraceReport]) -> String {
    let overall = reports.iter().map(|r| r.status).max().unwrap_or(Status::Ok);
    let doc = json!({
        "status": overall,
        "exit_code": Status::exit_code(reports.iter().map(|r| &r.status)),
        "traces": reports,
    });
    let mut s = serde_json::to_string_pretty(&doc).unwrap_or_else(|e| {
        json!({"status": "error", "error": format!("serializing the report: {e}")}).to_string()
    });
    s.push('\n');
    s
}

/// A frame range around the first divergences: from `before` frames
/// before the first divergent frame to `after` frames after the last one
/// kept in detail (or the first, when none is kept in detail). `None` when
/// there is no divergence.
pub fn frames_around(
    r: &TraceReport,
    before: u64,
    after: u64,
) -> Option<crate::replay::FrameRange> {
    let first = *r.divergent_frames.first()?;
    let kept = r.divergences.len().max(1);
    let last = r
        .divergent_frames
        .iter()
        .take(kept)
        .copied()
        .max()
        .unwrap_or(first);
    Some(crate::replay::FrameRange {
        start: Some(first.saturating_sub(before)),
        end: Some(last.saturating_add(after).saturating_add(1)),
    })
}

/// Checks the trace file at `path`; a file that cannot be opened is a
/// report with [`Status::Error`].
pub fn check_file(path: &std::path::Path, options: &CheckOptions) -> TraceReport {
    let name = path.display().to_string();
    match std::fs::File::open(path) {
        Ok(file) => check_reader(
            std::io::BufReader::with_capacity(1 << 16, file),
            &name,
            options,
        ),
        Err(err) => {
            let mut report = check_events(std::iter::empty(), &name, options);
            report.errors.push(format!("{name}: cannot open: {err}"));
            report.status = Status::Error;
            report
        }
    }
}

/// The traces named by `paths`: files as given, directories searched
/// recursively for `*.mcap` files (sorted by path, hidden entries skipped).
/// Errors name the path that could not be read.
pub fn find_traces(paths: &[std::path::PathBuf]) -> Result<Vec<std::path::PathBuf>, String> {
    fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) -> Result<(), String> {
        let entries = std::fs::read_dir(dir)
            .map_err(|e| format!("{}: cannot list the directory: {e}", dir.display()))?;
        let mut found = Vec::new();
        for entry in entries {
            let entry =
                entry.map_err(|e| format!("{}: cannot list the directory: {e}", dir.display()))?;
            let path = entry.path();
            if entry.file_name().to_string_lossy().starts_with('.') {
                continue;
            }
            found.push(path);
        }
        found.sort();
        for path in found {
            if path.is_dir() {
                walk(&path, out)?;
            } else if path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
            {
                out.push(path);
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            walk(p, &mut out)?;
        } else {
            out.push(p.clone());
        }
    }
    Ok(out)
}
