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
/// Topic of the contact-query channel.
pub const CONTACT_TOPIC: &str = "/contact";
/// Topic of the expected-contacts channel.
pub const EXPECTED_CONTACTS_TOPIC: &str = "/expected_contacts";
/// Schema name of `/contact` messages.
pub const CONTACT_SCHEMA: &str = "sweeptrace.Contact";
/// Schema name of `/expected_contacts` messages.
pub const CONTACTS_SCHEMA: &str = "sweeptrace.Contacts";
/// Every topic of a trace's own channels (the others are foreign).
pub(crate) const TRACE_TOPICS: [&str; 5] = [
    SCENE_TOPIC,
    SWEEP_TOPIC,
    EXPECTED_TOPIC,
    CONTACT_TOPIC,
    EXPECTED_CONTACTS_TOPIC,
];

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
    /// No collision: `α = 1`, kind `none`, and `triangle`, `feature`,
    /// `normal`, `contact` null (every field present, so every field is
    /// compared).
    ///
    /// ```
    /// use sweeptrace::{Kind, OutcomeMsg};
    /// let miss = OutcomeMsg::miss(7, 0);
    /// assert_eq!((miss.alpha, miss.kind, miss.triangle), (1.0, Kind::None, Some(None)));
    /// ```
    pub fn miss(frame: u64, ball: u32) -> OutcomeMsg {
        OutcomeMsg {
            frame,
            ball,
            alpha: 1.0,
            kind: Kind::None,
            triangle: Some(None),
            feature: Some(None),
            normal: Some(None),
            contact: Some(None),
        }
    }

    /// A collision of `kind` at `alpha`. Give the fields the engine knows
    /// with [`triangle`](Self::triangle), [`feature`](Self::feature),
    /// [`normal`](Self::normal) and [`contact`](Self::contact); a field
    /// left unset is absent and so not compared (a face's `feature` is
    /// null: a face has none).
    ///
    /// ```
    /// use sweeptrace::{Kind, OutcomeMsg};
    /// let hit = OutcomeMsg::hit(3, 1, 0.25, Kind::Edge)
    ///     .triangle(12)
    ///     .feature(2)
    ///     .normal([0.0, 0.0, 1.0]);
    /// assert_eq!(hit.triangle, Some(Some(12)));
    /// assert_eq!(hit.contact, None); // not compared
    /// ```
    pub fn hit(frame: u64, ball: u32, alpha: f64, kind: Kind) -> OutcomeMsg {
        OutcomeMsg {
            frame,
            ball,
            alpha,
            kind,
            triangle: None,
            feature: (kind == Kind::Face).then_some(None),
            normal: None,
            contact: None,
        }
    }

    /// The primary triangle's input index.
    pub fn triangle(mut self, triangle: u32) -> OutcomeMsg {
        self.triangle = Some(Some(triangle));
        self
    }

    /// The edge or vertex index (0..2) within the triangle.
    pub fn feature(mut self, feature: u8) -> OutcomeMsg {
        self.feature = Some(Some(feature));
        self
    }

    /// The reported normal.
    pub fn normal(mut self, normal: [f64; 3]) -> OutcomeMsg {
        self.normal = Some(Some(normal));
        self
    }

    /// The contact point.
    pub fn contact(mut self, contact: [f64; 3]) -> OutcomeMsg {
        self.contact = Some(Some(contact));
        self
    }

    /// The full outcome record of a core result (every field present).
    pub fn from_outcome(frame: u64, ball: u32, o: &crate::core::Outcome) -> OutcomeMsg {
        let hit = o.hit.as_ref();
        OutcomeMsg {
            frame,
            ball,
            alpha: o.travelled(),
            kind: o.kind(),
            triangle: Some(hit.map(|h| h.triangle)),
            feature: Some(hit.and_then(|h| h.feature.index())),
            normal: Some(hit.map(|h| [h.normal.x, h.normal.y, h.normal.z])),
            contact: Some(hit.map(|h| [h.contact.x, h.contact.y, h.contact.z])),
        }
    }
}

/// A `/contact` message: what a ball of `radius` centred at `centre`
/// touches (SEMANTICS.md, "Contacts").
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactMsg {
    /// Frame number.
    pub frame: u64,
    /// Ball number (default 0).
    #[serde(default)]
    pub ball: u32,
    /// Radius of the ball.
    pub radius: f64,
    /// The ball's centre.
    pub centre: [f64; 3],
    /// The engine's contact distance: how far apart a triangle is still in
    /// contact (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub distance: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// One contact of an engine's manifold (an element of
/// [`ContactsMsg::contacts`]). Fields other than `triangle` may be omitted
/// (a recording engine may not know them); only those present are
/// compared.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactPointMsg {
    /// The triangle touched.
    pub triangle: u32,
    /// The feature's kind: `face`, `edge` or `vertex`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<Kind>,
    /// The edge or vertex index (0..2) within the triangle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feature: Option<u8>,
    /// The point of the triangle touched.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    /// The normal reported, pointing toward the ball's centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// The signed separation (negative: penetration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub separation: Option<f64>,
}

/// An `/expected_contacts` message: the contacts an engine reported for the
/// `/contact` query of the same `(frame, ball)` (an empty list: none).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactsMsg {
    /// Frame number.
    pub frame: u64,
    /// Ball number (default 0).
    #[serde(default)]
    pub ball: u32,
    /// The engine's contacts, in any order.
    pub contacts: Vec<ContactPointMsg>,
}

impl ContactPointMsg {
    /// Every field of a core contact, with the normal the rules report
    /// (`normal = "face"`): the triangle's, on the ball's side.
    pub fn from_contact(c: &crate::core::Contact) -> ContactPointMsg {
        let n = c.face_normal;
        ContactPointMsg {
            triangle: c.triangle,
            kind: Some(c.feature.kind()),
            feature: c.feature.index(),
            point: Some([c.point.x, c.point.y, c.point.z]),
            normal: Some([n.x, n.y, n.z]),
            separation: Some(c.separation),
        }
    }
}
