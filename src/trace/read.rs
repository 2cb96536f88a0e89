//! A streaming trace reader over any [`Read`].
//!
//! The reader walks the file once from start to end with the `mcap` crate's
//! sans-io linear reader, so it needs neither the summary nor the indexes
//! (a file without them is read in full, never refused or read as empty)
//! and never holds more than one chunk in memory. Chunked or not, zstd, lz4
//! or uncompressed: all are read.
//!
//! # Ordering
//! Events come in file order. The messages of the three trace channels must
//! be written in non-decreasing `log_time` order (the format says `log_time`
//! grows with `frame`); a message whose `log_time` is smaller than that of an
//! earlier trace message is an error ([`TraceError::OutOfOrder`]) rather
//! than being reordered, which keeps memory bounded. Messages with equal
//! `log_time` keep their file order, so a scene must be written before the
//! sweeps that share its `log_time`.
//!
//! A file whose chunks overlap in log time (written by a multi-threaded
//! recorder) cannot be read this way without reordering. When it has a
//! summary with chunk indexes, [`TraceReader::new_indexed`] reads its
//! messages in log-time order through the indexes instead, holding only the
//! chunks that overlap at once (`info` says so); without a summary it gives
//! the error above.
//!
//! # Limits
//! Sizes declared by the file are checked before anything is allocated for
//! them (see [`ReadLimits`]): any record, and any chunk compressed or
//! uncompressed, is refused above [`MAX_RECORD_BYTES`]; a `/scene` message
//! above [`MAX_SCENE_BYTES`]; a `/sweep` or `/expected` message above
//! [`MAX_SMALL_MESSAGE_BYTES`]. A scene's vertex and triangle counts are
//! bounded by its byte size (a JSON number takes at least one byte), so a
//! scene "claiming" a billion triangles is refused by its size.
//!
//! # Errors
//! Every message of the trace channels is parsed and validated; the first
//! error ends the iteration (the iterator returns `None` afterwards). The
//! events before it have already been yielded, so a truncated file still
//! gives every complete message before the cut, and the error says how many
//! complete messages were read.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{ErrorKind, Read};

use mcap::McapError;
use mcap::records::{Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::encoding::Encoding;
use super::error::{MessageAt, TraceError};
use super::messages::{EXPECTED_TOPIC, OutcomeMsg, SCENE_TOPIC, SWEEP_TOPIC, SceneMsg, SweepMsg};
use super::source::{EXPECTED_SOURCE_METADATA, ExpectedSource};
use super::validate::{parse_message_as, validate_outcome, validate_scene, validate_sweep};
use log_time_order::LogTimeOrder;

mod log_time_order;

/// Largest record, or chunk (compressed or uncompressed), accepted: 256 MiB.
pub const MAX_RECORD_BYTES: u64 = 256 * 1024 * 1024;
/// Largest `/scene` message accepted: 64 MiB (JSON or CBOR).
pub const MAX_SCENE_BYTES: u64 = 64 * 1024 * 1024;
/// Largest `/sweep` or `/expected` message accepted: 64 KiB (JSON or CBOR).
pub const MAX_SMALL_MESSAGE_BYTES: u64 = 64 * 1024;

/// Size limits of a [`TraceReader`]; the defaults are the `MAX_*` constants.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadLimits {
    /// Largest record, or chunk (compressed or uncompressed).
    pub record_bytes: u64,
    /// Largest `/scene` message.
    pub scene_bytes: u64,
    /// Largest `/sweep` or `/expected` message.
    pub small_message_bytes: u64,
}

impl Default for ReadLimits {
    fn default() -> Self {
        ReadLimits {
            record_bytes: MAX_RECORD_BYTES,
            scene_bytes: MAX_SCENE_BYTES,
            small_message_bytes: MAX_SMALL_MESSAGE_BYTES,
        }
    }
}

/// One message of a trace channel, parsed and validated.
#[derive(Debug, Clone, PartialEq)]
pub enum TraceEvent {
    /// A `/scene` message.
    Scene {
        /// Its `log_time`.
        log_time_nanos: u64,
        /// Its index among all messages of the file, from 0.
        index: u64,
        /// The scene.
        scene: SceneMsg,
    },
    /// A `/sweep` message.
    Sweep {
        /// Its `log_time`.
        log_time_nanos: u64,
        /// Its index among all messages of the file, from 0.
        index: u64,
        /// The sweep.
        sweep: SweepMsg,
    },
    /// An `/expected` message.
    Expected {
        /// Its `log_time`.
        log_time_nanos: u64,
        /// Its index among all messages of the file, from 0.
        index: u64,
        /// The expected outcome.
        outcome: OutcomeMsg,
    },
}

impl TraceEvent {
    /// The message's `log_time` in nanoseconds.
    pub fn log_time_nanos(&self) -> u64 {
        match self {
            TraceEvent::Scene { log_time_nanos, .. }
            | TraceEvent::Sweep { log_time_nanos, .. }
            | TraceEvent::Expected { log_time_nanos, .. } => *log_time_nanos,
        }
    }

    /// The message's index in the file.
    pub fn index(&self) -> u64 {
        match self {
            TraceEvent::Scene { index, .. }
            | TraceEvent::Sweep { index, .. }
            | TraceEvent::Expected { index, .. } => *index,
        }
    }
}

/// One channel (or several sharing a topic) as seen in the file.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct ChannelStats {
    /// Schema name (empty when the channel has no schema).
    pub schema_name: String,
    /// Schema encoding.
    pub schema_encoding: String,
    /// Message encoding.
    pub message_encoding: String,
    /// Messages read on this topic.
    pub messages: u64,
}

/// What the reader has seen so far.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct ReadStats {
    /// Complete messages read, on every topic.
    pub messages: u64,
    /// Messages of foreign topics, skipped, by topic.
    pub skipped_by_topic: BTreeMap<String, u64>,
    /// Every topic seen, with its schema and message count.
    pub channels: BTreeMap<String, ChannelStats>,
    /// Chunks read.
    pub chunks: u64,
    /// Compression of the chunks (`zstd`, `lz4`, `none`); empty when the
    /// file has no chunk.
    pub compression: BTreeSet<String>,
    /// Bytes read from the input.
    pub bytes: u64,
    /// Whether the file has a summary section.
    pub has_summary: bool,
    /// Whether the messages were read in log-time order through the
    /// summary's chunk indexes, because chunks of the file overlap in log
    /// time ([`TraceReader::new_indexed`]).
    pub read_through_chunk_indexes: bool,
    /// Metadata records, by name, in file order (the summary's copies are not repeated).
    pub metadata: Vec<(String, BTreeMap<String, String>)>,
    /// Who computed the expectations: the `sweeptrace.expected_source`
    /// record, validated; `None` when the trace does not say. (Left out of
    /// the JSON: the record is also in `metadata`, and reports give it
    /// field of their own.)
    #[serde(skip)]
    pub expected_source: Option<ExpectedSource>,
    /// Whether the file's magic and header record were read: the input is
    /// an MCAP file (what follows may still be damaged).
    pub header_read: bool,
    /// The header's library string.
    pub library: String,
    /// The header's profile.
    pub profile: String,
}

#[derive(Debug, Clone)]
struct ChannelInfo {
    topic: String,
    /// The message encoding of a trace channel (`None` for other topics,
    /// whose messages are skipped whatever their encoding).
    encoding: Option<Encoding>,
}

/// Everything but the byte sources, so records borrowed from a reader can be
/// handled while the reader is borrowed.
struct State {
    source_name: String,
    limits: ReadLimits,
    stats: ReadStats,
    schemas: HashMap<u16, (String, String)>,
    channels: HashMap<u16, ChannelInfo>,
    after_data_end: bool,
    last_log_time: Option<u64>,
    /// The margin of the current scene; `None` before the first scene.
    scene_margin: Option<f64>,
    /// Messages are left for a second pass (the pass in file order before
    /// a read in log-time order).
    skip_messages: bool,
}

/// Reads a trace from any [`Read`], yielding the messages of the three trace
/// channels in file order. See the [module documentation](self).
pub struct TraceReader<R: Read> {
    input: R,
    file: LinearReader,
    chunk: Option<LinearReader>,
    /// Set when the messages are read through the chunk indexes.
    log_time_order: Option<LogTimeOrder<R>>,
    state: State,
    done: bool,
}

impl<R: Read> TraceReader<R> {
    /// A reader with the default [`ReadLimits`]; `source_name` (a file name)
    /// is used in error messages.
    pub fn new(reader: R, source_name: &str) -> Self {
        Self::with_limits(reader, source_name, ReadLimits::default())
    }

    /// A reader with the given limits.
    pub fn with_limits(reader: R, source_name: &str, limits: ReadLimits) -> Self {
        let options = LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_record_length_limit(clamp(limits.record_bytes));
        TraceReader {
            input: reader,
            file: LinearReader::new_with_options(options),
            chunk: None,
            state: State {
                source_name: source_name.to_string(),
                limits,
                stats: ReadStats::default(),
                schemas: HashMap::new(),
                channels: HashMap::new(),
                after_data_end: false,
                last_log_time: None,
                scene_margin: None,
                skip_messages: false,
            },
            log_time_order: None,
            done: false,
        }
    }

    /// What has been read so far (complete after the iterator returned `None`).
    pub fn stats(&self) -> &ReadStats {
        &self.state.stats
    }

    /// Who computed the expectations, when the trace says so (its
    /// `sweeptrace.expected_source` record). Known once the reader has
    /// passed the record: the project's writer puts it before the first
    /// message, other writers may put it anywhere in the data section, so
    /// read to the end to be sure. A malformed record (or a second one)
    /// is an error of the iteration, [`TraceError::ExpectedSource`].
    pub fn expected_source(&self) -> Option<&ExpectedSource> {
        self.state.stats.expected_source.as_ref()
    }

    /// The name given to [`TraceReader::new`].
    pub fn source_name(&self) -> &str {
        &self.state.source_name
    }

    fn step(&mut self) -> Result<Option<TraceEvent>, TraceError> {
        if self.log_time_order.is_some() {
            return self.step_in_log_time_order();
        }
        self.step_in_file_order()
    }

    fn step_in_file_order(&mut self) -> Result<Option<TraceEvent>, TraceError> {
        loop {
            if let Some(chunk) = self.chunk.as_mut() {
                match chunk.next_event() {
                    None => {
                        self.chunk = None;
                    }
                    Some(Err(err)) => {
                        let context =
                            format!("chunk {}", self.state.stats.chunks.saturating_sub(1));
                        return Err(self.state.mcap_error(err, &context, true));
                    }
                    Some(Ok(LinearReadEvent::ReadRequest(_))) => {
                        // The whole chunk was handed over: this is its end.
                        let _ = chunk.insert(0);
                        chunk.notify_read(0);
                    }
                    Some(Ok(LinearReadEvent::Record { data, opcode })) => {
                        if let Some(event) = self.state.record(opcode, data)? {
                            return Ok(Some(event));
                        }
                    }
                }
                continue;
            }
            match self.file.next_event() {
                None => return Ok(None),
                Some(Err(err)) => return Err(self.state.mcap_error(err, "record", false)),
                Some(Ok(LinearReadEvent::ReadRequest(want))) => {
                    let buf = self.file.insert(want);
                    let read = loop {
                        match self.input.read(buf) {
                            Ok(n) => break n,
                            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                            Err(cause) => {
                                return Err(TraceError::Io {
                                    file: self.state.source_name.clone(),
                                    messages: self.state.stats.messages,
                                    cause,
                                });
                            }
                        }
                    };
                    self.file.notify_read(read);
                    self.state.stats.bytes += read as u64;
                }
                Some(Ok(LinearReadEvent::Record { data, opcode })) => {
                    if opcode == op::CHUNK {
                        self.chunk = Some(self.state.open_chunk(data)?);
                    } else if let Some(event) = self.state.record(opcode, data)? {
                        return Ok(Some(event));
                    }
                }
            }
        }
    }
}

impl<R: Read> Iterator for TraceReader<R> {
    type Item = Result<TraceEvent, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        match self.step() {
            Ok(Some(event)) => Some(Ok(event)),
            Ok(None) => {
                self.done = true;
                None
            }
            Err(err) => {
                self.done = true;
                Some(Err(err))
            }
        }
    }
}

fn clamp(n: u64) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}

impl State {
    fn mcap_error(&self, err: McapError, context: &str, in_chunk: bool) -> TraceError {
        let file = self.source_name.clone();
        let messages = self.stats.messages;
        let limit = self.limits.record_bytes;
        match err {
            McapError::UnexpectedEof if !in_chunk && self.stats.bytes == 0 => {
                TraceError::Empty { file }
            }
            McapError::UnexpectedEof if !in_chunk => TraceError::Truncated { file, messages },
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
    fn open_chunk(&mut self, data: &[u8]) -> Result<LinearReader, TraceError> {
        let index = self.stats.chunks;
        let context = format!("chunk {index}");
        let messages = self.stats.messages;
        super::lengths::refuse(op::CHUNK, data, &self.source_name, messages, || {
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
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<Option<TraceEvent>, TraceError> {
        if self.after_data_end && opcode != op::FOOTER {
            self.stats.has_summary = true;
        }
        match opcode {
            op::HEADER | op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA | op::DATA_END => {}
            // Indexes, statistics, attachments and unknown records are not needed.
            _ => return Ok(None),
        }
        let context = || format!("record with opcode {opcode:#04x}");
        super::lengths::refuse(
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
                let is_trace =
                    [SCENE_TOPIC, SWEEP_TOPIC, EXPECTED_TOPIC].contains(&channel.topic.as_str());
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

    fn message(
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
                super::validate::frame_of_message(data, encoding)
            };
            return Err(TraceError::OutOfOrder {
                at: Box::new(at(frame)),
                log_time_nanos,
                previous_nanos,
            });
        }
        let event = match topic {
            SCENE_TOPIC => {
                let scene: SceneMsg = parse_message_as(data, encoding, || at(None))?;
                validate_scene(&scene).map_err(|p| p.at(at(None)))?;
                self.scene_margin = Some(scene.margin);
                TraceEvent::Scene {
                    log_time_nanos,
                    index,
                    scene,
                }
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
                TraceEvent::Sweep {
                    log_time_nanos,
                    index,
                    sweep,
                }
            }
            _ => {
                let outcome: OutcomeMsg = parse_message_as(data, encoding, || at(None))?;
                validate_outcome(&outcome).map_err(|p| p.at(at(Some(outcome.frame))))?;
                TraceEvent::Expected {
                    log_time_nanos,
                    index,
                    outcome,
                }
            }
        };
        if let Some(c) = self.stats.channels.get_mut(topic) {
            c.messages += 1;
        }
        self.last_log_time = Some(log_time_nanos);
        self.stats.messages += 1;
        Ok(Some(event))
    }
}
