//! The lines of the engine protocol (`docs/ENGINE_PROTOCOL.md`): the trace
//! format's JSON messages ([`SceneMsg`], [`SweepMsg`], [`OutcomeMsg`]) with
//! a `type` tag, one per line.

use serde_json::{Map, Value};

use crate::trace::validate::validate_outcome;
use crate::trace::{ContactMsg, ContactsMsg, OutcomeMsg, SceneMsg, SweepMsg, validate_contacts};

/// The longest output line accepted from an engine, in bytes.
pub const MAX_ANSWER_BYTES: usize = 1 << 16;

/// `{"type":"scene", ...the /scene fields}` and a newline.
pub fn scene_line(scene: &SceneMsg) -> Result<String, serde_json::Error> {
    tagged("scene", serde_json::to_string(scene)?)
}

/// `{"type":"sweep","frame":..,"ball":..,"radius":..,"p0":[..],"p1":[..]}`
/// and a newline. Numbers are shortest round-trip decimals: an engine that
/// parses them correctly gets the trace's bits.
pub fn sweep_line(sweep: &SweepMsg) -> Result<String, serde_json::Error> {
    tagged("sweep", serde_json::to_string(sweep)?)
}

/// `{"type":"contact","frame":..,"ball":..,"radius":..,"centre":[..],...}`
/// and a newline: a contact query (sent only to an engine that answers
/// them, `check --engine-contacts`).
pub fn contact_line(contact: &ContactMsg) -> Result<String, serde_json::Error> {
    tagged("contact", serde_json::to_string(contact)?)
}

/// `{"type":"contacts", ...the /expected_contacts fields}` and a newline:
/// an engine's answer to a contact query, as [`parse_contacts`] reads it.
pub fn contacts_line(contacts: &ContactsMsg) -> Result<String, serde_json::Error> {
    tagged("contacts", serde_json::to_string(contacts)?)
}

/// `{"type":"outcome", ...the /expected fields}` and a newline: an
/// engine's answer as [`parse_answer`] reads it.
pub fn answer_line(outcome: &OutcomeMsg) -> Result<String, serde_json::Error> {
    tagged("outcome", serde_json::to_string(outcome)?)
}

/// A line sent to an engine, as the engine's side of the protocol reads it.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// A `scene` line.
    Scene(SceneMsg),
    /// A `sweep` line.
    Sweep(SweepMsg),
    /// A `contact` line.
    Contact(ContactMsg),
    /// A line of another `type`, which a version-1 engine ignores.
    Other(String),
}

/// Parses one line sent to an engine (the engine's side of the protocol):
/// a JSON object with a string `type`; `scene` and `sweep` with the fields
/// of `/scene` and `/sweep` (an unknown field is an error), any other type
/// [`Request::Other`]. The error says what is wrong, naming the field.
/// The values are not validated ([`crate::trace::validate::validate_outcome`] does that).
pub fn parse_request(line: &[u8]) -> Result<Request, String> {
    let text = std::str::from_utf8(line).map_err(|_| "it is not UTF-8 text".to_string())?;
    let mut object: Map<String, Value> = match serde_json::from_str::<Value>(text.trim()) {
        Ok(Value::Object(o)) => o,
        Ok(_) => return Err("it is not a JSON object".to_string()),
        Err(e) => return Err(format!("it is not valid JSON ({e})")),
    };
    let kind = match object.remove("type") {
        Some(Value::String(t)) => t,
        Some(other) => return Err(format!("field `type`: must be a string, got {other}")),
        None => return Err("field `type` is missing".to_string()),
    };
    fn fields<T: serde::de::DeserializeOwned>(object: Map<String, Value>) -> Result<T, String> {
        serde_path_to_error::deserialize(Value::Object(object)).map_err(|e| {
            let path = e.path().to_string();
            if path == "." {
                e.inner().to_string()
            } else {
                format!("field `{path}`: {}", e.inner())
            }
        })
    }
    match kind.as_str() {
        "scene" => fields(object).map(Request::Scene),
        "sweep" => fields(object).map(Request::Sweep),
        "contact" => fields(object).map(Request::Contact),
        _ => Ok(Request::Other(kind)),
    }
}

fn tagged(tag: &str, object: String) -> Result<String, serde_json::Error> {
    // `object` is a JSON object with at least one field: `{"..`.
    let rest = object.strip_prefix('{').unwrap_or(&object);
    Ok(format!("{{\"type\":\"{tag}\",{rest}\n"))
}

/// Parses one answer line: a JSON object with the fields of `/expected`
/// (`frame`, `alpha` and `kind` required, the others optional) and
/// optionally `"type": "outcome"`. The error says what is wrong, naming the
/// field.
pub fn parse_answer(line: &[u8]) -> Result<OutcomeMsg, String> {
    let outcome: OutcomeMsg = parse_tagged(line, "outcome", "an answer")?;
    validate_outcome(&outcome).map_err(|p| format!("field `{}`: {}", p.field, p.problem))?;
    Ok(outcome)
}

/// Parses one answer to a contact query: a JSON object with the fields of
/// `/expected_contacts` (`frame` and `contacts` required) and optionally
/// `"type": "contacts"`. The error says what is wrong, naming the field.
pub fn parse_contacts(line: &[u8]) -> Result<ContactsMsg, String> {
    let contacts: ContactsMsg = parse_tagged(line, "contacts", "the answer to a contact query")?;
    validate_contacts(&contacts).map_err(|p| format!("field `{}`: {}", p.field, p.problem))?;
    Ok(contacts)
}

/// A JSON object line with the fields of `T` and, optionally, `"type":
/// tag` (`what` names it in the error).
fn parse_tagged<T: serde::de::DeserializeOwned>(
    line: &[u8],
    tag: &str,
    what: &str,
) -> Result<T, String> {
    let text = std::str::from_utf8(line).map_err(|_| "it is not UTF-8 text".to_string())?;
    let mut object: Map<String, Value> = match serde_json::from_str::<Value>(text.trim()) {
        Ok(Value::Object(o)) => o,
        Ok(_) => return Err("it is not a JSON object".to_string()),
        Err(e) => return Err(format!("it is not valid JSON ({e})")),
    };
    match object.remove("type") {
        None => {}
        Some(Value::String(t)) if t == tag => {}
        Some(other) => {
            return Err(format!(
                "field `type`: {what} is of type \"{tag}\", got {other}"
            ));
        }
    }
    serde_path_to_error::deserialize(Value::Object(object)).map_err(|e| {
        let path = e.path().to_string();
        if path == "." {
            e.inner().to_string()
        } else {
            format!("field `{path}`: {}", e.inner())
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_tagged_messages() {
        let sweep = SweepMsg {
            frame: 3,
            ball: 1,
            radius: 0.5,
            p0: [0.1, 0.0, 3.0],
            p1: [0.1, 0.0, -3.0],
        };
        assert_eq!(
            sweep_line(&sweep).unwrap(),
            "{\"type\":\"sweep\",\"frame\":3,\"ball\":1,\"radius\":0.5,\"p0\":[0.1,0.0,3.0],\"p1\":[0.1,0.0,-3.0]}\n"
        );
        let answer = parse_answer(
            br#"{"type":"outcome","frame":3,"ball":1,"alpha":0.5,"kind":"face","triangle":0}"#,
        )
        .unwrap();
        assert_eq!(answer.frame, 3);
        assert_eq!(answer.triangle, Some(Some(0)));
        assert_eq!(answer.normal, None);
        assert!(
            parse_answer(b"hello")
                .unwrap_err()
                .contains("not valid JSON")
        );
        assert!(
            parse_answer(br#"{"frame":3,"alpha":2,"kind":"face"}"#)
                .unwrap_err()
                .contains("alpha")
        );
        assert!(
            parse_answer(br#"{"frame":3,"alpha":0.5,"kind":"side"}"#)
                .unwrap_err()
                .contains("kind")
        );
    }

    #[test]
    fn requests_read_back_what_is_sent() {
        let sweep = SweepMsg {
            frame: 3,
            ball: 1,
            radius: 0.5,
            p0: [0.1, 0.0, 3.0],
            p1: [0.1, 0.0, -3.0],
        };
        let line = sweep_line(&sweep).unwrap();
        assert_eq!(
            parse_request(line.as_bytes()).unwrap(),
            Request::Sweep(sweep)
        );
        assert_eq!(
            parse_request(br#"{"type":"hello","x":1}"#).unwrap(),
            Request::Other("hello".to_string())
        );
        assert!(
            parse_request(br#"{"frame":3}"#)
                .unwrap_err()
                .contains("type")
        );
        assert!(
            parse_request(
                br#"{"type":"sweep","frame":3,"radius":1,"p0":[0,0,0],"p1":[0,0,0],"speed":2}"#
            )
            .unwrap_err()
            .contains("speed")
        );
        let query = ContactMsg {
            frame: 4,
            ball: 1,
            radius: 0.5,
            centre: [0.1, 0.0, 0.4],
            distance: 0.02,
        };
        let line = contact_line(&query).unwrap();
        assert_eq!(
            parse_request(line.as_bytes()).unwrap(),
            Request::Contact(query)
        );
        let contacts = ContactsMsg {
            frame: 4,
            ball: 1,
            contacts: Vec::new(),
        };
        let line = contacts_line(&contacts).unwrap();
        assert_eq!(parse_contacts(line.as_bytes()).unwrap(), contacts);
        assert!(
            parse_contacts(br#"{"type":"outcome","frame":4,"contacts":[]}"#)
                .unwrap_err()
                .contains("type")
        );
        assert!(
            parse_contacts(br#"{"frame":4,"contacts":[{"triangle":0,"normal":[0,0,0]}]}"#)
                .unwrap_err()
                .contains("contacts[0].normal")
        );
        let answer = OutcomeMsg::miss(3, 1);
        let line = answer_line(&answer).unwrap();
        assert!(line.starts_with("{\"type\":\"outcome\",") && line.ends_with("}\n"));
        assert_eq!(parse_answer(line.as_bytes()).unwrap(), answer);
    }
}
