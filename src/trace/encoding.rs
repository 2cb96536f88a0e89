//! The message encodings a trace channel may use: MCAP's well-known `json`
//! and `cbor`, the same messages either way (`docs/TRACE_FORMAT.md`).

use serde::Serialize;

/// The message encoding of a trace's channels (MCAP's `message_encoding`).
///
/// Both encode the same messages, with the same fields and the same JSON
/// Schemas: JSON as text, CBOR (RFC 8949) as binary, where every number
/// the writer writes is an 8-byte double, read without parsing. JSON is the
/// default.
///
/// ```
/// use sweeptrace::Encoding;
/// assert_eq!(Encoding::default(), Encoding::Json);
/// assert_eq!(Encoding::Cbor.as_str(), "cbor");
/// assert_eq!(Encoding::from_message_encoding("cbor"), Some(Encoding::Cbor));
/// ```
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    serde::Deserialize,
    strum::EnumIter,
    strum::IntoStaticStr,
    strum::EnumString,
    strum::Display,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[cfg_attr(feature = "cli", clap(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Encoding {
    /// `json`: one JSON object per message.
    #[default]
    Json,
    /// `cbor`: one CBOR map per message, floats as 8-byte doubles.
    Cbor,
}

impl Encoding {
    /// Every encoding.
    pub fn all() -> impl Iterator<Item = Encoding> {
        <Encoding as strum::IntoEnumIterator>::iter()
    }

    /// Its MCAP `message_encoding` string (`json`, `cbor`).
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// The encoding of a channel's `message_encoding`, if it is one the
    /// reader reads (exactly `json` or `cbor`).
    pub fn from_message_encoding(message_encoding: &str) -> Option<Encoding> {
        Encoding::all().find(|e| e.as_str() == message_encoding)
    }

    /// Encodes a message.
    pub fn encode<T: Serialize>(self, message: &T) -> Result<Vec<u8>, String> {
        match self {
            Encoding::Json => serde_json::to_vec(message).map_err(|e| e.to_string()),
            Encoding::Cbor => super::cbor::to_vec(message),
        }
    }
}
