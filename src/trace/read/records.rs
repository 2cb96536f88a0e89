//! The reader's handling of one record: the schemas, channels and
//! metadata it declares, a chunk opened, and each trace message parsed,
//! validated and checked for order, into the [`TraceEvent`]s the reader
//! yields.

use std::collections::BTreeMap;

use mcap::McapError;
use mcap::records::{Record, op};
use mcap::sans_io::{LinearReader, LinearReaderOptions};

use super::{ChannelInfo, EventBody, EventHeader, State, TraceError, TraceEvent, clamp};
use crate::trace::encoding::Encoding;
use crate::trace::error::MessageAt;
use crate::trace::messages::{
    CONTACT_TOPIC, ContactMsg, ContactsMsg, EXPECTED_CONTACTS_TOPIC, OutcomeMsg, SCENE_TOPIC,
    SWEEP_TOPIC, SceneMsg, SweepMsg, TRACE_TOPICS,
};
use crate::trace::source::{EXPECTED_SOURCE_METADATA, ExpectedSource};
use crate::trace::validate::{
    parse_message_as, validate_contact, validate_contacts, validate_outcome, validate_scene,
    validate_sweep,
};

impl State {
    pub(super) fn mcap_error(&self, err: McapError, context: &str, in_chunk: bool) -> TraceError {
        let file = self.source_name.clone();
        let messages = self.stats.messages;
        let limit = self.limits.record_bytes;
        match err {
            McapError::UnexpectedEof if !in_chunk && self.stats.bytes == 0 => {
                TraceError::Empty { file }
            }
            McapError::UnexpectedEof if !in_chunk => TraceError::Truncated { file, messages },
            McapError::BadMagic if !in_chunk && messages == 0 => TraceError::NotMcap { file },
            McapError::RecordTooLarge { opcode, len } => TraceError::TooLarge {
                file,
                what: format!("a record with opcode {opcode:#04x} ({context})"),
                declared: len,
                limit,
            },
            McapError::ChunkTooLarge(len) => TraceError::TooLarge {
                file,
                what: context.to_string(),
                declared: len,
                limit,
            },
            cause => TraceError::Corrupt {
                file,
                messages,
                context: context.to_string(),
                cause,
            },
        }
    }

    /// Checks a chunk's declared sizes and returns a reader over its records.
    pub(super) fn open_chunk(&mut self, data: &[u8]) -> Result<LinearReader, TraceError> {
        let index = self.stats.chunks;
        let context = format!("chunk {index}");
        let messages = self.stats.messages;
        crate::trace::lengths::refuse(op::CHUNK, data, &self.source_name, messages, || {
            context.clone()
        })?;
        let header = match mcap::parse_record(op::CHUNK, data) {
            Ok(Record::Chunk { header, .. }) => header,
            // `parse_record(op::CHUNK, ..)` always returns a chunk.
            Ok(_) => return Err(self.mcap_error(McapError::UnexpectedEoc, &context, true)),
            Err(err) => return Err(self.mcap_error(err, &context, true)),
        };
        if header.uncompressed_size > self.limits.record_bytes {
            return Err(TraceError::TooLarge {
                file: self.source_name.clone(),
                what: format!("{context} (uncompressed)"),
                declared: header.uncompressed_size,
                limit: self.limits.record_bytes,
            });
        }
        self.stats.chunks += 1;
        let compression = if header.compression.is_empty() {
            "none".to_string()
        } else {
            header.compression.clone()
        };
        self.stats.compression.insert(compression);
        // Hand the whole chunk record to a reader of its own, which checks
        // the CRC before yielding any record of it.
        let options = LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(clamp(self.limits.record_bytes));
        let mut chunk = LinearReader::new_with_options(options);
        let total = 9 + data.len();
        let buf = chunk.insert(total);
        buf[0] = op::CHUNK;
        buf[1..9].copy_from_slice(&(data.len() as u64).to_le_bytes());
        buf[9..].copy_from_slice(data);
        chunk.notify_read(total);
        Ok(chunk)
    }

    /// Handles one record (outside or inside a chunk).
    pub(super) fn record(
        &mut self,
        opcode: u8,
        data: &[u8],
    ) -> Result<Option<TraceEvent>, TraceError> {
        if self.after_data_end && opcode != op::FOOTER {
            self.stats.has_summary = true;
        }
        match opcode {
            op::HEADER | op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA | op::DATA_END => {}
            // Indexes, statistics, attachments and unknown records are not needed.
            _ => return Ok(None),
        }
        let context = || format!("record with opcode {opcode:#04x}");
        crate::trace::lengths::refuse(
            opcode,
            data,
            &self.source_name,
            self.stats.messages,
            context,
        )?;
        let record = match mcap::parse_record(opcode, data) {
            Ok(record) => record,
            Err(err) => return Err(self.mcap_error(err, &context(), false)),
        };
        match record {
            Record::Header(header) => {
                self.stats.header_read = true;
                self.stats.library = header.library;
                self.stats.profile = header.profile;
            }
            Record::Schema { header, .. } => {
                self.schemas
                    .insert(header.id, (header.name, header.encoding));
            }
            Record::Channel(channel) => {
                let is_trace = TRACE_TOPICS.contains(&channel.topic.as_str());
                let encoding = Encoding::from_message_encoding(&channel.message_encoding);
                if is_trace && encoding.is_none() {
                    return Err(TraceError::WrongEncoding {
                        file: self.source_name.clone(),
                        channel: channel.topic,
                        encoding: channel.message_encoding,
                    });
                }
                let encoding = encoding.filter(|_| is_trace);
                let (schema_name, schema_encoding) = self
                    .schemas
                    .get(&channel.schema_id)
                    .cloned()
                    .unwrap_or_default();
                let entry = self
                    .stats
                    .channels
                    .entry(channel.topic.clone())
                    .or_default();
                entry.schema_name = schema_name;
                entry.schema_encoding = schema_encoding;
                entry.message_encoding = channel.message_encoding;
                self.channels.insert(
                    channel.id,
                    ChannelInfo {
                        topic: channel.topic,
                        encoding,
                    },
                );
            }
            Record::Metadata(metadata) if !self.after_data_end => {
                if metadata.name == EXPECTED_SOURCE_METADATA {
                    self.expected_source(&metadata.metadata)?;
                }
                self.stats.metadata.push((metadata.name, metadata.metadata));
            }
            Record::DataEnd(_) => {
                self.after_data_end = true;
            }
            Record::Message { header, data } => {
                if self.after_data_end || self.skip_messages {
                    return Ok(None);
                }
                return self.message(header.channel_id, header.log_time, &data);
            }
            _ => {}
        }
        Ok(None)
    }

    /// Reads the `sweeptrace.expected_source` record into the stats.
    fn expected_source(&mut self, entries: &BTreeMap<String, String>) -> Result<(), TraceError> {
        let refuse = |problem: String| TraceError::ExpectedSource {
            file: self.source_name.clone(),
            problem,
        };
        if self.stats.expected_source.is_some() {
            return Err(refuse(
                "the file holds two; a trace has at most one expected source".to_string(),
            ));
        }
        let source = ExpectedSource::from_metadata(entries).map_err(refuse)?;
        self.stats.expected_source = Some(source);
        Ok(())
    }

    pub(super) fn message(
        &mut self,
        channel_id: u16,
        log_time_nanos: u64,
        data: &[u8],
    ) -> Result<Option<TraceEvent>, TraceError> {
        let index = self.stats.messages;
        let Some(channel) = self.channels.get(&channel_id) else {
            return Err(TraceError::UnknownChannel {
                file: self.source_name.clone(),
                index,
                channel_id,
            });
        };
        let Some(encoding) = channel.encoding else {
            let topic = channel.topic.clone();
            self.stats.messages += 1;
            if let Some(c) = self.stats.channels.get_mut(&topic) {
                c.messages += 1;
            }
            *self.stats.skipped_by_topic.entry(topic).or_default() += 1;
            return Ok(None);
        };
        let topic = channel.topic.as_str();
        let limit = match topic {
            SCENE_TOPIC => self.limits.scene_bytes,
            _ => self.limits.small_message_bytes,
        };
        // Where the message is, made only for an error.
        let at = |frame: Option<u64>| MessageAt {
            file: self.source_name.clone(),
            channel: topic.to_string(),
            index,
            frame,
        };
        if data.len() as u64 > limit {
            return Err(TraceError::MessageTooLarge {
                at: Box::new(at(None)),
                bytes: data.len() as u64,
                limit,
            });
        }
        if let Some(previous_nanos) = self.last_log_time
            && log_time_nanos < previous_nanos
        {
            let frame = if topic == SCENE_TOPIC {
                None
            } else {
                crate::trace::validate::frame_of_message(data, encoding)
            };
            return Err(TraceError::OutOfOrder {
                at: Box::new(at(frame)),
                log_time_nanos,
                previous_nanos,
            });
        }
        let body = match topic {
            SCENE_TOPIC => {
                let scene: SceneMsg = parse_message_as(data, encoding, || at(None))?;
                validate_scene(&scene).map_err(|p| p.at(at(None)))?;
                self.scene_margin = Some(scene.margin);
                EventBody::Scene(scene)
            }
            SWEEP_TOPIC => {
                let sweep: SweepMsg = parse_message_as(data, encoding, || at(None))?;
                if self.scene_margin.is_none() {
                    return Err(TraceError::SweepBeforeScene {
                        at: Box::new(at(Some(sweep.frame))),
                    });
                }
                validate_sweep(&sweep, self.scene_margin)
                    .map_err(|p| p.at(at(Some(sweep.frame))))?;
                EventBody::Sweep(sweep)
            }
            CONTACT_TOPIC => {
                let contact: ContactMsg = parse_message_as(data, encoding, || at(None))?;
                if self.scene_margin.is_none() {
                    return Err(TraceError::SweepBeforeScene {
                        at: Box::new(at(Some(contact.frame))),
                    });
                }
                validate_contact(&contact).map_err(|p| p.at(at(Some(contact.frame))))?;
                EventBody::Contact(contact)
            }
            EXPECTED_CONTACTS_TOPIC => {
                let contacts: ContactsMsg = parse_message_as(data, encoding, || at(None))?;
                validate_contacts(&contacts).map_err(|p| p.at(at(Some(contacts.frame))))?;
                EventBody::ExpectedContacts(contacts)
            }
            _ => {
                let outcome: OutcomeMsg = parse_message_as(data, encoding, || at(None))?;
                validate_outcome(&outcome).map_err(|p| p.at(at(Some(outcome.frame))))?;
                EventBody::Expected(outcome)
            }
        };
        if let Some(c) = self.stats.channels.get_mut(topic) {
            c.messages += 1;
        }
        self.last_log_time = Some(log_time_nanos);
        self.stats.messages += 1;
        Ok(Some(TraceEvent {
            header: EventHeader {
                log_time_nanos,
                index,
            },
            body,
        }))
    }
}
