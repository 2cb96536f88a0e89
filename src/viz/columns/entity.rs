//! The buffer of one entity and set of components: its time columns, row
//! numbers and component columns, taken out as a [`Part`] and made a chunk.

use rerun::log::{Chunk, ChunkComponents, ChunkId, RowId, TimeColumn};
use rerun::{EntityPath, RecordingStreamError, TimelineName};

use super::component::Column;
use super::{Key, Part, row_id};
use crate::viz::{FRAME_TIMELINE, TIME_TIMELINE};

#[derive(Debug)]
pub(super) struct EntityColumns {
    pub(super) key: Key,
    /// Built when first sent (not in buffers that are only appended).
    path: Option<EntityPath>,
    pub(super) frames: Vec<i64>,
    pub(super) times: Vec<i64>,
    /// Row numbers (0-based, in the order the rows were logged).
    pub(super) rows: Vec<u64>,
    pub(super) columns: Vec<Box<dyn Column>>,
}

impl EntityColumns {
    pub(super) fn new(key: Key) -> EntityColumns {
        EntityColumns {
            key,
            path: None,
            frames: Vec::new(),
            times: Vec::new(),
            rows: Vec::new(),
            columns: Vec::new(),
        }
    }

    pub(super) fn append(&mut self, other: &mut EntityColumns) {
        self.frames.append(&mut other.frames);
        self.times.append(&mut other.times);
        self.rows.append(&mut other.rows);
        debug_assert_eq!(self.columns.len(), other.columns.len());
        for (mine, theirs) in self.columns.iter_mut().zip(&mut other.columns) {
            mine.append(theirs.as_mut());
        }
    }

    /// The buffered rows, taken out of the buffer (`None` when there are
    /// none).
    pub(super) fn take_part(&mut self) -> Result<Option<Part>, RecordingStreamError> {
        if self.rows.is_empty() {
            return Ok(None);
        }
        let rows = self.rows.len();
        let frames = std::mem::replace(&mut self.frames, Vec::with_capacity(rows));
        let times = std::mem::replace(&mut self.times, Vec::with_capacity(rows));
        let mut lists = Vec::with_capacity(self.columns.len());
        for column in &mut self.columns {
            lists.push(column.take_list()?);
        }
        let row_numbers = std::mem::replace(&mut self.rows, Vec::with_capacity(rows));
        Ok(Some(Part {
            frames,
            times,
            rows: row_numbers,
            lists,
        }))
    }

    /// The chunk of `part` (rows of this entity and set).
    pub(super) fn chunk(&mut self, id: ChunkId, part: Part) -> Result<Chunk, RecordingStreamError> {
        let Part {
            frames,
            times,
            rows,
            lists,
        } = part;
        let timelines = timelines(frames, times, self.key.timestamps);
        let components: ChunkComponents = self
            .columns
            .iter()
            .map(|c| c.descriptor().clone())
            .zip(lists)
            .collect();
        let row_ids: Vec<RowId> = rows.into_iter().map(row_id).collect();
        Chunk::from_native_row_ids(
            id,
            self.path
                .get_or_insert_with(|| EntityPath::from(self.key.entity.path()))
                .clone(),
            None,
            &row_ids,
            timelines,
            components,
        )
        .map_err(RecordingStreamError::Chunk)
    }
}

/// The `frame` and `time` columns of rows at `frames` and `times` (the
/// times timestamps when `timestamps`, else durations).
pub(super) fn timelines<C: FromIterator<(TimelineName, TimeColumn)>>(
    frames: Vec<i64>,
    times: Vec<i64>,
    timestamps: bool,
) -> C {
    let time_column = if timestamps {
        TimeColumn::new_timestamp_nanos_since_epoch(TIME_TIMELINE, times)
    } else {
        TimeColumn::new_duration_nanos(TIME_TIMELINE, times)
    };
    [
        TimeColumn::new_sequence(FRAME_TIMELINE, frames),
        time_column,
    ]
    .into_iter()
    .map(|c| (*c.timeline().name(), c))
    .collect()
}
