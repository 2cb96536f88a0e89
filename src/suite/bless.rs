//! Blessing a trace: replacing its `/expected` channel with the current
//! core's outcomes (or a running engine's answers: an engine snapshot),
//! keeping everything else. A selection ([`BlessSelection`]) blesses some
//! sweeps only; the others keep the expectation they had (or none).
//!
//! Three passes over the input bytes:
//! 1. the trace is replayed (the same [`crate::replay`] engine as `check`;
//!    with an engine, its answers alongside) and every sweep's new
//!    expectation is kept, by `(frame, ball)`;
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

// An engine's error carries its command, the line and its last stderr
// lines; it happens once per run, so its size does not matter.
#![allow(clippy::result_large_err)]

use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet, VecDeque};
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use mcap::read::ChunkFlattener;
use mcap::records::{MessageHeader, Record};
use mcap::{Attachment, McapError};
use thiserror::Error;

use crate::atomic::{FinishStep, PendingFile};
use crate::engine::{
    AnswerSink, EngineAnswers, EngineCommand, EngineError, EngineOptions, EngineSession,
};
use crate::error_text::full_text;
use crate::replay::{
    FrameRange, ReplayError, ReplayEvent, ReplayOptions, Selection, SweepExtent, SweepResult,
    replay_events,
};
use crate::trace::{
    EXPECTED_SOURCE_METADATA, EXPECTED_TOPIC, Encoding, ExpectedSource, MAX_NAME_BYTES,
    MAX_SETTING_VALUE_BYTES, OUTCOME_SCHEMA, OUTCOME_SCHEMA_JSON, OutcomeMsg, SCHEMA_ENCODING,
    SWEEP_TOPIC, TraceError, TraceReader, default_write_options, frame_of_message,
    sweeptrace_source, validate_outcome, validate_triangle,
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
    /// The engine could not be started, or failed while answering.
    #[error("{cause}")]
    Engine {
        /// What went wrong, naming the command.
        cause: EngineError,
    },
    /// The engine's answer to a sweep is one the trace cannot hold (a
    /// triangle the scene does not have): the checks every writer of
    /// `/expected` makes ([`crate::trace::validate_outcome`],
    /// [`crate::trace::validate_triangle`]).
    #[error(
        "the engine `{command}` answered frame {frame}, ball {ball} with an outcome the trace cannot hold: field `{field}`: {problem}"
    )]
    Answer {
        /// The engine's command.
        command: String,
        /// The sweep's frame.
        frame: u64,
        /// The sweep's ball.
        ball: u32,
        /// The field at fault.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A selection (`--frames`, `--ball`, `--accept`) that selects no
    /// sweep of the trace: nothing is written.
    #[error("{file}: {selection}; nothing written")]
    NothingSelected {
        /// The input's name.
        file: String,
        /// The selection and what the trace holds.
        selection: Selection,
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
    /// Expectations written: the new ones and the kept ones.
    pub expected_written: u64,
    /// New expectations written (every sweep, unless a selection).
    pub blessed: u64,
    /// Sweeps left out of the selection that kept the expectation they
    /// had (re-encoded in the project's schema).
    pub kept: u64,
    /// Sweeps in the trace.
    pub sweeps: u64,
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

/// Which sweeps a bless gives a new expectation. The others keep the
/// trace's own expectation, or none if they had none.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum BlessSelection {
    /// Every sweep (the whole `/expected` channel is replaced).
    #[default]
    All,
    /// The sweeps of these frames, of one ball or of all.
    Range {
        /// The frames.
        frames: FrameRange,
        /// Only this ball.
        ball: Option<u32>,
    },
    /// These `(frame, ball)` sweeps (`--accept`, the review's choices).
    Sweeps(BTreeSet<(u64, u32)>),
}

impl BlessSelection {
    /// The selection in words (`frames 100..200, ball 1`, `sweeps 12:0,
    /// 40:3`); `None` for every sweep.
    pub fn text(&self) -> Option<String> {
        match self {
            BlessSelection::All => None,
            BlessSelection::Range { frames, ball } => ReplayOptions {
                frames: *frames,
                ball: *ball,
                ..ReplayOptions::default()
            }
            .filter_text(),
            BlessSelection::Sweeps(set) => {
                const LISTED: usize = 8;
                let mut list: Vec<String> = set
                    .iter()
                    .take(LISTED)
                    .map(|(frame, ball)| format!("{frame}:{ball}"))
                    .collect();
                if set.len() > LISTED {
                    list.push(format!("and {} more", set.len() - LISTED));
                }
                Some(format!("sweeps {}", list.join(", ")))
            }
        }
    }

    /// Whether the sweep `(frame, ball)` gets a new expectation.
    pub fn selects(&self, frame: u64, ball: u32) -> bool {
        match self {
            BlessSelection::All => true,
            BlessSelection::Range { frames, ball: b } => {
                frames.contains(frame) && b.is_none_or(|b| b == ball)
            }
            BlessSelection::Sweeps(set) => set.contains(&(frame, ball)),
        }
    }
}

/// The engine whose answers become the expectations (an engine snapshot:
/// after an upgrade, `check --engine ... --against expected` says which
/// sweeps changed).
#[derive(Clone, Debug)]
pub struct BlessEngine {
    /// How to start it.
    pub command: EngineCommand,
    /// Its timeout and window.
    pub options: EngineOptions,
    /// Its name in the expectations' source (the program's, unless given).
    pub name: String,
    /// Its version in the expectations' source (empty when not known).
    pub version: String,
}

/// How to bless: which sweeps, from the core or an engine.
#[derive(Clone, Debug, Default)]
pub struct BlessOptions {
    /// The replay: the scenes' margin and facing overrides and the
    /// engine conventions the core's answers are computed under. Its frame
    /// and ball filters are ignored (`select` chooses).
    pub replay: ReplayOptions,
    /// Which sweeps get a new expectation.
    pub select: BlessSelection,
    /// The new expectations are this engine's answers instead of the
    /// core's.
    pub engine: Option<BlessEngine>,
    /// The engine conventions the core's answers were computed under, in
    /// words, when some are declared: written in the source's settings.
    pub conventions: Option<String>,
}

/// What the replay pass found: the expectation to write after every sweep
/// of a trace (`None`: none), by `(frame, ball)` in trace order, and the
/// source of the new expectations.
struct Replayed {
    outcomes: HashMap<(u64, u32), VecDeque<Option<OutcomeMsg>>>,
    source: ExpectedSource,
    replaced: Option<ExpectedSource>,
    blessed: u64,
    kept: u64,
    sweeps: u64,
}

/// Pass 1's bookkeeping: each replayed sweep's expectation to write.
#[derive(Default)]
struct Collected {
    outcomes: HashMap<(u64, u32), VecDeque<Option<OutcomeMsg>>>,
    /// The margins and facing rules the scenes were replayed with, in order.
    margins: Vec<String>,
    facings: Vec<String>,
    blessed: u64,
    kept: u64,
    sweeps: u64,
    /// The trace's frames and balls, for a selection that selects none.
    seen: SweepExtent,
}

impl Collected {
    /// Takes one replayed event; `answer` gives the engine's answer to a
    /// sweep, checked (with an engine: every sweep's, selected or not),
    /// else the core's outcome is the new expectation.
    fn event(
        &mut self,
        event: Result<ReplayEvent, ReplayError>,
        name: &str,
        select: &BlessSelection,
        answer: impl FnOnce(&SweepResult) -> Result<Option<OutcomeMsg>, BlessError>,
    ) -> Result<(), BlessError> {
        match event {
            Ok(ReplayEvent::Sweep(r)) => {
                self.sweeps += 1;
                self.seen.add(r.frame, r.ball);
                let answer = answer(&r)?;
                let written = if select.selects(r.frame, r.ball) {
                    self.blessed += 1;
                    Some(answer.unwrap_or_else(|| r.outcome_msg()))
                } else {
                    self.kept += u64::from(r.expected.is_some());
                    r.expected
                };
                self.outcomes
                    .entry((r.frame, r.ball))
                    .or_default()
                    .push_back(written);
            }
            Ok(ReplayEvent::Scene(scene)) => {
                for (list, value) in [
                    (&mut self.margins, scene.options.margin.to_string()),
                    (&mut self.facings, scene.options.facing.to_string()),
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
        Ok(())
    }
}

/// The engine's answer to the sweep `r`, if it gave one, when the trace
/// can hold it: checked as every writer of `/expected` checks an outcome
/// (its values, and a triangle of the sweep's scene), so that a snapshot
/// is never written that its own reader or writer would refuse.
fn checked_answer(
    answer: Option<OutcomeMsg>,
    r: &SweepResult,
    engine: &BlessEngine,
) -> Result<Option<OutcomeMsg>, BlessError> {
    let Some(answer) = answer else {
        return Ok(None);
    };
    validate_outcome(&answer)
        .and_then(|()| validate_triangle(&answer, r.scene.mesh.triangles().len()))
        .map_err(|problem| BlessError::Answer {
            command: engine.command.text.clone(),
            frame: r.frame,
            ball: r.ball,
            field: problem.field,
            problem: problem.problem,
        })?;
    Ok(Some(answer))
}

/// `text` cut to at most `max` bytes, at a character boundary, with `...`
/// when cut.
fn clipped(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_string();
    }
    let mut end = max.saturating_sub(3);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}...", &text[..end])
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

fn outcomes_of(input: &[u8], name: &str, options: &BlessOptions) -> Result<Replayed, BlessError> {
    let replay = ReplayOptions {
        explain: None,
        frames: Default::default(),
        ball: None,
        ..options.replay
    };
    let mut collected = Collected::default();
    let mut reader = TraceReader::new_indexed(std::io::Cursor::new(input), name);
    match &options.engine {
        None => {
            for event in replay_events(reader.by_ref(), replay) {
                collected.event(event, name, &options.select, |_| Ok(None))?;
            }
        }
        Some(engine) => {
            let session = EngineSession::start(&engine.command, engine.options)
                .map_err(|cause| BlessError::Engine { cause })?;
            let sink = AnswerSink::default();
            let mut answers = EngineAnswers::keeping_expectations(
                reader.by_ref(),
                session,
                engine.options.window,
                sink.clone(),
            );
            for event in replay_events(answers.by_ref(), replay) {
                collected.event(event, name, &options.select, |r| {
                    checked_answer(sink.borrow_mut().remove(&(r.frame, r.ball)), r, engine)
                })?;
            }
            if let Some(cause) = answers.finish().error {
                return Err(BlessError::Engine { cause });
            }
        }
    }
    // A selection that selects no sweep would rewrite the trace for
    // nothing: an error naming what the trace holds, as a filter of
    // `check` or `replay` that keeps nothing.
    if collected.blessed == 0
        && let Some(filter) = options.select.text()
    {
        return Err(BlessError::NothingSelected {
            file: name.to_string(),
            selection: Selection::Nothing {
                filter,
                seen: collected.seen,
            },
        });
    }
    let replaced = reader.expected_source().cloned();
    let mut source = match &options.engine {
        None => {
            let source =
                sweeptrace_source(&listed(&collected.margins), &listed(&collected.facings));
            match &options.conventions {
                Some(text) => source.setting("conventions", clipped(text, MAX_SETTING_VALUE_BYTES)),
                None => source,
            }
        }
        Some(engine) => ExpectedSource::new(
            clipped(&engine.name, MAX_NAME_BYTES),
            clipped(&engine.version, MAX_NAME_BYTES),
        )
        .setting(
            "command",
            clipped(&engine.command.text, MAX_SETTING_VALUE_BYTES),
        )
        .setting(
            "blessed_by",
            format!("sweeptrace {}", env!("CARGO_PKG_VERSION")),
        ),
    };
    if options.select != BlessSelection::All {
        let earlier = match &replaced {
            Some(old) if collected.kept > 0 => {
                format!(" from {}", clipped(&old.engine, MAX_NAME_BYTES))
            }
            _ => String::new(),
        };
        source = source.setting(
            "blessed",
            format!(
                "{} of {} sweeps; the other {} keep their expectations{earlier}",
                collected.blessed, collected.sweeps, collected.kept
            ),
        );
    }
    Ok(Replayed {
        outcomes: collected.outcomes,
        source,
        replaced,
        blessed: collected.blessed,
        kept: collected.kept,
        sweeps: collected.sweeps,
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
    let options = BlessOptions {
        replay: options,
        ..BlessOptions::default()
    };
    bless_into(input, name, output, name, &options)
}

/// [`bless_bytes`], with write errors naming `output_name`.
fn bless_into<W: Write + Seek>(
    input: &[u8],
    name: &str,
    output: W,
    output_name: &str,
    options: &BlessOptions,
) -> Result<(BlessSummary, W), BlessError> {
    let Replayed {
        outcomes,
        source,
        replaced,
        blessed,
        kept,
        sweeps,
    } = outcomes_of(input, name, options)?;
    let (write_options, expected_only) = scan(input, name)?;
    let mut writer = write_options
        .create(output)
        .map_err(write_error(output_name))?;
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
        .map_err(write_error(output_name))?;
    let mut copier = Copier {
        name,
        output_name,
        writer,
        outcomes,
        expected_only,
        schema_ids: HashMap::new(),
        channel_ids: HashMap::new(),
        channel_topics: HashMap::new(),
        channel_encodings: HashMap::new(),
        expected_channels: BTreeMap::new(),
        index: 0,
        sequence: 0,
        summary: BlessSummary {
            expected_source: source,
            replaced_expected_source: replaced,
            blessed,
            kept,
            sweeps,
            ..BlessSummary::default()
        },
    };
    for record in ChunkFlattener::new(input).map_err(read_error(name))? {
        match record.map_err(read_error(name))? {
            // The summary section is rebuilt by the writer.
            Record::DataEnd(_) => break,
            record => copier.record(record)?,
        }
    }
    copier.writer.finish().map_err(write_error(output_name))?;
    Ok((copier.summary, copier.writer.into_inner()))
}

/// An error reading the input `name`'s container.
fn read_error(name: &str) -> impl Fn(McapError) -> BlessError + '_ {
    move |cause| BlessError::Mcap {
        file: name.to_string(),
        what: "reading the container".to_string(),
        cause,
    }
}

/// An error writing the blessed trace `output_name`.
fn write_error(output_name: &str) -> impl Fn(McapError) -> BlessError + '_ {
    move |cause| BlessError::Mcap {
        file: output_name.to_string(),
        what: "writing the blessed trace".to_string(),
        cause,
    }
}

/// Pass 2 (cheap; pass 1 was the replay): the writer's options with the
/// input's header (profile, library), and the schemas only `/expected`
/// channels use (not copied).
fn scan(input: &[u8], name: &str) -> Result<(mcap::WriteOptions, HashSet<u16>), BlessError> {
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
struct Copier<'a, W: Write + Seek> {
    /// The input's name.
    name: &'a str,
    /// The output's name.
    output_name: &'a str,
    writer: mcap::Writer<W>,
    /// The expectation to write after each sweep by `(frame, ball)`, in
    /// trace order (`None`: none).
    outcomes: HashMap<(u64, u32), VecDeque<Option<OutcomeMsg>>>,
    /// The input's schemas that only `/expected` channels use.
    expected_only: HashSet<u16>,
    /// Input schema id to output schema id.
    schema_ids: HashMap<u16, u16>,
    /// Input channel id to output channel id (`/expected` channels have none).
    channel_ids: HashMap<u16, u16>,
    /// Every input channel's topic.
    channel_topics: HashMap<u16, String>,
    /// The message encoding of each input channel (trace channels: the
    /// replay pass checked they are `json` or `cbor`).
    channel_encodings: HashMap<u16, Encoding>,
    /// The output's `/expected` channel for each encoding.
    expected_channels: BTreeMap<Encoding, u16>,
    /// The index of the next input message.
    index: u64,
    /// The sequence number of the next output message.
    sequence: u32,
    summary: BlessSummary,
}

impl<W: Write + Seek> Copier<'_, W> {
    /// Copies one record (or drops it: `/expected`'s own, the old
    /// `sweeptrace.expected_source` record).
    fn record(&mut self, record: Record<'_>) -> Result<(), BlessError> {
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

/// Blesses the file `input` into `output` (which may be the same path, for
/// `--in-place`), through a temporary file in `output`'s directory renamed
/// when complete: every sweep, from the core.
pub fn bless_file(
    input: &Path,
    output: &Path,
    options: ReplayOptions,
) -> Result<BlessSummary, BlessError> {
    let options = BlessOptions {
        replay: options,
        ..BlessOptions::default()
    };
    bless_file_with(input, output, &options)
}

/// [`bless_file`] with a selection, an engine's answers or declared
/// conventions ([`BlessOptions`]).
pub fn bless_file_with(
    input: &Path,
    output: &Path,
    options: &BlessOptions,
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
