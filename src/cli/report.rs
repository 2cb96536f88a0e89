//! Rendering reports: pure functions from results to strings.

use std::fmt::Write;

use serde_json::json;

use sweeptrace::core::crossing::Crossing;
use sweeptrace::core::explain::{describe, miss_distance, num};
use sweeptrace::core::record::{TestRecord, Verdict};
use sweeptrace::core::{Options, Outcome, Sweep};
use sweeptrace::judge::inputs::SweepInputs;
use sweeptrace::replay::tunnel::Tunnel;
use sweeptrace::replay::{SweepStory, TunnelAt};
use sweeptrace::trace::OutcomeMsg;

/// Formats `[x, y, z]` compactly.
pub fn vec3(v: &[f64]) -> String {
    format!(
        "({})",
        v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", ")
    )
}

/// A core outcome in words, for the `sweep` report (`outcome: ...`).
pub fn outcome_text(o: &Outcome) -> String {
    let Some(hit) = o.hit else {
        return format!("no collision (alpha = {})", num(o.travelled()));
    };
    let mut s = format!(
        "{} collision at alpha = {}: triangle {}, feature {}",
        hit.feature.kind(),
        num(hit.alpha),
        hit.triangle,
        hit.feature.index().map_or("-".into(), |f| f.to_string()),
    );
    write!(s, ", normal {}", vec3(hit.normal.as_slice())).unwrap();
    write!(s, ", contact {}", vec3(hit.contact.coords.as_slice())).unwrap();
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
/// (contact off the edge, touch point outside the triangle, back-facing),
/// or it is the face test of a triangle the centre's path passes through
/// (`crossed`: from behind, or front to back from a start within `rho`,
/// where the face test does not look). A back-facing face test whose path
/// stays on one side of the plane, farther than the detection radius `rho`
/// from it, did not come close: the ball never got near that face.
pub fn came_close(r: &TestRecord, rho: f64, crossed: bool) -> bool {
    if crossed && matches!(r, TestRecord::Face(_)) {
        return true;
    }
    match r {
        TestRecord::Face(f) if f.verdict == Verdict::BackFacing => {
            let crosses = (f.h0 <= 0.0) != (f.h1 <= 0.0);
            crosses || f.h0.abs().min(f.h1.abs()) <= rho
        }
        _ => matches!(
            r.verdict(),
            Verdict::Hit | Verdict::OffEdge | Verdict::OutsideTriangle | Verdict::BackFacing
        ),
    }
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

/// How many tests that came close are shown without `--all` (every hit
/// is shown, then the nearest misses up to this many in all).
pub const SHOWN_CLOSE_TESTS: usize = 5;

/// The records to show and how many more came close: with `--all` every
/// record, ordered by triangle, then face, edges, vertices; otherwise the
/// tests that came close ranked by how close (hits by α, then misses by
/// [`miss_distance`], ties in triangle and feature order), every hit and
/// the nearest misses up to [`SHOWN_CLOSE_TESTS`].
fn shown_records<'a>(r: &SweepReport<'a>) -> (Vec<&'a TestRecord>, usize) {
    if r.all {
        let mut shown: Vec<&TestRecord> = r.story.records.iter().collect();
        shown.sort_by_key(|t| (t.triangle(), t.kind(), t.feature()));
        return (shown, 0);
    }
    let rho = r.sweep.radius - r.options.margin;
    let mut close: Vec<&TestRecord> = r
        .story
        .records
        .iter()
        .filter(|t| came_close(t, rho, r.crossing(t).is_some()))
        .collect();
    // Hits by α, then the faces the path passes through, where it does,
    // then the other misses by how near.
    let rank = |t: &TestRecord| match (t.verdict(), t.alpha(), r.crossing(t)) {
        (Verdict::Hit, Some(alpha), _) => (0u8, alpha),
        (_, _, Some(c)) => (1u8, c.fraction),
        _ => (2u8, miss_distance(t).unwrap_or(f64::INFINITY)),
    };
    close.sort_by(|a, b| {
        let (ka, da) = rank(a);
        let (kb, db) = rank(b);
        ka.cmp(&kb)
            .then(da.total_cmp(&db))
            .then((a.triangle(), a.kind(), a.feature()).cmp(&(b.triangle(), b.kind(), b.feature())))
    });
    let hits = close.iter().filter(|t| t.verdict() == Verdict::Hit).count();
    let keep = hits.max(SHOWN_CLOSE_TESTS).min(close.len());
    let more = close.len() - keep;
    close.truncate(keep);
    (close, more)
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
    /// The sweep explained: its outcome, every test's record, the place of
    /// an edge or vertex hit, the tunnels, the defects within reach, the
    /// ghost contact and the triangles the centre's path crosses.
    pub story: &'a SweepStory,
    /// Explain every test, not only those that came close.
    pub all: bool,
    /// The frame and ball of the sweep, when it was taken from a trace.
    pub at: Option<(u64, u32)>,
    /// The engine conventions the sweep was computed under (in the JSON as
    /// `conventions` when some are declared, as `check --json` says them).
    pub conventions: &'a sweeptrace::conventions::EngineConventions,
}

impl SweepReport<'_> {
    /// Where the centre's path passes through the triangle of `t`, when
    /// `t` is a face test.
    fn crossing(&self, t: &TestRecord) -> Option<&Crossing> {
        let TestRecord::Face(f) = t else {
            return None;
        };
        self.story
            .crossings
            .iter()
            .find(|c| c.triangle == f.triangle)
    }

    /// A tunnel in words: with the frame and ball, as `check` says it,
    /// when the sweep comes from a trace.
    fn tunnel_text(&self, t: &Tunnel) -> String {
        match self.at {
            Some((frame, ball)) => TunnelAt {
                frame,
                ball,
                tunnel: t.clone(),
            }
            .to_string(),
            None => t.sentence(None),
        }
    }
}

/// Why a face test of a triangle the centre's path passes through did not
/// count: `the centre's path crosses it at (1, 3, 0), back to front:
/// back-facing: the ball comes from behind (n·d = +4)`.
fn crossing_words(t: &TestRecord, c: &Crossing, rho: f64) -> Option<String> {
    let TestRecord::Face(f) = t else {
        return None;
    };
    let at = vec3(c.point.coords.as_slice());
    Some(if c.back_to_front {
        format!(
            "the centre's path crosses it at {at}, back to front: back-facing: \
             the ball comes from behind (n·d = +{})",
            num(f.normal_dot_d)
        )
    } else if f.verdict == Verdict::StartsTooClose {
        format!(
            "the centre's path crosses it at {at}, front to back: the ball starts within ρ \
             of its plane (h0 = {} < ρ = {}), where the face test does not look",
            num(f.h0),
            num(rho)
        )
    } else {
        format!("the centre's path crosses it at {at}, front to back")
    })
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
    writeln!(s, "outcome: {}", outcome_text(&r.story.outcome)).unwrap();
    if let Some(place) = &r.story.place {
        writeln!(s, "{}", place.text).unwrap();
    }
    if let Some(e) = r.expected {
        writeln!(s, "expected (the trace's /expected): {}", expected_line(e)).unwrap();
    }
    for t in &r.story.tunnels {
        writeln!(s, "tunnel: {}", r.tunnel_text(t)).unwrap();
    }
    if let Some(g) = &r.story.ghost {
        writeln!(s, "ghost contact: {g}").unwrap();
    }
    if !r.story.within_reach.is_empty() {
        writeln!(
            s,
            "defects within reach (within ρ = {} of the centre's path, nearest first):",
            num(rho)
        )
        .unwrap();
        for d in &r.story.within_reach {
            writeln!(s, "  {} at {}", d.text, num(d.distance)).unwrap();
        }
    } else if let Some(n) = r.story.defects.filter(|&n| n > 0) {
        writeln!(
            s,
            "defects within reach: none (the mesh has {}; `sweeptrace mesh` lists them)",
            sweeptrace::numbers::counted(n as u64, "defect", "defects")
        )
        .unwrap();
    }
    if r.story.outcome.fragile.is_robust() {
        writeln!(s, "decision: robust").unwrap();
    } else {
        writeln!(
            s,
            "decision: fragile ({}): a change of the inputs at the level of their rounding \
             could change it (docs/SEMANTICS.md, \"Fragile decisions\")",
            r.story.outcome.fragile
        )
        .unwrap();
    }
    let (shown, more_close) = shown_records(r);
    let hidden = r.story.records.len() - shown.len() - more_close;
    if shown.is_empty() {
        writeln!(
            s,
            "no test came close ({} run; --all explains each)",
            sweeptrace::numbers::counted(r.story.records.len() as u64, "test", "tests")
        )
        .unwrap();
    } else {
        writeln!(
            s,
            "tests{}:",
            if r.all {
                ""
            } else {
                " that came close (hits, contacts off the feature, back-facing, faces the centre's \
                 path passes through), the closest first"
            }
        )
        .unwrap();
        for t in shown {
            let crossing = r
                .crossing(t)
                .and_then(|c| crossing_words(t, c, rho))
                .map_or(String::new(), |w| format!("; {w}"));
            writeln!(
                s,
                "  {}{crossing}{}",
                describe(t),
                role(&r.story.outcome, t)
            )
            .unwrap();
        }
        if more_close > 0 {
            writeln!(
                s,
                "({} came close too, less so; --all explains each)",
                sweeptrace::numbers::counted(more_close as u64, "other test", "other tests")
            )
            .unwrap();
        }
        if hidden > 0 {
            writeln!(
                s,
                "({} missed earlier; --all explains each)",
                sweeptrace::numbers::counted(hidden as u64, "other test", "other tests")
            )
            .unwrap();
        }
    }
    s
}

/// The `sweep` report as one JSON object.
pub fn sweep_json(r: &SweepReport) -> String {
    let (shown, more_close) = shown_records(r);
    let rho = r.sweep.radius - r.options.margin;
    let tests: Vec<serde_json::Value> = shown
        .into_iter()
        .map(|t| {
            let mut v = serde_json::to_value(t).unwrap_or(serde_json::Value::Null);
            if let Some(obj) = v.as_object_mut() {
                obj.insert("explanation".into(), json!(describe(t)));
                obj.insert("primary".into(), json!(r.story.outcome.is_reported_by(t)));
                if let Some(c) = r.crossing(t) {
                    obj.insert(
                        "crossing".into(),
                        json!({
                            "point": [c.point.x, c.point.y, c.point.z],
                            "fraction": c.fraction,
                            "back_to_front": c.back_to_front,
                            "text": crossing_words(t, c, rho),
                        }),
                    );
                }
            }
            v
        })
        .collect();
    let tunnels: Vec<serde_json::Value> = r
        .story
        .tunnels
        .iter()
        .map(|t| {
            let mut v = serde_json::to_value(t).unwrap_or(serde_json::Value::Null);
            if let Some(obj) = v.as_object_mut() {
                obj.insert("text".into(), json!(r.tunnel_text(t)));
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
        "outcome": outcome_json(&r.story.outcome),
        "tests": tests,
        "close_tests_not_shown": more_close,
        "tunnels": tunnels,
        "defects_within_reach": &r.story.within_reach,
        "defects": r.story.defects,
    });
    let mut value = value;
    if let Some(object) = value.as_object_mut() {
        if let Some(source) = r.source {
            object.insert("source".into(), json!(source));
        }
        if !r.conventions.is_rules() {
            object.insert("conventions".into(), json!(r.conventions));
        }
        if let Some(place) = &r.story.place {
            if let Some(outcome) = object.get_mut("outcome").and_then(|o| o.as_object_mut()) {
                outcome.insert("edge_class".into(), json!(place.class));
            }
            object.insert("place".into(), json!(place.text));
        }
        if let Some(e) = r.expected {
            object.insert("expected".into(), json!(e));
        }
        if let Some((frame, ball)) = r.at {
            object.insert("frame".into(), json!(frame));
            object.insert("ball".into(), json!(ball));
        }
        if let Some(g) = &r.story.ghost {
            let mut v = serde_json::to_value(g).unwrap_or(serde_json::Value::Null);
            if let Some(obj) = v.as_object_mut() {
                obj.insert("text".into(), json!(g.to_string()));
            }
            object.insert("ghost".into(), v);
        }
    }
    serde_json::to_string_pretty(&value).unwrap_or_default()
}
