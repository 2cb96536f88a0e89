//! Reading ahead on a second thread, so that decoding a trace overlaps the
//! work done on what was already read.
//!
//! [`prefetch`] moves an iterator (typically a [`TraceReader`]) to a
//! background thread that sends its items in chunks over a bounded channel:
//! memory stays bounded by `chunk × depth` items, and the order is kept.
//! Dropping the returned iterator stops the thread at its next send.
//!
//! [`TraceReader`]: super::TraceReader

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread;

/// Items read ahead per message on the channel.
pub const DEFAULT_PREFETCH_CHUNK: usize = 1024;
/// Chunks that may wait in the channel.
pub const DEFAULT_PREFETCH_DEPTH: usize = 4;

/// Runs `source` on a background thread, `chunk` items at a time, with at
/// most `depth` chunks waiting; the result yields the same items in the
/// same order. Fails only if the operating system cannot start a thread.
pub fn prefetch<I>(source: I, chunk: usize, depth: usize) -> std::io::Result<Prefetched<I::Item>>
where
    I: Iterator + Send + 'static,
    I::Item: Send + 'static,
{
    let chunk = chunk.max(1);
    let (tx, rx) = sync_channel::<Vec<I::Item>>(depth.max(1));
    thread::Builder::new()
        .name("trace-reader".into())
        .spawn(move || pump(source, chunk, tx))?;
    Ok(Prefetched {
        rx,
        current: Vec::new().into_iter(),
    })
}

fn pump<I: Iterator>(mut source: I, chunk: usize, tx: SyncSender<Vec<I::Item>>) {
    loop {
        let mut items = Vec::with_capacity(chunk);
        items.extend(source.by_ref().take(chunk));
        let last = items.len() < chunk;
        if !items.is_empty() && tx.send(items).is_err() {
            return; // the consumer went away
        }
        if last {
            return;
        }
    }
}

/// The iterator returned by [`prefetch`].
pub struct Prefetched<T> {
    rx: Receiver<Vec<T>>,
    current: std::vec::IntoIter<T>,
}

impl<T> Iterator for Prefetched<T> {
    type Item = T;

    fn next(&mut self) -> Option<T> {
        loop {
            if let Some(item) = self.current.next() {
                return Some(item);
            }
            let chunk = self.rx.recv().ok()?;
            self.current = chunk.into_iter();
        }
    }
}
