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

mod copy;
mod expectations;

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use mcap::McapError;
use mcap::read::ChunkFlattener;
use mcap::records::Record;
use thiserror::Error;

use crate::atomic::{FinishStep, PendingFile};
use crate::engine::{EngineCommand, EngineError, EngineOptions};
use crate::error_text::full_text;
use crate::replay::{FrameRange, ReplayError, ReplayOptions, Selection};
use crate::trace::source::EXPECTED_SOURCE_METADATA;
use crate::trace::{ExpectedSource, TraceError};
use copy::{Copier, read_error, scan, write_error};
use expectations::{Replayed, outcomes_of};

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
    /// `/expected` makes ([`crate::trace::validate::validate_outcome`],
    /// [`crate::trace::validate::validate_triangle`]).
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
