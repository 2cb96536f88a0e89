//! `replay`'s reading and its progress: the trace decoded ahead through a
//! count of the bytes read so far, the bar on stderr that shows them, and
//! the worker threads.

use std::fs::File;
use std::io::{BufReader, IsTerminal, Read};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sweeptrace::trace::prefetch::{
    DEFAULT_PREFETCH_CHUNK, DEFAULT_PREFETCH_DEPTH, Prefetched, prefetch,
};
use sweeptrace::trace::{TraceError, TraceEvent, TraceReader};

/// The trace's events, decoded on a thread of their own.
type ReadAhead = Prefetched<Result<TraceEvent, TraceError>>;

/// The trace in `file` decoded ahead (in log-time order, through the chunk
/// indexes when it has them), a progress bar saying `what`, and the count
/// of bytes read that moves it.
pub(super) fn read_with_progress(
    file: File,
    total_bytes: u64,
    source_name: &str,
    what: &str,
) -> anyhow::Result<(ReadAhead, ProgressBar, Arc<AtomicU64>)> {
    let count = Arc::new(AtomicU64::new(0));
    let reader = CountingReader {
        inner: BufReader::with_capacity(1 << 16, file),
        count: count.clone(),
    };
    let progress = progress_bar(total_bytes, what);
    // Decode on a thread of its own, so reading overlaps the core's work.
    let read_ahead = prefetch(
        TraceReader::new_indexed(reader, source_name),
        DEFAULT_PREFETCH_CHUNK,
        DEFAULT_PREFETCH_DEPTH,
    )
    .context("starting the trace reader thread")?;
    Ok((read_ahead, progress, count))
}

/// Counts bytes read, for the progress bar.
struct CountingReader<R> {
    inner: R,
    count: Arc<AtomicU64>,
}

/// Seeking (to the summary, and to chunks when a trace is read through
/// its chunk indexes) counts nothing: only bytes read.
impl<R: std::io::Seek> std::io::Seek for CountingReader<R> {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        self.inner.seek(to)
    }
}

impl<R: Read> Read for CountingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
}

/// A progress bar on stderr (hidden when stderr is not a terminal): `what`,
/// then the bar, bytes and time left.
pub(super) fn progress_bar(total_bytes: u64, what: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(total_bytes), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(&format!(
        "{{spinner}} {what} [{{bar:40}}] {{bytes}}/{{total_bytes}} ({{eta}})"
    )) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// The worker threads of the replay: `threads` of them, or one per core.
pub(super) fn worker_pool(threads: Option<usize>) -> anyhow::Result<Arc<rayon::ThreadPool>> {
    if threads == Some(0) {
        anyhow::bail!("--threads must be at least 1");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("starting the worker threads")?;
    Ok(Arc::new(pool))
}
