//! Comparing the outcomes of two replays: two traces, or one trace replayed
//! twice with different options (`diff T T --facing-b strict`).
//!
//! Sweeps are matched by `(frame, ball)`; every field of the two outcomes is
//! compared with [`crate::judge::compare()`] and the same [`Tolerances`]. The
//! [`DiffReport`] counts the sweeps that are the same, differ, or exist on one
//! side only, summarises the changes by kind (`edge -> none: 12`) and
//! explains the first divergence on both sides (the tests that decided, from
//! an exhaustive explained re-run of that one sweep). Contact queries are
//! compared as well, each side's answered by the core
//! ([`super::contact_diff`]).

use crate::conventions::{FacingRule, MarginRule};
use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;
use serde_json::json;

use crate::core::explain::num;
use crate::judge::{
    Agreement, ExpectedTest, FieldDiff, Tolerances, agreement, compare, expected_tests,
    explain_outcome, explained_records,
};
use crate::numbers::plural;
use crate::replay::{
    ReplayError, ReplayEvent, ReplayOptions, ReplaySummary, SceneState, SweepResult, replay_events,
};
use crate::trace::{EventBody, OutcomeMsg, TraceError, TraceEvent};

use super::contact_diff::{
    ContactDiff, SideQueries, diff_contacts, note_unmatched, write_contact_diff,
};
use std::sync::Arc;

/// One side's replayed sweeps, by `(frame, ball)`.
pub struct Side {
    /// The trace's name.
    pub name: String,
    /// The options it was replayed with.
    pub options: ReplayOptions,
    sweeps: BTreeMap<(u64, u32), Box<SweepResult>>,
    /// Sweeps that share a `(frame, ball)` with an earlier one (only the
    /// first is compared).
    pub duplicates: u64,
    /// The scenes, in trace order.
    pub scenes: Vec<Arc<SceneState>>,
    /// The replay's counts (what the frame and ball filters kept:
    /// [`ReplaySummary::selection`]).
    pub summary: ReplaySummary,
    /// The contact queries the frame and ball filters kept.
    contacts: SideQueries,
}

impl Side {
    /// Replays `events` with `options` (no explanation: the fast query).
    /// The first error (read error, invalid scene or sweep) is returned.
    pub fn replay<I>(events: I, name: &str, options: ReplayOptions) -> Result<Side, ReplayError>
    where
        I: Iterator<Item = Result<TraceEvent, TraceError>>,
    {
        let options = ReplayOptions {
            explain: None,
            ..options
        };
        let mut side = Side {
            name: name.to_string(),
            options,
            sweeps: BTreeMap::new(),
            duplicates: 0,
            scenes: Vec::new(),
            summary: ReplaySummary::default(),
            contacts: SideQueries::default(),
        };
        // The contact queries pass the replay by: kept with the number of
        // scenes before them, answered by the core when compared.
        let mut contacts = SideQueries::default();
        let mut scenes_seen = 0usize;
        let events = events.inspect(|e| match e {
            Ok(TraceEvent {
                body: EventBody::Scene(_),
                ..
            }) => scenes_seen += 1,
            Ok(TraceEvent {
                body: EventBody::Contact(query),
                ..
            }) if scenes_seen > 0 && options.wants(query.frame, query.ball) => {
                contacts.add(scenes_seen - 1, *query);
            }
            _ => {}
        });
        let mut replay = replay_events(events, options);
        for event in replay.by_ref() {
            match event? {
                ReplayEvent::Scene(scene) => side.scenes.push(scene),
                ReplayEvent::Sweep(r) => {
                    let key = (r.frame, r.ball);
                    if let std::collections::btree_map::Entry::Vacant(e) = side.sweeps.entry(key) {
                        e.insert(r);
                    } else {
                        side.duplicates += 1;
                    }
                }
            }
        }
        side.summary = replay.summary();
        drop(replay);
        side.contacts = contacts;
        Ok(side)
    }

    /// Number of distinct sweeps.
    pub fn len(&self) -> usize {
        self.sweeps.len()
    }

    /// Whether there is no sweep.
    pub fn is_empty(&self) -> bool {
        self.sweeps.is_empty()
    }
}

/// The first sweep whose outcomes differ.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FirstDifference {
    /// Frame.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// The fields that differ (`expected` is side A, `got` side B).
    pub fields: Vec<FieldDiff>,
    /// Side A's outcome.
    pub a: OutcomeMsg,
    /// Side B's outcome.
    pub b: OutcomeMsg,
    /// The tests that decided side A's outcome.
    pub a_explanation: Vec<String>,
    /// The tests that decided side B's outcome.
    pub b_explanation: Vec<String>,
    /// Side B's records of the test that decided side A, and why it did
    /// not decide side B.
    pub a_test_in_b: Vec<ExpectedTest>,
    /// Side A's records of the test that decided side B, and why it did
    /// not decide side A.
    pub b_test_in_a: Vec<ExpectedTest>,
}

/// The comparison of two replays.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct DiffReport {
    /// Side A's name and options in words.
    pub a: String,
    /// Side B's name and options in words.
    pub b: String,
    /// Sweeps on both sides.
    pub compared: u64,
    /// Sweeps whose outcomes match.
    pub same: u64,
    /// Sweeps whose outcomes differ only in which member of the tie set
    /// was chosen (an equally valid answer to the rules): counted as same.
    #[serde(rename = "ties")]
    pub tie_members: u64,
    /// Sweeps whose outcomes differ.
    pub different: u64,
    /// Sweeps only in A.
    pub only_in_a: u64,
    /// Sweeps only in B.
    pub only_in_b: u64,
    /// Differing sweeps by `"<kind in A> -> <kind in B>"`.
    pub by_kind: BTreeMap<String, u64>,
    /// Differing sweeps by field.
    pub by_field: BTreeMap<String, u64>,
    /// The first differing sweep (in frame, then ball order).
    pub first: Option<FirstDifference>,
    /// The first sweep present on one side only: `(frame, ball, side)`.
    pub first_unmatched: Option<(u64, u32, char)>,
    /// How the two sides' scenes differ, one line per difference
    /// ([`scene_differences`]); empty when they are the same.
    pub scene_differences: Vec<String>,
    /// The contact queries compared (absent when neither side has one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<ContactDiff>,
    /// The tolerances used.
    pub tolerances: Tolerances,
}

impl DiffReport {
    /// Whether the two replays agree on every sweep and contact query.
    pub fn is_same(&self) -> bool {
        self.sweeps_same() && self.contacts.as_ref().is_none_or(ContactDiff::is_same)
    }

    /// Whether they agree on every sweep.
    fn sweeps_same(&self) -> bool {
        self.different == 0 && self.only_in_a == 0 && self.only_in_b == 0
    }
}

fn describe_side(side: &Side) -> String {
    let mut s = side.name.clone();
    let mut opts = Vec::new();
    if let MarginRule::Fixed(m) = side.options.conventions.margin {
        opts.push(format!("margin {}", num(m)));
    }
    if let Some(f) = side.options.conventions.facing.facing() {
        opts.push(format!("facing {f}"));
    }
    if !opts.is_empty() {
        let _ = write!(s, " ({})", opts.join(", "));
    }
    s
}

/// How the scenes of two replays differ, one line per difference (empty
/// when they are the same): their number, and scene by scene (in trace
/// order) the vertex and triangle counts, the geometry, and the margin and
/// facing rule (those two only when neither side overrides them: an
/// override is the point of `diff T T --margin-b 0.01`).
pub fn scene_differences(a: &Side, b: &Side) -> Vec<String> {
    let mut out = Vec::new();
    if a.scenes.len() != b.scenes.len() {
        out.push(format!(
            "A has {} {}, B has {}",
            a.scenes.len(),
            plural(a.scenes.len() as u64, "scene"),
            b.scenes.len()
        ));
    }
    for (i, (sa, sb)) in a.scenes.iter().zip(&b.scenes).enumerate() {
        let at = if sa.index == sb.index {
            format!("scene {i} (message {})", sa.index)
        } else {
            format!("scene {i} (message {} in A, {} in B)", sa.index, sb.index)
        };
        let (va, vb) = (sa.mesh.vertices().len(), sb.mesh.vertices().len());
        let (ta, tb) = (
            sa.mesh.input_triangle_count(),
            sb.mesh.input_triangle_count(),
        );
        if va != vb || ta != tb {
            out.push(format!(
                "{at}: {va} {} and {ta} {} in A, {vb} and {tb} in B",
                if va == 1 { "vertex" } else { "vertices" },
                plural(ta as u64, "triangle"),
            ));
        } else if !same_geometry(sa, sb) {
            out.push(format!(
                "{at}: the same counts ({va} {}, {ta} {}), other vertex positions or triangles",
                if va == 1 { "vertex" } else { "vertices" },
                plural(ta as u64, "triangle"),
            ));
        }
        if a.options.conventions.margin == MarginRule::Scene
            && b.options.conventions.margin == MarginRule::Scene
            && sa.options.margin.to_bits() != sb.options.margin.to_bits()
        {
            out.push(format!(
                "{at}: margin {} in A, {} in B",
                num(sa.options.margin),
                num(sb.options.margin)
            ));
        }
        if a.options.conventions.facing == FacingRule::Scene
            && b.options.conventions.facing == FacingRule::Scene
            && sa.options.facing != sb.options.facing
        {
            out.push(format!(
                "{at}: facing {} in A, {} in B",
                sa.options.facing, sb.options.facing
            ));
        }
    }
    out
}

/// Whether two scenes have the same vertices (bit for bit) and triangles.
fn same_geometry(a: &SceneState, b: &SceneState) -> bool {
    let bits = |s: &SceneState| -> Vec<[u64; 3]> {
        s.mesh
            .vertices()
            .iter()
            .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .collect()
    };
    let triangles = |s: &SceneState| -> Vec<(u32, [u32; 3])> {
        let mut t: Vec<(u32, [u32; 3])> = s
            .mesh
            .triangles()
            .iter()
            .map(|t| (t.index, t.vertex_indices))
            .collect();
        t.sort_unstable();
        t
    };
    let degenerate =
        |s: &SceneState| -> Vec<usize> { s.mesh.degenerate().iter().map(|d| d.index).collect() };
    bits(a) == bits(b) && triangles(a) == triangles(b) && degenerate(a) == degenerate(b)
}

/// Compares two replays sweep by sweep.
pub fn diff(a: &Side, b: &Side, tolerances: &Tolerances) -> DiffReport {
    let mut report = DiffReport {
        a: describe_side(a),
        b: describe_side(b),
        compared: 0,
        same: 0,
        tie_members: 0,
        different: 0,
        only_in_a: 0,
        only_in_b: 0,
        by_kind: BTreeMap::new(),
        by_field: BTreeMap::new(),
        first: None,
        first_unmatched: None,
        scene_differences: scene_differences(a, b),
        contacts: diff_contacts(
            (&a.contacts, &a.scenes, a.options.conventions.sides),
            (&b.contacts, &b.scenes, b.options.conventions.sides),
            tolerances,
        ),
        tolerances: *tolerances,
    };
    for (key, ra) in &a.sweeps {
        let Some(rb) = b.sweeps.get(key) else {
            report.only_in_a += 1;
            note_unmatched(&mut report.first_unmatched, *key, 'A');
            continue;
        };
        report.compared += 1;
        let oa = ra.outcome_msg();
        let ob = rb.outcome_msg();
        let fields = compare(&oa, &ob, tolerances);
        if fields.is_empty() {
            report.same += 1;
            continue;
        }
        // Each side's answer judged against the other's decision: naming
        // another member of its tie set is the same decision by the rules.
        if matches!(agreement(&ob, ra, tolerances), Agreement::Tie)
            || matches!(agreement(&oa, rb, tolerances), Agreement::Tie)
        {
            report.same += 1;
            report.tie_members += 1;
            continue;
        }
        report.different += 1;
        *report
            .by_kind
            .entry(format!("{} -> {}", oa.kind, ob.kind))
            .or_default() += 1;
        for f in &fields {
            *report.by_field.entry(f.field.to_string()).or_default() += 1;
        }
        if report.first.is_none() {
            let records_a = explained_records(ra);
            let records_b = explained_records(rb);
            report.first = Some(FirstDifference {
                frame: key.0,
                ball: key.1,
                fields,
                a: oa,
                b: ob,
                a_explanation: explain_outcome(&ra.outcome, &records_a),
                b_explanation: explain_outcome(&rb.outcome, &records_b),
                a_test_in_b: expected_tests(
                    &oa,
                    &rb.outcome,
                    &records_b,
                    Some(&rb.scene),
                    rb.sweep.radius - rb.options().margin,
                ),
                b_test_in_a: expected_tests(
                    &ob,
                    &ra.outcome,
                    &records_a,
                    Some(&ra.scene),
                    ra.sweep.radius - ra.options().margin,
                ),
            });
        }
    }
    for key in b.sweeps.keys() {
        if !a.sweeps.contains_key(key) {
            report.only_in_b += 1;
            note_unmatched(&mut report.first_unmatched, *key, 'B');
        }
    }
    report
}

/// The report in words.
pub fn render_diff_text(r: &DiffReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "A: {}\nB: {}", r.a, r.b);
    if !r.scene_differences.is_empty() {
        let _ = writeln!(s, "the scenes differ:");
        for d in &r.scene_differences {
            let _ = writeln!(s, "  {d}");
        }
    }
    if r.sweeps_same() {
        if r.compared == 0 && r.contacts.is_some() {
            // Contact queries only: no line about sweeps.
        } else if r.tie_members > 0 {
            let _ = writeln!(
                s,
                "same: {} sweeps, identical outcomes ({} of them ties: another member of the \
                 tie set, equally valid by the rules)",
                r.compared, r.tie_members
            );
        } else {
            let _ = writeln!(
                s,
                "same: {}, identical outcomes",
                crate::numbers::counted(r.compared, "sweep", "sweeps")
            );
        }
        if let Some(c) = &r.contacts {
            write_contact_diff(&mut s, c);
        }
        return s;
    }
    let _ = writeln!(
        s,
        "different: {} of {} differ; {} only in A, {} only in B",
        r.different,
        crate::numbers::counted(r.compared, "sweep", "sweeps"),
        r.only_in_a,
        r.only_in_b
    );
    if !r.by_kind.is_empty() {
        let _ = writeln!(s, "by kind (A -> B):");
        for (k, n) in &r.by_kind {
            let _ = writeln!(s, "  {k}: {n}");
        }
        let fields = r
            .by_field
            .iter()
            .map(|(f, n)| format!("{f} {n}"))
            .collect::<Vec<_>>()
            .join(", ");
        let _ = writeln!(s, "by field: {fields}");
    }
    if let Some(f) = &r.first {
        let _ = writeln!(s, "first divergence: frame {}, ball {}", f.frame, f.ball);
        for d in &f.fields {
            let (a, b) = crate::judge::divergence::values_text(&d.expected, &d.got);
            let _ = write!(s, "  {}: A {a}, B {b}", d.field);
            if let Some(detail) = &d.detail {
                let _ = write!(s, " ({detail})");
            }
            s.push('\n');
        }
        let _ = writeln!(s, "  A:");
        for line in &f.a_explanation {
            let _ = writeln!(s, "    {line}");
        }
        let _ = writeln!(s, "  B:");
        for line in &f.b_explanation {
            let _ = writeln!(s, "    {line}");
        }
        for t in &f.a_test_in_b {
            let _ = writeln!(s, "  A's test in B: {}", t.description);
            let _ = writeln!(s, "    why it does not decide B: {}", t.why_not);
        }
        for t in &f.b_test_in_a {
            let _ = writeln!(s, "  B's test in A: {}", t.description);
            let _ = writeln!(s, "    why it does not decide A: {}", t.why_not);
        }
    }
    if let Some((frame, ball, side)) = r.first_unmatched {
        let _ = writeln!(
            s,
            "first sweep on one side only: frame {frame}, ball {ball}, in {side}"
        );
    }
    if let Some(c) = &r.contacts {
        write_contact_diff(&mut s, c);
    }
    s
}

/// The report as pretty JSON, ending with a newline.
pub fn render_diff_json(r: &DiffReport) -> String {
    let mut v = serde_json::to_value(r).unwrap_or_else(|e| json!({ "error": e.to_string() }));
    if let Some(obj) = v.as_object_mut() {
        obj.insert("same_outcomes".into(), json!(r.is_same()));
    }
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
    s.push('\n');
    s
}
