//! Reading ahead on a background thread keeps order, errors and memory bounds.

use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use libtest_mimic::Trial;
use sweeptrace::trace::TraceReader;
use sweeptrace::trace::prefetch::prefetch;

use crate::ensure;
use crate::trial;

/// Far above what any of these takes: reaching it means the prefetching
/// thread or its consumer is stuck.
const LIMIT: Duration = Duration::from_secs(60);

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(keeps_order_and_errors, timeout = LIMIT),
        trial!(dropping_stops_the_thread, timeout = LIMIT),
        trial!(same_events_as_the_reader, timeout = LIMIT),
    ]
}

fn keeps_order_and_errors() -> anyhow::Result<()> {
    let source = (0..10_000u32).map(|i| if i % 997 == 0 { Err(i) } else { Ok(i) });
    let want: Vec<Result<u32, u32>> = source.clone().collect();
    for (chunk, depth) in [(1, 1), (7, 2), (1024, 4), (20_000, 1)] {
        let got: Vec<_> = prefetch(source.clone(), chunk, depth)?.collect();
        ensure!(got == want, "chunk {chunk} depth {depth}: items differ");
    }
    let empty: Vec<u8> = prefetch(std::iter::empty::<u8>(), 8, 2)?.collect();
    ensure!(empty.is_empty(), "empty source yields {empty:?}");
    Ok(())
}

/// An endless source that reports when it is dropped.
struct Endless {
    next: u64,
    _dropped: std::sync::mpsc::Sender<()>,
}

impl Iterator for Endless {
    type Item = u64;
    fn next(&mut self) -> Option<u64> {
        self.next += 1;
        Some(self.next)
    }
}

fn dropping_stops_the_thread() -> anyhow::Result<()> {
    let (tx, rx) = channel();
    let source = Endless {
        next: 0,
        _dropped: tx,
    };
    let mut it = prefetch(source, 16, 2)?;
    let first: Vec<u64> = it.by_ref().take(5).collect();
    ensure!(first == vec![1, 2, 3, 4, 5], "first items {first:?}");
    drop(it);
    // The background thread ends (dropping the source, which closes the
    // channel) once its next send fails; give it a few seconds.
    match rx.recv_timeout(Duration::from_secs(10)) {
        Err(RecvTimeoutError::Disconnected) => {}
        Err(RecvTimeoutError::Timeout) => {
            return Err(anyhow::anyhow!("the source was not dropped within 10 s"));
        }
        Ok(()) => return Err(anyhow::anyhow!("the source sent a value")),
    }
    Ok(())
}

fn same_events_as_the_reader() -> anyhow::Result<()> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_mini_golf.mcap");
    let bytes = std::fs::read(&path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let direct: Vec<String> = TraceReader::new(std::io::Cursor::new(bytes.clone()), "t")
        .map(|e| format!("{e:?}"))
        .collect();
    let ahead: Vec<String> = prefetch(TraceReader::new(std::io::Cursor::new(bytes), "t"), 100, 3)?
        .map(|e| format!("{e:?}"))
        .collect();
    ensure!(direct.len() > 4000, "only {} events", direct.len());
    ensure!(direct == ahead, "events differ");
    Ok(())
}
