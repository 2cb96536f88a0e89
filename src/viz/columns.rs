//! Rows buffered per entity as typed columns and sent as one chunk per
//! entity.
//!
//! Logging a row at a time costs a channel message and a pass through the
//! SDK's batcher per row, and serializing each archetype at once costs
//! several small Arrow arrays per component per row. Here a row is a set of
//! plain values: each entity and set of components (an entity that logs a
//! `Points3D` at one frame and a `Clear` at another has two sets) keeps its
//! time columns (`frame`, `time`), its row numbers and one typed column per
//! component (a `Vec` of the component's values and the number of values of
//! each row; strings in one byte buffer). [`Columns::send`] turns each into
//! one dense [`Chunk`], with one Arrow array per component built from the
//! whole column, like the chunks the SDK's batcher builds.
//!
//! A [`Columns`] can be filled on its own (for example on a worker thread,
//! for a run of sweeps) and appended to another one in order
//! ([`Columns::append`]): its rows are numbered after those already there.
//!
//! Row and chunk ids come from counters, not from the clock and a random
//! number: the `n`-th row gets row id `n` (above a fixed base), so later rows
//! still win over earlier ones at the same time, as with row-by-row logging,
//! and the same rows give the same chunks.

mod component;
mod entity;
mod lengths;
pub(crate) mod row;

use rerun::external::arrow::array::ListArray;
use rerun::log::{Chunk, ChunkId, RowId};
use rerun::{RecordingStream, RecordingStreamError, SerializedComponentBatch};
use rustc_hash::FxHashMap;

use super::RecordError;
use super::paths::Entity;
use super::spill::Spill;
use entity::EntityColumns;
use lengths::{Lengths, list_array};
use row::Row;

/// Time part of the ids: 2020-01-01T00:00:00Z in nanoseconds. Fixed, so
/// that ids do not depend on when the recording was made.
const ID_BASE_NANOS: u64 = 1_577_836_800_000_000_000;

/// A value on the `time` timeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Time {
    /// Nanoseconds since the Unix epoch.
    Timestamp(i64),
    /// Nanoseconds since the recording's origin.
    Duration(i64),
}

impl Time {
    fn is_timestamp(self) -> bool {
        matches!(self, Time::Timestamp(_))
    }

    fn nanos(self) -> i64 {
        match self {
            Time::Timestamp(n) | Time::Duration(n) => n,
        }
    }
}

/// The buffer of one entity and set of components: the entity, a number
/// naming the set (chosen by the caller; every row of a set puts the same
/// components in the same order) and the kind of `time` (one chunk holds
/// one kind).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Key {
    entity: Entity,
    set: u8,
    timestamps: bool,
}

#[cfg(test)]
impl Key {
    /// The key of `entity`'s set `set` with durations on `time`.
    pub(crate) fn for_test(entity: Entity, set: u8) -> Key {
        Key {
            entity,
            set,
            timestamps: false,
        }
    }
}

/// Rows of one entity and set taken out of the buffer, in the order they
/// were logged: what a chunk is made of.
#[derive(Debug)]
pub(crate) struct Part {
    /// `frame` of each row.
    pub(crate) frames: Vec<i64>,
    /// `time` of each row (nanoseconds).
    pub(crate) times: Vec<i64>,
    /// Number of each row (see [`row_id`]).
    pub(crate) rows: Vec<u64>,
    /// Each component's values, one list per row, in the set's order.
    pub(crate) lists: Vec<ListArray>,
}

/// The row id of the `n`-th row (0-based).
fn row_id(n: u64) -> RowId {
    RowId::from_u128(((ID_BASE_NANOS as u128) << 64) | (n as u128 + 1))
}

/// Rows not yet sent.
#[derive(Debug, Default)]
pub struct Columns {
    entities: Vec<EntityColumns>,
    /// FxHash: the keys are a few small integers.
    index: FxHashMap<Key, usize>,
    /// Rows buffered.
    rows: usize,
    /// Rows numbered so far (buffered or sent).
    next_row: u64,
    next_chunk: u64,
}

impl Columns {
    /// Rows buffered.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Bytes the buffered rows take: their times, row numbers and values
    /// (not the buffers' spare capacity). Visits every entity's columns.
    pub fn bytes(&self) -> usize {
        self.entities
            .iter()
            .map(|e| {
                (e.frames.len() + e.times.len() + e.rows.len()) * 8
                    + e.columns.iter().map(|c| c.bytes()).sum::<usize>()
            })
            .sum()
    }

    fn chunk_id(&mut self) -> ChunkId {
        self.next_chunk += 1;
        ChunkId::from_u128(((ID_BASE_NANOS as u128) << 64) | self.next_chunk as u128)
    }

    /// Starts a row of `entity` at (`frame`, `time`) in the buffer of
    /// component set `set`; put its components with the returned [`Row`]
    /// (at least one, the same ones in the same order in every row of the
    /// set).
    pub(crate) fn row(&mut self, entity: Entity, set: u8, frame: i64, time: Time) -> Row<'_> {
        let key = Key {
            entity,
            set,
            timestamps: time.is_timestamp(),
        };
        let index = match self.index.get(&key) {
            Some(&i) => i,
            None => {
                let i = self.entities.len();
                self.index.insert(key, i);
                self.entities.push(EntityColumns::new(key));
                i
            }
        };
        let n = self.next_row;
        self.next_row += 1;
        self.rows += 1;
        let e = &mut self.entities[index];
        e.frames.push(frame);
        e.times.push(time.nanos());
        e.rows.push(n);
        Row { entity: e, next: 0 }
    }

    /// Moves the rows of `other` here, after the rows numbered so far
    /// (`other`'s entities that are new here come after those already
    /// here, in `other`'s order). `other` is left empty, with its buffers
    /// (and their capacity) kept for its next rows.
    pub fn append(&mut self, other: &mut Columns) {
        let base = self.next_row;
        for e in &mut other.entities {
            if e.rows.is_empty() {
                continue;
            }
            for r in &mut e.rows {
                *r += base;
            }
            match self.index.get(&e.key) {
                Some(&i) => self.entities[i].append(e),
                None => {
                    self.index.insert(e.key, self.entities.len());
                    let empty = EntityColumns::new(e.key);
                    self.entities.push(std::mem::replace(e, empty));
                }
            }
        }
        self.rows += other.rows;
        self.next_row += other.next_row;
        other.rows = 0;
        other.next_row = 0;
    }

    /// Sends a static row of `path` at once.
    pub fn send_static(
        &mut self,
        rec: &RecordingStream,
        path: String,
        batches: Vec<SerializedComponentBatch>,
    ) -> Result<(), RecordingStreamError> {
        self.send_row(rec, path, batches, None)
    }

    /// Sends a row of `path` at `frame` and `time` at once, in a chunk of
    /// its own (a row too large to share a chunk: a scene's mesh).
    pub fn send_at(
        &mut self,
        rec: &RecordingStream,
        path: String,
        batches: Vec<SerializedComponentBatch>,
        frame: i64,
        time: Time,
    ) -> Result<(), RecordingStreamError> {
        self.send_row(rec, path, batches, Some((frame, time)))
    }

    /// A row of `path`, static or at `(frame, time)`, sent as a chunk.
    fn send_row(
        &mut self,
        rec: &RecordingStream,
        path: String,
        batches: Vec<SerializedComponentBatch>,
        at: Option<(i64, Time)>,
    ) -> Result<(), RecordingStreamError> {
        if batches.is_empty() {
            return Ok(());
        }
        let row = row_id(self.next_row);
        self.next_row += 1;
        let id = self.chunk_id();
        let mut components = Vec::with_capacity(batches.len());
        for batch in batches {
            let len = batch_len(&batch);
            let mut lengths = Lengths::default();
            lengths.push(len);
            let list = list_array(batch.array, &mut lengths)?;
            components.push((batch.descriptor, list));
        }
        let timelines = match at {
            None => Default::default(),
            Some((frame, time)) => {
                entity::timelines(vec![frame], vec![time.nanos()], time.is_timestamp())
            }
        };
        let chunk = Chunk::from_native_row_ids(
            id,
            path.as_str().into(),
            None,
            &[row],
            timelines,
            components.into_iter().collect(),
        )
        .map_err(RecordingStreamError::Chunk)?;
        rec.send_chunk(chunk);
        Ok(())
    }

    /// Sends every buffered row, one chunk per entity and set, in the order
    /// they were first logged.
    pub fn send(&mut self, rec: &RecordingStream) -> Result<(), RecordingStreamError> {
        for i in 0..self.entities.len() {
            if let Some(part) = self.entities[i].take_part()? {
                let id = self.chunk_id();
                rec.send_chunk(self.entities[i].chunk(id, part)?);
            }
        }
        self.rows = 0;
        Ok(())
    }

    /// Writes every buffered row to `spill`, one part per entity and set,
    /// in the order they were first logged.
    pub(crate) fn spill(&mut self, spill: &mut Spill) -> Result<(), RecordError> {
        for e in &mut self.entities {
            if let Some(part) = e.take_part()? {
                spill.put(e.key, part)?;
            }
        }
        self.rows = 0;
        Ok(())
    }

    /// Sends what `spill` holds in chunks' worth (see
    /// [`Spill::drain_ready`]), as chunks built like those of
    /// [`Columns::send`].
    pub(crate) fn send_ready(
        &mut self,
        spill: &mut Spill,
        rec: &RecordingStream,
    ) -> Result<(), RecordError> {
        spill.drain_ready(|key, part| self.send_part(rec, key, part))
    }

    fn send_part(
        &mut self,
        rec: &RecordingStream,
        key: Key,
        part: Part,
    ) -> Result<(), RecordError> {
        let Some(&i) = self.index.get(&key) else {
            unreachable!("a spilled part comes from a buffered entity");
        };
        let id = self.chunk_id();
        rec.send_chunk(self.entities[i].chunk(id, part)?);
        Ok(())
    }

    /// Sends what `spill` holds (see [`Spill::drain`]), as chunks built like
    /// those of [`Columns::send`].
    pub(crate) fn send_spilled(
        &mut self,
        spill: &mut Spill,
        rec: &RecordingStream,
        progress: impl FnMut(u64, u64),
    ) -> Result<(), RecordError> {
        spill.drain(|key, part| self.send_part(rec, key, part), progress)
    }
}

fn batch_len(batch: &SerializedComponentBatch) -> usize {
    use rerun::external::arrow::array::Array as _;
    batch.array.len()
}
