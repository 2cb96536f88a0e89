//! The JSON messages of the three channels of a trace (see `docs/TRACE_FORMAT.md`).

use serde::{Deserialize, Deserializer, Serialize};

use crate::core::{Facing, Kind};

/// Topic of the scene channel.
pub const SCENE_TOPIC: &str = "/scene";
/// Topic of the sweep channel.
pub const SWEEP_TOPIC: &str = "/sweep";
/// Topic of the expected-outcome channel.
pub const EXPECTED_TOPIC: &str = "/expected";
/// Schema name of `/scene` messages.
pub const SCENE_SCHEMA: &str = "sweeptrace.Scene";
/// Schema name of `/sweep` messages.
pub const SWEEP_SCHEMA: &str = "sweeptrace.Sweep";
/// Schema name of `/expected` messages.
pub const OUTCOME_SCHEMA: &str = "sweeptrace.Outcome";

/// A `/scene` message: the mesh that applies to the sweeps logged at or
/// after its `log_time`, until the next scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneMsg {
    /// Optional name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Vertex-index triples, counter-clockwise seen from the front.
    pub triangles: Vec<[u64; 3]>,
    /// The margin `ε` (default 0).
    #[serde(default)]
    pub margin: f64,
    /// The facing rule (default `non_strict`).
    #[serde(default)]
    pub facing: Facing,
}

/// A `/sweep` message: one ball moving from `p0` to `p1`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepMsg {
    /// Frame number.
    pub frame: u64,
    /// Ball number (default 0).
    #[serde(default)]
    pub ball: u32,
    /// Radius of the ball.
    pub radius: f64,
    /// Start of the ball's center.
    pub p0: [f64; 3],
    /// End of the ball's center.
    pub p1: [f64; 3],
}

/// An outcome: a `/expected` message, or one line of `replay --outcomes`.
///
/// Optional fields distinguish *absent* (`None`: not compared) from
/// *null* (`Some(None)`: no triangle, no normal, ...).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutcomeMsg {
    /// Frame number.
    pub frame: u64,
    /// Ball number (default 0).
    #[serde(default)]
    pub ball: u32,
    /// `α`.
    pub alpha: f64,
    /// Kind of the primary collision.
    pub kind: Kind,
    /// Primary triangle.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub triangle: Option<Option<u32>>,
    /// Primary feature.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub feature: Option<Option<u8>>,
    /// Reported normal.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub normal: Option<Option<[f64; 3]>>,
    /// Contact point.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub contact: Option<Option<[f64; 3]>>,
}

/// A field that is present deserializes to `Some(value-or-null)`.
fn present<'de, T: Deserialize<'de>, D: Deserializer<'de>>(
    d: D,
) -> Result<Option<Option<T>>, D::Error> {
    Option::<T>::deserialize(d).map(Some)
}

impl OutcomeMsg {
    /// The full outcome record of a core result (every field present).
    pub fn from_outcome(frame: u64, ball: u32, o: &crate::core::Outcome) -> OutcomeMsg {
        OutcomeMsg {
            frame,
            ball,
            alpha: o.alpha,
            kind: o.kind,
            triangle: Some(o.triangle),
            feature: Some(o.feature),
            normal: Some(o.normal.map(|n| [n.x, n.y, n.z])),
            contact: Some(o.contact.map(|c| [c.x, c.y, c.z])),
        }
    }
}
