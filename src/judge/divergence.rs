//! One divergent sweep, as every report shows it: the [`Divergence`]
//! (the fields that differ, the sweep's exact inputs, the tests that
//! decided and those that would have given the expectation), made by
//! [`divergence_details`], and its wording ([`render_divergence_as`],
//! [`divergence_line`], the two [`Parties`] it names). `check`, `conform`,
//! the Foxglove output and the JUnit reports share it.

use std::fmt::Write as _;

use serde::Serialize;
use serde_json::Value;

use crate::core::explain::num;
use crate::core::{Facing, Kind};
use crate::replay::SweepResult;
use crate::trace::OutcomeMsg;

use super::compare::FieldDiff;
use super::explain::{ExpectedTest, expected_tests, explain_outcome, explained_records};
use super::inputs::{HexInputs, SweepInputs};

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
    pub reproduced: Option<crate::judge::perturbation::Reproduced>,
    /// Whether the expectation names another member of the core's tie set
    /// (a failure only where the tie order must be followed exactly:
    /// `conform`). Only in the JSON when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub names_tie_member: bool,
    /// At single precision, when the difference is within what it
    /// explains: its backward error, in units of `u₃₂ · S` (see
    /// [`super::precision::Sensitivity`]). Absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub backward_error: Option<f64>,
    /// The answer named, when it is one of an engine's known limitations
    /// (`a hit past the path's end`, `a false hit while leaving at a
    /// grazing angle`: [`super::explain::limitation`]). Only in the JSON
    /// when some.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limitation: Option<String>,
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

/// A divergent sweep explained as `check` reports it (render it with
/// [`render_divergence`]): `fields` are the fields that differ
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
    let mut d = Divergence {
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
        got_explanation: match explain_outcome(&result.outcome, &records) {
            lines if lines.is_empty() => super::explain::explain_initial(result),
            lines => lines,
        },
        expected_tests: expected_tests(
            &expected,
            &result.outcome,
            &records,
            Some(&result.scene),
            result.sweep.radius - result.options().margin,
        )
        .into_iter()
        .map(|mut test| {
            if let Some(Some(triangle)) = expected.triangle
                && let Some(why) = super::explain::initial_why(result, &test, triangle)
            {
                test.why_not = why;
            }
            test
        })
        .collect(),
        limitation: None,
    };
    d.limitation = super::explain::limitation(result, &d.expected, &d.expected_tests);
    d
}

/// A JSON value in words: numbers as [`num`], null as `null`.
pub fn value_text(v: &Value) -> String {
    text_with(v, num)
}

/// [`value_text`] with every number in full (the shortest decimal that
/// reads back to the same `f64`).
pub fn value_text_exact(v: &Value) -> String {
    text_with(v, crate::numbers::shortest)
}

/// `v` in words, its numbers by `number`; an integer (a triangle index, a
/// feature) as the integer it is (`1000000`, not `1.0000e6`).
fn text_with(v: &Value, number: fn(f64) -> String) -> String {
    match v {
        Value::Null => "null".to_string(),
        Value::String(s) => crate::error_text::escaped(s).into_owned(),
        Value::Number(n) if n.is_u64() || n.is_i64() => n.to_string(),
        Value::Number(n) => n.as_f64().map(number).unwrap_or_else(|| n.to_string()),
        Value::Array(a) => format!(
            "[{}]",
            a.iter()
                .map(|x| text_with(x, number))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        other => other.to_string(),
    }
}

/// The two sides of a differing field in words: short numbers, unless
/// they would read the same (a difference below the fifth significant
/// digit), then in full, so that the reader sees where they differ.
pub fn values_text(expected: &Value, got: &Value) -> (String, String) {
    let (e, g) = (value_text(expected), value_text(got));
    if e == g && expected != got {
        (value_text_exact(expected), value_text_exact(got))
    } else {
        (e, g)
    }
}

/// Who the two sides of a divergence are, in words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parties {
    /// A trace's `/expected` against the core: "expected", "got".
    ExpectedAndCore,
    /// A running engine's answer against the core (`check --engine`,
    /// `conform`): "engine", "core".
    EngineAndCore,
    /// A trace's `/expected` against a running engine's answer (`check
    /// --engine --against expected`): "expected", "engine".
    ExpectedAndEngine,
}

impl Parties {
    fn expected(self) -> &'static str {
        match self {
            Parties::ExpectedAndCore | Parties::ExpectedAndEngine => "expected",
            Parties::EngineAndCore => "engine",
        }
    }

    /// The expectation's answer, as a phrase.
    fn answer(self) -> &'static str {
        match self {
            Parties::ExpectedAndCore | Parties::ExpectedAndEngine => "the expected answer",
            Parties::EngineAndCore => "the engine's answer",
        }
    }

    /// The other side's answer, as a phrase.
    fn other_answer(self) -> &'static str {
        match self {
            Parties::ExpectedAndCore => "the core's",
            Parties::EngineAndCore => "the core's",
            Parties::ExpectedAndEngine => "the engine's answer",
        }
    }

    fn got(self) -> &'static str {
        match self {
            Parties::ExpectedAndCore => "got",
            Parties::EngineAndCore => "core",
            Parties::ExpectedAndEngine => "engine",
        }
    }
}

/// One divergence in words, several lines, indented by `indent`.
pub fn render_divergence(d: &Divergence, indent: &str) -> String {
    render_divergence_as(d, indent, Parties::ExpectedAndCore)
}

/// One divergence in words, naming its two sides as `sides` says.
pub fn render_divergence_as(d: &Divergence, indent: &str, sides: Parties) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{indent}frame {}, ball {}: {} {} (margin {}, facing {}{})",
        d.frame,
        d.ball,
        d.fields
            .iter()
            .map(|f| f.field.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        crate::numbers::verb(d.fields.len() as u64, "differs", "differ"),
        num(d.margin),
        d.facing,
        if d.fragile.is_robust() {
            String::new()
        } else {
            format!("; the core's decision is fragile: {}", d.fragile)
        }
    );
    match &d.reproduced {
        Some(r) => {
            let _ = writeln!(
                s,
                "{indent}  rounding explains it: {}",
                r.text(sides.answer(), sides.other_answer())
            );
        }
        None if !d.fragile.is_robust() && !d.names_tie_member => {
            let _ = writeln!(
                s,
                "{indent}  no perturbation of the inputs within the rounding budget gives {}: \
                 a divergence, not rounding",
                sides.answer()
            );
        }
        None => {}
    }
    if let Some(named) = &d.limitation {
        let _ = writeln!(s, "{indent}  named: {named}");
    }
    let _ = writeln!(s, "{indent}  inputs: {}", d.inputs.text());
    if let Some(hex) = &d.inputs_hex {
        let _ = writeln!(s, "{indent}  inputs (hex): {}", hex.text());
    }
    for f in &d.fields {
        let (expected, got) = values_text(&f.expected, &f.got);
        let _ = write!(
            s,
            "{indent}  {}: {} {expected}, {} {got}",
            f.field,
            sides.expected(),
            sides.got(),
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
    let (expected, whose) = match sides {
        Parties::ExpectedAndCore | Parties::ExpectedAndEngine => ("expected", "expected result's"),
        Parties::EngineAndCore => ("the engine answered", "the engine's result's"),
    };
    if d.expected.kind == Kind::None {
        let _ = writeln!(s, "{indent}  {expected} no collision");
    } else if d.expected_tests.is_empty() {
        let _ = writeln!(
            s,
            "{indent}  {expected} a {} collision; no test of that kind hit",
            d.expected.kind
        );
    } else {
        for t in &d.expected_tests {
            // The test that decided the sweep, described just above: named,
            // not described again.
            let primary = format!("primary: {}", t.description);
            if d.got_explanation.contains(&primary) {
                let _ = writeln!(
                    s,
                    "{indent}  {whose} test: the same test, {} (the primary above)",
                    t.test
                );
            } else {
                let _ = writeln!(s, "{indent}  {whose} test: {}", t.description);
            }
            let _ = writeln!(s, "{indent}    why not: {}", t.why_not);
        }
    }
    s
}

/// One divergence on one line: the sweep, each differing field's two
/// sides, and what rounding explains when it does (`frame 2, ball 0: kind
/// expected edge, got none; alpha expected 0.4, got 1`). The summary CI
/// reports show ([`github_annotations`](crate::suite::github_annotations)).
pub fn divergence_line(d: &Divergence, sides: Parties) -> String {
    let fields = d
        .fields
        .iter()
        .map(|f| {
            let (expected, got) = values_text(&f.expected, &f.got);
            let detail = f
                .detail
                .as_ref()
                .map_or_else(String::new, |x| format!(" ({x})"));
            format!(
                "{} {} {expected}, {} {got}{detail}",
                f.field,
                sides.expected(),
                sides.got()
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    let mut s = format!("frame {}, ball {}: {fields}", d.frame, d.ball);
    if let Some(r) = &d.reproduced {
        let _ = write!(
            s,
            "; rounding explains it: {}",
            r.text(sides.answer(), sides.other_answer())
        );
    }
    s
}
