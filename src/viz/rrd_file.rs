//! The `.rrd` file writer: a [`LogSink`] of ours that encodes every message
//! into the file on the stream's own thread and keeps the first write error,
//! so a full disk, a vanished directory or any other I/O failure ends the
//! command with the file's name and the operating system's reason.
//!
//! The SDK's `FileSink` writes on a thread of its own; when that thread dies
//! on an error (`No space left on device`), the stream's flush waits for it
//! without end and the cause is lost. Here nothing waits on a thread that may
//! be gone: a write error stops further writes, every later message is
//! dropped, flushing returns at once, and [`RrdFileWriter::finish`] reports
//! the error.
//!
//! The file ends with a footer unless told otherwise
//! ([`RrdFileOptions::footer`]). The SDK's encoder builds the footer's index
//! in memory, one row per chunk with a column per timeline and component
//! type (the memory per chunk is measured in BENCHMARKS.md), until the file
//! is finished, so that memory grows with the trace's length; without the
//! footer the writer's memory is bounded, but `rerun rrd verify` (0.36.3)
//! rejects the file ("Missing RRD footer").

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use rerun::external::re_log_encoding::{CrateVersion, EncodeError, Encoder, EncodingOptions};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};
use thiserror::Error;

/// Writing a recording file failed.
#[derive(Debug, Error)]
#[error("writing the recording {}: {reason}", path.display())]
pub struct RrdFileError {
    /// The file being written.
    pub path: PathBuf,
    /// The first error, in words (the operating system's reason for an I/O
    /// error).
    pub reason: String,
}

struct State {
    encoder: Option<Encoder<BufWriter<File>>>,
    error: Option<String>,
}

/// How the file is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RrdFileOptions {
    /// Write the footer (the default): an index of every chunk (entity,
    /// time ranges, byte offsets) at the end of the file, which lets a
    /// reader locate chunks without reading the whole file. Built in memory
    /// while the file is written, a row per chunk (see the module's doc).
    pub footer: bool,
}

impl Default for RrdFileOptions {
    fn default() -> Self {
        RrdFileOptions { footer: true }
    }
}

/// The sink to hand to the recording stream ([`rerun::RecordingStreamBuilder`]'s
/// `set_sinks`).
pub struct RrdFileSink {
    state: Arc<Mutex<State>>,
}

/// Finishes the file once the recording stream is flushed and dropped.
pub struct RrdFileWriter {
    state: Arc<Mutex<State>>,
    path: PathBuf,
}

/// Creates `path` and starts an `.rrd` stream in it (compressed; with the
/// footer when `options` ask for it).
pub fn create_rrd_file(
    path: &Path,
    options: RrdFileOptions,
) -> Result<(RrdFileSink, RrdFileWriter), RrdFileError> {
    let error = |reason: String| RrdFileError {
        path: path.to_path_buf(),
        reason,
    };
    let file = File::create(path).map_err(|e| error(e.to_string()))?;
    let mut encoder = Encoder::new_eager(
        CrateVersion::LOCAL,
        EncodingOptions::PROTOBUF_COMPRESSED,
        BufWriter::with_capacity(1 << 20, file),
    )
    .map_err(|e| error(reason_of(&e)))?;
    if !options.footer {
        encoder.do_not_emit_footer();
    }
    let state = Arc::new(Mutex::new(State {
        encoder: Some(encoder),
        error: None,
    }));
    Ok((
        RrdFileSink {
            state: state.clone(),
        },
        RrdFileWriter {
            state,
            path: path.to_path_buf(),
        },
    ))
}

/// The reason of an encoder error: the I/O error's own text when it is one
/// (without the encoder's "Failed to write:" prefix).
fn reason_of(err: &EncodeError) -> String {
    match err {
        EncodeError::Write(io) => io.to_string(),
        other => other.to_string(),
    }
}

fn lock(state: &Mutex<State>) -> MutexGuard<'_, State> {
    // A panic while holding the lock leaves the state as it was: still usable.
    state
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl State {
    /// Records the first error and stops writing. The encoder is unwrapped
    /// rather than dropped, so it does not try to write its footer.
    fn fail(&mut self, reason: String) {
        if self.error.is_none() {
            self.error = Some(reason);
        }
        if let Some(encoder) = self.encoder.take() {
            let _ = encoder.into_inner();
        }
    }
}

impl LogSink for RrdFileSink {
    fn send(&self, msg: LogMsg) {
        let mut state = lock(&self.state);
        let Some(encoder) = state.encoder.as_mut() else {
            return;
        };
        if let Err(err) = encoder.append(&msg) {
            state.fail(reason_of(&err));
        }
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        let mut state = lock(&self.state);
        if let Some(encoder) = state.encoder.as_mut()
            && let Err(err) = encoder.flush_blocking()
        {
            state.fail(reason_of(&err));
        }
        // Errors are reported by `RrdFileWriter::finish`, not here: the
        // stream would only log them.
        Ok(())
    }
}

impl RrdFileWriter {
    /// Writes the footer, flushes and syncs the file; or the first error
    /// met while writing. Call it after the recording stream is flushed and
    /// every clone of it dropped.
    pub fn finish(self) -> Result<(), RrdFileError> {
        let mut state = lock(&self.state);
        let result = (|| -> Result<(), String> {
            if let Some(reason) = state.error.take() {
                return Err(reason);
            }
            let mut encoder = state
                .encoder
                .take()
                .ok_or_else(|| "the recording was already finished".to_string())?;
            encoder.finish().map_err(|e| reason_of(&e))?;
            let writer = encoder.into_inner().map_err(|e| reason_of(&e))?;
            crate::atomic::seal(writer).map_err(|e| e.cause.to_string())
        })();
        result.map_err(|reason| RrdFileError {
            path: self.path.clone(),
            reason,
        })
    }
}
