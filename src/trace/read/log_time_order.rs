//! Reading a trace whose chunks overlap in log time through the summary's
//! chunk indexes, in log-time order (the `mcap` crate's sans-io
//! [`IndexedReader`], which keeps only the chunks whose time ranges
//! overlap decompressed at once).
//!
//! The file is read twice: once in file order with the messages left out
//! (the header, schemas, channels, metadata, statistics and every chunk's
//! CRC, exactly as for any other file), then the messages through the
//! indexes. Ordinary files, whose chunks follow each other in time, are
//! streamed once as before.

use std::io::{ErrorKind, Read, Seek, SeekFrom};

use mcap::records::{ChunkIndex, Record, op};
use mcap::sans_io::indexed_reader::{
    IndexedReadEvent, IndexedReader, IndexedReaderOptions, ReadOrder,
};
use mcap::{MAGIC, Summary};

use crate::trace::lengths;

use super::{ReadLimits, TraceError, TraceEvent, TraceReader, clamp};

/// The state of a read in log-time order.
pub(super) struct LogTimeOrder<R> {
    reader: IndexedReader,
    /// Seeks the input (the reader type is only known to be `Seek` where
    /// this is made).
    seek: fn(&mut R, u64) -> std::io::Result<u64>,
    /// The compressed data of the chunk being loaded.
    buffer: Vec<u8>,
    /// Whether the pass in file order is done.
    first_pass_done: bool,
}

impl<R: Read + Seek> TraceReader<R> {
    /// A reader with the default [`ReadLimits`] over a seekable input (a
    /// file): like [`TraceReader::new`], but when the file's summary shows
    /// chunks that overlap in log time, the messages are read in log-time
    /// order through the chunk indexes ([`ReadStats::read_through_chunk_indexes`](super::ReadStats::read_through_chunk_indexes))
    /// instead of failing with [`TraceError::OutOfOrder`]. The input must
    /// be at the start of the file.
    pub fn new_indexed(reader: R, source_name: &str) -> Self {
        Self::with_limits_indexed(reader, source_name, ReadLimits::default())
    }

    /// [`TraceReader::new_indexed`] with the given limits.
    pub fn with_limits_indexed(mut reader: R, source_name: &str, limits: ReadLimits) -> Self {
        // Offsets in the file count from its start: a reader elsewhere is
        // read as it is, in file order.
        if !matches!(reader.stream_position(), Ok(0)) {
            return Self::with_limits(reader, source_name, limits);
        }
        let indexed = overlapping_chunks(&mut reader, limits).and_then(|summary| {
            let options = IndexedReaderOptions::new()
                .with_order(ReadOrder::LogTime)
                .with_record_length_limit(clamp(limits.record_bytes));
            IndexedReader::new_with_options(&summary, options).ok()
        });
        // Back to the start for the pass in file order; where that fails
        // the file is read in file order and the failure shows there.
        let rewound = reader.seek(SeekFrom::Start(0)).is_ok();
        let mut this = Self::with_limits(reader, source_name, limits);
        if let (Some(indexed), true) = (indexed, rewound) {
            this.log_time_order = Some(LogTimeOrder {
                reader: indexed,
                seek: |input, offset| input.seek(SeekFrom::Start(offset)),
                buffer: Vec::new(),
                first_pass_done: false,
            });
            this.state.skip_messages = true;
            this.state.stats.read_through_chunk_indexes = true;
        }
        this
    }
}

/// The footer record with its opcode and length, and the closing magic.
const FOOTER_BYTES: u64 = 1 + 8 + 20 + 8;

/// The summary of the file (its chunk indexes), when it has one and two
/// chunks overlap in log time (a chunk starts before an earlier chunk of
/// the file ends). Any problem reading it gives `None`: the file is then
/// read in file order, which reports problems with their place.
fn overlapping_chunks<R: Read + Seek>(input: &mut R, limits: ReadLimits) -> Option<Summary> {
    let chunk_indexes = chunk_indexes(input, limits)?;
    let mut in_file_order: Vec<&ChunkIndex> = chunk_indexes.iter().collect();
    in_file_order.sort_by_key(|chunk| chunk.chunk_start_offset);
    let mut latest_end: Option<u64> = None;
    let mut overlap = false;
    for chunk in in_file_order {
        if latest_end.is_some_and(|end| chunk.message_start_time < end) {
            overlap = true;
        }
        latest_end = latest_end.max(Some(chunk.message_end_time));
    }
    overlap.then(|| Summary {
        chunk_indexes,
        ..Summary::default()
    })
}

/// The chunk indexes of the file's summary section, read through the
/// footer. Read here rather than with the `mcap` crate's summary reader so
/// that every record's declared lengths are checked before it is parsed
/// ([`crate::trace::lengths`]; the crate's reader would reserve a 4 GiB
/// string a corrupt summary declares, as fuzzing found).
fn chunk_indexes<R: Read + Seek>(input: &mut R, limits: ReadLimits) -> Option<Vec<ChunkIndex>> {
    let size = input.seek(SeekFrom::End(0)).ok()?;
    let footer_start = size.checked_sub(FOOTER_BYTES)?;
    let mut footer = [0u8; FOOTER_BYTES as usize];
    input.seek(SeekFrom::Start(footer_start)).ok()?;
    input.read_exact(&mut footer).ok()?;
    if footer[0] != op::FOOTER || footer[29..] != MAGIC[..] {
        return None;
    }
    let field = |at: usize| u64::from_le_bytes(footer[at..at + 8].try_into().unwrap_or_default());
    let (summary_start, summary_offset_start) = (field(9), field(17));
    let summary_end = if summary_offset_start == 0 {
        footer_start
    } else {
        summary_offset_start
    };
    if summary_start == 0 || summary_start >= summary_end || summary_end > footer_start {
        return None;
    }
    let length = summary_end - summary_start;
    if length > limits.record_bytes {
        return None;
    }
    let mut summary = vec![0u8; length as usize];
    input.seek(SeekFrom::Start(summary_start)).ok()?;
    input.read_exact(&mut summary).ok()?;
    let mut indexes = Vec::new();
    let mut rest = summary.as_slice();
    while let Some((&opcode, after)) = rest.split_first() {
        let (length, after) = after.split_first_chunk::<8>()?;
        let length = usize::try_from(u64::from_le_bytes(*length)).ok()?;
        let data = after.get(..length)?;
        rest = &after[length..];
        if opcode == op::CHUNK_INDEX {
            lengths::check(opcode, data).ok()?;
            match mcap::parse_record(opcode, data).ok()? {
                Record::ChunkIndex(index) => indexes.push(index),
                _ => return None,
            }
        }
    }
    (!indexes.is_empty()).then_some(indexes)
}

impl<R: Read> TraceReader<R> {
    /// The next event of a read in log-time order.
    pub(super) fn step_in_log_time_order(&mut self) -> Result<Option<TraceEvent>, TraceError> {
        let first_pass_done = self
            .log_time_order
            .as_ref()
            .is_none_or(|order| order.first_pass_done);
        if !first_pass_done {
            while self.step_in_file_order()?.is_some() {}
            self.chunk = None;
            self.state.skip_messages = false;
            if let Some(order) = self.log_time_order.as_mut() {
                order.first_pass_done = true;
            }
        }
        let TraceReader {
            input,
            state,
            log_time_order,
            ..
        } = self;
        let Some(order) = log_time_order.as_mut() else {
            return Ok(None);
        };
        const CONTEXT: &str = "a chunk read through the chunk indexes";
        loop {
            match order.reader.next_event() {
                None => return Ok(None),
                Some(Err(err)) => return Err(state.mcap_error(err, CONTEXT, true)),
                Some(Ok(IndexedReadEvent::ReadChunkRequest { offset, length })) => {
                    if length as u64 > state.limits.record_bytes {
                        return Err(TraceError::TooLarge {
                            file: state.source_name.clone(),
                            what: format!("the chunk at byte {offset}"),
                            declared: length as u64,
                            limit: state.limits.record_bytes,
                        });
                    }
                    order.buffer.resize(length, 0);
                    let read = (order.seek)(input, offset)
                        .and_then(|_| input.read_exact(&mut order.buffer));
                    if let Err(cause) = read {
                        let file = state.source_name.clone();
                        let messages = state.stats.messages;
                        return Err(if cause.kind() == ErrorKind::UnexpectedEof {
                            TraceError::Truncated { file, messages }
                        } else {
                            TraceError::Io {
                                file,
                                messages,
                                cause,
                            }
                        });
                    }
                    order
                        .reader
                        .insert_chunk_record_data(offset, &order.buffer)
                        .map_err(|err| state.mcap_error(err, CONTEXT, true))?;
                }
                Some(Ok(IndexedReadEvent::Message { header, data })) => {
                    if let Some(event) = state.message(header.channel_id, header.log_time, data)? {
                        return Ok(Some(event));
                    }
                }
            }
        }
    }
}
