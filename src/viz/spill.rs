//! Rows kept on disk until a recording file is finished, so that its chunks
//! are long whatever the number of balls.
//!
//! The logger's buffer is bounded in bytes, and at each flush every entity
//! and set of components that has rows gets a chunk; with many balls, the
//! entities share the buffer and each chunk holds few rows. Every chunk
//! costs the file its Arrow schema and the footer one row of its index
//! (several KB of memory until the file is finished), so short chunks make
//! the file larger and the footer's memory grow with the trace.
//!
//! When the recording goes to a file only, each flush's chunks are written
//! here instead (to an anonymous temporary file next to the output, which
//! disappears with the process however it ends): each part's Arrow arrays
//! as they are in memory (lengths, offsets, null bits and buffers), their
//! types kept once per entity and set, not in the file; Arrow IPC wrote a
//! schema with every part and cost twice as much (BENCHMARKS.md). After
//! each flush, [`Spill::drain_ready`] sends the entities that have a chunk's
//! worth waiting ([`MAX_CHUNK_ROWS`] rows or [`MAX_CHUNK_BYTES`] bytes), so
//! the file is written while the replay goes on; at the end
//! [`Spill::drain`] sends the rest, entity after entity. Either way the
//! parts are joined into chunks of up to [`MAX_CHUNK_ROWS`] rows and about
//! [`MAX_CHUNK_BYTES`] bytes ([`SHORT_CHUNK_BYTES`] for the recording's
//! first [`SHORT_CHUNKS`] chunks). Memory: one entity's pending chunk and the
//! index of the parts (32 bytes each). The rows, their ids and their times
//! are unchanged; only the chunking and the order of the chunks in the file
//! differ (the viewer orders rows by time, and rows of equal time by row
//! id).

use std::collections::hash_map::Entry;
use std::fs::File;
use std::io::{self, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use rerun::external::arrow::array::{Array, AsArray};
use rerun::external::arrow::compute::concat;
use rustc_hash::FxHashMap;

use super::RecordError;
use super::columns::{Key, Part};
use encoding::{Arrays, Shape, read_part};

mod encoding;

/// At most this many rows per chunk of a recording written through a
/// temporary file ([`crate::viz::Logger::with_spill`]).
pub const MAX_CHUNK_ROWS: usize = 16384;

/// About this many bytes of arrays per chunk at most (a chunk is closed at
/// the first part that reaches it; the schema each part carries in the
/// temporary file is not counted).
///
/// Shorter chunks make a smaller file (likely because the chunks are
/// compressed with LZ4, whose matches reach back 64 KiB at most, and a
/// chunk lays its columns out one after the other: the same values in
/// several columns of a row, a ball's position in its balls, capsule and
/// contact, are only seen as repeats while the columns are short; not
/// verified): 512 KiB gave 458 B a
/// sweep on a 347 k-sweep session, 256 KiB 442; 4 MiB chunks (tried to
/// bound the footer) 471, and 468 against 411 on a 1.86 M-sweep one. The
/// other way, each chunk costs the footer's index about 7.5 KB of memory
/// until the file is finished (one row of every timeline and component
/// column), which grows with the trace: 256 KiB took a 9.4 M-sweep session
/// from 309 to 460 MB (BENCHMARKS.md).
pub const MAX_CHUNK_BYTES: usize = 512 << 10;

/// The first [`SHORT_CHUNKS`] chunks of a recording hold about this many
/// bytes at most instead of [`MAX_CHUNK_BYTES`]: shorter chunks make a
/// smaller file, and while they are few their entries in the footer's
/// index cost little (at most about 30 MB for all of them, whatever the
/// trace's length). A 347 k-sweep session fits in them: 458 -> 442 B a
/// sweep (BENCHMARKS.md).
pub(crate) const SHORT_CHUNK_BYTES: usize = 256 << 10;

/// How many chunks of a recording are cut at [`SHORT_CHUNK_BYTES`].
pub(crate) const SHORT_CHUNKS: usize = 4096;

/// Where a part lies in the file, its rows and the bytes of its arrays
/// (without the schema each part carries in the file).
#[derive(Clone, Copy, Debug)]
struct PartRef {
    offset: u64,
    len: u64,
    rows: usize,
    bytes: usize,
}

/// Parts of chunks written to a temporary file, by entity and set of
/// components.
#[derive(Debug)]
pub(crate) struct Spill {
    /// The recording file it is for (for messages).
    recording: PathBuf,
    file: BufWriter<File>,
    /// Bytes written so far.
    written: u64,
    /// The keys in the order they first came.
    order: Vec<Key>,
    /// The parts not sent yet, by key.
    parts: FxHashMap<Key, Vec<PartRef>>,
    /// The types of each key's lists (the same in every part of the key).
    shapes: FxHashMap<Key, Vec<Shape>>,
    /// Scratch: one part's bytes.
    buf: Vec<u8>,
    /// At most this many rows per chunk: [`MAX_CHUNK_ROWS`] unless set
    /// ([`Spill::set_max_rows`]).
    max_rows: usize,
    /// Chunks handed out so far (see [`Spill::max_bytes`]).
    chunks: usize,
}

impl Spill {
    /// A spill in an anonymous temporary file in `dir`, for the recording
    /// file `recording`.
    pub(crate) fn new(dir: &Path, recording: &Path) -> Result<Spill, RecordError> {
        let file = tempfile::tempfile_in(dir).map_err(|cause| RecordError::Spill {
            recording: recording.to_path_buf(),
            doing: "creating",
            cause,
        })?;
        Ok(Spill {
            recording: recording.to_path_buf(),
            file: BufWriter::with_capacity(1 << 20, file),
            written: 0,
            order: Vec::new(),
            parts: FxHashMap::default(),
            shapes: FxHashMap::default(),
            buf: Vec::new(),
            max_rows: MAX_CHUNK_ROWS,
            chunks: 0,
        })
    }

    /// At most `rows` rows per chunk (at least 1).
    pub(crate) fn set_max_rows(&mut self, rows: usize) {
        self.max_rows = rows.max(1);
    }

    /// About the most bytes of the next chunk: [`SHORT_CHUNK_BYTES`] for
    /// the first [`SHORT_CHUNKS`], [`MAX_CHUNK_BYTES`] after.
    fn max_bytes(&self) -> usize {
        if self.chunks < SHORT_CHUNKS {
            SHORT_CHUNK_BYTES
        } else {
            MAX_CHUNK_BYTES
        }
    }

    fn error(&self, doing: &'static str, cause: io::Error) -> RecordError {
        RecordError::Spill {
            recording: self.recording.clone(),
            doing,
            cause,
        }
    }

    /// Writes `part`, rows of `key` (later than every part of `key` written
    /// before).
    pub(crate) fn put(&mut self, key: Key, part: Part) -> Result<(), RecordError> {
        let rows = part.rows.len();
        let columns = Arrays::of(part);
        let bytes = columns.memory_size();
        let offset = self.written;
        let written = match self.shapes.entry(key) {
            Entry::Occupied(e) => columns.write(&mut self.file, e.get()),
            Entry::Vacant(e) => {
                let shapes = columns.lists.iter().map(|l| Shape::of(&l.to_data()));
                columns.write(&mut self.file, e.insert(shapes.collect()))
            }
        };
        let len = match written {
            Ok(len) => len,
            Err(cause) => return Err(self.error("writing", cause)),
        };
        self.written += len;
        let r = PartRef {
            offset,
            len,
            rows,
            bytes,
        };
        match self.parts.entry(key) {
            Entry::Occupied(mut e) => e.get_mut().push(r),
            Entry::Vacant(e) => {
                self.order.push(key);
                e.insert(vec![r]);
            }
        }
        Ok(())
    }

    /// Hands to `send` the parts of the keys that have a chunk's worth
    /// ([`MAX_CHUNK_ROWS`] rows or [`MAX_CHUNK_BYTES`] bytes) waiting, joined
    /// as [`Spill::drain`] joins them, keeping back each key's last parts
    /// that are less than a chunk; so the recording is written while the
    /// replay goes on, and the chunks stay long.
    pub(crate) fn drain_ready(
        &mut self,
        mut send: impl FnMut(Key, Part) -> Result<(), RecordError>,
    ) -> Result<(), RecordError> {
        let max_rows = self.max_rows;
        let mut flushed = false;
        for i in 0..self.order.len() {
            let key = self.order[i];
            let max_bytes = self.max_bytes();
            let ready = |refs: &[PartRef]| {
                refs.iter().map(|r| r.rows).sum::<usize>() >= max_rows
                    || refs.iter().map(|r| r.bytes).sum::<usize>() >= max_bytes
            };
            let Some(refs) = self.parts.get_mut(&key) else {
                continue;
            };
            if !ready(refs) {
                continue;
            }
            // The start of the last group of parts that is not a chunk's
            // worth: those wait for more.
            let (mut start, mut rows, mut bytes) = (0, 0, 0);
            for (j, r) in refs.iter().enumerate() {
                if rows > 0 && (rows + r.rows > max_rows || bytes + r.bytes > max_bytes) {
                    (start, rows, bytes) = (j, 0, 0);
                }
                rows += r.rows;
                bytes += r.bytes;
            }
            if rows >= max_rows || bytes >= max_bytes {
                start = refs.len();
            }
            let now: Vec<PartRef> = refs.drain(..start).collect();
            if now.is_empty() {
                continue;
            }
            if !flushed {
                if let Err(cause) = self.file.flush() {
                    return Err(self.error("writing", cause));
                }
                flushed = true;
            }
            self.emit(key, &now, &mut send, &mut |_| {})?;
        }
        Ok(())
    }

    /// Hands every part written to `send`, key after key in the order they
    /// first came, joined into parts of at most [`MAX_CHUNK_ROWS`] rows and
    /// about [`MAX_CHUNK_BYTES`] bytes; empties the spill (its file is
    /// reused).
    ///
    /// `progress` is told the bytes read back so far and the total, after
    /// each part.
    pub(crate) fn drain(
        &mut self,
        mut send: impl FnMut(Key, Part) -> Result<(), RecordError>,
        mut progress: impl FnMut(u64, u64),
    ) -> Result<(), RecordError> {
        if let Err(cause) = self.file.flush() {
            return Err(self.error("writing", cause));
        }
        let order = std::mem::take(&mut self.order);
        let mut parts = std::mem::take(&mut self.parts);
        let total: u64 = parts.values().flatten().map(|r| r.len).sum();
        let mut done = 0;
        for key in order {
            let refs = parts.remove(&key).unwrap_or_default();
            self.emit(key, &refs, &mut send, &mut |len| {
                done += len;
                progress(done, total);
            })?;
        }
        let file = self.file.get_mut();
        let emptied = file.set_len(0).and_then(|()| file.seek(SeekFrom::Start(0)));
        if let Err(cause) = emptied {
            return Err(self.error("emptying", cause));
        }
        self.written = 0;
        Ok(())
    }

    /// Reads the parts `refs` of `key` back and hands them to `send`,
    /// joined into chunks of at most `max_rows` rows and about
    /// [`MAX_CHUNK_BYTES`] bytes (a part longer than that is cut); tells
    /// `read` the bytes of each part read.
    fn emit(
        &mut self,
        key: Key,
        refs: &[PartRef],
        send: &mut impl FnMut(Key, Part) -> Result<(), RecordError>,
        read: &mut impl FnMut(u64),
    ) -> Result<(), RecordError> {
        let mut pending: Vec<Part> = Vec::new();
        let (mut rows, mut bytes) = (0usize, 0usize);
        for r in refs {
            let whole = self.read(key, r.offset, r.len)?;
            read(r.len);
            // A part longer than a chunk is cut (slices share its
            // buffers).
            let total = whole.rows.len();
            let mut start = 0;
            while start < total {
                let n = (total - start).min(self.max_rows);
                let part = slice(&whole, start, n);
                start += n;
                if rows > 0 && (rows + n > self.max_rows || bytes >= self.max_bytes()) {
                    send(key, joined(&mut pending)?)?;
                    self.chunks += 1;
                    (rows, bytes) = (0, 0);
                }
                rows += n;
                bytes += r.bytes * n / total;
                pending.push(part);
            }
        }
        if rows > 0 {
            send(key, joined(&mut pending)?)?;
            self.chunks += 1;
        }
        Ok(())
    }

    /// The part of `key` written at `offset`.
    fn read(&mut self, key: Key, offset: u64, len: u64) -> Result<Part, RecordError> {
        let file = self.file.get_mut();
        let buf = &mut self.buf;
        let read = (|| {
            file.seek(SeekFrom::Start(offset))?;
            buf.clear();
            Read::by_ref(file).take(len).read_to_end(buf)?;
            if buf.len() as u64 != len {
                return Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    "the file is shorter than what was written to it",
                ));
            }
            // Later writes go to the end.
            file.seek(SeekFrom::End(0))?;
            Ok(())
        })();
        if let Err(cause) = read {
            return Err(self.error("reading", cause));
        }
        let part = self
            .shapes
            .get(&key)
            .and_then(|shapes| read_part(&mut &self.buf[..], shapes));
        part.ok_or_else(|| {
            self.error(
                "reading",
                io::Error::new(io::ErrorKind::InvalidData, "a part does not read back"),
            )
        })
    }
}

/// Rows `start..start + n` of `part` (the lists sliced, sharing their
/// buffers).
fn slice(part: &Part, start: usize, n: usize) -> Part {
    let range = start..start + n;
    Part {
        frames: part.frames[range.clone()].to_vec(),
        times: part.times[range.clone()].to_vec(),
        rows: part.rows[range].to_vec(),
        lists: part.lists.iter().map(|l| l.slice(start, n)).collect(),
    }
}

/// The parts in `pending` (rows of one key, in order) as one, each list
/// joined with Arrow's `concat`; empties `pending`.
fn joined(pending: &mut Vec<Part>) -> Result<Part, RecordError> {
    let columns = pending.first().map_or(0, |p| p.lists.len());
    let mut lists = Vec::with_capacity(columns);
    for i in 0..columns {
        let arrays: Vec<&dyn Array> = pending.iter().map(|p| &p.lists[i] as &dyn Array).collect();
        lists.push(concat(&arrays)?.as_list::<i32>().clone());
    }
    let part = Part {
        frames: pending
            .iter()
            .flat_map(|p| p.frames.iter().copied())
            .collect(),
        times: pending
            .iter()
            .flat_map(|p| p.times.iter().copied())
            .collect(),
        rows: pending
            .iter()
            .flat_map(|p| p.rows.iter().copied())
            .collect(),
        lists,
    };
    pending.clear();
    Ok(part)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use rerun::external::arrow::array::{AsArray, Int64Array, ListArray};
    use rerun::external::arrow::buffer::OffsetBuffer;
    use rerun::external::arrow::datatypes::{Field, Int64Type};

    use rerun::external::arrow::datatypes::DataType;

    use super::{Part, Spill};
    use crate::viz::columns::Key;
    use crate::viz::paths::Entity;

    /// Rows `from..to`, each with `row % 3` values (0, 1 or 2).
    fn part(from: u64, to: u64) -> Part {
        let lengths: Vec<usize> = (from..to).map(|r| (r % 3) as usize).collect();
        let values: Vec<i64> = (from..to)
            .flat_map(|r| (0..r % 3).map(move |k| (r * 10 + k) as i64))
            .collect();
        let list = ListArray::new(
            Arc::new(Field::new_list_field(
                rerun::external::arrow::datatypes::DataType::Int64,
                true,
            )),
            OffsetBuffer::from_lengths(lengths),
            Arc::new(Int64Array::from(values)),
            None,
        );
        Part {
            frames: (from..to).map(|r| r as i64 / 4).collect(),
            times: (from..to).map(|r| r as i64 * 1000).collect(),
            rows: (from..to).collect(),
            lists: vec![list],
        }
    }

    /// The rows of `parts` as (row, frame, time, values).
    fn flat(parts: &[Part]) -> Vec<(u64, i64, i64, Vec<i64>)> {
        let mut out = Vec::new();
        for p in parts {
            for i in 0..p.rows.len() {
                let v = p.lists[0].value(i);
                let v = v.as_primitive::<Int64Type>().values().to_vec();
                out.push((p.rows[i], p.frames[i], p.times[i], v));
            }
        }
        out
    }

    /// A part whose lists are of every layout the rows use (numbers with
    /// nulls, strings, lists of fixed-size lists, a slice of a longer array)
    /// comes back equal, as Arrow sees it, with its times and row numbers.
    #[test]
    fn a_part_of_every_layout_reads_back_equal() {
        use rerun::external::arrow::array::{
            Array, FixedSizeListArray, Float32Array, Float64Array, StringArray,
        };
        let list = |values: Arc<dyn Array>, lengths: &[usize]| {
            ListArray::new(
                Arc::new(Field::new_list_field(values.data_type().clone(), true)),
                OffsetBuffer::from_lengths(lengths.iter().copied()),
                values,
                None,
            )
        };
        let numbers = Float64Array::from(vec![Some(1.5), None, Some(-0.0), Some(f64::NAN)]);
        let texts = StringArray::from(vec!["edge 3.1", "", "hit"]);
        let points = Float32Array::from((0..12).map(|i| i as f32).collect::<Vec<_>>());
        let item = Arc::new(Field::new_list_field(DataType::Float32, false));
        let points = FixedSizeListArray::new(item, 3, Arc::new(points), None);
        let strips = list(Arc::new(points), &[2, 0, 1, 1]);
        // Longer than the part, and sliced: an offset into its buffers.
        let long = Float64Array::from((0..20).map(f64::from).collect::<Vec<_>>());
        let sliced = list(Arc::new(long), &[5, 5, 5, 5]).slice(1, 3);
        let lists = vec![
            list(Arc::new(numbers), &[1, 1, 2]),
            list(Arc::new(texts), &[2, 0, 1]),
            strips.slice(0, 3),
            sliced,
        ];
        let original = Part {
            frames: vec![3, 3, 4],
            times: vec![-7, 0, 9],
            rows: vec![10, 11, 12],
            lists: lists.clone(),
        };
        let dir = tempfile::tempdir().unwrap();
        let mut spill = Spill::new(dir.path(), &dir.path().join("x.rrd")).unwrap();
        let key = Key::for_test(Entity::Log, 0);
        spill.put(key, original).unwrap();
        let mut got = Vec::new();
        spill
            .drain(
                |k, p| {
                    got.push((k, p));
                    Ok(())
                },
                |_, _| {},
            )
            .unwrap();
        assert_eq!(got.len(), 1);
        let (k, p) = &got[0];
        assert_eq!(*k, key);
        assert_eq!(
            (&p.frames[..], &p.times[..]),
            (&[3, 3, 4][..], &[-7, 0, 9][..])
        );
        assert_eq!(p.rows, [10, 11, 12]);
        assert_eq!(p.lists.len(), lists.len());
        for (i, (a, b)) in p.lists.iter().zip(&lists).enumerate() {
            assert_eq!(a.data_type(), b.data_type(), "list {i}");
            // NaN is not equal to itself: compare the debug texts.
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "list {i}");
        }
    }

    /// Parts of two keys, interleaved and of uneven lengths, some longer
    /// than a chunk, come back per key in order, whole, joined or cut into
    /// chunks of at most the limit; the file is reusable; sending what is
    /// ready along the way (round 1) changes nothing of that.
    #[test]
    fn parts_come_back_per_key_joined_and_cut() {
        let dir = tempfile::tempdir().unwrap();
        let mut spill = Spill::new(dir.path(), &dir.path().join("x.rrd")).unwrap();
        spill.set_max_rows(10);
        let (a, b) = (
            Key::for_test(Entity::Log, 0),
            Key::for_test(Entity::Divergences, 0),
        );
        let cuts_a = [0u64, 3, 7, 30, 31, 40, 42, 44, 47, 49, 52];
        let cuts_b = [100u64, 104, 125];
        for round in 0..2 {
            let mut got: Vec<(Key, Part)> = Vec::new();
            let (mut ia, mut ib) = (cuts_a.windows(2), cuts_b.windows(2));
            loop {
                let (wa, wb) = (ia.next(), ib.next());
                if wa.is_none() && wb.is_none() {
                    break;
                }
                if let Some(w) = wa {
                    spill.put(a, part(w[0], w[1])).unwrap();
                }
                if let Some(w) = wb {
                    spill.put(b, part(w[0], w[1])).unwrap();
                }
                if round == 1 {
                    spill
                        .drain_ready(|k, p| {
                            got.push((k, p));
                            Ok(())
                        })
                        .unwrap();
                }
            }
            let early = got.len();
            let mut last = (0, 0);
            spill
                .drain(
                    |k, p| {
                        got.push((k, p));
                        Ok(())
                    },
                    |done, total| last = (done, total),
                )
                .unwrap();
            assert!(last.0 > 0 && last.0 == last.1, "progress {last:?}");
            assert_eq!(early > 0, round == 1, "round {round}: {early} sent early");
            let of = |k: Key| -> Vec<Part> {
                got.iter()
                    .filter(|(g, _)| *g == k)
                    .map(|(_, p)| Part {
                        frames: p.frames.clone(),
                        times: p.times.clone(),
                        rows: p.rows.clone(),
                        lists: p.lists.clone(),
                    })
                    .collect()
            };
            assert!(got.iter().all(|(_, p)| p.rows.len() <= 10), "round {round}");
            assert_eq!(flat(&of(a)), flat(&[part(0, 52)]), "round {round}");
            assert_eq!(flat(&of(b)), flat(&[part(100, 125)]), "round {round}");
            for k in [a, b] {
                let lengths: Vec<usize> = of(k).iter().map(|p| p.rows.len()).collect();
                if round == 0 {
                    // Joined as far as the limit allows: no two neighbours
                    // would fit in one chunk.
                    assert!(
                        lengths.windows(2).all(|w| w[0] + w[1] > 10),
                        "round {round}: {lengths:?}"
                    );
                } else {
                    // Sent early only a chunk's worth at a time: at most one
                    // short chunk more per early sending.
                    let rows: usize = lengths.iter().sum();
                    assert!(lengths.len() <= 2 * rows.div_ceil(10), "{lengths:?}");
                }
            }
            if round == 0 {
                // Key a's chunks before key b's.
                let first_b = got.iter().position(|(k, _)| *k == b).unwrap();
                assert!(got[..first_b].iter().all(|(k, _)| *k == a));
            }
        }
    }
}
