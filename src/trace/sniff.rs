//! Telling the MCAP files sweeptrace reads apart from those it writes for
//! other viewers: a Foxglove file written by `replay --foxglove` is an
//! MCAP file but not a trace ([`foxglove_output`]), told by its metadata
//! record ([`FOXGLOVE_METADATA_NAME`]), which the trace layer owns so that
//! both the Foxglove writer and the suite's discovery point down to it.

/// The name of the metadata record `replay --foxglove` writes right after
/// the file's header (`trace`: the trace it was made from).
pub const FOXGLOVE_METADATA_NAME: &str = "sweeptrace.foxglove";

/// How far into a file [`foxglove_output`] looks for the metadata record
/// that `replay --foxglove` writes right after the file's header.
const FOXGLOVE_PROBE_BYTES: usize = 1 << 16;

/// Whether the file at `path` is a Foxglove file written by `sweeptrace
/// replay --foxglove` (an MCAP file, but not a trace: it has no `/sweep`
/// channel). Told by its metadata record
/// [`FOXGLOVE_METADATA_NAME`], which the writer puts before any
/// message; returns the name of the trace it was made from (empty when
/// the record does not say). A file that cannot be read, or is anything
/// else, is `None`: it is left to be read as a trace, which reports what is
/// wrong with it.
pub fn foxglove_output(path: &std::path::Path) -> Option<String> {
    use std::io::Read;
    let mut head = Vec::with_capacity(FOXGLOVE_PROBE_BYTES);
    std::fs::File::open(path)
        .ok()?
        .take(FOXGLOVE_PROBE_BYTES as u64)
        .read_to_end(&mut head)
        .ok()?;
    foxglove_output_of(&head)
}

/// [`foxglove_output`] on the first bytes of a file.
fn foxglove_output_of(head: &[u8]) -> Option<String> {
    // Record opcodes of the MCAP specification.
    const METADATA: u8 = 0x0C;
    const CHUNK: u8 = 0x06;
    const MESSAGE: u8 = 0x05;
    const DATA_END: u8 = 0x0F;
    let mut rest = head.strip_prefix(mcap::MAGIC)?;
    while rest.len() >= 9 {
        let op = rest[0];
        let len = usize::try_from(u64::from_le_bytes(rest[1..9].try_into().ok()?)).ok()?;
        let body = rest.get(9..9usize.checked_add(len)?)?;
        match op {
            METADATA => {
                let (name, mut map) = mcap_string(body)?;
                if name != FOXGLOVE_METADATA_NAME {
                    rest = &rest[9 + len..];
                    continue;
                }
                let map_len =
                    usize::try_from(u32::from_le_bytes(map.get(..4)?.try_into().ok()?)).ok()?;
                map = map.get(4..4 + map_len)?;
                let mut trace = String::new();
                while !map.is_empty() {
                    let (key, after) = mcap_string(map)?;
                    let (value, after) = mcap_string(after)?;
                    if key == "trace" {
                        trace = value.to_string();
                    }
                    map = after;
                }
                return Some(trace);
            }
            CHUNK | MESSAGE | DATA_END => return None,
            _ => rest = &rest[9 + len..],
        }
    }
    None
}

/// An MCAP string (a `u32` byte length, then UTF-8) at the start of
/// `bytes`, and what follows it.
fn mcap_string(bytes: &[u8]) -> Option<(&str, &[u8])> {
    let len = usize::try_from(u32::from_le_bytes(bytes.get(..4)?.try_into().ok()?)).ok()?;
    let text = std::str::from_utf8(bytes.get(4..4 + len)?).ok()?;
    Some((text, &bytes[4 + len..]))
}
