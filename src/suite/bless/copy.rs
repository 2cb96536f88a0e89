//! Blessing's passes 2 and 3: the scan of the input's header and of the
//! schemas only `/expected` channels use, and the copy of its records, one
//! by one, with each sweep's new expectation written after it.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap, HashSet, VecDeque};
use std::io::{Seek, Write};

use mcap::read::ChunkFlattener;
use mcap::records::{MessageHeader, Record};
use mcap::{Attachment, McapError};

use super::{BlessError, BlessSummary};
use crate::trace::schemas::OUTCOME_SCHEMA_JSON;
use crate::trace::source::EXPECTED_SOURCE_METADATA;
use crate::trace::{
    EXPECTED_TOPIC, Encoding, OUTCOME_SCHEMA, OutcomeMsg, SCHEMA_ENCODING, SWEEP_TOPIC,
    default_write_options, frame_of_message,
};

/// An error reading the input `name`'s container.
pub(super) fn read_error(name: &str) -> impl Fn(McapError) -> BlessError + '_ {
    move |cause| BlessError::Mcap {
        file: name.to_string(),
        what: "reading the container".to_string(),
        cause,
    }
}

/// An error writing the blessed trace `output_name`.
pub(super) fn write_error(output_name: &str) -> impl Fn(McapError) -> BlessError + '_ {
    move |cause| BlessError::Mcap {
        file: output_name.to_string(),
        what: "writing the blessed trace".to_string(),
        cause,
    }
}

/// Pass 2 (cheap; pass 1 was the replay): the writer's options with the
/// input's header (profile, library), and the schemas only `/expected`
/// channels use (not copied).
pub(super) fn scan(
    input: &[u8],
    name: &str,
) -> Result<(mcap::WriteOptions, HashSet<u16>), BlessError> {
    let mut write_options = default_write_options();
    let mut used_by_others: HashSet<u16> = HashSet::new();
    let mut used_by_expected: HashSet<u16> = HashSet::new();
    for record in ChunkFlattener::new(input).map_err(read_error(name))? {
        match record.map_err(read_error(name))? {
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
    let expected_only = used_by_expected
        .difference(&used_by_others)
        .copied()
        .collect();
    Ok((write_options, expected_only))
}

/// Pass 3: the copy of the input's records, record by record, with each
/// sweep's new expectation after it.
pub(super) struct Copier<'a, W: Write + Seek> {
    /// The input's name.
    pub(super) name: &'a str,
    /// The output's name.
    pub(super) output_name: &'a str,
    pub(super) writer: mcap::Writer<W>,
    /// The expectation to write after each sweep by `(frame, ball)`, in
    /// trace order (`None`: none).
    pub(super) outcomes: HashMap<(u64, u32), VecDeque<Option<OutcomeMsg>>>,
    /// The input's schemas that only `/expected` channels use.
    pub(super) expected_only: HashSet<u16>,
    /// Input schema id to output schema id.
    pub(super) schema_ids: HashMap<u16, u16>,
    /// Input channel id to output channel id (`/expected` channels have none).
    pub(super) channel_ids: HashMap<u16, u16>,
    /// Every input channel's topic.
    pub(super) channel_topics: HashMap<u16, String>,
    /// The message encoding of each input channel (trace channels: the
    /// replay pass checked they are `json` or `cbor`).
    pub(super) channel_encodings: HashMap<u16, Encoding>,
    /// The output's `/expected` channel for each encoding.
    pub(super) expected_channels: BTreeMap<Encoding, u16>,
    /// The index of the next input message.
    pub(super) index: u64,
    /// The sequence number of the next output message.
    pub(super) sequence: u32,
    pub(super) summary: BlessSummary,
}

impl<W: Write + Seek> Copier<'_, W> {
    /// Copies one record (or drops it: `/expected`'s own, the old
    /// `sweeptrace.expected_source` record).
    pub(super) fn record(&mut self, record: Record<'_>) -> Result<(), BlessError> {
        match record {
            Record::Schema { header, data } => {
                if self.schema_ids.contains_key(&header.id)
                    || self.expected_only.contains(&header.id)
                {
                    return Ok(());
                }
                let id = self
                    .writer
                    .add_schema(&header.name, &header.encoding, &data)
                    .map_err(write_error(self.output_name))?;
                self.schema_ids.insert(header.id, id);
                self.summary.schemas_copied += 1;
            }
            Record::Channel(c) => self.channel(&c)?,
            Record::Message { header, data } => self.message(header, &data)?,
            // Replaced by the record written first.
            Record::Metadata(m) if m.name == EXPECTED_SOURCE_METADATA => {}
            Record::Metadata(m) => {
                self.writer
                    .write_metadata(&m)
                    .map_err(write_error(self.output_name))?;
                self.summary.metadata_copied += 1;
            }
            Record::Attachment { header, data, .. } => {
                self.writer
                    .attach(&Attachment {
                        log_time: header.log_time,
                        create_time: header.create_time,
                        name: header.name,
                        media_type: header.media_type,
                        data: Cow::Borrowed(&data),
                    })
                    .map_err(write_error(self.output_name))?;
                self.summary.attachments_copied += 1;
            }
            _ => {}
        }
        Ok(())
    }

    /// Copies a channel, except an `/expected` one (its topic and
    /// encoding are kept either way).
    fn channel(&mut self, c: &mcap::records::Channel) -> Result<(), BlessError> {
        if self.channel_topics.contains_key(&c.id) {
            return Ok(());
        }
        self.channel_topics.insert(c.id, c.topic.clone());
        if let Some(encoding) = Encoding::from_message_encoding(&c.message_encoding) {
            self.channel_encodings.insert(c.id, encoding);
        }
        if c.topic == EXPECTED_TOPIC {
            return Ok(());
        }
        let schema_id = if c.schema_id == 0 {
            0
        } else {
            *self
                .schema_ids
                .get(&c.schema_id)
                .ok_or_else(|| BlessError::Mcap {
                    file: self.name.to_string(),
                    what: format!("channel `{}`", c.topic),
                    cause: McapError::UnknownSchema(c.topic.clone(), c.schema_id),
                })?
        };
        let id = self
            .writer
            .add_channel(schema_id, &c.topic, &c.message_encoding, &c.metadata)
            .map_err(write_error(self.output_name))?;
        self.channel_ids.insert(c.id, id);
        self.summary.channels_copied += 1;
        Ok(())
    }

    /// Copies a message, except an `/expected` one; after a `/sweep`
    /// message, writes its new expectation.
    fn message(&mut self, header: MessageHeader, data: &[u8]) -> Result<(), BlessError> {
        let this = self.index;
        self.index += 1;
        let topic = self
            .channel_topics
            .get(&header.channel_id)
            .map(String::as_str);
        if topic == Some(EXPECTED_TOPIC) {
            self.summary.expected_dropped += 1;
            return Ok(());
        }
        let is_sweep = topic == Some(SWEEP_TOPIC);
        let Some(&channel_id) = self.channel_ids.get(&header.channel_id) else {
            return Err(BlessError::Mcap {
                file: self.name.to_string(),
                what: format!("message {this}"),
                cause: McapError::UnknownChannel(header.sequence, header.channel_id),
            });
        };
        self.write(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                ..header
            },
            data,
        )?;
        self.summary.messages_copied += 1;
        if is_sweep {
            self.expectation(this, &header, data)?;
        }
        Ok(())
    }

    /// Writes the expectation of the sweep message `index` (`header`,
    /// `data`): the next one of its frame and ball, on the `/expected`
    /// channel of its encoding, at its `log_time` (nothing for a sweep left
    /// out of the selection that had none).
    fn expectation(
        &mut self,
        index: u64,
        header: &MessageHeader,
        data: &[u8],
    ) -> Result<(), BlessError> {
        let encoding = self
            .channel_encodings
            .get(&header.channel_id)
            .copied()
            .unwrap_or_default();
        let ball = ball_of(data, encoding);
        let Some(outcome) = frame_of_message(data, encoding)
            .and_then(|frame| self.outcomes.get_mut(&(frame, ball)))
            .and_then(VecDeque::pop_front)
        else {
            return Err(BlessError::Unmatched {
                file: self.name.to_string(),
                index,
            });
        };
        let Some(outcome) = outcome else {
            return Ok(());
        };
        let channel_id = self.expected_channel(encoding)?;
        let encoded = encoding.encode(&outcome).map_err(|e| BlessError::Io {
            file: self.name.to_string(),
            what: format!("serializing the outcome of frame {}", outcome.frame),
            cause: std::io::Error::other(e),
        })?;
        self.write(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: header.log_time,
                publish_time: header.log_time,
            },
            &encoded,
        )?;
        self.summary.expected_written += 1;
        Ok(())
    }

    /// The output's `/expected` channel for `encoding`, added the first
    /// time.
    fn expected_channel(&mut self, encoding: Encoding) -> Result<u16, BlessError> {
        if let Some(&id) = self.expected_channels.get(&encoding) {
            return Ok(id);
        }
        let schema = self
            .writer
            .add_schema(
                OUTCOME_SCHEMA,
                SCHEMA_ENCODING,
                OUTCOME_SCHEMA_JSON.as_bytes(),
            )
            .map_err(write_error(self.output_name))?;
        let id = self
            .writer
            .add_channel(schema, EXPECTED_TOPIC, encoding.as_str(), &BTreeMap::new())
            .map_err(write_error(self.output_name))?;
        self.expected_channels.insert(encoding, id);
        Ok(id)
    }

    /// Writes one message and advances the sequence number.
    fn write(&mut self, header: &MessageHeader, data: &[u8]) -> Result<(), BlessError> {
        self.writer
            .write_to_known_channel(header, data)
            .map_err(write_error(self.output_name))?;
        self.sequence = self.sequence.wrapping_add(1);
        Ok(())
    }
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
