//! One component's column over the buffered rows (the [`Column`] trait),
//! of each kind: a component's own values (`Typed`), strings in one byte
//! buffer (`Strings`), line strips' points in one buffer (`Strips`).

use std::any::Any;
use std::fmt;
use std::sync::Arc;

use rerun::components::LineStrip3D;
use rerun::external::arrow::array::{FixedSizeListArray, Float32Array, ListArray, StringArray};
use rerun::external::arrow::buffer::{Buffer, OffsetBuffer, ScalarBuffer};
use rerun::external::arrow::datatypes::DataType;
use rerun::{Component, ComponentDescriptor, RecordingStreamError};

use super::lengths::{Lengths, list_array, widen};

/// One component's values over the buffered rows.
pub(super) trait Column: Send + fmt::Debug {
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
pub(super) struct Typed<C> {
    pub(super) descriptor: ComponentDescriptor,
    pub(super) values: Vec<C>,
    pub(super) lengths: Lengths,
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
pub(super) struct Strings {
    pub(super) descriptor: ComponentDescriptor,
    pub(super) bytes: String,
    /// Length in bytes of each string.
    pub(super) string_lengths: Vec<u32>,
    /// Strings of each row.
    pub(super) lengths: Lengths,
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
pub(super) struct Strips {
    pub(super) descriptor: ComponentDescriptor,
    /// x, y, z of every point.
    pub(super) coords: Vec<f32>,
    /// Points of each strip.
    pub(super) strip_lengths: Vec<u32>,
    /// Strips of each row.
    pub(super) lengths: Lengths,
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
