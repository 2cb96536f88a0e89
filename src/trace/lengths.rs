//! The lengths a record declares for its fields, checked against the
//! record before the `mcap` crate parses it.
//!
//! The crate reserves a string's, map's or byte array's declared length
//! before reading it, so a record of a few bytes declaring a 4 GiB string
//! asks for 4 GiB of memory (found by fuzzing the reader). Checking each
//! declared length against the bytes left in the record first keeps
//! every allocation within the record, whose size is already bounded by
//! [`ReadLimits`](super::ReadLimits).

use mcap::records::op;

use super::TraceError;

/// A field of a record's layout (docs: the MCAP specification's records).
#[derive(Clone, Copy)]
enum Field {
    /// A fixed-size field of this many bytes.
    Fixed(usize),
    /// A `uint32` length and that many bytes (a string or byte array).
    Bytes32,
    /// A `uint64` length and that many bytes.
    Bytes64,
    /// A `uint32` byte length and that many bytes of string pairs.
    StringMap,
}

use Field::{Bytes32, Bytes64, Fixed, StringMap};

/// The fields the reader parses, up to the last one with a length, of the
/// records it parses; `None` for the others.
fn layout(opcode: u8) -> Option<&'static [Field]> {
    Some(match opcode {
        op::HEADER => &[Bytes32, Bytes32],
        op::SCHEMA => &[Fixed(2), Bytes32, Bytes32, Bytes32],
        op::CHANNEL => &[Fixed(2), Fixed(2), Bytes32, Bytes32, StringMap],
        op::METADATA => &[Bytes32, StringMap],
        op::CHUNK => &[Fixed(8), Fixed(8), Fixed(8), Fixed(4), Bytes32, Bytes64],
        op::ATTACHMENT => &[Fixed(8), Fixed(8), Bytes32, Bytes32, Bytes64],
        // The map of channel ids to offsets has fixed-size entries: only
        // its byte length is checked.
        op::CHUNK_INDEX => &[Fixed(32), Bytes32, Fixed(8), Bytes32],
        op::STATISTICS => &[Fixed(8 + 2 + 4 * 4 + 8 + 8), Bytes32],
        _ => return None,
    })
}

/// [`check`] as the reader's error: a record of `file` read after
/// `messages` complete messages, described by `context` (called only on an
/// error: this runs for every record).
pub fn refuse(
    opcode: u8,
    data: &[u8],
    file: &str,
    messages: u64,
    context: impl FnOnce() -> String,
) -> Result<(), TraceError> {
    check(opcode, data).map_err(|(declared, available)| TraceError::FieldTooLong {
        file: file.to_string(),
        messages,
        context: context(),
        declared,
        available,
    })
}

/// A declared length above what is left: `(declared, available)`.
pub type TooLong = (u64, u64);

/// Checks every declared length of the record `data` with `opcode` against
/// the bytes left after it. A record too short for its fixed fields is
/// left to the parser, which reports it without allocating.
pub fn check(opcode: u8, data: &[u8]) -> Result<(), TooLong> {
    let Some(fields) = layout(opcode) else {
        return Ok(());
    };
    let mut rest = data;
    for field in fields {
        let Some(after) = skip(*field, rest)? else {
            return Ok(());
        };
        rest = after;
    }
    Ok(())
}

/// `rest` after `field`: `Ok(None)` when the record ends before the field's
/// length, an error when the length exceeds what is left.
fn skip(field: Field, rest: &[u8]) -> Result<Option<&[u8]>, TooLong> {
    let (length, after) = match field {
        Fixed(size) => return Ok(rest.get(size..)),
        Bytes32 | StringMap => match rest.split_first_chunk::<4>() {
            Some((length, after)) => (u64::from(u32::from_le_bytes(*length)), after),
            None => return Ok(None),
        },
        Bytes64 => match rest.split_first_chunk::<8>() {
            Some((length, after)) => (u64::from_le_bytes(*length), after),
            None => return Ok(None),
        },
    };
    let available = after.len() as u64;
    if length > available {
        return Err((length, available));
    }
    let (inside, after) = after.split_at(length as usize);
    if let StringMap = field {
        // The crate reads a key and its value while the map has bytes
        // left, lengths included, even past the map's end: every length
        // must lie inside the map, and every string too.
        let mut entries = inside;
        while !entries.is_empty() {
            for _ in 0..2 {
                entries = match skip(Bytes32, entries)? {
                    Some(next) => next,
                    None => return Err((4, entries.len() as u64)),
                };
            }
        }
    }
    Ok(Some(after))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_string_longer_than_its_record_is_refused() {
        // A header whose profile declares 0xfdffffff bytes (the fuzzer's find).
        let mut header = 0xfdff_ffffu32.to_le_bytes().to_vec();
        header.extend_from_slice(b"abc");
        assert_eq!(check(op::HEADER, &header), Err((0xfdff_ffff, 3)));
        let mut fine = 3u32.to_le_bytes().to_vec();
        fine.extend_from_slice(b"abc");
        fine.extend_from_slice(&0u32.to_le_bytes());
        assert_eq!(check(op::HEADER, &fine), Ok(()));
    }

    #[test]
    fn a_map_entry_longer_than_its_map_is_refused() {
        let mut metadata = 1u32.to_le_bytes().to_vec();
        metadata.push(b'n');
        // The map: 8 bytes, whose first key declares 100 bytes.
        metadata.extend_from_slice(&8u32.to_le_bytes());
        metadata.extend_from_slice(&100u32.to_le_bytes());
        metadata.extend_from_slice(&[0; 4]);
        assert_eq!(check(op::METADATA, &metadata), Err((100, 4)));
    }

    #[test]
    fn a_map_whose_last_length_lies_past_its_end_is_refused() {
        // The fuzzer's find: the map ends two bytes into a key's length; the
        // crate read that length from the bytes after the map.
        let mut metadata = 1u32.to_le_bytes().to_vec();
        metadata.push(b'n');
        metadata.extend_from_slice(&2u32.to_le_bytes());
        metadata.extend_from_slice(&[0xff; 6]);
        assert_eq!(check(op::METADATA, &metadata), Err((4, 2)));
    }
}
