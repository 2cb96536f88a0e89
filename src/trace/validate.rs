//! Parsing and validation of the messages of a trace, JSON or CBOR.
//!
//! The reader parses every message of the three channels through
//! [`parse_message_as`] (so an error names the field by its path, in either
//! encoding) and then
//! checks the values with [`validate_scene`], [`validate_sweep`] and
//! [`validate_outcome`]. The writer runs the same checks, so a trace written
//! by this crate is always readable by it.

use serde::Deserialize;
use serde::de::DeserializeOwned;

use super::encoding::Encoding;
use super::error::{MessageAt, TraceError};
use super::messages::{ContactMsg, ContactsMsg, OutcomeMsg, SceneMsg, SweepMsg};
use crate::core::Kind;
use crate::numbers::{self, Rule};

/// A field holding an invalid value, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldProblem {
    /// Path of the field, such as `triangles[12][1]` or `radius`.
    pub field: String,
    /// What is wrong with it.
    pub problem: String,
}

impl FieldProblem {
    pub(crate) fn new(field: impl Into<String>, problem: impl Into<String>) -> FieldProblem {
        FieldProblem {
            field: field.into(),
            problem: problem.into(),
        }
    }

    /// Attaches the message's position to make a [`TraceError::Invalid`].
    pub fn at(self, at: MessageAt) -> TraceError {
        TraceError::Invalid {
            at: Box::new(at),
            field: self.field,
            problem: self.problem,
        }
    }
}

/// Just the frame of a sweep or outcome, read leniently to name the frame of
/// a message that fails to parse.
#[derive(Deserialize)]
struct FrameOnly {
    #[serde(default)]
    frame: Option<u64>,
}

/// The frame of a message in `encoding`, if one can be read from it.
pub fn frame_of_message(data: &[u8], encoding: Encoding) -> Option<u64> {
    match encoding {
        Encoding::Json => serde_json::from_slice::<FrameOnly>(data).ok(),
        Encoding::Cbor => {
            FrameOnly::deserialize(&mut super::cbor::Deserializer::from_slice(data)).ok()
        }
    }
    .and_then(|f| f.frame)
}

/// Parses one JSON message; errors name the field by its path.
///
/// `at` is the message's position; its frame is filled in from the raw
/// message when it can be read.
pub fn parse_message<T: DeserializeOwned>(data: &[u8], at: MessageAt) -> Result<T, TraceError> {
    parse_message_as(data, Encoding::Json, || at)
}

/// Parses one message in `encoding`; errors name the field by its path.
///
/// `at` gives the message's position, asked for only on an error; its
/// frame is filled in from the raw message when it can be read.
pub fn parse_message_as<T: DeserializeOwned>(
    data: &[u8],
    encoding: Encoding,
    at: impl FnOnce() -> MessageAt,
) -> Result<T, TraceError> {
    // The plain parse first; only a message that fails is parsed again,
    // keeping track of the path, to name the field.
    let fast = match encoding {
        Encoding::Json => serde_json::from_slice::<T>(data).ok(),
        Encoding::Cbor => {
            let mut de = super::cbor::Deserializer::from_slice(data);
            T::deserialize(&mut de).ok().filter(|_| de.end().is_ok())
        }
    };
    if let Some(value) = fast {
        return Ok(value);
    }
    let (path, detail) = match encoding {
        Encoding::Json => json_error::<T>(data),
        Encoding::Cbor => cbor_error::<T>(data),
    };
    let mut at = at();
    if at.frame.is_none() {
        at.frame = frame_of_message(data, encoding);
    }
    let (field, detail) = match detail {
        // Reached only if the two parses disagree, which they cannot.
        None => (".".to_string(), "the message cannot be read".to_string()),
        Some((message, malformed)) => field_and_detail(path, message, malformed, encoding),
    };
    Err(TraceError::Json {
        at: Box::new(at),
        field,
        detail,
    })
}

/// The path and the error (its text, whether the bytes are malformed) of
/// a JSON message that fails to parse.
fn json_error<T: DeserializeOwned>(data: &[u8]) -> (String, Option<(String, bool)>) {
    let mut de = serde_json::Deserializer::from_slice(data);
    // Trailing characters after the object are an error too.
    match serde_path_to_error::deserialize::<_, T>(&mut de) {
        Ok(_) => match de.end() {
            Ok(()) => (".".to_string(), None),
            Err(e) => (".".to_string(), Some((e.to_string(), true))),
        },
        Err(err) => {
            let path = err.path().to_string();
            let inner = err.into_inner();
            let malformed = inner.is_syntax() || inner.is_eof();
            (path, Some((inner.to_string(), malformed)))
        }
    }
}

/// As [`json_error`], for a CBOR message.
fn cbor_error<T: DeserializeOwned>(data: &[u8]) -> (String, Option<(String, bool)>) {
    let mut de = super::cbor::Deserializer::from_slice(data);
    match serde_path_to_error::deserialize::<_, T>(&mut de) {
        Ok(_) => match de.end() {
            Ok(()) => (".".to_string(), None),
            Err(e) => (".".to_string(), Some((e.to_string(), true))),
        },
        Err(err) => {
            let path = err.path().to_string();
            let inner = err.into_inner();
            let malformed = inner.is_malformed();
            (path, Some((inner.to_string(), malformed)))
        }
    }
}

/// The field an error names and what it says about it.
fn field_and_detail(
    path: String,
    message: String,
    malformed: bool,
    encoding: Encoding,
) -> (String, String) {
    let field = match message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next())
    {
        Some(name) if path == "." => name.to_string(),
        Some(name) => format!("{path}.{name}"),
        None => path,
    };
    let detail = if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((_, expected)) = rest.rsplit_once("`, expected ")
    {
        // The field's name is already given as the field.
        format!("not a field of this message; expected {expected}")
    } else if malformed {
        match encoding {
            Encoding::Json => format!("the message is not valid JSON: {message}"),
            Encoding::Cbor => format!("the message is not valid CBOR: {message}"),
        }
    } else if message.contains("invalid type: null") {
        match encoding {
            Encoding::Json => {
                format!("{message} (`null` is not a number; JSON has no NaN or infinity)")
            }
            Encoding::Cbor => format!("{message} (`null` is not a number)"),
        }
    } else {
        message
    };
    (field, detail)
}

fn finite3(field: &str, v: &[f64; 3]) -> Result<(), FieldProblem> {
    for (k, &c) in v.iter().enumerate() {
        numbers::check(c, Rule::Finite)
            .map_err(|e| FieldProblem::new(format!("{field}[{k}]"), e))?;
    }
    Ok(())
}

/// Checks a scene: finite coordinates, vertex indices in range, a finite
/// margin `≥ 0`.
pub fn validate_scene(scene: &SceneMsg) -> Result<(), FieldProblem> {
    for (i, v) in scene.vertices.iter().enumerate() {
        finite3(&format!("vertices[{i}]"), v)?;
    }
    let count = scene.vertices.len() as u64;
    for (t, tri) in scene.triangles.iter().enumerate() {
        for (k, &index) in tri.iter().enumerate() {
            if index >= count {
                return Err(FieldProblem::new(
                    format!("triangles[{t}][{k}]"),
                    format!(
                        "vertex index {index} is out of range (the scene has {count} vertices)"
                    ),
                ));
            }
        }
    }
    numbers::check(scene.margin, Rule::NonNegative).map_err(|e| FieldProblem::new("margin", e))?;
    Ok(())
}

/// Checks a sweep: a finite radius `> 0` above the scene's margin (when a
/// scene is given), finite `p0` and `p1` at a finite distance.
pub fn validate_sweep(sweep: &SweepMsg, scene_margin: Option<f64>) -> Result<(), FieldProblem> {
    numbers::check(sweep.radius, Rule::Positive).map_err(|e| FieldProblem::new("radius", e))?;
    if let Some(margin) = scene_margin
        && margin >= sweep.radius
    {
        return Err(FieldProblem::new(
            "radius",
            format!(
                "must be larger than the scene's margin {}, got {}",
                numbers::Shortest(margin),
                numbers::Shortest(sweep.radius)
            ),
        ));
    }
    finite3("p0", &sweep.p0)?;
    finite3("p1", &sweep.p1)?;
    // The core measures the path (as `SweptPath::new` does): finite ends
    // far apart can still overflow its length (found by fuzzing).
    let length = (nalgebra::Vector3::from(sweep.p1) - nalgebra::Vector3::from(sweep.p0)).norm();
    if !length.is_finite() {
        return Err(FieldProblem::new(
            "p1",
            format!("is too far from p0: the path's length overflows to {length}"),
        ));
    }
    Ok(())
}

/// Checks an outcome: `alpha` in `[0, 1]`, `feature` in `0..=2`, finite
/// `normal` and `contact`, and a hit's normal not zero.
pub fn validate_outcome(outcome: &OutcomeMsg) -> Result<(), FieldProblem> {
    if !(0.0..=1.0).contains(&outcome.alpha) {
        return Err(FieldProblem::new(
            "alpha",
            format!(
                "must be a number in [0, 1], got {}",
                numbers::Shortest(outcome.alpha)
            ),
        ));
    }
    if let Some(Some(feature)) = outcome.feature
        && feature > 2
    {
        return Err(FieldProblem::new(
            "feature",
            format!("must be 0, 1 or 2, got {feature}"),
        ));
    }
    if let Some(Some(normal)) = &outcome.normal {
        finite3("normal", normal)?;
        // A hit's normal is a direction: a zero vector is no answer (a
        // miss may carry one, which the comparison reports as a value
        // where null is expected).
        if outcome.kind != Kind::None && normal.iter().all(|x| *x == 0.0) {
            return Err(FieldProblem::new(
                "normal",
                "must be a nonzero vector on a hit, got [0, 0, 0]",
            ));
        }
    }
    if let Some(Some(contact)) = &outcome.contact {
        finite3("contact", contact)?;
    }
    Ok(())
}

/// Checks a contact query: a finite radius `> 0`, a finite centre, a
/// finite contact distance `≥ 0`.
pub fn validate_contact(contact: &ContactMsg) -> Result<(), FieldProblem> {
    numbers::check(contact.radius, Rule::Positive).map_err(|e| FieldProblem::new("radius", e))?;
    finite3("centre", &contact.centre)?;
    numbers::check(contact.distance, Rule::NonNegative)
        .map_err(|e| FieldProblem::new("distance", e))?;
    // The core measures the reach, radius + distance (as a sweep's path
    // length is measured): finite parts can overflow it.
    let reach = contact.radius + contact.distance;
    if !reach.is_finite() {
        return Err(FieldProblem::new(
            "distance",
            format!("is too large: the radius plus the distance overflows to {reach}"),
        ));
    }
    Ok(())
}

/// Checks an engine's contacts: per contact, `kind` not `none`, `feature`
/// in `0..=2` (and absent on a face), finite `point`, `normal` and
/// `separation`, a nonzero normal.
pub fn validate_contacts(contacts: &ContactsMsg) -> Result<(), FieldProblem> {
    for (i, c) in contacts.contacts.iter().enumerate() {
        let field = |name: &str| format!("contacts[{i}].{name}");
        if c.kind == Some(Kind::None) {
            return Err(FieldProblem::new(
                field("kind"),
                "must be face, edge or vertex, got none",
            ));
        }
        if let Some(feature) = c.feature {
            if feature > 2 {
                return Err(FieldProblem::new(
                    field("feature"),
                    format!("must be 0, 1 or 2, got {feature}"),
                ));
            }
            if c.kind == Some(Kind::Face) {
                return Err(FieldProblem::new(
                    field("feature"),
                    format!("a face has no feature index, got {feature}"),
                ));
            }
        }
        if let Some(point) = &c.point {
            finite3(&field("point"), point)?;
        }
        if let Some(normal) = &c.normal {
            finite3(&field("normal"), normal)?;
            if normal.iter().all(|x| *x == 0.0) {
                return Err(FieldProblem::new(
                    field("normal"),
                    "must be a nonzero vector, got [0, 0, 0]",
                ));
            }
        }
        if let Some(separation) = c.separation {
            numbers::check(separation, Rule::Finite)
                .map_err(|e| FieldProblem::new(field("separation"), e))?;
        }
    }
    Ok(())
}

/// Checks an outcome's `triangle` against its scene: an index below
/// `scene_triangles`. The writers check it ([`TraceWriter::expected`](super::TraceWriter::expected)
/// and the C API's); the reader does not, so that a recording engine that
/// names a triangle the scene does not have is judged (a divergence), not
/// refused with the file.
pub fn validate_triangle(outcome: &OutcomeMsg, scene_triangles: usize) -> Result<(), FieldProblem> {
    match outcome.triangle {
        Some(Some(triangle)) if triangle as usize >= scene_triangles => Err(FieldProblem::new(
            "triangle",
            format!("index {triangle} is out of range (the scene has {scene_triangles} triangles)"),
        )),
        _ => Ok(()),
    }
}

/// Checks an engine's contacts' triangles against their scene, as
/// [`validate_triangle`] checks an outcome's (the writer checks them; the
/// reader does not, so that a wrong triangle is judged, an extra contact).
pub(crate) fn validate_contact_triangles(
    contacts: &ContactsMsg,
    scene_triangles: usize,
) -> Result<(), FieldProblem> {
    for (i, c) in contacts.contacts.iter().enumerate() {
        if c.triangle as usize >= scene_triangles {
            return Err(FieldProblem::new(
                format!("contacts[{i}].triangle"),
                format!(
                    "index {} is out of range (the scene has {scene_triangles} triangles)",
                    c.triangle
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 42: a zero normal is no answer, so `bless --engine` cannot
    /// write one and `check` never meets two identical answers it calls
    /// different. A miss may still carry one.
    #[test]
    fn a_hit_with_a_zero_normal_is_refused() {
        let hit = OutcomeMsg::hit(0, 0, 0.5, Kind::Face).normal([0.0, 0.0, 0.0]);
        let problem = validate_outcome(&hit).expect_err("a zero normal on a hit");
        assert_eq!(problem.field, "normal");
        assert!(
            validate_outcome(&OutcomeMsg::hit(0, 0, 0.5, Kind::Face).normal([0.0, 0.0, 1.0]))
                .is_ok()
        );
        let mut miss = OutcomeMsg::hit(0, 0, 1.0, Kind::None);
        miss.normal = Some(Some([0.0, 0.0, 0.0]));
        assert!(validate_outcome(&miss).is_ok());
    }
}
