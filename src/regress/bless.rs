//! Blessing a trace: replacing its `/expected` channel with the current
//! core's outcomes, keeping everything else.
//!
//! Three passes over the input bytes:
//! 1. the trace is replayed (the same [`crate::replay`] engine as `check`)
//!    and every sweep's outcome is kept, by `(frame, ball)`;
//! 2. a quick scan reads the header and which schemas only `/expected`
//!    channels use (those are not copied);
//! 3. the file's records are copied in order with the `mcap` crate's raw
//!    reader: every schema, channel, message, metadata record and attachment
//!    is kept verbatim (channel and schema ids may be renumbered), except the
//!    messages of `/expected` channels, which are dropped; after each `/sweep`
//!    message its new expectation is written on a `/expected` channel with
//!    the project's `sweeptrace.Outcome` schema, at the sweep's `log_time`,
//!    in the message encoding of that sweep's channel (JSON or CBOR: a
//!    trace keeps its encoding, one `/expected` channel per encoding).
//!    The expectations now come from sweeptrace: the input's
//!    `sweeptrace.expected_source` record, if any, is dropped and a new one
//!    (engine `sweeptrace`, its version, the margin and facing rule the
//!    replay used) is written first.
//!
//! The header's profile and library string are kept. The output is written
//! with the project's container options (chunked, zstd, summary and
//! indexes). [`bless_file`] writes to a temporary file next to the output
//! and renames it when complete, so the output is never half-written and the
//! input is untouched unless it is also the output.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap, HashSet, VecDeque};
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use mcap::read::ChunkFlattener;
use mcap::records::{MessageHeader, Record};
use mcap::{Attachment, McapError};
use thiserror::Error;

use crate::atomic::{FinishStep, PendingFile};
use crate::error_text::full_text;
use crate::replay::{ReplayError, ReplayEvent, ReplayOptions, replay_events};
use crate::trace::{
    EXPECTED_SOURCE_METADATA, EXPECTED_TOPIC, Encoding, ExpectedSource, OUTCOME_SCHEMA,
    OUTCOME_SCHEMA_JSON, OutcomeMsg, SCHEMA_ENCODING, SWEEP_TOPIC, TraceError, TraceReader,
    default_write_options, frame_of_message, sweeptrace_source,
};

/// What went wrong while blessing.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BlessError {
    /// The trace could not be replayed (read error, invalid scene or sweep).
    #[error("{}", replay_error_text(file, cause))]
    Replay {
        /// The input's name.
        file: String,
        /// What went wrong.
        cause: ReplayError,
    },
    /// The MCAP container could not be read or written.
    #[error("{file}: {what}: {}", full_text(.cause))]
    Mcap {
        /// The file's name.
        file: String,
        /// What was being done.
        what: String,
        /// The error.
        cause: McapError,
    },
    /// A file could not be read or written.
    #[error("{file}: {what}: {}", full_text(.cause))]
    Io {
        /// The file's name.
        file: String,
        /// What was being done.
        what: String,
        /// The error.
        cause: std::io::Error,
    },
    /// The blessed trace could not be given its expectations' source.
    #[error("{cause}")]
    Trace {
        /// The error, naming the output.
        cause: TraceError,
    },
    /// A `/sweep` message found in the copy pass has no outcome from the
    /// replay pass (the replay and the copy disagree on the file).
    #[error("{file}: channel `/sweep`, message {index}: no replayed outcome for this sweep")]
    Unmatched {
        /// The input's name.
        file: String,
        /// Index of the message in the file.
        index: u64,
    },
}

impl BlessError {
    /// Whether the input ends early (it is truncated): nothing is written
    /// then, since a blessed trace would lose the sweeps after the cut.
    pub fn is_truncation(&self) -> bool {
        match self {
            BlessError::Replay {
                cause: ReplayError::Trace(e),
                ..
            } => e.is_truncation(),
            BlessError::Trace { cause } => cause.is_truncation(),
            _ => false,
        }
    }
}

/// A replay error in words, naming the file once: a read error names it
/// already; the other errors (an invalid scene or sweep) do not.
fn replay_error_text(file: &str, cause: &ReplayError) -> String {
    match cause {
        ReplayError::Trace(_) => cause.to_string(),
        _ => format!("{file}: cannot replay the trace: {cause}"),
    }
}

/// Counts of a bless.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct BlessSummary {
    /// Expectations written (one per sweep).
    pub expected_written: u64,
    /// `/expected` messages of the input dropped.
    pub expected_dropped: u64,
    /// Messages of other channels copied.
    pub messages_copied: u64,
    /// Channels other than `/expected` copied.
    pub channels_copied: u64,
    /// Schemas copied.
    pub schemas_copied: u64,
    /// Metadata records copied.
    pub metadata_copied: u64,
    /// Attachments copied.
    pub attachments_copied: u64,
    /// The expectations' source written (sweeptrace, with the margins and
    /// facing rules of the replay).
    pub expected_source: ExpectedSource,
    /// The input's expectations' source, replaced, if it had one.
    pub replaced_expected_source: Option<ExpectedSource>,
}

/// What the replay pass found: the outcomes of every sweep of a trace, by
/// `(frame, ball)` in trace order, and the source of the new expectations.
struct Replayed {
    outcomes: HashMap<(u64, u32), VecDeque<OutcomeMsg>>,
    source: ExpectedSource,
    replaced: Option<ExpectedSource>,
}

/// Values in words, the first few of many only (a setting's value is
/// bounded: [`crate::trace::MAX_SETTING_VALUE_BYTES`]).
fn listed(values: &[String]) -> String {
    const SHOWN: usize = 8;
    let text = values
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if values.len() > SHOWN {
        format!("{text} and {} more", values.len() - SHOWN)
    } else {
        text
    }
}

fn outcomes_of(input: &[u8], name: &str, options: ReplayOptions) -> Result<Replayed, BlessError> {
    let options = ReplayOptions {
        explain: None,
        frames: Default::default(),
        ball: None,
        ..options
    };
    let mut out: HashMap<(u64, u32), VecDeque<OutcomeMsg>> = HashMap::new();
    // The margins and facing rules the scenes were replayed with, in order.
    let (mut margins, mut facings): (Vec<String>, Vec<String>) = (Vec::new(), Vec::new());
    let mut reader = TraceReader::new_indexed(std::io::Cursor::new(input), name);
    for event in replay_events(reader.by_ref(), options) {
        match event {
            Ok(ReplayEvent::Sweep(r)) => out
                .entry((r.frame, r.ball))
                .or_default()
                .push_back(r.outcome_msg()),
            Ok(ReplayEvent::Scene(scene)) => {
                for (list, value) in [
                    (&mut margins, scene.options.margin.to_string()),
                    (&mut facings, scene.options.facing.to_string()),
                ] {
                    if !list.contains(&value) {
                        list.push(value);
                    }
                }
            }
            Err(cause) => {
                return Err(BlessError::Replay {
                    file: name.to_string(),
                    cause,
                });
            }
        }
    }
    Ok(Replayed {
        outcomes: out,
        source: sweeptrace_source(&listed(&margins), &listed(&facings)),
        replaced: reader.expected_source().cloned(),
    })
}

/// Blesses the trace `input` (its bytes; `name` is used in messages) into
/// `output`. `options` may override the scenes' margin and facing rule (the
/// frame and ball filters are ignored: every sweep gets an expectation);
/// the command line always uses the scenes' own.
pub fn bless_bytes<W: Write + Seek>(
    input: &[u8],
    name: &str,
    output: W,
    options: ReplayOptions,
) -> Result<(BlessSummary, W), BlessError> {
    bless_into(input, name, output, name, options)
}

/// [`bless_bytes`], with write errors naming `output_name`.
fn bless_into<W: Write + Seek>(
    input: &[u8],
    name: &str,
    output: W,
    output_name: &str,
    options: ReplayOptions,
) -> Result<(BlessSummary, W), BlessError> {
    let Replayed {
        mut outcomes,
        source,
        replaced,
    } = outcomes_of(input, name, options)?;
    let read_err = |cause| BlessError::Mcap {
        file: name.to_string(),
        what: "reading the container".to_string(),
        cause,
    };
    let write_err = |cause| BlessError::Mcap {
        file: output_name.to_string(),
        what: "writing the blessed trace".to_string(),
        cause,
    };

    // Pass 2 (cheap; pass 1 was the replay): the header, and which schemas
    // only `/expected` uses.
    let mut write_options = default_write_options();
    let mut used_by_others: HashSet<u16> = HashSet::new();
    let mut used_by_expected: HashSet<u16> = HashSet::new();
    for record in ChunkFlattener::new(input).map_err(read_err)? {
        match record.map_err(read_err)? {
            Record::Header(h) => {
                write_options = write_options.profile(h.profile).library(h.library);
            }
            Record::Channel(c) if c.topic == EXPECTED_TOPIC => {
                used_by_expected.insert(c.schema_id);
            }
            Record::Channel(c) => {
                used_by_others.insert(c.schema_id);
            }
            Record::DataEnd(_) => break,
            _ => {}
        }
    }

    // Pass 3: the copy.
    let mut writer = write_options.create(output).map_err(write_err)?;
    source.validate().map_err(|problem| BlessError::Trace {
        cause: TraceError::ExpectedSource {
            file: output_name.to_string(),
            problem,
        },
    })?;
    writer
        .write_metadata(&mcap::records::Metadata {
            name: EXPECTED_SOURCE_METADATA.to_string(),
            metadata: source.to_metadata(),
        })
        .map_err(write_err)?;
    let mut summary = BlessSummary {
        expected_source: source,
        replaced_expected_source: replaced,
        ..BlessSummary::default()
    };
    let mut schema_ids: HashMap<u16, u16> = HashMap::new();
    let mut channel_ids: HashMap<u16, u16> = HashMap::new();
    let mut channel_topics: HashMap<u16, String> = HashMap::new();
    // The message encoding of each input channel (trace channels: the
    // replay pass checked they are `json` or `cbor`).
    let mut channel_encodings: HashMap<u16, Encoding> = HashMap::new();
    let mut expected_channels: BTreeMap<Encoding, u16> = BTreeMap::new();
    let mut index: u64 = 0;
    let mut sequence: u32 = 0;
    for record in ChunkFlattener::new(input).map_err(read_err)? {
        match record.map_err(read_err)? {
            Record::Schema { header, data } => {
                if schema_ids.contains_key(&header.id)
                    || (used_by_expected.contains(&header.id)
                        && !used_by_others.contains(&header.id))
                {
                    continue;
                }
                let id = writer
                    .add_schema(&header.name, &header.encoding, &data)
                    .map_err(write_err)?;
                schema_ids.insert(header.id, id);
                summary.schemas_copied += 1;
            }
            Record::Channel(c) => {
                if channel_topics.contains_key(&c.id) {
                    continue;
                }
                channel_topics.insert(c.id, c.topic.clone());
                if let Some(encoding) = Encoding::from_message_encoding(&c.message_encoding) {
                    channel_encodings.insert(c.id, encoding);
                }
                if c.topic == EXPECTED_TOPIC {
                    continue;
                }
                let schema_id = if c.schema_id == 0 {
                    0
                } else {
                    *schema_ids
                        .get(&c.schema_id)
                        .ok_or_else(|| BlessError::Mcap {
                            file: name.to_string(),
                            what: format!("channel `{}`", c.topic),
                            cause: McapError::UnknownSchema(c.topic.clone(), c.schema_id),
                        })?
                };
                let id = writer
                    .add_channel(schema_id, &c.topic, &c.message_encoding, &c.metadata)
                    .map_err(write_err)?;
                channel_ids.insert(c.id, id);
                summary.channels_copied += 1;
            }
            Record::Message { header, data } => {
                let this = index;
                index += 1;
                let topic = channel_topics.get(&header.channel_id).map(String::as_str);
                if topic == Some(EXPECTED_TOPIC) {
                    summary.expected_dropped += 1;
                    continue;
                }
                let Some(&channel_id) = channel_ids.get(&header.channel_id) else {
                    return Err(BlessError::Mcap {
                        file: name.to_string(),
                        what: format!("message {this}"),
                        cause: McapError::UnknownChannel(header.sequence, header.channel_id),
                    });
                };
                writer
                    .write_to_known_channel(
                        &MessageHeader {
                            channel_id,
                            sequence,
                            ..header
                        },
                        &data,
                    )
                    .map_err(write_err)?;
                sequence = sequence.wrapping_add(1);
                summary.messages_copied += 1;
                if topic != Some(SWEEP_TOPIC) {
                    continue;
                }
                let encoding = channel_encodings
                    .get(&header.channel_id)
                    .copied()
                    .unwrap_or_default();
                let ball = ball_of(&data, encoding);
                let Some(outcome) = frame_of_message(&data, encoding)
                    .and_then(|frame| outcomes.get_mut(&(frame, ball)))
                    .and_then(VecDeque::pop_front)
                else {
                    return Err(BlessError::Unmatched {
                        file: name.to_string(),
                        index: this,
                    });
                };
                let channel_id = match expected_channels.get(&encoding) {
                    Some(&id) => id,
                    None => {
                        let schema = writer
                            .add_schema(
                                OUTCOME_SCHEMA,
                                SCHEMA_ENCODING,
                                OUTCOME_SCHEMA_JSON.as_bytes(),
                            )
                            .map_err(write_err)?;
                        let id = writer
                            .add_channel(
                                schema,
                                EXPECTED_TOPIC,
                                encoding.as_str(),
                                &BTreeMap::new(),
                            )
                            .map_err(write_err)?;
                        expected_channels.insert(encoding, id);
                        id
                    }
                };
                let encoded = encoding.encode(&outcome).map_err(|e| BlessError::Io {
                    file: name.to_string(),
                    what: format!("serializing the outcome of frame {}", outcome.frame),
                    cause: std::io::Error::other(e),
                })?;
                writer
                    .write_to_known_channel(
                        &MessageHeader {
                            channel_id,
                            sequence,
                            log_time: header.log_time,
                            publish_time: header.log_time,
                        },
                        &encoded,
                    )
                    .map_err(write_err)?;
                sequence = sequence.wrapping_add(1);
                summary.expected_written += 1;
            }
            // Replaced by the record written first.
            Record::Metadata(m) if m.name == EXPECTED_SOURCE_METADATA => {}
            Record::Metadata(m) => {
                writer.write_metadata(&m).map_err(write_err)?;
                summary.metadata_copied += 1;
            }
            Record::Attachment { header, data, .. } => {
                writer
                    .attach(&Attachment {
                        log_time: header.log_time,
                        create_time: header.create_time,
                        name: header.name,
                        media_type: header.media_type,
                        data: Cow::Borrowed(&data),
                    })
                    .map_err(write_err)?;
                summary.attachments_copied += 1;
            }
            // The summary section is rebuilt by the writer.
            Record::DataEnd(_) => break,
            _ => {}
        }
    }
    writer.finish().map_err(write_err)?;
    Ok((summary, writer.into_inner()))
}

#[derive(serde::Deserialize)]
struct BallOnly {
    #[serde(default)]
    ball: u32,
}

/// The ball of a sweep message (0 when it cannot be read: the replay pass
/// already read every sweep).
fn ball_of(data: &[u8], encoding: Encoding) -> u32 {
    use serde::Deserialize;
    match encoding {
        Encoding::Cbor => {
            BallOnly::deserialize(&mut crate::trace::CborDeserializer::from_slice(data)).ok()
        }
        Encoding::Json => serde_json::from_slice::<BallOnly>(data).ok(),
    }
    .map_or(0, |b| b.ball)
}

/// Blesses the file `input` into `output` (which may be the same path, for
/// `--in-place`), through a temporary file in `output`'s directory renamed
/// when complete.
pub fn bless_file(
    input: &Path,
    output: &Path,
    options: ReplayOptions,
) -> Result<BlessSummary, BlessError> {
    let in_name = input.display().to_string();
    let out_name = output.display().to_string();
    let io = |file: &str, what: &str| {
        let file = file.to_string();
        let what = what.to_string();
        move |cause| BlessError::Io { file, what, cause }
    };
    let bytes = std::fs::read(input).map_err(io(&in_name, "reading"))?;
    let (pending, file) = PendingFile::create_seekable(output)
        .map_err(io(&out_name, "creating a temporary file next to it"))?;
    let (summary, buffered) =
        bless_into(&bytes, &in_name, BufWriter::new(file), &out_name, options)?;
    pending.finish(buffered).map_err(|e| {
        let what = match e.step {
            FinishStep::Renaming => e.step.doing(),
            FinishStep::Flushing | FinishStep::Syncing => "writing",
        };
        io(&out_name, what)(e.cause)
    })?;
    Ok(summary)
}
