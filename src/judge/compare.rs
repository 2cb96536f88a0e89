//! The field-by-field comparison of an outcome with its expectation, on
//! which the one judgement ([`super::agreement`]) rests: [`compare`].

use nalgebra::Vector3;
use serde::Serialize;
use serde_json::{Value, json};

use crate::core::Kind;
use crate::core::explain::num;
use crate::numbers::{self, Rule};
use crate::trace::OutcomeMsg;

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
/// A normal must also be a unit vector: its length within
/// [`Tolerances::normal_length`] of 1 (the normal's angular tolerance, in
/// radians, unless set), on both sides. Two identical normals always
/// compare equal.
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
    /// Distance tolerance on the contact point (across
    /// [`Tolerances::contact_axis`] when one is set).
    pub contact: f64,
    /// A direction in which the contact point has a tolerance of its own:
    /// at single precision, the contact normal, along which rounding moves
    /// the contact far less than across it (set per sweep by
    /// [`super::precision::Sensitivity::widen`]; not in the JSON).
    #[serde(skip)]
    pub contact_axis: Option<ContactAxis>,
    /// How far a normal's length may be from 1; `None`: the angular
    /// tolerance `normal_degrees` in radians. Not in the JSON.
    #[serde(skip)]
    pub normal_length: Option<f64>,
    /// The fields compared (those the expectation holds among them).
    pub fields: FieldSet,
}

/// The contact's own tolerance along one direction ([`Tolerances::contact_axis`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactAxis {
    /// The direction, a unit vector.
    pub axis: [f64; 3],
    /// How far the contact may move along it.
    pub tolerance: f64,
    /// Whether the contact is on a face, whose plane the axis is normal to
    /// (the wording: "off the triangle's plane").
    pub plane: bool,
}

impl Tolerances {
    /// How far a normal's length may be from 1 ([`Tolerances::normal_length`]).
    pub fn normal_length(&self) -> f64 {
        self.normal_length
            .unwrap_or_else(|| self.normal_degrees.to_radians())
    }
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            alpha: DEFAULT_ALPHA_TOLERANCE,
            normal_degrees: DEFAULT_NORMAL_TOLERANCE_DEGREES,
            contact: DEFAULT_CONTACT_TOLERANCE,
            contact_axis: None,
            normal_length: None,
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

    /// Whether the set holds no field.
    pub fn is_empty(self) -> bool {
        self.0 == 0
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

/// The words that say a normal's length is wrong (a fixed tolerance, not
/// one that single precision widens).
pub(crate) const NOT_A_UNIT_VECTOR: &str = "not a unit vector";

/// What a difference is reported as: its words (`String`), or only the
/// fact that there is one (`()`, for the judge's searches, which compare
/// many times and read no words).
trait Words {
    fn say(words: impl FnOnce() -> String) -> Self;
}

impl Words for String {
    fn say(words: impl FnOnce() -> String) -> String {
        words()
    }
}

impl Words for () {
    fn say(_: impl FnOnce() -> String) {}
}

/// How two normals differ; `None` when they match: identical, or within
/// the angle and both of unit length.
fn normal_difference<W: Words>(w: [f64; 3], h: [f64; 3], tol: &Tolerances) -> Option<W> {
    if w == h && w.iter().all(|x| x.is_finite()) {
        return None;
    }
    let Some(angle) = angle_degrees(w, h) else {
        return Some(W::say(|| {
            "one of the normals has zero or non-finite length".to_string()
        }));
    };
    let wide = angle > tol.normal_degrees;
    let lengths = [w, h].map(|v| Vector3::from(v).norm());
    let not_unit = |length: f64| (length - 1.0).abs() > tol.normal_length();
    if !wide && !lengths.iter().any(|&l| not_unit(l)) {
        return None;
    }
    Some(W::say(|| {
        let mut words = Vec::new();
        if wide {
            words.push(format!(
                "angle {}° > {}°",
                num(angle),
                num(tol.normal_degrees)
            ));
        }
        for length in lengths.into_iter().filter(|&l| not_unit(l)) {
            words.push(format!(
                "|n| = {}, {NOT_A_UNIT_VECTOR} (within {} of 1)",
                num(length),
                num(tol.normal_length())
            ));
        }
        words.join("; ")
    }))
}

/// How two contact points differ; `None` when they match.
fn contact_difference<W: Words>(w: [f64; 3], h: [f64; 3], tol: &Tolerances) -> Option<W> {
    let d = distance(w, h);
    let too_far = || W::say(|| format!("distance {} > {}", num(d), num(tol.contact)));
    // NaN (a non-finite point) is a difference too.
    if d.is_nan() {
        return Some(too_far());
    }
    let Some(axis) = tol.contact_axis else {
        return (d > tol.contact).then(too_far);
    };
    let moved = Vector3::from(h) - Vector3::from(w);
    let along = moved.dot(&Vector3::from(axis.axis)).abs();
    let across = (d * d - along * along).max(0.0).sqrt();
    if along > axis.tolerance {
        return Some(W::say(|| {
            let off = if axis.plane {
                "off the triangle's plane"
            } else {
                "along the contact normal"
            };
            format!(
                "contact {} {off} > {} (distance {})",
                num(along),
                num(axis.tolerance),
                num(d)
            )
        }));
    }
    (across > tol.contact).then(|| {
        W::say(|| {
            format!(
                "distance {} across the normal > {}",
                num(across),
                num(tol.contact)
            )
        })
    })
}

/// Compares `got` with `expected`, field by field, **only over the fields
/// `expected` holds** (an absent field is `None` in [`OutcomeMsg`] and is
/// not compared; a `null` field is `Some(None)` and is compared: it must be
/// null in the outcome too). Discrete fields (`kind`, `triangle`,
/// `feature`) must be equal; the continuous ones are compared within the
/// [`Tolerances`], whose defaults are listed there. Returns the fields that
/// differ, in the order kind, triangle, feature, alpha, normal, contact;
/// empty when they match. `frame` and `ball` are not compared (they are the
/// matching key). A NaN anywhere counts as a difference, never as a match.
/// Fields outside `tol.fields` are not compared.
pub fn compare(expected: &OutcomeMsg, got: &OutcomeMsg, tol: &Tolerances) -> Vec<FieldDiff> {
    let mut out = Vec::new();
    differences::<String>(expected, got, tol, |field, detail| {
        let (expected, got) = values(field, expected, got);
        out.push(FieldDiff {
            field,
            expected,
            got,
            detail,
        });
    });
    out
}

/// The fields [`compare`] would return, without their values or words:
/// for the judge's searches, which compare the same answer many times.
pub fn differing(expected: &OutcomeMsg, got: &OutcomeMsg, tol: &Tolerances) -> FieldSet {
    let mut set = FieldSet(0);
    differences::<()>(expected, got, tol, |field, _| {
        set.0 |= FieldSet::bit(field);
    });
    set
}

/// A field's expected and replayed values, as [`FieldDiff`] shows them.
fn values(field: Field, expected: &OutcomeMsg, got: &OutcomeMsg) -> (Value, Value) {
    match field {
        Field::Kind => (json!(expected.kind), json!(got.kind)),
        Field::Triangle => (
            json!(expected.triangle.flatten()),
            json!(got.triangle.flatten()),
        ),
        Field::Feature => (
            json!(expected.feature.flatten()),
            json!(got.feature.flatten()),
        ),
        Field::Alpha => (json!(expected.alpha), json!(got.alpha)),
        Field::Normal => (
            vec3(&expected.normal.flatten()),
            vec3(&got.normal.flatten()),
        ),
        Field::Contact => (
            vec3(&expected.contact.flatten()),
            vec3(&got.contact.flatten()),
        ),
    }
}

/// Calls `found` with each field of `tol.fields` the expectation holds and
/// `got` does not match, in the order of [`Field`], with the difference's
/// words (when `W` keeps them; `None` where the values say it).
fn differences<W: Words>(
    expected: &OutcomeMsg,
    got: &OutcomeMsg,
    tol: &Tolerances,
    mut found: impl FnMut(Field, Option<W>),
) {
    let mut found = |field: Field, detail: Option<W>| {
        if tol.fields.contains(field) {
            found(field, detail);
        }
    };
    if expected.kind != got.kind {
        found(Field::Kind, None);
    }
    if let Some(want) = expected.triangle
        && want != got.triangle.flatten()
    {
        found(Field::Triangle, None);
    }
    // A face has no feature: an expected face hit matches a face hit whatever
    // feature it names (`null`, or the 0 older recordings wrote).
    let both_faces = expected.kind == Kind::Face && got.kind == Kind::Face;
    if let Some(want) = expected.feature.filter(|_| !both_faces)
        && want != got.feature.flatten()
    {
        found(Field::Feature, None);
    }
    let delta = (got.alpha - expected.alpha).abs();
    if delta.is_nan() || delta > tol.alpha {
        found(
            Field::Alpha,
            Some(W::say(|| {
                format!("|Δα| = {} > {}", num(delta), num(tol.alpha))
            })),
        );
    }
    if let Some(want) = expected.normal {
        // Null on one side only: the values say it (`engine null, core
        // [0, 0, 1]`), in the words of whoever renders the two sides.
        match (want, got.normal.flatten()) {
            (None, None) => {}
            (Some(_), None) | (None, Some(_)) => found(Field::Normal, None),
            (Some(w), Some(h)) => {
                if let Some(detail) = normal_difference(w, h, tol) {
                    found(Field::Normal, Some(detail));
                }
            }
        }
    }
    if let Some(want) = expected.contact {
        match (want, got.contact.flatten()) {
            (None, None) => {}
            (Some(_), None) | (None, Some(_)) => found(Field::Contact, None),
            (Some(w), Some(h)) => {
                if let Some(detail) = contact_difference(w, h, tol) {
                    found(Field::Contact, Some(detail));
                }
            }
        }
    }
}
