//! Errors of reading and writing traces.
//!
//! Each message is whole (its cause's text included, no `source()`: see
//! [`crate::error_text`]) and names the file, and when a message is at fault its channel,
//! its index in the file, its frame when known, and the field.

use std::fmt;

use thiserror::Error;

use crate::error_text::full_text;

/// Where in a trace a message sits: its channel, its index in the file
/// (counting every message, foreign topics included) and its frame when the
/// message has one that could be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MessageAt {
    /// The file (or other source) name given to the reader or writer.
    pub file: String,
    /// Topic of the channel.
    pub channel: String,
    /// Index of the message in the file, from 0.
    pub index: u64,
    /// Frame of the message, when known.
    pub frame: Option<u64>,
}

impl fmt::Display for MessageAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: channel `{}`, ", self.file, self.channel)?;
        if let Some(frame) = self.frame {
            write!(f, "frame {frame}, ")?;
        }
        write!(f, "message {}", self.index)
    }
}

/// An error reading or writing a trace.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TraceError {
    /// The underlying reader or writer failed.
    #[error("{file}: I/O error after {messages} complete messages: {}", full_text(.cause))]
    Io {
        /// File name.
        file: String,
        /// Messages read (or written) before the error.
        messages: u64,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// The file is empty (0 bytes): not a trace, and not a truncated one.
    #[error("{file}: empty file (0 bytes): not an MCAP trace")]
    Empty {
        /// File name.
        file: String,
    },
    /// The file does not start with MCAP's magic bytes: some other file
    /// (a README, an OBJ mesh, a JSON report), not a trace.
    #[error("{file}: not an MCAP trace (it does not start with MCAP's magic bytes)")]
    NotMcap {
        /// File name.
        file: String,
    },
    /// The file ends in the middle of a record (or before its footer).
    #[error(
        "{file}: the file is truncated: it ends in the middle of a record after {messages} complete messages \
         (those were read; everything after is lost)"
    )]
    Truncated {
        /// File name.
        file: String,
        /// Complete messages read before the end.
        messages: u64,
    },
    /// The MCAP container is malformed (bad magic, bad chunk, CRC mismatch, ...).
    #[error(
        "{file}: corrupt MCAP data after {messages} complete messages ({context}): {}",
        full_text(.cause)
    )]
    Corrupt {
        /// File name.
        file: String,
        /// Complete messages read before the error.
        messages: u64,
        /// What was being read (`chunk 3`, `record`, ...).
        context: String,
        /// The container error.
        cause: mcap::McapError,
    },
    /// A record declares a field (a string, a map, a byte array) longer
    /// than what is left of the record.
    #[error(
        "{file}: corrupt MCAP data after {messages} complete messages ({context}): a field \
         declares {declared} bytes, but only {available} are left in the record"
    )]
    FieldTooLong {
        /// File name.
        file: String,
        /// Complete messages read before the error.
        messages: u64,
        /// What was being read (`record with opcode 0x03`, `chunk 2`).
        context: String,
        /// The field's declared length.
        declared: u64,
        /// Bytes left in the record after the length.
        available: u64,
    },
    /// A chunk or record declares a size above the reader's limit.
    #[error(
        "{file}: {what} declares {declared} bytes, above the limit of {limit} bytes; refused before reading it"
    )]
    TooLarge {
        /// File name.
        file: String,
        /// What is too large (`chunk 2 (uncompressed)`, `record with opcode 0x05`).
        what: String,
        /// Declared size in bytes.
        declared: u64,
        /// The limit in bytes.
        limit: u64,
    },
    /// A message of one of the trace's channels is larger than its limit.
    #[error(
        "{at}: the message is {bytes} bytes, above the limit of {limit} bytes for this channel; refused"
    )]
    MessageTooLarge {
        /// The message.
        at: Box<MessageAt>,
        /// Its size.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// A message is not valid JSON, or does not match its schema.
    #[error("{at}: field `{field}`: {detail}")]
    Json {
        /// The message.
        at: Box<MessageAt>,
        /// The field (a path such as `p0[1]`; `.` for the whole message).
        field: String,
        /// What is wrong.
        detail: String,
    },
    /// A message is well-formed JSON but holds an invalid value.
    #[error("{at}: field `{field}`: {problem}")]
    Invalid {
        /// The message.
        at: Box<MessageAt>,
        /// The field (a path such as `triangles[12][1]`).
        field: String,
        /// What is wrong.
        problem: String,
    },
    /// A sweep (or a contact query) comes before any scene.
    #[error(
        "{at}: a {} comes before any `/scene` message; a scene must be logged at or before the first sweep or contact query",
        if at.channel == "/contact" { "contact query" } else { "sweep" }
    )]
    SweepBeforeScene {
        /// The sweep or contact message.
        at: Box<MessageAt>,
    },
    /// A message's `log_time` is smaller than that of an earlier message.
    #[error(
        "{at}: `log_time` {log_time_nanos} ns is earlier than the previous message's {previous_nanos} ns; \
         trace messages must be written in `log_time` order (a file whose chunks overlap in time \
         is read in log-time order only through the chunk indexes of its summary)"
    )]
    OutOfOrder {
        /// The message.
        at: Box<MessageAt>,
        /// Its log time.
        log_time_nanos: u64,
        /// The largest log time seen before it.
        previous_nanos: u64,
    },
    /// A trace channel uses a message encoding other than `json` and `cbor`.
    #[error(
        "{file}: channel `{channel}` has message encoding `{encoding}`; trace channels must use `json` or `cbor`"
    )]
    WrongEncoding {
        /// File name.
        file: String,
        /// Topic.
        channel: String,
        /// The encoding found.
        encoding: String,
    },
    /// A message refers to a channel that was never declared.
    #[error("{file}: message {index} refers to channel id {channel_id}, which was never declared")]
    UnknownChannel {
        /// File name.
        file: String,
        /// Message index.
        index: u64,
        /// The channel id.
        channel_id: u16,
    },
    /// The metadata record `sweeptrace.expected_source` is malformed (or
    /// there are two), or the writer was given an invalid source.
    #[error("{file}: metadata record `sweeptrace.expected_source`: {problem}")]
    ExpectedSource {
        /// File name.
        file: String,
        /// What is wrong.
        problem: String,
    },
    /// The MCAP writer failed.
    #[error("{file}: cannot write the trace: {}", full_text(.cause))]
    Write {
        /// File name.
        file: String,
        /// The container error.
        cause: mcap::McapError,
    },
}

impl TraceError {
    /// Whether the file ends early (in the middle of a record, or before its
    /// footer): what came before was read.
    pub fn is_truncation(&self) -> bool {
        matches!(self, TraceError::Truncated { .. })
    }

    /// Where the error happened, when a message is at fault.
    pub fn message_at(&self) -> Option<&MessageAt> {
        match self {
            TraceError::MessageTooLarge { at, .. }
            | TraceError::Json { at, .. }
            | TraceError::Invalid { at, .. }
            | TraceError::SweepBeforeScene { at }
            | TraceError::OutOfOrder { at, .. } => Some(at.as_ref()),
            _ => None,
        }
    }
}
