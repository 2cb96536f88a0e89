//! Recording traces.
//!
//! [`TraceWriter`] writes the project's own flavour of the format: chunked,
//! zstd, summary and indexes, library string `sweeptrace <version>`, a
//! `sweeptrace` metadata record with `format_version = "1"`, the three JSON
//! Schemas, the messages in JSON (the default) or CBOR ([`Encoding`]), and
//! when given ([`TraceWriter::expected_source`]) the
//! `sweeptrace.expected_source` record naming who computed the
//! expectations. Output is deterministic: no clock is read and zstd runs on the
//! calling thread. Every message is checked with the reader's validation
//! and size limits before it is written, so whatever this writer accepts,
//! the reader reads.
//!
//! [`write_trace_file`] writes to a temporary file next to the destination
//! and renames it only when everything succeeded: no half-written trace is
//! ever left under the destination name.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use mcap::records::{MessageHeader, Metadata};
use mcap::{Compression, WriteOptions, Writer};
use serde::Serialize;

use super::encoding::Encoding;
use super::error::{MessageAt, TraceError};
use super::messages::{
    CONTACT_SCHEMA, CONTACT_TOPIC, CONTACTS_SCHEMA, ContactMsg, ContactsMsg,
    EXPECTED_CONTACTS_TOPIC, EXPECTED_TOPIC, OUTCOME_SCHEMA, OutcomeMsg, SCENE_SCHEMA, SCENE_TOPIC,
    SWEEP_SCHEMA, SWEEP_TOPIC, SceneMsg, SweepMsg,
};
use super::read::{MAX_SCENE_BYTES, MAX_SMALL_MESSAGE_BYTES};
use super::schemas::{
    CONTACT_SCHEMA_JSON, CONTACTS_SCHEMA_JSON, FORMAT_VERSION, METADATA_NAME, OUTCOME_SCHEMA_JSON,
    SCENE_SCHEMA_JSON, SCHEMA_ENCODING, SWEEP_SCHEMA_JSON,
};
use super::source::{EXPECTED_SOURCE_METADATA, ExpectedSource};
use super::validate::{
    validate_contact, validate_contact_triangles, validate_contacts, validate_outcome,
    validate_scene, validate_sweep, validate_triangle,
};
use crate::atomic::PendingFile;

/// The library string written into every trace: `sweeptrace <version>`.
pub fn library_string() -> String {
    format!("sweeptrace {}", env!("CARGO_PKG_VERSION"))
}

/// The write options of the project's own traces: chunked, zstd on the
/// calling thread (deterministic), summary and indexes on.
pub fn default_write_options() -> WriteOptions {
    WriteOptions::new()
        .compression(Some(Compression::Zstd))
        .compression_threads(0)
        .use_chunks(true)
        .library(library_string())
}

/// Writes a trace to any `Write + Seek`.
pub struct TraceWriter<W: Write + Seek> {
    writer: Writer<W>,
    name: String,
    encoding: Encoding,
    scene_channel: u16,
    sweep_channel: u16,
    expected_channel: u16,
    /// The contact channels, added at their first message (a trace without
    /// contacts has none).
    contact_channel: Option<u16>,
    contacts_channel: Option<u16>,
    messages: u64,
    last_log_time: Option<u64>,
    scene_margin: Option<f64>,
    /// The current scene's triangle count, against which an `/expected`
    /// triangle is checked; `None` before the first scene.
    scene_triangles: Option<usize>,
    /// Whether the `sweeptrace.expected_source` record was written.
    wrote_expected_source: bool,
}

impl<W: Write + Seek> TraceWriter<W> {
    /// A writer with the project's options ([`default_write_options`]).
    pub fn new(w: W) -> Result<Self, TraceError> {
        Self::with_options(w, default_write_options())
    }

    /// A writer with other container options (unchunked, lz4, no summary,
    /// ...); the schemas, channels and metadata are the same. Meant for
    /// tests and tools; traces recorded by the project use [`TraceWriter::new`].
    pub fn with_options(w: W, options: WriteOptions) -> Result<Self, TraceError> {
        Self::with_encoding(w, options, Encoding::Json)
    }

    /// A writer whose three channels use the message `encoding` (JSON or
    /// CBOR; [`TraceWriter::new`] and [`TraceWriter::with_options`] write
    /// JSON), with the container `options` ([`default_write_options`] for
    /// the project's own).
    ///
    /// ```
    /// use sweeptrace::trace::default_write_options;
    /// use sweeptrace::{Encoding, SceneMsg, TraceReader, TraceWriter};
    /// let mut w = TraceWriter::with_encoding(
    ///     std::io::Cursor::new(Vec::new()),
    ///     default_write_options(),
    ///     Encoding::Cbor,
    /// )?;
    /// let scene = SceneMsg {
    ///     name: None,
    ///     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ///     triangles: vec![[0, 1, 2]],
    ///     margin: 0.0,
    ///     facing: Default::default(),
    /// };
    /// w.scene(0, &scene)?;
    /// let bytes = w.finish()?.into_inner();
    /// let mut reader = TraceReader::new(bytes.as_slice(), "scene.mcap");
    /// assert!(matches!(reader.next(), Some(Ok(_))));
    /// assert_eq!(reader.stats().channels["/scene"].message_encoding, "cbor");
    /// # Ok::<(), sweeptrace::TraceError>(())
    /// ```
    pub fn with_encoding(
        w: W,
        options: WriteOptions,
        encoding: Encoding,
    ) -> Result<Self, TraceError> {
        Self::build(w, options, "<trace being written>".to_string(), encoding)
    }

    /// The message encoding of the trace's channels.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    fn build(
        w: W,
        options: WriteOptions,
        name: String,
        encoding: Encoding,
    ) -> Result<Self, TraceError> {
        let error = |cause| TraceError::Write {
            file: name.clone(),
            cause,
        };
        let mut writer = options.create(w).map_err(error)?;
        let metadata = BTreeMap::from([
            ("format_version".to_string(), FORMAT_VERSION.to_string()),
            ("writer".to_string(), library_string()),
        ]);
        writer
            .write_metadata(&Metadata {
                name: METADATA_NAME.to_string(),
                metadata,
            })
            .map_err(error)?;
        let mut channel = |schema: &str, data: &str, topic: &str| -> Result<u16, TraceError> {
            let schema_id = writer
                .add_schema(schema, SCHEMA_ENCODING, data.as_bytes())
                .map_err(error)?;
            writer
                .add_channel(schema_id, topic, encoding.as_str(), &BTreeMap::new())
                .map_err(error)
        };
        let scene_channel = channel(SCENE_SCHEMA, SCENE_SCHEMA_JSON, SCENE_TOPIC)?;
        let sweep_channel = channel(SWEEP_SCHEMA, SWEEP_SCHEMA_JSON, SWEEP_TOPIC)?;
        let expected_channel = channel(OUTCOME_SCHEMA, OUTCOME_SCHEMA_JSON, EXPECTED_TOPIC)?;
        Ok(TraceWriter {
            writer,
            name,
            encoding,
            scene_channel,
            sweep_channel,
            expected_channel,
            contact_channel: None,
            contacts_channel: None,
            messages: 0,
            last_log_time: None,
            scene_margin: None,
            scene_triangles: None,
            wrote_expected_source: false,
        })
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.messages
    }

    fn at(&self, channel: &str, frame: Option<u64>) -> MessageAt {
        MessageAt {
            file: self.name.clone(),
            channel: channel.to_string(),
            index: self.messages,
            frame,
        }
    }

    fn check_time(
        &self,
        channel: &str,
        frame: Option<u64>,
        log_time_nanos: u64,
    ) -> Result<(), TraceError> {
        match self.last_log_time {
            Some(previous_nanos) if log_time_nanos < previous_nanos => {
                Err(TraceError::OutOfOrder {
                    at: Box::new(self.at(channel, frame)),
                    log_time_nanos,
                    previous_nanos,
                })
            }
            _ => Ok(()),
        }
    }

    fn put<T: Serialize>(
        &mut self,
        channel_id: u16,
        channel: &str,
        frame: Option<u64>,
        log_time_nanos: u64,
        msg: &T,
    ) -> Result<(), TraceError> {
        let data = self
            .encoding
            .encode(msg)
            .map_err(|detail| TraceError::Json {
                at: Box::new(self.at(channel, frame)),
                field: ".".to_string(),
                detail,
            })?;
        // The reader's limits, so that whatever is written can be read.
        let limit = if channel_id == self.scene_channel {
            MAX_SCENE_BYTES
        } else {
            MAX_SMALL_MESSAGE_BYTES
        };
        if data.len() as u64 > limit {
            return Err(TraceError::MessageTooLarge {
                at: Box::new(self.at(channel, frame)),
                bytes: data.len() as u64,
                limit,
            });
        }
        let header = MessageHeader {
            channel_id,
            sequence: self.messages as u32,
            log_time: log_time_nanos,
            publish_time: log_time_nanos,
        };
        self.writer
            .write_to_known_channel(&header, &data)
            .map_err(|cause| TraceError::Write {
                file: self.name.clone(),
                cause,
            })?;
        self.messages += 1;
        self.last_log_time = Some(log_time_nanos);
        Ok(())
    }

    /// Writes the `sweeptrace.expected_source` record: who computed the
    /// `/expected` outcomes of this trace (an engine, its version, its
    /// settings). Call it once, before the first message, so that a reader
    /// streaming the file sees it first (it is valid anywhere in the data
    /// section). The source is validated first
    /// ([`ExpectedSource::validate`]: a non-empty engine name, bounded
    /// lengths, no control characters); an invalid source, or a second
    /// call, is an error and writes nothing. Like every record it goes into
    /// the trace being written: [`write_trace_file`] and [`PendingTrace`]
    /// rename the file only when the whole trace is written.
    pub fn expected_source(&mut self, source: &ExpectedSource) -> Result<(), TraceError> {
        let refuse = |problem: String| TraceError::ExpectedSource {
            file: self.name.clone(),
            problem,
        };
        if self.wrote_expected_source {
            return Err(refuse(
                "already written; a trace has at most one expected source".to_string(),
            ));
        }
        source.validate().map_err(refuse)?;
        self.write_metadata(EXPECTED_SOURCE_METADATA, source.to_metadata())?;
        self.wrote_expected_source = true;
        Ok(())
    }

    /// Writes a metadata record `name` (besides the `sweeptrace` record
    /// every trace has), e.g. where a trace was cut from. The name
    /// `sweeptrace.expected_source` is written only through
    /// [`TraceWriter::expected_source`], which validates it.
    pub fn metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), TraceError> {
        if name == EXPECTED_SOURCE_METADATA {
            let source = ExpectedSource::from_metadata(&entries).map_err(|problem| {
                TraceError::ExpectedSource {
                    file: self.name.clone(),
                    problem,
                }
            })?;
            return self.expected_source(&source);
        }
        self.write_metadata(name, entries)
    }

    fn write_metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), TraceError> {
        self.writer
            .write_metadata(&Metadata {
                name: name.to_string(),
                metadata: entries,
            })
            .map_err(|cause| TraceError::Write {
                file: self.name.clone(),
                cause,
            })
    }

    /// Writes a `/scene` message; it applies to the sweeps written after it.
    pub fn scene(&mut self, log_time_nanos: u64, scene: &SceneMsg) -> Result<(), TraceError> {
        self.check_time(SCENE_TOPIC, None, log_time_nanos)?;
        validate_scene(scene).map_err(|p| p.at(self.at(SCENE_TOPIC, None)))?;
        self.put(self.scene_channel, SCENE_TOPIC, None, log_time_nanos, scene)?;
        self.scene_margin = Some(scene.margin);
        self.scene_triangles = Some(scene.triangles.len());
        Ok(())
    }

    /// Writes a `/sweep` message; a scene must have been written before.
    pub fn sweep(&mut self, log_time_nanos: u64, sweep: &SweepMsg) -> Result<(), TraceError> {
        let frame = Some(sweep.frame);
        self.check_time(SWEEP_TOPIC, frame, log_time_nanos)?;
        if self.scene_margin.is_none() {
            return Err(TraceError::SweepBeforeScene {
                at: Box::new(self.at(SWEEP_TOPIC, frame)),
            });
        }
        validate_sweep(sweep, self.scene_margin).map_err(|p| p.at(self.at(SWEEP_TOPIC, frame)))?;
        self.put(
            self.sweep_channel,
            SWEEP_TOPIC,
            frame,
            log_time_nanos,
            sweep,
        )
    }

    /// Writes an `/expected` message. Its triangle must be one of the
    /// current scene's ([`validate_triangle`]), when a scene was written.
    pub fn expected(
        &mut self,
        log_time_nanos: u64,
        outcome: &OutcomeMsg,
    ) -> Result<(), TraceError> {
        let frame = Some(outcome.frame);
        self.check_time(EXPECTED_TOPIC, frame, log_time_nanos)?;
        validate_outcome(outcome)
            .and_then(|()| match self.scene_triangles {
                Some(count) => validate_triangle(outcome, count),
                None => Ok(()),
            })
            .map_err(|p| p.at(self.at(EXPECTED_TOPIC, frame)))?;
        self.put(
            self.expected_channel,
            EXPECTED_TOPIC,
            frame,
            log_time_nanos,
            outcome,
        )
    }

    /// The id of a channel added at its first message.
    fn lazy_channel(&mut self, contacts: bool) -> Result<u16, TraceError> {
        let (slot, schema, data, topic) = if contacts {
            (
                self.contacts_channel,
                CONTACTS_SCHEMA,
                CONTACTS_SCHEMA_JSON,
                EXPECTED_CONTACTS_TOPIC,
            )
        } else {
            (
                self.contact_channel,
                CONTACT_SCHEMA,
                CONTACT_SCHEMA_JSON,
                CONTACT_TOPIC,
            )
        };
        if let Some(id) = slot {
            return Ok(id);
        }
        let error = |cause| TraceError::Write {
            file: self.name.clone(),
            cause,
        };
        let schema_id = self
            .writer
            .add_schema(schema, SCHEMA_ENCODING, data.as_bytes())
            .map_err(error)?;
        let id = self
            .writer
            .add_channel(schema_id, topic, self.encoding.as_str(), &BTreeMap::new())
            .map_err(error)?;
        if contacts {
            self.contacts_channel = Some(id);
        } else {
            self.contact_channel = Some(id);
        }
        Ok(id)
    }

    /// Writes a `/contact` query; a scene must have been written before.
    pub fn contact(&mut self, log_time_nanos: u64, contact: &ContactMsg) -> Result<(), TraceError> {
        let frame = Some(contact.frame);
        self.check_time(CONTACT_TOPIC, frame, log_time_nanos)?;
        if self.scene_margin.is_none() {
            return Err(TraceError::SweepBeforeScene {
                at: Box::new(self.at(CONTACT_TOPIC, frame)),
            });
        }
        validate_contact(contact).map_err(|p| p.at(self.at(CONTACT_TOPIC, frame)))?;
        let id = self.lazy_channel(false)?;
        self.put(id, CONTACT_TOPIC, frame, log_time_nanos, contact)
    }

    /// Writes an engine's `/expected_contacts` for the query of the same
    /// frame and ball. Its triangles must be the current scene's.
    pub fn expected_contacts(
        &mut self,
        log_time_nanos: u64,
        contacts: &ContactsMsg,
    ) -> Result<(), TraceError> {
        let frame = Some(contacts.frame);
        self.check_time(EXPECTED_CONTACTS_TOPIC, frame, log_time_nanos)?;
        validate_contacts(contacts)
            .and_then(|()| match self.scene_triangles {
                Some(count) => validate_contact_triangles(contacts, count),
                None => Ok(()),
            })
            .map_err(|p| p.at(self.at(EXPECTED_CONTACTS_TOPIC, frame)))?;
        let id = self.lazy_channel(true)?;
        self.put(id, EXPECTED_CONTACTS_TOPIC, frame, log_time_nanos, contacts)
    }

    /// Writes the summary and footer and returns the underlying writer.
    pub fn finish(mut self) -> Result<W, TraceError> {
        self.writer.finish().map_err(|cause| TraceError::Write {
            file: self.name.clone(),
            cause,
        })?;
        Ok(self.writer.into_inner())
    }
}

/// A trace file being written: a [`TraceWriter`] on a temporary file next
/// to the destination, renamed to the destination by
/// [`PendingTrace::commit`] once the summary and footer are written and the
/// data reached the disk. Dropped without a commit (an error, an abandoned
/// writer), the temporary file is removed and the destination is untouched;
/// a process killed while writing leaves only the temporary file
/// (`.{name}.partial-*`, see [`crate::atomic`]), never a file under the
/// destination name.
pub struct PendingTrace {
    pending: PendingFile,
    writer: TraceWriter<BufWriter<File>>,
    name: String,
}

impl PendingTrace {
    /// Creates the temporary file next to `path` and starts the trace in
    /// it (header, metadata, schemas, channels). Error messages name `path`.
    pub fn create(path: impl AsRef<Path>) -> Result<PendingTrace, TraceError> {
        Self::create_with_encoding(path, Encoding::Json)
    }

    /// [`PendingTrace::create`], with the channels in the message `encoding`.
    pub fn create_with_encoding(
        path: impl AsRef<Path>,
        encoding: Encoding,
    ) -> Result<PendingTrace, TraceError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let (pending, file) =
            PendingFile::create_seekable(path).map_err(|cause| TraceError::Io {
                file: name.clone(),
                messages: 0,
                cause,
            })?;
        let writer = TraceWriter::build(
            BufWriter::new(file),
            default_write_options(),
            name.clone(),
            encoding,
        )?;
        Ok(PendingTrace {
            pending,
            writer,
            name,
        })
    }

    /// The writer, for the scenes, sweeps and outcomes.
    pub fn writer(&mut self) -> &mut TraceWriter<BufWriter<File>> {
        &mut self.writer
    }

    /// The destination's name, as error messages give it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Finishes the trace (summary, footer), syncs it to the disk and
    /// renames it to the destination.
    pub fn commit(self) -> Result<(), TraceError> {
        let PendingTrace {
            pending,
            writer,
            name,
        } = self;
        let messages = writer.messages();
        let io = |cause: std::io::Error| TraceError::Io {
            file: name.clone(),
            messages,
            cause,
        };
        let buffered = writer.finish()?;
        pending.finish(buffered).map_err(|e| io(e.cause))
    }
}

/// Writes a trace to `path` through `f`, atomically: the trace goes to a
/// temporary file in the same directory, which is renamed to `path` only
/// when `f` and the writer both succeeded (and the data reached the disk).
/// `f` gives the expectations' source, when it writes expectations, with
/// [`TraceWriter::expected_source`] before its first message.
/// On any error the temporary file is removed and `path` is untouched.
/// ([`PendingTrace`] is the same without a closure.)
pub fn write_trace_file<T, E: From<TraceError>>(
    path: impl AsRef<Path>,
    f: impl FnOnce(&mut TraceWriter<BufWriter<File>>) -> Result<T, E>,
) -> Result<T, E> {
    write_trace_file_with_encoding(path, Encoding::Json, f)
}

/// [`write_trace_file`], with the channels in the message `encoding`
/// (JSON or CBOR).
pub fn write_trace_file_with_encoding<T, E: From<TraceError>>(
    path: impl AsRef<Path>,
    encoding: Encoding,
    f: impl FnOnce(&mut TraceWriter<BufWriter<File>>) -> Result<T, E>,
) -> Result<T, E> {
    let mut trace = PendingTrace::create_with_encoding(path, encoding)?;
    let value = f(trace.writer())?;
    trace.commit()?;
    Ok(value)
}
