//! The Foxglove MCAP writer: channels with self-contained JSON Schemas,
//! JSON messages in the order they are given (a replay gives them in
//! `log_time` order), chunked and compressed as it goes, so memory stays
//! bounded by one chunk and the index, whatever the trace's length.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use mcap::records::{MessageHeader, Metadata};
use mcap::{Compression, WriteOptions, Writer};
use serde::Serialize;
use thiserror::Error;

use super::contacts::{contact_query_log, contact_query_update};
use super::convert::{
    ball_update, clear_update, contact_update, decision_log, expected_update, ghost_update,
    mesh_update, sweep_numbers, sweep_update,
};
use super::messages::Time;
use super::schemas::{
    LOG_SCHEMA, LOG_SCHEMA_JSON, MESSAGE_ENCODING, SCENE_UPDATE_SCHEMA, SCENE_UPDATE_SCHEMA_JSON,
    SCHEMA_ENCODING, SWEEP_NUMBERS_SCHEMA, SWEEP_NUMBERS_SCHEMA_JSON,
};
use super::{
    BALLS_TOPIC, CONTACT_DECISIONS_TOPIC, CONTACT_QUERIES_TOPIC, CONTACTS_TOPIC, DECISIONS_TOPIC,
    EXPECTED_TOPIC, GHOSTS_TOPIC, MESH_TOPIC, METADATA_NAME, NUMBERS_TOPIC, SWEEPS_TOPIC,
};
use crate::atomic::PendingFile;
use crate::judge::contact_marks::{
    ContactDrawing, ContactEvent, ContactsDrawn, for_each_judged_query,
};
use crate::judge::{Tolerances, divergence};
use crate::replay::{ReplayEvent, SceneState, SweepResult};
use crate::trace::{TraceError, TraceEvent, library_string};

/// Writing the Foxglove file failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FoxgloveError {
    /// The MCAP writer failed (an I/O error underneath, usually).
    #[error("{file}: writing the Foxglove file: {}", crate::error_text::full_text(.cause))]
    Write {
        /// The output file.
        file: String,
        /// The writer's error.
        cause: mcap::McapError,
    },
    /// Creating, flushing, syncing or renaming the file failed.
    #[error("{file}: {doing}: {}", crate::error_text::full_text(.cause))]
    Io {
        /// The output file.
        file: String,
        /// What was being done.
        doing: &'static str,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// A message could not be serialized.
    #[error("{file}: serializing the {topic} message of frame {frame}: {}", crate::error_text::full_text(.cause))]
    Json {
        /// The output file.
        file: String,
        /// Its channel.
        topic: &'static str,
        /// The sweep's frame (0 for a scene).
        frame: u64,
        /// The serializer's error.
        cause: serde_json::Error,
    },
}

/// What goes into the file besides the replay.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FoxgloveOptions {
    /// The trace's file name: the `file` of every Log message and the
    /// `trace` entry of the metadata record.
    pub trace_name: String,
    /// When a sweep diverges from its expectation (`check`'s comparison).
    pub tolerances: Tolerances,
}

/// Messages written per channel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FoxgloveCounts {
    /// Scenes (one mesh message each).
    pub scenes: u64,
    /// Sweeps (one message on each per-sweep channel).
    pub sweeps: u64,
    /// Contact queries (one message on the queries' channel and a Log
    /// line each).
    pub contact_queries: u64,
    /// Messages in all.
    pub messages: u64,
}

#[derive(Clone, Copy, Debug)]
struct Channels {
    mesh: u16,
    balls: u16,
    sweeps: u16,
    contacts: u16,
    expected: u16,
    ghosts: u16,
    decisions: u16,
    numbers: u16,
}

/// The MCAP write options: chunked, zstd on the calling thread
/// (deterministic), summary and indexes (Foxglove seeks with them).
pub fn write_options() -> WriteOptions {
    WriteOptions::new()
        .compression(Some(Compression::Zstd))
        .compression_threads(0)
        .use_chunks(true)
        .library(library_string())
}

/// Writes a replay as Foxglove messages to any `Write + Seek` (see the
/// [module documentation](super) for the channels).
pub struct FoxgloveWriter<W: Write + Seek> {
    writer: Writer<W>,
    file: String,
    options: FoxgloveOptions,
    channels: Channels,
    /// The `foxglove.SceneUpdate` and `foxglove.Log` schemas, for the
    /// contact queries' channels.
    scene_update: u16,
    log: u16,
    /// The contact queries' channels (the queries, their Log lines), added
    /// at the first query: a trace without any has neither.
    contact_queries: Option<(u16, u16)>,
    counts: FoxgloveCounts,
    data: Vec<u8>,
}

impl<W: Write + Seek> FoxgloveWriter<W> {
    /// A writer on `w`; `file` names the output in errors. Writes the
    /// header, the metadata record, the schemas and the channels.
    pub fn new(w: W, file: &str, options: FoxgloveOptions) -> Result<Self, FoxgloveError> {
        let error = |cause| FoxgloveError::Write {
            file: file.to_string(),
            cause,
        };
        let mut writer = write_options().create(w).map_err(error)?;
        writer
            .write_metadata(&Metadata {
                name: METADATA_NAME.to_string(),
                metadata: BTreeMap::from([
                    ("trace".to_string(), options.trace_name.clone()),
                    ("writer".to_string(), library_string()),
                ]),
            })
            .map_err(error)?;
        let scene_update = writer
            .add_schema(
                SCENE_UPDATE_SCHEMA,
                SCHEMA_ENCODING,
                SCENE_UPDATE_SCHEMA_JSON.as_bytes(),
            )
            .map_err(error)?;
        let log = writer
            .add_schema(LOG_SCHEMA, SCHEMA_ENCODING, LOG_SCHEMA_JSON.as_bytes())
            .map_err(error)?;
        let numbers = writer
            .add_schema(
                SWEEP_NUMBERS_SCHEMA,
                SCHEMA_ENCODING,
                SWEEP_NUMBERS_SCHEMA_JSON.as_bytes(),
            )
            .map_err(error)?;
        let mut channel = |schema: u16, topic: &str| {
            writer
                .add_channel(schema, topic, MESSAGE_ENCODING, &BTreeMap::new())
                .map_err(error)
        };
        let channels = Channels {
            mesh: channel(scene_update, MESH_TOPIC)?,
            balls: channel(scene_update, BALLS_TOPIC)?,
            sweeps: channel(scene_update, SWEEPS_TOPIC)?,
            contacts: channel(scene_update, CONTACTS_TOPIC)?,
            expected: channel(scene_update, EXPECTED_TOPIC)?,
            ghosts: channel(scene_update, GHOSTS_TOPIC)?,
            decisions: channel(log, DECISIONS_TOPIC)?,
            numbers: channel(numbers, NUMBERS_TOPIC)?,
        };
        Ok(FoxgloveWriter {
            writer,
            file: file.to_string(),
            options,
            channels,
            scene_update,
            log,
            contact_queries: None,
            counts: FoxgloveCounts::default(),
            data: Vec::new(),
        })
    }

    /// Messages written so far.
    pub fn counts(&self) -> FoxgloveCounts {
        self.counts
    }

    fn put<T: Serialize>(
        &mut self,
        channel_id: u16,
        topic: &'static str,
        frame: u64,
        log_time_nanos: u64,
        message: &T,
    ) -> Result<(), FoxgloveError> {
        self.data.clear();
        serde_json::to_writer(&mut self.data, message).map_err(|cause| FoxgloveError::Json {
            file: self.file.clone(),
            topic,
            frame,
            cause,
        })?;
        let header = MessageHeader {
            channel_id,
            sequence: self.counts.messages as u32,
            log_time: log_time_nanos,
            publish_time: log_time_nanos,
        };
        self.writer
            .write_to_known_channel(&header, &self.data)
            .map_err(|cause| FoxgloveError::Write {
                file: self.file.clone(),
                cause,
            })?;
        self.counts.messages += 1;
        Ok(())
    }

    /// One replay event: a scene or a sweep.
    pub fn event(&mut self, event: &ReplayEvent) -> Result<(), FoxgloveError> {
        match event {
            ReplayEvent::Scene(scene) => self.scene(scene),
            ReplayEvent::Sweep(result) => self.sweep(result),
        }
    }

    /// A scene: its mesh; after the first scene, also clears the per-sweep
    /// channels (the balls of the previous scene).
    pub fn scene(&mut self, scene: &SceneState) -> Result<(), FoxgloveError> {
        let t = scene.log_time_nanos;
        if self.counts.scenes > 0 {
            let clear = clear_update(Time::from_nanos(t));
            let c = self.channels;
            for (id, topic) in [
                (c.balls, BALLS_TOPIC),
                (c.sweeps, SWEEPS_TOPIC),
                (c.contacts, CONTACTS_TOPIC),
                (c.expected, EXPECTED_TOPIC),
                (c.ghosts, GHOSTS_TOPIC),
            ] {
                self.put(id, topic, 0, t, &clear)?;
            }
        }
        self.put(self.channels.mesh, MESH_TOPIC, 0, t, &mesh_update(scene))?;
        self.counts.scenes += 1;
        Ok(())
    }

    /// A sweep: the ball, the sweep, the contact and normal, the expected
    /// outcome where it diverges, its ghost contact where it is one, the
    /// decision and the numbers. The
    /// decisive test comes from the result's records (replay with
    /// `explain` on, or the decision line and numbers lack it).
    pub fn sweep(&mut self, r: &SweepResult) -> Result<(), FoxgloveError> {
        let t = r.log_time_nanos;
        let f = r.frame;
        let decisive = r.decisive_record();
        let diffs = divergence(r, &self.options.tolerances);
        let c = self.channels;
        self.put(c.balls, BALLS_TOPIC, f, t, &ball_update(r))?;
        self.put(c.sweeps, SWEEPS_TOPIC, f, t, &sweep_update(r))?;
        self.put(c.contacts, CONTACTS_TOPIC, f, t, &contact_update(r))?;
        self.put(
            c.expected,
            EXPECTED_TOPIC,
            f,
            t,
            &expected_update(r, !diffs.is_empty()),
        )?;
        self.put(c.ghosts, GHOSTS_TOPIC, f, t, &ghost_update(r))?;
        let log = decision_log(r, decisive, &diffs, &self.options.trace_name);
        self.put(c.decisions, DECISIONS_TOPIC, f, t, &log)?;
        let numbers = sweep_numbers(r, decisive, &diffs);
        self.put(c.numbers, NUMBERS_TOPIC, f, t, &numbers)?;
        self.counts.sweeps += 1;
        Ok(())
    }

    /// The trace's contact queries (`events`: the trace read again, sweeps
    /// and expectations pass by), each judged as `check` judges it under
    /// `how`, at its `log_time`: one message on
    /// [`CONTACT_QUERIES_TOPIC`] and a Log line on
    /// [`CONTACT_DECISIONS_TOPIC`] each: channels of their own, so that
    /// each channel stays in `log_time` order when this is called after
    /// the replay's events (MCAP readers merge the channels by time).
    /// (`crate::viz::draw_contacts` judges them once for both files when a
    /// recording is drawn too.)
    pub fn contact_queries(
        &mut self,
        events: impl Iterator<Item = Result<TraceEvent, TraceError>>,
        how: &ContactDrawing<'_>,
    ) -> Result<ContactsDrawn, FoxgloveError> {
        for_each_judged_query(events, how, |event| self.contact_event(event))
    }

    /// Writes one judged query, or clears the previous scene's at a new one.
    pub(crate) fn contact_event(&mut self, event: ContactEvent<'_>) -> Result<(), FoxgloveError> {
        let p = match event {
            ContactEvent::Query(p) => p,
            // The previous scene's queries go, as the per-sweep
            // channels' entities do (`scene`).
            ContactEvent::NewScene { log_time_nanos: t } => {
                if let Some((queries, _)) = self.contact_queries {
                    let clear = clear_update(Time::from_nanos(t));
                    self.put(queries, CONTACT_QUERIES_TOPIC, 0, t, &clear)?;
                }
                return Ok(());
            }
        };
        let (queries, decisions) = match self.contact_queries {
            Some(channels) => channels,
            None => {
                let error = |cause| FoxgloveError::Write {
                    file: self.file.clone(),
                    cause,
                };
                let mut channel = |schema: u16, topic: &str| {
                    self.writer
                        .add_channel(schema, topic, MESSAGE_ENCODING, &BTreeMap::new())
                        .map_err(error)
                };
                let channels = (
                    channel(self.scene_update, CONTACT_QUERIES_TOPIC)?,
                    channel(self.log, CONTACT_DECISIONS_TOPIC)?,
                );
                self.contact_queries = Some(channels);
                channels
            }
        };
        let (f, t) = (p.query.frame, p.log_time_nanos);
        self.put(
            queries,
            CONTACT_QUERIES_TOPIC,
            f,
            t,
            &contact_query_update(p),
        )?;
        let log = contact_query_log(p, &self.options.trace_name);
        self.put(decisions, CONTACT_DECISIONS_TOPIC, f, t, &log)?;
        self.counts.contact_queries += 1;
        Ok(())
    }

    /// Writes the last chunk, the summary and the footer; returns the
    /// underlying writer.
    pub fn finish(mut self) -> Result<W, FoxgloveError> {
        self.writer.finish().map_err(|cause| FoxgloveError::Write {
            file: self.file.clone(),
            cause,
        })?;
        Ok(self.writer.into_inner())
    }
}

/// A Foxglove file being written under a temporary name next to its target
/// ([`PendingFile`]): [`FoxgloveFile::commit`] finishes it and renames it
/// into place; dropped without that (an error on the way), it is removed and
/// the target is untouched.
pub struct FoxgloveFile {
    writer: FoxgloveWriter<BufWriter<File>>,
    pending: PendingFile,
}

impl FoxgloveFile {
    /// Creates the temporary file next to `target` (a target that exists
    /// and is not a regular file is refused: MCAP is written with seeks).
    pub fn create(target: &Path, options: FoxgloveOptions) -> Result<FoxgloveFile, FoxgloveError> {
        let name = target.display().to_string();
        let (pending, file) =
            PendingFile::create_seekable(target).map_err(|cause| FoxgloveError::Io {
                file: name.clone(),
                doing: "creating a temporary file next to it",
                cause,
            })?;
        let writer = FoxgloveWriter::new(BufWriter::new(file), &name, options)?;
        Ok(FoxgloveFile { writer, pending })
    }

    /// The writer.
    pub fn writer(&mut self) -> &mut FoxgloveWriter<BufWriter<File>> {
        &mut self.writer
    }

    /// Finishes the file, makes it durable and renames it to its target.
    pub fn commit(self) -> Result<FoxgloveCounts, FoxgloveError> {
        let name = self.pending.target().display().to_string();
        let io = |doing| {
            let name = name.clone();
            move |cause| FoxgloveError::Io {
                file: name,
                doing,
                cause,
            }
        };
        let counts = self.writer.counts();
        let buffered = self.writer.finish()?;
        self.pending
            .finish(buffered)
            .map_err(|e| io(e.step.doing())(e.cause))?;
        Ok(counts)
    }
}
