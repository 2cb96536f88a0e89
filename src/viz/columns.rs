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

use std::any::Any;
use std::fmt;
use std::sync::Arc;

use rerun::components::LineStrip3D;
use rerun::external::arrow::array::{
    ArrayRef, FixedSizeListArray, Float32Array, ListArray, StringArray,
};
use rerun::external::arrow::buffer::{Buffer, OffsetBuffer, ScalarBuffer};
use rerun::external::arrow::datatypes::{DataType, Field};
use rerun::log::{Chunk, ChunkComponents, ChunkId, RowId, TimeColumn};
use rerun::{
    Component, ComponentDescriptor, EntityPath, RecordingStream, RecordingStreamError,
    SerializedComponentBatch,
};
use rustc_hash::FxHashMap;

use super::RecordError;
use super::paths::Entity;
use super::spill::Spill;
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

/// One component's values over the buffered rows.
trait Column: Send + fmt::Debug {
    fn descriptor(&self) -> &ComponentDescriptor;
    /// Moves the rows of `other` (a column of the same type) to the end.
    fn append(&mut self, other: &mut dyn Column);
    /// The list array of the buffered rows (one list per row); empties the
    /// column.
    fn take_list(&mut self) -> Result<ListArray, RecordingStreamError>;
    fn as_any_mut(&mut self) -> &mut dyn Any;
    /// Bytes the buffered rows take (values and lengths, not the spare
    /// capacity).
    fn bytes(&self) -> usize;
}

/// A column of component `C`: all values in one `Vec`, and how many each
/// row has.
struct Typed<C> {
    descriptor: ComponentDescriptor,
    values: Vec<C>,
    lengths: Lengths,
}

impl<C> fmt::Debug for Typed<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Typed")
            .field("descriptor", &self.descriptor)
            .field("values", &self.values.len())
            .field("rows", &self.lengths.len())
            .finish()
    }
}

impl<C: Component> Column for Typed<C> {
    fn descriptor(&self) -> &ComponentDescriptor {
        &self.descriptor
    }

    fn append(&mut self, other: &mut dyn Column) {
        let other = other
            .as_any_mut()
            .downcast_mut::<Typed<C>>()
            .expect("columns of one set have the same types");
        self.values.append(&mut other.values);
        self.lengths.append(&mut other.lengths);
    }

    fn take_list(&mut self) -> Result<ListArray, RecordingStreamError> {
        let values = C::to_arrow(self.values.iter().map(std::borrow::Cow::Borrowed))?;
        self.values.clear();
        list_array(values, &mut self.lengths)
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }

    fn bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<C>() + self.lengths.bytes()
    }
}

/// A column of a string component (`Text`, `TextLogLevel`, ...; Arrow
/// `Utf8`): the bytes of every string in one buffer.
#[derive(Debug)]
struct Strings {
    descriptor: ComponentDescriptor,
    bytes: String,
    /// Length in bytes of each string.
    string_lengths: Vec<u32>,
    /// Strings of each row.
    lengths: Lengths,
}

impl Column for Strings {
    fn descriptor(&self) -> &ComponentDescriptor {
        &self.descriptor
    }

    fn append(&mut self, other: &mut dyn Column) {
        let other = other
            .as_any_mut()
            .downcast_mut::<Strings>()
            .expect("columns of one set have the same types");
        self.bytes.push_str(&other.bytes);
        other.bytes.clear();
        self.string_lengths.append(&mut other.string_lengths);
        self.lengths.append(&mut other.lengths);
    }

    fn take_list(&mut self) -> Result<ListArray, RecordingStreamError> {
        let offsets = OffsetBuffer::<i32>::from_lengths(self.string_lengths.drain(..).map(widen));
        // The next flush holds about as many bytes: allocate them at once.
        let n = self.bytes.len();
        let bytes = std::mem::replace(&mut self.bytes, String::with_capacity(n));
        let bytes = Buffer::from_vec(bytes.into_bytes());
        let values = StringArray::try_new(offsets, bytes, None)
            .map_err(|e| RecordingStreamError::Chunk(e.into()))?;
        list_array(Arc::new(values), &mut self.lengths)
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }

    fn bytes(&self) -> usize {
        self.bytes.len() + self.string_lengths.len() * 4 + self.lengths.bytes()
    }
}

/// A column of `LineStrip3D`s (Arrow: a list of `Vec3D` per strip): the
/// points of every strip in one buffer, no `Vec` per strip.
#[derive(Debug)]
struct Strips {
    descriptor: ComponentDescriptor,
    /// x, y, z of every point.
    coords: Vec<f32>,
    /// Points of each strip.
    strip_lengths: Vec<u32>,
    /// Strips of each row.
    lengths: Lengths,
}

impl Column for Strips {
    fn descriptor(&self) -> &ComponentDescriptor {
        &self.descriptor
    }

    fn append(&mut self, other: &mut dyn Column) {
        let other = other
            .as_any_mut()
            .downcast_mut::<Strips>()
            .expect("columns of one set have the same types");
        self.coords.append(&mut other.coords);
        self.strip_lengths.append(&mut other.strip_lengths);
        self.lengths.append(&mut other.lengths);
    }

    fn take_list(&mut self) -> Result<ListArray, RecordingStreamError> {
        // The fields `LineStrip3D::to_arrow` uses.
        let strip_type = <LineStrip3D as rerun::Loggable>::arrow_datatype();
        let DataType::List(strip_field) = &strip_type else {
            unreachable!("LineStrip3D is a list");
        };
        let DataType::FixedSizeList(point_field, 3) = strip_field.data_type() else {
            unreachable!("a LineStrip3D's points are Vec3D");
        };
        let n = self.coords.len();
        let coords = std::mem::replace(&mut self.coords, Vec::with_capacity(n));
        let coords = Float32Array::new(ScalarBuffer::from(coords), None);
        let points = FixedSizeListArray::try_new(point_field.clone(), 3, Arc::new(coords), None)
            .map_err(|e| RecordingStreamError::Chunk(e.into()))?;
        let offsets = OffsetBuffer::<i32>::from_lengths(self.strip_lengths.drain(..).map(widen));
        let strips = ListArray::try_new(strip_field.clone(), offsets, Arc::new(points), None)
            .map_err(|e| RecordingStreamError::Chunk(e.into()))?;
        list_array(Arc::new(strips), &mut self.lengths)
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }

    fn bytes(&self) -> usize {
        self.coords.len() * 4 + self.strip_lengths.len() * 4 + self.lengths.bytes()
    }
}

/// How many values each buffered row of a column has: only a count while
/// every row has exactly one (most components), which then costs nothing
/// per row; the lengths themselves from the first row that does not.
#[derive(Debug, Default)]
struct Lengths {
    /// Rows, while every row has one value (`list` is empty then).
    ones: usize,
    /// Every row's length, once a row has not had exactly one.
    list: Vec<u32>,
}

impl Lengths {
    fn push(&mut self, n: usize) {
        if self.list.is_empty() {
            if n == 1 {
                self.ones += 1;
                return;
            }
            self.spell_out();
        }
        self.list.push(narrow(n));
    }

    /// From the count to the list.
    fn spell_out(&mut self) {
        self.list.extend(std::iter::repeat_n(1, self.ones));
        self.ones = 0;
    }

    fn len(&self) -> usize {
        if self.list.is_empty() {
            self.ones
        } else {
            self.list.len()
        }
    }

    /// Moves the rows of `other` to the end.
    fn append(&mut self, other: &mut Lengths) {
        if self.list.is_empty() && other.list.is_empty() {
            self.ones += std::mem::take(&mut other.ones);
            return;
        }
        self.spell_out();
        other.spell_out();
        self.list.append(&mut other.list);
    }

    fn bytes(&self) -> usize {
        self.list.len() * 4
    }

    /// The offsets of the rows; empties the lengths.
    fn take_offsets(&mut self) -> OffsetBuffer<i32> {
        if self.list.is_empty() {
            OffsetBuffer::from_lengths(std::iter::repeat_n(1, std::mem::take(&mut self.ones)))
        } else {
            OffsetBuffer::from_lengths(self.list.drain(..).map(widen))
        }
    }
}

/// A length as stored (Arrow's offsets here are `i32`, so no list is near
/// `u32::MAX` long).
fn narrow(n: usize) -> u32 {
    u32::try_from(n).expect("a list of fewer than 2^31 values")
}

fn widen(n: u32) -> usize {
    n as usize
}

/// One list per row over `values`, `lengths` values each; empties
/// `lengths`.
fn list_array(values: ArrayRef, lengths: &mut Lengths) -> Result<ListArray, RecordingStreamError> {
    let offsets = lengths.take_offsets();
    let field = Arc::new(Field::new_list_field(values.data_type().clone(), true));
    ListArray::try_new(field, offsets, values, None)
        .map_err(|e| RecordingStreamError::Chunk(e.into()))
}

#[derive(Debug)]
struct EntityColumns {
    key: Key,
    /// Built when first sent (not in buffers that are only appended).
    path: Option<EntityPath>,
    frames: Vec<i64>,
    times: Vec<i64>,
    /// Row numbers (0-based, in the order the rows were logged).
    rows: Vec<u64>,
    columns: Vec<Box<dyn Column>>,
}

impl EntityColumns {
    fn new(key: Key) -> EntityColumns {
        EntityColumns {
            key,
            path: None,
            frames: Vec::new(),
            times: Vec::new(),
            rows: Vec::new(),
            columns: Vec::new(),
        }
    }

    fn append(&mut self, other: &mut EntityColumns) {
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
    fn take_part(&mut self) -> Result<Option<Part>, RecordingStreamError> {
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
    fn chunk(&mut self, id: ChunkId, part: Part) -> Result<Chunk, RecordingStreamError> {
        let Part {
            frames,
            times,
            rows,
            lists,
        } = part;
        let time_column = if self.key.timestamps {
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
        let chunk = Chunk::from_native_row_ids(
            id,
            path.as_str().into(),
            None,
            &[row],
            Default::default(),
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

/// One row being written: put each component of the set in turn.
pub(crate) struct Row<'a> {
    entity: &'a mut EntityColumns,
    next: usize,
}

impl Row<'_> {
    /// The next column, created with `make` in the set's first row.
    fn column(&mut self, make: impl FnOnce() -> Box<dyn Column>) -> &mut dyn Any {
        let i = self.next;
        self.next += 1;
        if i == self.entity.columns.len() {
            self.entity.columns.push(make());
        }
        self.entity.columns[i].as_any_mut()
    }

    /// Puts the values of component `C` (`descriptor` names it).
    pub(crate) fn put<C: Component>(
        &mut self,
        descriptor: fn() -> ComponentDescriptor,
        values: impl IntoIterator<Item = C>,
    ) -> &mut Self {
        let column = self
            .column(|| {
                Box::new(Typed::<C> {
                    descriptor: descriptor(),
                    values: Vec::new(),
                    lengths: Lengths::default(),
                })
            })
            .downcast_mut::<Typed<C>>()
            .expect("every row of a set puts the same components");
        let before = column.values.len();
        column.values.extend(values);
        column.lengths.push(column.values.len() - before);
        self
    }

    /// Puts one `LineStrip3D` through each of `strips` (none, one or
    /// several; `descriptor` names the component).
    pub(crate) fn put_strips(
        &mut self,
        descriptor: fn() -> ComponentDescriptor,
        strips: &[&[[f32; 3]]],
    ) -> &mut Self {
        let column = self
            .column(|| {
                Box::new(Strips {
                    descriptor: descriptor(),
                    coords: Vec::new(),
                    strip_lengths: Vec::new(),
                    lengths: Lengths::default(),
                })
            })
            .downcast_mut::<Strips>()
            .expect("every row of a set puts the same components");
        for points in strips {
            column.coords.extend_from_slice(points.as_flattened());
            column.strip_lengths.push(narrow(points.len()));
        }
        column.lengths.push(strips.len());
        self
    }

    /// Puts the strings of a string component (`descriptor` names it; its
    /// Arrow type must be `Utf8`, as `Text`'s).
    pub(crate) fn put_strs<'s>(
        &mut self,
        descriptor: fn() -> ComponentDescriptor,
        strings: impl IntoIterator<Item = &'s str>,
    ) -> &mut Self {
        let column = self.strings(descriptor);
        let mut n = 0;
        for s in strings {
            column.bytes.push_str(s);
            column.string_lengths.push(narrow(s.len()));
            n += 1;
        }
        column.lengths.push(n);
        self
    }

    /// Puts one formatted string of a string component.
    pub(crate) fn put_fmt(
        &mut self,
        descriptor: fn() -> ComponentDescriptor,
        args: fmt::Arguments<'_>,
    ) -> &mut Self {
        let column = self.strings(descriptor);
        let before = column.bytes.len();
        fmt::Write::write_fmt(&mut column.bytes, args).expect("writing to a String");
        column
            .string_lengths
            .push(narrow(column.bytes.len() - before));
        column.lengths.push(1);
        self
    }

    /// Puts the strings of a string component that `write` pushes (or
    /// formats) straight into the column's byte buffer.
    pub(crate) fn put_texts(
        &mut self,
        descriptor: fn() -> ComponentDescriptor,
        write: impl FnOnce(&mut Texts<'_>),
    ) -> &mut Self {
        let column = self.strings(descriptor);
        let mut texts = Texts { column, n: 0 };
        write(&mut texts);
        let n = texts.n;
        texts.column.lengths.push(n);
        self
    }

    fn strings(&mut self, descriptor: fn() -> ComponentDescriptor) -> &mut Strings {
        self.column(|| {
            Box::new(Strings {
                descriptor: descriptor(),
                bytes: String::new(),
                string_lengths: Vec::new(),
                lengths: Lengths::default(),
            })
        })
        .downcast_mut::<Strings>()
        .expect("every row of a set puts the same components")
    }
}

/// The strings of one row of a string column (see [`Row::put_texts`]).
pub(crate) struct Texts<'a> {
    column: &'a mut Strings,
    n: usize,
}

impl Texts<'_> {
    /// Adds a formatted string.
    pub(crate) fn push_fmt(&mut self, args: fmt::Arguments<'_>) -> &mut Self {
        self.push_with(|b| fmt::Write::write_fmt(b, args).expect("writing to a String"))
    }

    /// Adds the string `write` appends to the given buffer (it must only
    /// append).
    pub(crate) fn push_with(&mut self, write: impl FnOnce(&mut String)) -> &mut Self {
        let before = self.column.bytes.len();
        write(&mut self.column.bytes);
        debug_assert!(self.column.bytes.len() >= before);
        self.column
            .string_lengths
            .push(narrow(self.column.bytes.len() - before));
        self.n += 1;
        self
    }
}

impl Drop for Row<'_> {
    fn drop(&mut self) {
        debug_assert_eq!(
            self.next,
            self.entity.columns.len(),
            "a row of {:?} put {} of the set's {} components",
            self.entity.key,
            self.next,
            self.entity.columns.len()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::Lengths;

    fn offsets(lengths: &[usize]) -> Vec<i32> {
        let mut o = vec![0];
        for n in lengths {
            o.push(o.last().unwrap() + *n as i32);
        }
        o
    }

    /// Every way of splitting short sequences of lengths 0, 1 and 2 into
    /// two appended halves gives the offsets of the plain list.
    #[test]
    fn lengths_give_the_offsets_of_the_plain_list() {
        for code in 0..3usize.pow(6) {
            let seq: Vec<usize> = (0..6).map(|i| code / 3usize.pow(i) % 3).collect();
            for cut in 0..=seq.len() {
                let (a, b) = seq.split_at(cut);
                let mut x = Lengths::default();
                a.iter().for_each(|&n| x.push(n));
                let mut y = Lengths::default();
                b.iter().for_each(|&n| y.push(n));
                x.append(&mut y);
                assert_eq!(y.len(), 0);
                assert_eq!(x.len(), seq.len());
                assert_eq!(x.take_offsets().to_vec(), offsets(&seq), "{a:?} + {b:?}");
                assert_eq!(x.len(), 0);
                // Reused after taking.
                x.push(2);
                assert_eq!(x.take_offsets().to_vec(), vec![0, 2]);
            }
        }
    }

    #[test]
    fn rows_of_one_value_cost_nothing() {
        let mut x = Lengths::default();
        (0..1000).for_each(|_| x.push(1));
        assert_eq!(x.bytes(), 0);
        x.push(3);
        assert_eq!(x.bytes(), 1001 * 4);
    }
}
