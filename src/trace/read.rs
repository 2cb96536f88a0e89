//! The streaming trace reader, [`TraceReader`] (its documentation says
//! how it orders, bounds and fails).

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{ErrorKind, Read};

use mcap::records::op;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use super::encoding::Encoding;
use super::error::TraceError;
use super::messages::{ContactMsg, ContactsMsg, OutcomeMsg, SceneMsg, SweepMsg};
use super::source::ExpectedSource;
use log_time_order::LogTimeOrder;

mod log_time_order;
mod records;

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

/// One message of a trace channel, parsed and validated: where it sits in
/// the file, and what it says.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceEvent {
    /// Its `log_time` and its index in the file.
    pub header: EventHeader,
    /// The message.
    pub body: EventBody,
}

/// Where a message sits in its trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EventHeader {
    /// Its `log_time`.
    pub log_time_nanos: u64,
    /// Its index among all messages of the file, from 0.
    pub index: u64,
}

/// The message of a [`TraceEvent`], by channel.
#[derive(Debug, Clone, PartialEq)]
pub enum EventBody {
    /// A `/scene` message.
    Scene(SceneMsg),
    /// A `/sweep` message.
    Sweep(SweepMsg),
    /// An `/expected` message.
    Expected(OutcomeMsg),
    /// A `/contact` message: a contact query.
    Contact(ContactMsg),
    /// An `/expected_contacts` message: an engine's contacts.
    ExpectedContacts(ContactsMsg),
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
/// channels in file order.
///
/// The reader walks the file once from start to end with the `mcap` crate's
/// sans-io linear reader, so it needs neither the summary nor the indexes
/// (a file without them is read in full, never refused or read as empty)
/// and never holds more than one chunk in memory. Chunked or not, zstd, lz4
/// or uncompressed: all are read.
///
/// # Ordering
/// Events come in file order. The messages of the three trace channels must
/// be written in non-decreasing `log_time` order (the format says `log_time`
/// grows with `frame`); a message whose `log_time` is smaller than that of an
/// earlier trace message is an error ([`TraceError::OutOfOrder`]) rather
/// than being reordered, which keeps memory bounded. Messages with equal
/// `log_time` keep their file order, so a scene must be written before the
/// sweeps that share its `log_time`.
///
/// A file whose chunks overlap in log time (written by a multi-threaded
/// recorder) cannot be read this way without reordering. When it has a
/// summary with chunk indexes, [`TraceReader::new_indexed`] reads its
/// messages in log-time order through the indexes instead, holding only the
/// chunks that overlap at once (`info` says so); without a summary it gives
/// the error above.
///
/// # Limits
/// Sizes declared by the file are checked before anything is allocated for
/// them (see [`ReadLimits`]): any record, and any chunk compressed or
/// uncompressed, is refused above [`MAX_RECORD_BYTES`]; a `/scene` message
/// above [`MAX_SCENE_BYTES`]; a `/sweep` or `/expected` message above
/// [`MAX_SMALL_MESSAGE_BYTES`]. A scene's vertex and triangle counts are
/// bounded by its byte size (a JSON number takes at least one byte), so a
/// scene "claiming" a billion triangles is refused by its size.
///
/// # Errors
/// Every message of the trace channels is parsed and validated; the first
/// error ends the iteration (the iterator returns `None` afterwards). The
/// events before it have already been yielded, so a truncated file still
/// gives every complete message before the cut, and the error says how many
/// complete messages were read.
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
