//! How many values each buffered row of a column has ([`Lengths`]), and
//! the list array of the rows built from them.

use std::sync::Arc;

use rerun::RecordingStreamError;
use rerun::external::arrow::array::{ArrayRef, ListArray};
use rerun::external::arrow::buffer::OffsetBuffer;
use rerun::external::arrow::datatypes::Field;

/// How many values each buffered row of a column has: only a count while
/// every row has exactly one (most components), which then costs nothing
/// per row; the lengths themselves from the first row that does not.
#[derive(Debug, Default)]
pub(super) struct Lengths {
    /// Rows, while every row has one value (`list` is empty then).
    ones: usize,
    /// Every row's length, once a row has not had exactly one.
    list: Vec<u32>,
}

impl Lengths {
    pub(super) fn push(&mut self, n: usize) {
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

    pub(super) fn len(&self) -> usize {
        if self.list.is_empty() {
            self.ones
        } else {
            self.list.len()
        }
    }

    /// Moves the rows of `other` to the end.
    pub(super) fn append(&mut self, other: &mut Lengths) {
        if self.list.is_empty() && other.list.is_empty() {
            self.ones += std::mem::take(&mut other.ones);
            return;
        }
        self.spell_out();
        other.spell_out();
        self.list.append(&mut other.list);
    }

    pub(super) fn bytes(&self) -> usize {
        self.list.len() * 4
    }

    /// The offsets of the rows; empties the lengths.
    pub(super) fn take_offsets(&mut self) -> OffsetBuffer<i32> {
        if self.list.is_empty() {
            OffsetBuffer::from_lengths(std::iter::repeat_n(1, std::mem::take(&mut self.ones)))
        } else {
            OffsetBuffer::from_lengths(self.list.drain(..).map(widen))
        }
    }
}

/// A length as stored (Arrow's offsets here are `i32`, so no list is near
/// `u32::MAX` long).
pub(super) fn narrow(n: usize) -> u32 {
    u32::try_from(n).expect("a list of fewer than 2^31 values")
}

pub(super) fn widen(n: u32) -> usize {
    n as usize
}

/// One list per row over `values`, `lengths` values each; empties
/// `lengths`.
pub(super) fn list_array(
    values: ArrayRef,
    lengths: &mut Lengths,
) -> Result<ListArray, RecordingStreamError> {
    let offsets = lengths.take_offsets();
    let field = Arc::new(Field::new_list_field(values.data_type().clone(), true));
    ListArray::try_new(field, offsets, values, None)
        .map_err(|e| RecordingStreamError::Chunk(e.into()))
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
