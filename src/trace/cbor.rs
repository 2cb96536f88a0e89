//! The CBOR encoding of the messages (RFC 8949): the same maps, field
//! names and values as the JSON, through the same serde structs, so the
//! validation is shared.
//!
//! Writing goes through `minicbor-serde`: maps of definite length with
//! text keys, text strings for the enums, `null` for "none", and every
//! `f64` as an 8-byte double (major type 7, `0xfb`), never shortened.
//!
//! Reading is a serde [`Deserializer`] over `minicbor`'s [`Decoder`]
//! (bounds-checked reads from a byte slice, nothing allocated for a
//! declared length), accepting what a JSON reader accepts: a number field
//! takes a float of any width (half, single, double: each is exact in an
//! `f64`) or an integer (converted as JSON's integers are), an integer
//! field an unsigned or negative integer (refused with serde's own message
//! when out of range), a map key must be a text string. Tags, byte strings,
//! `undefined` and simple values are not part of the format and are
//! refused. Nesting deeper than [`MAX_DEPTH`] is refused (the messages
//! nest three deep), so no input can exhaust the stack; a declared array
//! or map length only bounds the loop, never an allocation (serde's
//! collections reserve at most a small fixed amount up front).

use std::fmt;

use minicbor::data::Type;
use minicbor::decode::Decoder;
use serde::Serialize;
use serde::de::{
    self, DeserializeSeed, IntoDeserializer, MapAccess, SeqAccess, Unexpected, Visitor,
};

/// Deepest nesting of arrays and maps accepted.
pub const MAX_DEPTH: usize = 32;

/// The break byte ending an indefinite-length array or map.
const BREAK: u8 = 0xff;

/// Encodes a message as CBOR (floats as 8-byte doubles).
pub fn to_vec<T: Serialize>(value: &T) -> Result<Vec<u8>, String> {
    minicbor_serde::to_vec(value).map_err(|e| e.to_string())
}

/// A CBOR message that cannot be read into its struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    message: String,
    malformed: bool,
}

impl Error {
    fn malformed(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            malformed: true,
        }
    }

    /// Whether the bytes are not well-formed CBOR (truncated, a reserved
    /// byte, bytes after the message, text that is not UTF-8), rather than
    /// well-formed CBOR of the wrong shape.
    pub fn is_malformed(&self) -> bool {
        self.malformed
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

impl de::Error for Error {
    fn custom<T: fmt::Display>(message: T) -> Error {
        Error {
            message: message.to_string(),
            malformed: false,
        }
    }

    // As serde_json says it: a `null` is `null`, not serde's "unit value".
    fn invalid_type(unexpected: Unexpected, expected: &dyn de::Expected) -> Error {
        match unexpected {
            Unexpected::Unit => {
                de::Error::custom(format_args!("invalid type: null, expected {expected}"))
            }
            other => de::Error::custom(format_args!("invalid type: {other}, expected {expected}")),
        }
    }
}

/// The value of an IEEE 754 half-precision float (exact in an `f64`).
fn f64_of_half(bits: u16) -> f64 {
    let sign = if bits & 0x8000 == 0 { 1.0 } else { -1.0 };
    let exponent = i32::from((bits >> 10) & 0x1f);
    let fraction = f64::from(bits & 0x3ff);
    match exponent {
        0 => sign * fraction * 2f64.powi(-24),
        31 if fraction == 0.0 => sign * f64::INFINITY,
        31 => f64::NAN,
        _ => sign * (1.0 + fraction / 1024.0) * 2f64.powi(exponent - 15),
    }
}

/// A decoding error of `minicbor`, in an item that starts at byte `at`.
fn decode_error(at: usize, err: minicbor::decode::Error) -> Error {
    if err.is_end_of_input() {
        Error::malformed(format!(
            "the message ends inside a CBOR item (started at byte {at}; truncated?)"
        ))
    } else {
        Error::malformed(format!("{err} (in the item at byte {at})"))
    }
}

/// Reads one message from a byte slice; see the [module documentation](self).
pub struct Deserializer<'de> {
    decoder: Decoder<'de>,
    depth: usize,
}

impl<'de> Deserializer<'de> {
    /// A deserializer over `data`, which must hold exactly one CBOR item
    /// (check with [`Deserializer::end`]).
    pub fn from_slice(data: &'de [u8]) -> Deserializer<'de> {
        Deserializer {
            decoder: Decoder::new(data),
            depth: 0,
        }
    }

    /// Fails when bytes are left after the item read.
    pub fn end(&self) -> Result<(), Error> {
        let at = self.decoder.position();
        let len = self.decoder.input().len();
        if at < len {
            return Err(Error::malformed(format!(
                "{} bytes after the end of the message at byte {at}",
                len - at
            )));
        }
        Ok(())
    }

    fn position(&self) -> usize {
        self.decoder.position()
    }

    /// The type of the next item.
    fn peek(&self) -> Result<Type, Error> {
        let at = self.position();
        self.decoder.datatype().map_err(|e| decode_error(at, e))
    }

    fn with<T>(
        &mut self,
        read: impl FnOnce(&mut Decoder<'de>) -> Result<T, minicbor::decode::Error>,
    ) -> Result<T, Error> {
        let at = self.position();
        read(&mut self.decoder).map_err(|e| decode_error(at, e))
    }

    /// Runs `f` one level deeper, refusing nesting beyond [`MAX_DEPTH`].
    fn nested<T>(&mut self, f: impl FnOnce(&mut Self) -> Result<T, Error>) -> Result<T, Error> {
        if self.depth >= MAX_DEPTH {
            return Err(Error::malformed(format!(
                "arrays and maps nested more than {MAX_DEPTH} deep (at byte {})",
                self.position()
            )));
        }
        self.depth += 1;
        let result = f(self);
        self.depth -= 1;
        result
    }

    /// Refuses an item that is not part of the format.
    fn refuse(&self, ty: Type) -> Error {
        let at = self.position();
        match ty {
            Type::Tag => de::Error::custom(format_args!(
                "a CBOR tag (at byte {at}) is not part of the format"
            )),
            Type::Break => Error::malformed(format!("an unexpected break byte at byte {at}")),
            Type::Unknown(byte) => Error::malformed(format!(
                "the byte {byte:#04x} at byte {at} does not start a CBOR item"
            )),
            other => de::Error::custom(format_args!(
                "a CBOR {other} (at byte {at}) is not part of the format"
            )),
        }
    }

    /// A definite text string, borrowed, or an indefinite one, collected.
    fn text<V: Visitor<'de>>(&mut self, ty: Type, visitor: V) -> Result<V::Value, Error> {
        if ty == Type::StringIndef {
            let mut text = String::new();
            let at = self.position();
            let pieces = self.decoder.str_iter().map_err(|e| decode_error(at, e))?;
            for piece in pieces {
                text.push_str(piece.map_err(|e| decode_error(at, e))?);
            }
            return visitor.visit_string(text);
        }
        let text = self.with(|d| d.str())?;
        visitor.visit_borrowed_str(text)
    }

    fn seq<V: Visitor<'de>>(&mut self, visitor: V) -> Result<V::Value, Error> {
        let len = self.with(|d| d.array())?;
        self.nested(|de| {
            let mut access = Items { de, left: len };
            let value = visitor.visit_seq(&mut access)?;
            access.finish("array")?;
            Ok(value)
        })
    }

    fn map<V: Visitor<'de>>(&mut self, visitor: V) -> Result<V::Value, Error> {
        let len = self.with(|d| d.map())?;
        self.nested(|de| {
            let mut access = Items { de, left: len };
            let value = visitor.visit_map(&mut access)?;
            access.finish("map")?;
            Ok(value)
        })
    }
}

/// The elements of an array, or the entries of a map (`left` counts
/// entries; `None` for an indefinite length, ended by a break byte).
struct Items<'a, 'de> {
    de: &'a mut Deserializer<'de>,
    left: Option<u64>,
}

impl<'de> Items<'_, 'de> {
    /// Whether another element follows (consuming the break of an
    /// indefinite length).
    fn more(&mut self) -> Result<bool, Error> {
        match self.left {
            Some(0) => Ok(false),
            Some(n) => {
                self.left = Some(n - 1);
                Ok(true)
            }
            None => {
                let at = self.de.position();
                match self.de.decoder.input().get(at) {
                    Some(&BREAK) => {
                        self.de.decoder.set_position(at + 1);
                        self.left = Some(0);
                        Ok(false)
                    }
                    Some(_) => Ok(true),
                    None => Err(Error::malformed(format!(
                        "the message ends inside an array or map (at byte {at}; truncated?)"
                    ))),
                }
            }
        }
    }

    /// After the visitor: refuses elements it did not take.
    fn finish(&mut self, what: &str) -> Result<(), Error> {
        if self.more()? {
            return Err(de::Error::custom(format_args!(
                "the {what} has more elements than expected (at byte {})",
                self.de.position()
            )));
        }
        Ok(())
    }

    /// The declared length as a hint, never above the bytes left (every
    /// element takes at least one).
    fn hint(&self) -> Option<usize> {
        let left = self.de.decoder.input().len() - self.de.position();
        self.left
            .map(|n| usize::try_from(n).unwrap_or(usize::MAX).min(left))
    }
}

impl<'de> SeqAccess<'de> for Items<'_, 'de> {
    type Error = Error;

    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Error> {
        if !self.more()? {
            return Ok(None);
        }
        seed.deserialize(&mut *self.de).map(Some)
    }

    fn size_hint(&self) -> Option<usize> {
        self.hint()
    }
}

impl<'de> MapAccess<'de> for Items<'_, 'de> {
    type Error = Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, Error> {
        if !self.more()? {
            return Ok(None);
        }
        seed.deserialize(&mut *self.de).map(Some)
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, Error> {
        seed.deserialize(&mut *self.de)
    }

    fn size_hint(&self) -> Option<usize> {
        self.hint()
    }
}

impl<'de> de::Deserializer<'de> for &mut Deserializer<'de> {
    type Error = Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        let ty = self.peek()?;
        match ty {
            Type::U8 | Type::U16 | Type::U32 | Type::U64 => {
                let value = self.with(|d| d.u64())?;
                visitor.visit_u64(value)
            }
            Type::I8 | Type::I16 | Type::I32 | Type::I64 => {
                let value = self.with(|d| d.i64())?;
                visitor.visit_i64(value)
            }
            Type::Int => {
                let value = self.with(|d| d.int())?;
                Err(de::Error::custom(format_args!(
                    "integer `{value}` is out of range"
                )))
            }
            Type::F16 => {
                let at = self.position();
                let bytes = self
                    .decoder
                    .input()
                    .get(at + 1..at + 3)
                    .ok_or_else(|| decode_error(at, minicbor::decode::Error::end_of_input()))?;
                let value = f64_of_half(u16::from_be_bytes([bytes[0], bytes[1]]));
                self.decoder.set_position(at + 3);
                visitor.visit_f64(value)
            }
            Type::F32 | Type::F64 => {
                let value = self.with(|d| d.f64())?;
                visitor.visit_f64(value)
            }
            Type::Bool => {
                let value = self.with(|d| d.bool())?;
                visitor.visit_bool(value)
            }
            Type::Null => {
                self.with(|d| d.null())?;
                visitor.visit_unit()
            }
            Type::String | Type::StringIndef => self.text(ty, visitor),
            Type::Array | Type::ArrayIndef => self.seq(visitor),
            Type::Map | Type::MapIndef => self.map(visitor),
            Type::Bytes => {
                let value = self.with(|d| d.bytes())?;
                Err(de::Error::invalid_type(Unexpected::Bytes(value), &visitor))
            }
            other => Err(self.refuse(other)),
        }
    }

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        if self.peek()? == Type::Null {
            self.with(|d| d.null())?;
            return visitor.visit_none();
        }
        visitor.visit_some(self)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        // Only unit variants are in the format: a text string.
        match self.peek()? {
            Type::String => {
                let text = self.with(|d| d.str())?;
                visitor.visit_enum(text.into_deserializer())
            }
            _ => self.deserialize_any(visitor),
        }
    }

    fn deserialize_identifier<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.peek()? {
            ty @ (Type::String | Type::StringIndef) => self.text(ty, visitor),
            other => Err(de::Error::custom(format_args!(
                "a map key must be a text string, found a CBOR {other} (at byte {})",
                self.position()
            ))),
        }
    }

    fn deserialize_ignored_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        // `skip` walks nested items without recursion.
        self.with(|d| d.skip())?;
        visitor.visit_unit()
    }

    fn is_human_readable(&self) -> bool {
        false
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf unit unit_struct newtype_struct seq tuple
        tuple_struct map struct
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::Kind;
    use crate::trace::messages::{OutcomeMsg, SceneMsg, SweepMsg};
    use serde::de::DeserializeOwned;

    fn read<T: DeserializeOwned>(data: &[u8]) -> Result<T, Error> {
        let mut de = Deserializer::from_slice(data);
        let value = T::deserialize(&mut de)?;
        de.end()?;
        Ok(value)
    }

    #[test]
    fn floats_are_written_as_doubles_and_read_back_exactly() {
        let sweep = SweepMsg {
            frame: 3,
            ball: 1,
            radius: 0.5,
            p0: [1.0, 0.1, -0.0],
            p1: [f64::MIN_POSITIVE, 1e300, 5e-324],
        };
        let bytes = to_vec(&sweep).unwrap();
        // 0.5 and 1.0 fit a half; they are still written as doubles.
        let doubles = bytes.iter().filter(|&&b| b == 0xfb).count();
        assert_eq!(doubles, 7, "{bytes:02x?}");
        let back: SweepMsg = read(&bytes).unwrap();
        assert_eq!(back, sweep);
        assert_eq!(back.p0[2].to_bits(), (-0.0f64).to_bits());
    }

    #[test]
    fn integers_and_short_floats_are_numbers() {
        // {"frame": 2, "radius": half 0.5, "p0": [1, -1, single 2.5], "p1": [0, 0, 0]}
        let mut data = vec![0xa4];
        data.extend(b"\x65frame\x02");
        data.extend(b"\x66radius\xf9\x38\x00");
        data.extend(b"\x62p0\x83\x01\x20\xfa\x40\x20\x00\x00");
        data.extend(b"\x62p1\x83\x00\x00\x00");
        let sweep: SweepMsg = read(&data).unwrap();
        assert_eq!(sweep.radius, 0.5);
        assert_eq!(sweep.p0, [1.0, -1.0, 2.5]);
        assert_eq!(sweep.ball, 0);
    }

    #[test]
    fn half_floats_are_exact() {
        for (bits, value) in [
            (0x3c00, 1.0),
            (0x3800, 0.5),
            (0xc000, -2.0),
            (0x7bff, 65504.0),
            (0x0001, 2f64.powi(-24)),
            (0x0400, 2f64.powi(-14)),
            (0x8000, -0.0),
            (0x7c00, f64::INFINITY),
        ] {
            assert_eq!(
                f64_of_half(bits).to_bits(),
                f64::to_bits(value),
                "{bits:#06x}"
            );
        }
        assert!(f64_of_half(0x7e00).is_nan());
        // A truncated half is malformed, not a panic.
        assert!(read::<f64>(&[0xf9, 0x3c]).unwrap_err().is_malformed());
        assert_eq!(read::<f64>(&[0xf9, 0x3c, 0x00]).unwrap(), 1.0);
    }

    #[test]
    fn outcome_nulls_and_absent_fields() {
        let outcome = OutcomeMsg::miss(4, 2);
        let back: OutcomeMsg = read(&to_vec(&outcome).unwrap()).unwrap();
        assert_eq!(back, outcome);
        let hit = OutcomeMsg::hit(1, 0, 0.25, Kind::Edge).feature(1);
        let back: OutcomeMsg = read(&to_vec(&hit).unwrap()).unwrap();
        assert_eq!(back, hit);
        assert_eq!(back.normal, None);
    }

    #[test]
    fn malformed_input_is_refused_without_panic() {
        let scene = SceneMsg {
            name: Some("t".to_string()),
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
            margin: 0.0,
            facing: Default::default(),
        };
        let bytes = to_vec(&scene).unwrap();
        for cut in 0..bytes.len() {
            let err = read::<SceneMsg>(&bytes[..cut]).unwrap_err();
            assert!(err.is_malformed() || cut == 0, "{cut}: {err}");
        }
        let mut trailing = bytes.clone();
        trailing.push(0);
        assert!(read::<SceneMsg>(&trailing).unwrap_err().is_malformed());
        // An array claiming 2^63 vertices: refused by the bytes, not by memory.
        let mut huge = vec![0xa2, 0x68];
        huge.extend(b"vertices\x9b\x80\x00\x00\x00\x00\x00\x00\x00\x83\x00\x00\x00");
        assert!(read::<SceneMsg>(&huge).unwrap_err().is_malformed());
        // Deep nesting is refused, not a stack overflow.
        let deep = vec![0x81; 100_000];
        assert!(read::<SceneMsg>(&deep).is_err());
        let mut ignored = vec![0xa1, 0x65];
        ignored.extend(b"other");
        ignored.extend(vec![0x81; 100_000]);
        ignored.push(0x00);
        assert!(read::<SceneMsg>(&ignored).is_err());
    }

    #[test]
    fn shape_errors_read_like_json_errors() {
        // {"frame": 1, "radius": null, ...}
        let mut data = vec![0xa4];
        data.extend(b"\x65frame\x01\x66radius\xf6\x62p0\x83\x00\x00\x00\x62p1\x83\x00\x00\x00");
        let err = read::<SweepMsg>(&data).unwrap_err();
        assert_eq!(err.to_string(), "invalid type: null, expected f64");
        // An integer map key.
        let err = read::<SweepMsg>(&[0xa1, 0x00, 0x00]).unwrap_err();
        assert!(
            err.to_string().contains("map key must be a text string"),
            "{err}"
        );
        // A tag.
        let err = read::<SweepMsg>(&[0xc1, 0x00]).unwrap_err();
        assert!(err.to_string().contains("tag"), "{err}");
    }
}
