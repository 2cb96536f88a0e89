//! The ready-to-paste Rust test of a [`ReproCase`].

use std::fmt::Write as _;

use crate::conventions::NormalRule;
use crate::judge::Agreement;
use crate::judge::{Field, FieldSet, Tolerances};

use crate::core::{Facing, Kind};
use crate::trace::OutcomeMsg;

use super::case::{ReproCase, agreement_text, list_commas};

impl ReproCase {
    /// The numbers of the Rust test ([`ReproCase::rust_test`]) in the order
    /// its code writes them: vertices, `p0`, `p1`, radius, margin, then the
    /// asserted `α` and its tolerance, normal and its tolerance, contact
    /// and its tolerance (those the assertion holds).
    pub fn test_numbers(&self, tol: &Tolerances) -> Vec<f64> {
        let tol = &self.test_tolerances(tol);
        let mut out: Vec<f64> = self.vertices.iter().flatten().copied().collect();
        out.extend(self.inputs.p0);
        out.extend(self.inputs.p1);
        out.push(self.inputs.radius);
        out.push(self.inputs.margin);
        let a = self.asserted_within(tol.fields);
        out.push(a.alpha);
        out.push(tol.alpha);
        if let Some(Some(n)) = a.normal {
            out.extend(n);
            out.push(tol.normal_degrees);
        }
        if let Some(Some(c)) = a.contact {
            out.extend(c);
            out.push(tol.contact);
        }
        out
    }

    /// The tolerances and fields the test asserts: `tol`'s fields within
    /// the case's tolerances ([`ReproCase::asserted_tolerances`]), the
    /// normal left out when the engine's normal rule is not the face
    /// normal (the core's query gives the face normal; the engine's is the
    /// replay's, which the test does not run).
    fn test_tolerances(&self, tol: &Tolerances) -> Tolerances {
        let mut fields: Vec<Field> = tol.fields.fields().collect();
        if self.conventions.normal != NormalRule::Face {
            fields.retain(|f| *f != Field::Normal);
        }
        Tolerances {
            fields: FieldSet::of(&fields),
            ..self.asserted_tolerances
        }
    }

    /// Whether the test asserts membership of the tie set rather than the
    /// primary: the expectation names another member of the tie set.
    pub fn asserts_tie(&self) -> bool {
        matches!(self.agreement, Some(Agreement::Tie))
    }

    /// A ready-to-paste Rust test asserting [`ReproCase::asserted`] against
    /// the core through the public API, every number written as the
    /// shortest decimal that reads back to the same bits.
    pub fn rust_test(&self, tol: &Tolerances) -> String {
        let tol = &self.test_tolerances(tol);
        let mut s = String::new();
        let a = self.asserted_within(tol.fields);
        self.write_test_doc(&mut s);
        let _ = writeln!(s, "#[test]");
        let _ = writeln!(
            s,
            "fn repro_{}_frame_{}_ball_{}() {{",
            self.test_ident(),
            self.frame,
            self.ball
        );
        let mut names = vec!["Facing", "Kind", "Mesh", "Options", "Sweep"];
        if !self.conventions.sides.is_rules() {
            names.push("Sides");
        }
        if !self.conventions.initial_overlap.is_rules() {
            names.push("InitialOverlap");
        }
        names.sort_unstable();
        let _ = writeln!(s, "    use sweeptrace::{{{}}};", names.join(", "));
        if !self.conventions.is_rules() {
            let _ = writeln!(
                s,
                "    // Under the engine's declared conventions: {}.",
                self.conventions.summary()
            );
        }
        self.write_test_inputs(&mut s);
        if self.asserts_tie() {
            write_tie_assertion(&mut s, &a);
        } else {
            self.write_primary_assertions(&mut s, &a);
        }
        write_number_assertions(&mut s, &a, tol);
        let _ = writeln!(s, "}}");
        s
    }

    /// The file stem of the trace the case comes from.
    fn source_stem(&self) -> String {
        std::path::Path::new(&self.source)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "trace".into())
    }

    /// [`ReproCase::source_stem`] as part of a Rust identifier.
    fn test_ident(&self) -> String {
        self.source_stem()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '_'
                }
            })
            .collect()
    }

    /// The test's doc comment: where the sweep comes from, which triangles
    /// are kept, and what the core gives on the whole scene.
    fn write_test_doc(&self, s: &mut String) {
        let what = if self.expected.is_some() {
            "the outcome the trace expects"
        } else {
            "the outcome the core replays (the trace has no expectation for it)"
        };
        let _ = writeln!(
            s,
            "/// Frame {}, ball {} of `{}` (scene `{}`): {what}.",
            self.frame,
            self.ball,
            self.source_stem(),
            self.scene_name.as_deref().unwrap_or("unnamed")
        );
        let _ = writeln!(
            s,
            "/// Triangles within reach of the sweep: {} of the scene's {}; triangle i here",
            self.original_triangles.len(),
            self.original_triangle_count
        );
        let _ = writeln!(
            s,
            "/// is triangle [{}][i] there.",
            list_commas(&self.original_triangles)
        );
        if let Some(agreement) = &self.agreement {
            let _ = writeln!(
                s,
                "/// The core on the whole scene: {}.",
                agreement_text(agreement)
            );
        }
    }

    /// The test's `mesh`, `sweep` and `options`.
    fn write_test_inputs(&self, s: &mut String) {
        let _ = writeln!(s, "    let mesh = Mesh::new(");
        let _ = writeln!(s, "        vec![");
        for v in &self.vertices {
            let _ = writeln!(s, "            {},", vec3_literal(v));
        }
        let _ = writeln!(s, "        ],");
        let _ = writeln!(s, "        &[");
        for (t, o) in self.triangles.iter().zip(&self.original_triangles) {
            let note = if Some(*o) == self.extent_triangle {
                " (kept for the scene's extent, which sets the rounding unit)"
            } else {
                ""
            };
            let _ = writeln!(
                s,
                "            [{}, {}, {}], // triangle {o} of the trace's scene{note}",
                t[0], t[1], t[2]
            );
        }
        let _ = writeln!(s, "        ],");
        let _ = writeln!(s, "    )");
        let _ = writeln!(s, "    .expect(\"valid mesh\");");
        let _ = writeln!(
            s,
            "    let sweep = Sweep::new({}, {}, {});",
            vec3_literal(&self.inputs.p0),
            vec3_literal(&self.inputs.p1),
            literal(self.inputs.radius)
        );
        let facing = match self.inputs.facing {
            Facing::NonStrict => "NonStrict",
            Facing::Strict => "Strict",
        };
        let mut conventions = String::new();
        if !self.conventions.sides.is_rules() {
            let _ = write!(conventions, " sides: Sides::{:?},", self.conventions.sides);
        }
        if !self.conventions.initial_overlap.is_rules() {
            let _ = write!(
                conventions,
                " initial_overlap: InitialOverlap::{:?},",
                self.conventions.initial_overlap
            );
        }
        let _ = writeln!(
            s,
            "    let options = Options {{ margin: {}, facing: Facing::{facing},{conventions} ..Options::default() }};",
            literal(self.inputs.margin)
        );
    }

    /// The core's primary outcome: its kind, triangle and feature, as `a`
    /// asserts them.
    fn write_primary_assertions(&self, s: &mut String, a: &OutcomeMsg) {
        let _ = writeln!(
            s,
            "    let outcome = sweeptrace::sweep_mesh(&mesh, &sweep, &options).expect(\"valid sweep\");"
        );
        let _ = writeln!(
            s,
            "    assert_eq!(outcome.kind(), Kind::{});",
            kind_name(a.kind)
        );
        match a.triangle {
            Some(Some(t)) => {
                let note = match self.original_triangle(t) {
                    Some(o) => format!("// triangle {o} of the trace's scene"),
                    None => "// not a triangle of the trace's scene".to_string(),
                };
                let _ = writeln!(
                    s,
                    "    assert_eq!(outcome.hit.map(|h| h.triangle), Some({t})); {note}"
                );
            }
            Some(None) => {
                let _ = writeln!(s, "    assert_eq!(outcome.hit.map(|h| h.triangle), None);");
            }
            None => {}
        }
        if let Some(feature) = a.feature
            && a.kind != Kind::Face
        {
            let _ = writeln!(
                s,
                "    assert_eq!(outcome.hit.and_then(|h| h.feature.index()), {});",
                option_literal(feature)
            );
        }
    }
}

/// The shortest decimal that reads back to the same `f64`, as Rust.
fn literal(x: f64) -> String {
    format!("{x:?}")
}

/// A point or vector as a Rust array of [`literal`]s.
fn vec3_literal(p: &[f64; 3]) -> String {
    format!("[{}, {}, {}]", literal(p[0]), literal(p[1]), literal(p[2]))
}

/// `Some(x)` or `None`, as Rust.
fn option_literal<T: std::fmt::Display>(x: Option<T>) -> String {
    match x {
        Some(x) => format!("Some({x})"),
        None => "None".into(),
    }
}

/// The name of a [`Kind`] variant.
fn kind_name(kind: Kind) -> &'static str {
    match kind {
        Kind::None => "None",
        Kind::Face => "Face",
        Kind::Edge => "Edge",
        Kind::Vertex => "Vertex",
    }
}

/// The tie set's membership of `a`: the expectation names a member of
/// the tie set other than the primary.
fn write_tie_assertion(s: &mut String, a: &OutcomeMsg) {
    let _ = writeln!(
        s,
        "    let (outcome, ties) = sweeptrace::core::sweep_ties(&mesh, &sweep, &options).expect(\"valid sweep\");"
    );
    let _ = writeln!(
        s,
        "    // The expectation names a member of the tie set (an equally valid answer to the tie order)."
    );
    let _ = writeln!(
        s,
        "    assert!(ties.iter().any(|t| t.matches(Kind::{}, {}, {})), \"tie set {{ties:?}}\");",
        kind_name(a.kind),
        option_literal(a.triangle.flatten()),
        option_literal(a.feature.flatten())
    );
}

/// `α`, and the normal and contact point when `a` asserts them, each
/// within its tolerance in `tol`.
fn write_number_assertions(s: &mut String, a: &OutcomeMsg, tol: &Tolerances) {
    let _ = writeln!(
        s,
        "    let (alpha, tolerance) = ({}, {});",
        literal(a.alpha),
        literal(tol.alpha)
    );
    let _ = writeln!(
        s,
        "    assert!((outcome.travelled() - alpha).abs() <= tolerance, \"α = {{}}, expected {{alpha}}\", outcome.travelled());"
    );
    match a.normal {
        Some(Some(n)) => {
            let _ = writeln!(
                s,
                "    let (want, degrees) = ({}, {});",
                vec3_literal(&n),
                literal(tol.normal_degrees)
            );
            let _ = writeln!(
                s,
                "    let n = outcome.hit.expect(\"a hit with a normal\").normal;"
            );
            let _ = writeln!(
                s,
                "    let cross = [n.y * want[2] - n.z * want[1], n.z * want[0] - n.x * want[2], n.x * want[1] - n.y * want[0]];"
            );
            let _ = writeln!(
                s,
                "    let angle = cross[0].hypot(cross[1]).hypot(cross[2]).atan2(n.x * want[0] + n.y * want[1] + n.z * want[2]).to_degrees();"
            );
            let _ = writeln!(
                s,
                "    assert!(angle <= degrees, \"normal {{n:?}} is {{angle}}° from {{want:?}}\");"
            );
        }
        Some(None) => {
            let _ = writeln!(s, "    assert!(outcome.hit.is_none(), \"no normal\");");
        }
        None => {}
    }
    match a.contact {
        Some(Some(c)) => {
            let _ = writeln!(
                s,
                "    let (want, distance) = ({}, {});",
                vec3_literal(&c),
                literal(tol.contact)
            );
            let _ = writeln!(
                s,
                "    let c = outcome.hit.expect(\"a hit with a contact point\").contact;"
            );
            let _ = writeln!(
                s,
                "    let d = (c.x - want[0]).hypot(c.y - want[1]).hypot(c.z - want[2]);"
            );
            let _ = writeln!(
                s,
                "    assert!(d <= distance, \"contact {{c:?}} is {{d}} from {{want:?}}\");"
            );
        }
        Some(None) => {
            let _ = writeln!(
                s,
                "    assert!(outcome.hit.is_none(), \"no contact point\");"
            );
        }
        None => {}
    }
}
