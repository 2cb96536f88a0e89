//! Rendering reports: pure functions from results to strings.

use std::fmt::Write;

use serde_json::json;

use sweeptrace::core::explain::{describe, num};
use sweeptrace::core::{Options, Outcome, Sweep, TestRecord, Verdict};
use sweeptrace::regress::SweepInputs;
use sweeptrace::trace::messages::OutcomeMsg;

/// Formats `[x, y, z]` compactly.
pub fn vec3(v: &[f64]) -> String {
    format!(
        "({})",
        v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", ")
    )
}

/// One line describing an outcome.
pub fn outcome_line(o: &Outcome) -> String {
    if !o.is_hit() {
        return format!("no collision (alpha = {})", num(o.alpha));
    }
    let mut s = format!(
        "{} collision at alpha = {}: triangle {}, feature {}",
        o.kind,
        num(o.alpha),
        o.triangle.map_or("-".into(), |t| t.to_string()),
        o.feature.map_or("-".into(), |f| f.to_string()),
    );
    if let Some(n) = o.normal {
        write!(s, ", normal {}", vec3(n.as_slice())).unwrap();
    }
    if let Some(c) = o.contact {
        write!(s, ", contact {}", vec3(c.coords.as_slice())).unwrap();
    }
    s
}

/// An expectation in words (only the fields it holds).
pub fn expected_line(e: &OutcomeMsg) -> String {
    let mut s = format!("{} at alpha = {}", e.kind, num(e.alpha));
    if let Some(t) = e.triangle {
        write!(
            s,
            ", triangle {}",
            t.map_or("null".into(), |t| t.to_string())
        )
        .unwrap();
    }
    if let Some(f) = e.feature {
        write!(
            s,
            ", feature {}",
            f.map_or("null".into(), |f| f.to_string())
        )
        .unwrap();
    }
    if let Some(n) = e.normal {
        write!(s, ", normal {}", n.map_or("null".into(), |n| vec3(&n))).unwrap();
    }
    if let Some(c) = e.contact {
        write!(s, ", contact {}", c.map_or("null".into(), |c| vec3(&c))).unwrap();
    }
    s
}

/// The outcome as the JSON object of SEMANTICS.md, without `frame` and
/// `ball`: the trace's outcome record ([`OutcomeMsg`]) is the one
/// serialization.
pub fn outcome_json(o: &Outcome) -> serde_json::Value {
    let mut value =
        serde_json::to_value(OutcomeMsg::from_outcome(0, 0, o)).unwrap_or(serde_json::Value::Null);
    if let Some(object) = value.as_object_mut() {
        object.remove("frame");
        object.remove("ball");
        object.insert("fragile".into(), json!(o.fragile));
    }
    value
}

/// Whether a test "came close": it hit, or failed only at the last checks
/// (contact off the edge, touch point outside the triangle, back-facing).
pub fn came_close(r: &TestRecord) -> bool {
    matches!(
        r.verdict(),
        Verdict::Hit | Verdict::OffEdge | Verdict::OutsideTriangle | Verdict::BackFacing
    )
}

/// A marker for the primary test and for other hits tied with it
/// ([`Outcome::ties_with`]: their triangles' normals are averaged).
fn role(o: &Outcome, t: &TestRecord) -> &'static str {
    if o.is_reported_by(t) {
        "   <- primary"
    } else if t.alpha().is_some_and(|a| o.ties_with(a)) {
        "   <- tied"
    } else {
        ""
    }
}

/// The records to show, ordered by triangle, then face, edges, vertices.
fn shown_records<'a>(r: &SweepReport<'a>) -> Vec<&'a TestRecord> {
    let mut shown: Vec<&TestRecord> = r
        .records
        .iter()
        .filter(|t| r.all || came_close(t))
        .collect();
    shown.sort_by_key(|t| (t.triangle(), t.kind(), t.feature()));
    shown
}

/// Everything the `sweep` command reports.
pub struct SweepReport<'a> {
    /// Scene name.
    pub scene: &'a str,
    /// Usable triangles.
    pub triangles: usize,
    /// Where the sweep comes from, when it was taken from a trace.
    pub source: Option<&'a str>,
    /// The trace's expectation for the sweep, if any.
    pub expected: Option<&'a OutcomeMsg>,
    /// The sweep.
    pub sweep: &'a Sweep,
    /// The options.
    pub options: &'a Options,
    /// The outcome.
    pub outcome: &'a Outcome,
    /// Every test's record.
    pub records: &'a [TestRecord],
    /// Explain every test, not only those that came close.
    pub all: bool,
}

/// The `sweep` report as text.
pub fn sweep_text(r: &SweepReport) -> String {
    let mut s = String::new();
    let rho = r.sweep.radius - r.options.margin;
    if let Some(source) = r.source {
        writeln!(s, "{source}").unwrap();
    }
    writeln!(
        s,
        "scene {} ({}), radius {}, margin {} (ρ = {}), facing {}",
        r.scene,
        sweeptrace::numbers::counted(r.triangles as u64, "triangle", "triangles"),
        num(r.sweep.radius),
        num(r.options.margin),
        num(rho),
        r.options.facing
    )
    .unwrap();
    writeln!(
        s,
        "path {} -> {}",
        vec3(r.sweep.p0.coords.as_slice()),
        vec3(r.sweep.p1.coords.as_slice())
    )
    .unwrap();
    writeln!(s, "inputs: {}", SweepInputs::of(r.sweep, r.options).text()).unwrap();
    writeln!(s, "outcome: {}", outcome_line(r.outcome)).unwrap();
    if let Some(e) = r.expected {
        writeln!(s, "expected (the trace's /expected): {}", expected_line(e)).unwrap();
    }
    if r.outcome.fragile.is_robust() {
        writeln!(s, "decision: robust").unwrap();
    } else {
        writeln!(
            s,
            "decision: fragile ({}): a change of the inputs at the level of their rounding \
             could change it (docs/SEMANTICS.md, \"Fragile decisions\")",
            r.outcome.fragile
        )
        .unwrap();
    }
    let shown = shown_records(r);
    let hidden = r.records.len() - shown.len();
    if shown.is_empty() {
        writeln!(
            s,
            "no test came close ({} tests run; --all explains each)",
            r.records.len()
        )
        .unwrap();
    } else {
        writeln!(
            s,
            "tests{}:",
            if r.all {
                ""
            } else {
                " that came close (hits, contacts off the feature, back-facing)"
            }
        )
        .unwrap();
        for t in shown {
            writeln!(s, "  {}{}", describe(t), role(r.outcome, t)).unwrap();
        }
        if hidden > 0 {
            writeln!(
                s,
                "({hidden} other tests missed earlier; --all explains each)"
            )
            .unwrap();
        }
    }
    s
}

/// The `sweep` report as one JSON object.
pub fn sweep_json(r: &SweepReport) -> String {
    let tests: Vec<serde_json::Value> = shown_records(r)
        .into_iter()
        .map(|t| {
            let mut v = serde_json::to_value(t).unwrap_or(serde_json::Value::Null);
            if let Some(obj) = v.as_object_mut() {
                obj.insert("explanation".into(), json!(describe(t)));
                obj.insert("primary".into(), json!(r.outcome.is_reported_by(t)));
            }
            v
        })
        .collect();
    let value = json!({
        "scene": r.scene,
        "triangles": r.triangles,
        "radius": r.sweep.radius,
        "p0": [r.sweep.p0.x, r.sweep.p0.y, r.sweep.p0.z],
        "p1": [r.sweep.p1.x, r.sweep.p1.y, r.sweep.p1.z],
        "margin": r.options.margin,
        "facing": r.options.facing,
        "outcome": outcome_json(r.outcome),
        "tests": tests,
    });
    let mut value = value;
    if let Some(object) = value.as_object_mut() {
        if let Some(source) = r.source {
            object.insert("source".into(), json!(source));
        }
        if let Some(e) = r.expected {
            object.insert("expected".into(), json!(e));
        }
    }
    serde_json::to_string_pretty(&value).unwrap_or_default()
}
