//! The one comparison of an outcome with its expectation, used by `check`,
//! `diff` and the viewer's decision line.
//!
//! [`compare`] compares one outcome with one expectation, field by field,
//! **only over the fields the expectation holds** (an absent field is `None`
//! in [`OutcomeMsg`] and is not compared; a `null` field is `Some(None)` and
//! is compared: it must be null in the outcome too). Discrete fields
//! (`kind`, `triangle`, `feature`) must be equal; the continuous ones are
//! compared within the [`Tolerances`], whose defaults are listed there.

use nalgebra::Vector3;
use serde::Serialize;
use serde_json::{Value, json};

use crate::core::explain::num;
use crate::core::{Broadphase, CollectRecords, Fragility, Kind, TestRecord, Tie, sweep_mesh_with};
use crate::numbers::{self, Rule};
use crate::replay::SweepResult;
use crate::trace::messages::OutcomeMsg;

/// Default absolute tolerance on `α` (a fraction of the path, unitless).
pub const DEFAULT_ALPHA_TOLERANCE: f64 = 1e-6;
/// Default angular tolerance on the normal, in **degrees**.
pub const DEFAULT_NORMAL_TOLERANCE_DEGREES: f64 = 0.01;
/// Default tolerance on the contact point: a Euclidean distance, in the
/// scene's length unit.
pub const DEFAULT_CONTACT_TOLERANCE: f64 = 1e-6;

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
/// `kind`, `triangle` and `feature` are compared exactly. `fields` limits
/// the comparison to some fields (default: every field; `check --fields`),
/// for engines whose answers differ from the core's by design in the others
/// (a contact normal where the core reports the face normal, ...).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Tolerances {
    /// Absolute tolerance on `α`.
    pub alpha: f64,
    /// Angular tolerance on the normal, in degrees.
    pub normal_degrees: f64,
    /// Distance tolerance on the contact point.
    pub contact: f64,
    /// The fields compared (those the expectation holds among them).
    pub fields: FieldSet,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            alpha: DEFAULT_ALPHA_TOLERANCE,
            normal_degrees: DEFAULT_NORMAL_TOLERANCE_DEGREES,
            contact: DEFAULT_CONTACT_TOLERANCE,
            fields: FieldSet::ALL,
        }
    }
}

/// A set of outcome [`Field`]s: which fields [`compare`] looks at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FieldSet(u8);

impl FieldSet {
    /// Every field.
    pub const ALL: FieldSet = FieldSet(0b11_1111);

    /// The set of `fields` (empty: no field).
    pub fn of(fields: &[Field]) -> FieldSet {
        FieldSet(fields.iter().fold(0, |bits, &f| bits | FieldSet::bit(f)))
    }

    fn bit(field: Field) -> u8 {
        1 << field as u8
    }

    /// Whether `field` is in the set.
    pub fn contains(self, field: Field) -> bool {
        self.0 & FieldSet::bit(field) != 0
    }

    /// Whether the set holds every field.
    pub fn is_all(self) -> bool {
        self == FieldSet::ALL
    }

    /// The fields in the set, in the order of [`Field`].
    pub fn fields(self) -> impl Iterator<Item = Field> {
        <Field as strum::IntoEnumIterator>::iter().filter(move |&f| self.contains(f))
    }

    /// The names of the fields, comma-separated (`kind,alpha`).
    pub fn names(self) -> String {
        self.fields()
            .map(Field::as_str)
            .collect::<Vec<_>>()
            .join(",")
    }
}

impl Serialize for FieldSet {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.fields())
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
            numbers::check(v, Rule::NonNegative).map_err(|e| format!("the {name} {e}"))?;
        }
        Ok(())
    }
}

/// A field of the outcome record.
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
    strum::EnumString,
    strum::EnumIter,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
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
        self.into()
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
/// or non-finite length. Computed as `atan2(|a × b|, a · b)`, accurate for
/// small angles too (unlike `acos` of the cosine).
pub fn angle_degrees(a: [f64; 3], b: [f64; 3]) -> Option<f64> {
    let (a, b) = (Vector3::from(a), Vector3::from(b));
    let (na, nb) = (a.norm(), b.norm());
    if !(na.is_finite() && nb.is_finite() && na > 0.0 && nb > 0.0) {
        return None;
    }
    let angle = a.cross(&b).norm().atan2(a.dot(&b)).to_degrees();
    angle.is_finite().then_some(angle)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (Vector3::from(a) - Vector3::from(b)).norm()
}

/// Compares `got` with `expected` over the fields `expected` holds (see the
/// [module documentation](self)). Returns the fields that differ, in the
/// order kind, triangle, feature, alpha, normal, contact; empty when they
/// match. `frame` and `ball` are not compared (they are the matching key).
/// A NaN anywhere counts as a difference, never as a match. Fields outside
/// `tol.fields` are not compared.
pub fn compare(expected: &OutcomeMsg, got: &OutcomeMsg, tol: &Tolerances) -> Vec<FieldDiff> {
    let mut out = compare_all(expected, got, tol);
    out.retain(|d| tol.fields.contains(d.field));
    out
}

/// [`compare`] over every field the expectation holds.
fn compare_all(expected: &OutcomeMsg, got: &OutcomeMsg, tol: &Tolerances) -> Vec<FieldDiff> {
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

/// How a replayed sweep stands against its expectation: the one judgement
/// used by `check`, `diff` and the viewer's decision line.
#[derive(Clone, Debug, PartialEq)]
pub enum Agreement {
    /// Every field the expectation holds matches within the tolerances.
    Match,
    /// The expectation names another member of the replayed decision's tie
    /// set (its kind, triangle or feature differ) and every other field it
    /// holds matches that member (the contact is the member's own: a ball
    /// touching two faces at once touches them at two points; α and the
    /// averaged normal are the decision's): an equally valid answer to the
    /// rules' tie order, reached by different rounding. Not a divergence.
    Tie,
    /// Fields differ. When the replayed decision is fragile (rounding at the
    /// level of the inputs could change it), `fragile` names why; `check`
    /// counts such divergences apart and fails on them only with
    /// `--strict`.
    Diverges {
        /// The fields that differ (when the expectation names a member of
        /// the tie set: those that differ from that member).
        fields: Vec<FieldDiff>,
        /// Why the replayed decision is fragile; empty when robust.
        fragile: Fragility,
    },
}

impl Agreement {
    /// Whether the sweep diverges (robust or fragile).
    pub fn is_divergent(&self) -> bool {
        matches!(self, Agreement::Diverges { .. })
    }

    /// Whether the sweep fails a check: a divergence on a robust decision,
    /// or any divergence when `strict`.
    pub fn fails(&self, strict: bool) -> bool {
        match self {
            Agreement::Diverges { fragile, .. } => strict || fragile.is_robust(),
            Agreement::Match | Agreement::Tie => false,
        }
    }
}

/// Judges `result` against `expected` ([`compare`] over the fields the
/// expectation holds; see [`Agreement`]). An expectation naming another
/// member of the tie set in the scene the sweep was replayed against is a
/// [`Agreement::Tie`].
pub fn agreement(expected: &OutcomeMsg, result: &SweepResult, tol: &Tolerances) -> Agreement {
    let got = result.outcome_msg();
    let mut fields = compare(expected, &got, tol);
    if fields.is_empty() {
        return Agreement::Match;
    }
    let identity =
        |f: &FieldDiff| matches!(f.field, Field::Kind | Field::Triangle | Field::Feature);
    if fields.iter().any(identity) {
        match tie_member(expected, result, &result.scene.mesh, tol) {
            Some(TieMember::Agrees) => return Agreement::Tie,
            // Judged against the member it names: its fields that differ.
            Some(TieMember::Named(differ)) => fields = differ,
            None => {}
        }
    }
    Agreement::Diverges {
        fields,
        fragile: result.outcome.fragile,
    }
}

/// How an expectation relates to the replayed decision's tie set.
enum TieMember {
    /// It names a member of the tie set, and every field it holds matches
    /// that member (the contact is the member's own: two faces touched at
    /// once touch at two points).
    Agrees,
    /// It names a member, but some other field differs from every member
    /// it names: the fields that differ from the first of them.
    Named(Vec<FieldDiff>),
}

/// The point of the mesh a hit's test touches.
fn contact_of(record: &TestRecord) -> Option<[f64; 3]> {
    let p = match record {
        TestRecord::Face(r) => r.touch?,
        TestRecord::Edge(r) => r.frame.to_world(&nalgebra::Point3::new(r.xc?, 0.0, 0.0)),
        TestRecord::Vertex(r) => r.position,
    };
    Some([p.x, p.y, p.z])
}

/// Whether `expected` names a member of the tie set of `result`'s decision
/// (re-run with every hit recorded), and whether it matches that member.
fn tie_member(
    expected: &OutcomeMsg,
    result: &SweepResult,
    mesh: &crate::core::Mesh,
    tol: &Tolerances,
) -> Option<TieMember> {
    let mut records = CollectRecords::default();
    let outcome = sweep_mesh_with(
        mesh,
        &result.sweep,
        &result.options,
        Broadphase::Bvh,
        &mut records,
    )
    .ok()?;
    let mut named: Option<Vec<FieldDiff>> = None;
    for r in &records.records {
        let Some(tie) = Tie::of(r) else { continue };
        if !outcome.ties_with(tie.alpha)
            || !tie.matches(expected.kind, expected.triangle, expected.feature)
        {
            continue;
        }
        let mut member = OutcomeMsg::from_outcome(result.frame, result.ball, &outcome);
        member.kind = tie.kind;
        member.triangle = Some(Some(tie.triangle));
        member.feature = Some(tie.feature);
        member.contact = Some(contact_of(r));
        let differ = compare(expected, &member, tol);
        if differ.is_empty() {
            return Some(TieMember::Agrees);
        }
        named.get_or_insert(differ);
    }
    named.map(TieMember::Named)
}
