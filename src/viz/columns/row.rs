//! One row being written into the columns ([`Row`]): each component of
//! its set put in turn, strings written straight into their column
//! ([`Texts`]).

use std::any::Any;
use std::fmt;

use rerun::{Component, ComponentDescriptor};

use super::component::{Column, Strings, Strips, Typed};
use super::entity::EntityColumns;
use super::lengths::{Lengths, narrow};

/// One row being written: put each component of the set in turn.
pub(crate) struct Row<'a> {
    pub(super) entity: &'a mut EntityColumns,
    pub(super) next: usize,
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
