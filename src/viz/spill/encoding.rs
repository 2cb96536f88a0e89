//! How a part is kept in the temporary file: its `frame`, `time` and row
//! columns, then each list's Arrow array data as it is in memory (length,
//! offset, null bits, buffers, children), with the arrays' types kept
//! apart, once per entity and set ([`Shape`]), so that a part holds no
//! schema. Read back through Arrow's validating builder.

use std::io::{self, Write};

use rerun::external::arrow::array::{Array, ArrayData, Int64Array, ListArray, UInt64Array};
use rerun::external::arrow::buffer::{BooleanBuffer, Buffer, NullBuffer};
use rerun::external::arrow::datatypes::DataType;

use crate::viz::columns::Part;

/// A part's columns as arrays (the vectors moved, not copied).
pub(super) struct Arrays {
    frames: Int64Array,
    times: Int64Array,
    rows: UInt64Array,
    pub(super) lists: Vec<ListArray>,
}

impl Arrays {
    pub(super) fn of(part: Part) -> Arrays {
        Arrays {
            frames: Int64Array::from(part.frames),
            times: Int64Array::from(part.times),
            rows: UInt64Array::from(part.rows),
            lists: part.lists,
        }
    }

    /// The bytes the arrays take in memory (what a record batch of the
    /// columns reports: their buffers' capacity included).
    pub(super) fn memory_size(&self) -> usize {
        self.frames.get_array_memory_size()
            + self.times.get_array_memory_size()
            + self.rows.get_array_memory_size()
            + self
                .lists
                .iter()
                .map(|l| l.get_array_memory_size())
                .sum::<usize>()
    }

    /// Writes the part (rows of a key whose lists have the shapes
    /// `shapes`) to `w`: the number of rows, the `frame`, `time` and row
    /// columns, then each list's array data. Returns the bytes written.
    pub(super) fn write(&self, w: &mut impl Write, shapes: &[Shape]) -> io::Result<u64> {
        debug_assert_eq!(self.lists.len(), shapes.len());
        let mut n = 0u64;
        let mut put = |bytes: &[u8]| -> io::Result<()> {
            n += bytes.len() as u64;
            w.write_all(bytes)
        };
        put(&(self.rows.len() as u64).to_le_bytes())?;
        for column in [
            self.frames.values().inner(),
            self.times.values().inner(),
            self.rows.values().inner(),
        ] {
            put(column.as_slice())?;
        }
        for list in &self.lists {
            write_data(&mut put, &list.to_data())?;
        }
        Ok(n)
    }
}

/// The type of an array and of its children, kept once per key: a part in
/// the file holds only its lengths, buffers and nulls.
#[derive(Debug)]
pub(super) struct Shape {
    data_type: DataType,
    children: Vec<Shape>,
}

impl Shape {
    pub(super) fn of(data: &ArrayData) -> Shape {
        Shape {
            data_type: data.data_type().clone(),
            children: data.child_data().iter().map(Shape::of).collect(),
        }
    }
}

/// One array's data: length, offset, nulls, buffers, then its children.
fn write_data(put: &mut impl FnMut(&[u8]) -> io::Result<()>, data: &ArrayData) -> io::Result<()> {
    let mut number = |v: usize| put(&(v as u64).to_le_bytes());
    number(data.len())?;
    number(data.offset())?;
    let bytes = |b: &[u8], put: &mut dyn FnMut(&[u8]) -> io::Result<()>| {
        put(&(b.len() as u64).to_le_bytes())?;
        put(b)
    };
    match data.nulls() {
        Some(nulls) => {
            let inner = nulls.inner();
            put(&[1])?;
            put(&(inner.offset() as u64).to_le_bytes())?;
            put(&(inner.len() as u64).to_le_bytes())?;
            bytes(inner.inner().as_slice(), put)?;
        }
        None => put(&[0])?,
    }
    put(&(data.buffers().len() as u64).to_le_bytes())?;
    for b in data.buffers() {
        bytes(b.as_slice(), put)?;
    }
    for child in data.child_data() {
        write_data(put, child)?;
    }
    Ok(())
}

/// Reads what [`write_part`] wrote; `None` when it does not read back (a
/// temporary file damaged under us).
pub(super) fn read_part(r: &mut &[u8], shapes: &[Shape]) -> Option<Part> {
    let rows = take_number(r)?;
    let mut column = || -> Option<Vec<u64>> {
        let bytes = take(r, rows.checked_mul(8)?)?;
        Some(
            bytes
                .chunks_exact(8)
                .map(|b| u64::from_ne_bytes(b.try_into().unwrap_or_default()))
                .collect(),
        )
    };
    let frames = column()?.into_iter().map(|v| v as i64).collect();
    let times = column()?.into_iter().map(|v| v as i64).collect();
    let row_numbers = column()?;
    let lists = shapes
        .iter()
        .map(|shape| {
            let data = read_data(r, shape)?;
            Some(ListArray::from(data))
                .filter(|l| l.len() == rows && *l.data_type() == shape.data_type)
        })
        .collect::<Option<Vec<ListArray>>>()?;
    r.is_empty().then_some(Part {
        frames,
        times,
        rows: row_numbers,
        lists,
    })
}

/// Reads what [`write_data`] wrote, of type `shape`. A null buffer without
/// nulls is left out, as Arrow IPC's reader leaves it out.
fn read_data(r: &mut &[u8], shape: &Shape) -> Option<ArrayData> {
    let len = take_number(r)?;
    let offset = take_number(r)?;
    let nulls = match take(r, 1)?[0] {
        0 => None,
        _ => {
            let (offset, len) = (take_number(r)?, take_number(r)?);
            let bytes = take_bytes(r)?;
            let bits = BooleanBuffer::new(bytes, offset, len);
            Some(NullBuffer::new(bits)).filter(|n| n.null_count() > 0)
        }
    };
    let buffers = (0..take_number(r)?)
        .map(|_| take_bytes(r))
        .collect::<Option<Vec<Buffer>>>()?;
    let children = shape
        .children
        .iter()
        .map(|child| read_data(r, child))
        .collect::<Option<Vec<ArrayData>>>()?;
    ArrayData::builder(shape.data_type.clone())
        .len(len)
        .offset(offset)
        .nulls(nulls)
        .buffers(buffers)
        .child_data(children)
        .build()
        .ok()
}

fn take<'a>(r: &mut &'a [u8], n: usize) -> Option<&'a [u8]> {
    if r.len() < n {
        return None;
    }
    let (head, rest) = r.split_at(n);
    *r = rest;
    Some(head)
}

fn take_number(r: &mut &[u8]) -> Option<usize> {
    let bytes = take(r, 8)?;
    usize::try_from(u64::from_le_bytes(bytes.try_into().ok()?)).ok()
}

/// A buffer's bytes, copied into an aligned buffer.
fn take_bytes(r: &mut &[u8]) -> Option<Buffer> {
    let n = take_number(r)?;
    Some(Buffer::from_slice_ref(take(r, n)?))
}
