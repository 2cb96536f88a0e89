//! Rows buffered per entity as columns and sent as one chunk per entity.
//!
//! Logging a row at a time costs a channel message and a pass through the
//! SDK's batcher per row. Here the rows of each entity and set of components
//! (an entity that logs a `Points3D` at one frame and a `Clear` at another
//! has two sets) keep their time columns (`frame`, `time`), their row ids and
//! one column per component, and [`Columns::send`] turns each into one dense
//! [`Chunk`] with one concatenation per component, like the chunks the
//! batcher builds.
//!
//! Row and chunk ids come from counters, not from the clock and a random
//! number: the `n`-th row logged gets row id `n` (above a fixed base), so
//! later rows still win over earlier ones at the same time, as with
//! row-by-row logging, and the same rows give the same chunks.

use std::collections::HashMap;
use std::sync::Arc;

use rerun::external::arrow::array::{Array, ArrayRef, ListArray};
use rerun::external::arrow::buffer::{NullBuffer, OffsetBuffer};
use rerun::external::arrow::compute::concat;
use rerun::external::arrow::datatypes::Field;
use rerun::log::{Chunk, ChunkComponents, ChunkId, RowId, TimeColumn};
use rerun::{ComponentDescriptor, RecordingStream, RecordingStreamError, SerializedComponentBatch};

use super::{FRAME_TIMELINE, TIME_TIMELINE};

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

#[derive(Debug)]
struct ComponentColumn {
    descriptor: ComponentDescriptor,
    /// One entry per row of the entity; `None` where the row does not log it.
    cells: Vec<Option<ArrayRef>>,
}

#[derive(Debug)]
struct EntityColumns {
    path: String,
    frames: Vec<i64>,
    times: Vec<i64>,
    timestamps: bool,
    row_ids: Vec<RowId>,
    components: Vec<ComponentColumn>,
}

impl EntityColumns {
    fn rows(&self) -> usize {
        self.row_ids.len()
    }

    /// The chunk of the buffered rows, and the buffer emptied.
    fn take_chunk(&mut self, id: ChunkId) -> Result<Option<Chunk>, RecordingStreamError> {
        if self.row_ids.is_empty() {
            return Ok(None);
        }
        let frames = std::mem::take(&mut self.frames);
        let times = std::mem::take(&mut self.times);
        let time_column = if self.timestamps {
            TimeColumn::new_timestamp_nanos_since_epoch(TIME_TIMELINE, times)
        } else {
            TimeColumn::new_duration_nanos(TIME_TIMELINE, times)
        };
        let timelines = [
            TimeColumn::new_sequence(FRAME_TIMELINE, frames),
            time_column,
        ]
        .into_iter()
        .map(|c| (*c.timeline().name(), c))
        .collect();
        let mut components = Vec::with_capacity(self.components.len());
        for column in &mut self.components {
            let cells = std::mem::take(&mut column.cells);
            if let Some(list) = list_array(&cells)? {
                components.push((column.descriptor.clone(), list));
            }
        }
        let components: ChunkComponents = components.into_iter().collect();
        let row_ids = std::mem::take(&mut self.row_ids);
        let chunk = Chunk::from_native_row_ids(
            id,
            self.path.as_str().into(),
            None,
            &row_ids,
            timelines,
            components,
        )
        .map_err(RecordingStreamError::Chunk)?;
        Ok(Some(chunk))
    }
}

/// The rows of every entity not yet sent.
#[derive(Debug, Default)]
pub struct Columns {
    entities: Vec<EntityColumns>,
    /// The buffers of each path, one per set of components.
    by_path: HashMap<String, Vec<usize>>,
    rows: usize,
    next_row: u64,
    next_chunk: u64,
}

impl Columns {
    /// Rows buffered.
    pub fn rows(&self) -> usize {
        self.rows
    }

    fn row_id(&mut self) -> RowId {
        self.next_row += 1;
        RowId::from_u128(((ID_BASE_NANOS as u128) << 64) | self.next_row as u128)
    }

    fn chunk_id(&mut self) -> ChunkId {
        self.next_chunk += 1;
        ChunkId::from_u128(((ID_BASE_NANOS as u128) << 64) | self.next_chunk as u128)
    }

    /// Buffers one row of `path` at (`frame`, `time`). A row without
    /// components is dropped, as the SDK does.
    pub fn push_row(
        &mut self,
        rec: &RecordingStream,
        path: String,
        frame: i64,
        time: Time,
        batches: Vec<SerializedComponentBatch>,
    ) -> Result<(), RecordingStreamError> {
        if batches.is_empty() {
            return Ok(());
        }
        let row_id = self.row_id();
        let same_set = |e: &EntityColumns| {
            e.components.len() == batches.len()
                && e.components
                    .iter()
                    .zip(&batches)
                    .all(|(c, b)| c.descriptor == b.descriptor)
        };
        let found = self
            .by_path
            .get(&path)
            .and_then(|list| list.iter().copied().find(|&i| same_set(&self.entities[i])));
        let index = match found {
            Some(i) => i,
            None => {
                let i = self.entities.len();
                self.by_path.entry(path.clone()).or_default().push(i);
                self.entities.push(EntityColumns {
                    path,
                    frames: Vec::new(),
                    times: Vec::new(),
                    timestamps: time.is_timestamp(),
                    row_ids: Vec::new(),
                    components: batches
                        .iter()
                        .map(|b| ComponentColumn {
                            descriptor: b.descriptor.clone(),
                            cells: Vec::new(),
                        })
                        .collect(),
                });
                i
            }
        };
        // One chunk holds one kind of `time`: send what came before a change.
        if self.entities[index].timestamps != time.is_timestamp() {
            let id = self.chunk_id();
            let entity = &mut self.entities[index];
            self.rows -= entity.rows();
            if let Some(chunk) = entity.take_chunk(id)? {
                rec.send_chunk(chunk);
            }
            entity.timestamps = time.is_timestamp();
        }
        let entity = &mut self.entities[index];
        for (column, batch) in entity.components.iter_mut().zip(batches) {
            column.cells.push(Some(batch.array));
        }
        entity.frames.push(frame);
        entity.times.push(time.nanos());
        entity.row_ids.push(row_id);
        self.rows += 1;
        Ok(())
    }

    /// Sends a static row of `path` at once.
    pub fn send_static(
        &mut self,
        rec: &RecordingStream,
        path: String,
        batches: Vec<SerializedComponentBatch>,
    ) -> Result<(), RecordingStreamError> {
        if batches.is_empty() {
            return Ok(());
        }
        let row_id = self.row_id();
        let id = self.chunk_id();
        let mut components = Vec::with_capacity(batches.len());
        for batch in batches {
            if let Some(list) = list_array(&[Some(batch.array)])? {
                components.push((batch.descriptor, list));
            }
        }
        let chunk = Chunk::from_native_row_ids(
            id,
            path.as_str().into(),
            None,
            &[row_id],
            Default::default(),
            components.into_iter().collect(),
        )
        .map_err(RecordingStreamError::Chunk)?;
        rec.send_chunk(chunk);
        Ok(())
    }

    /// Sends every buffered row, one chunk per entity, entities in the order
    /// they were first logged.
    pub fn send(&mut self, rec: &RecordingStream) -> Result<(), RecordingStreamError> {
        for i in 0..self.entities.len() {
            if self.entities[i].rows() == 0 {
                continue;
            }
            let id = self.chunk_id();
            if let Some(chunk) = self.entities[i].take_chunk(id)? {
                rec.send_chunk(chunk);
            }
        }
        self.rows = 0;
        Ok(())
    }
}

/// The list array of one component column: one list per row, null where
/// the row does not log the component; `None` when no row does.
fn list_array(cells: &[Option<ArrayRef>]) -> Result<Option<ListArray>, RecordingStreamError> {
    let dense: Vec<&dyn Array> = cells.iter().flatten().map(|a| a.as_ref()).collect();
    let Some(first) = dense.first() else {
        return Ok(None);
    };
    let data_type = first.data_type().clone();
    let values = if dense.len() == 1 {
        cells.iter().flatten().next().cloned().expect("one cell")
    } else {
        concat(&dense).map_err(|e| RecordingStreamError::Chunk(e.into()))?
    };
    let offsets =
        OffsetBuffer::from_lengths(cells.iter().map(|c| c.as_ref().map_or(0, |a| a.len())));
    let nulls = if cells.iter().all(Option::is_some) {
        None
    } else {
        Some(NullBuffer::from_iter(cells.iter().map(Option::is_some)))
    };
    let field = Arc::new(Field::new_list_field(data_type, true));
    ListArray::try_new(field, offsets, values, nulls)
        .map(Some)
        .map_err(|e| RecordingStreamError::Chunk(e.into()))
}
