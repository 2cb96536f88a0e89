//! Checking another engine directly: the engine runs as a child process
//! and answers the sweeps of a trace over its standard input and output, in
//! JSON lines (the protocol of `docs/ENGINE_PROTOCOL.md`).
//!
//! - [`EngineCommand`]: the command line that starts the engine;
//! - [`EngineSession`](process::EngineSession): the running engine: a
//!   writer thread feeding its stdin, a reader thread parsing its stdout,
//!   the last lines of its stderr kept for the error messages, a timeout on
//!   every answer;
//! - [`EngineAnswers`]: a trace's events with the engine's answers put in
//!   as each sweep's expectation, pipelined (up to
//!   [`EngineOptions::window`] sweeps in flight), so that `check`'s whole
//!   machinery (comparison, ties, fragility, reports) judges them.
//!
//! Every fault of the engine is an [`EngineError`] naming the engine and,
//! where there is one, the sweep: it does not start, exits early (with its
//! last stderr lines), prints a line that is not an outcome, answers
//! another sweep than the one due, or does not answer in time.

// An engine's error carries its command, the line and its last stderr
// lines; it happens once per run, so its size does not matter.
#![allow(clippy::result_large_err)]

mod answers;
mod command;
mod error;
mod process;
pub mod protocol;

pub use answers::{EngineAnswers, EngineRun};
pub use command::EngineCommand;
pub use error::EngineError;
pub use process::EngineSession;

use std::time::Duration;

/// Default time an engine has to answer the next sweep.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(10);
/// Default number of sweeps sent ahead of the engine's answers.
pub const DEFAULT_WINDOW: usize = 1024;
/// How many of the engine's last stderr lines are kept for error messages.
pub const STDERR_TAIL_LINES: usize = 10;

/// How an engine is run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineOptions {
    /// The longest wait for the next answer (and for the engine to exit
    /// once its input is closed) before the engine is stopped and the
    /// run fails with [`EngineError::Timeout`].
    pub timeout: Duration,
    /// How many sweeps may be sent before their answers are read (at
    /// least 1): the pipeline that keeps a fast engine busy.
    pub window: usize,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions {
            timeout: DEFAULT_TIMEOUT,
            window: DEFAULT_WINDOW,
        }
    }
}

/// Checks the trace at `path` against a running engine: the engine answers
/// every sweep ([`EngineAnswers`]) and the answers are the expectations of
/// an ordinary check ([`crate::regress::check_events`]): the report counts
/// and explains where the engine and the core differ, with ties and
/// fragile decisions as `check` treats them. The trace's own `/expected`
/// channel is not used.
///
/// `Err` only when the engine cannot be started; any later fault of the
/// engine is an error of the report (what was answered before it is
/// reported too).
pub fn check_file_with_engine(
    path: &std::path::Path,
    command: &EngineCommand,
    engine: EngineOptions,
    options: &crate::regress::CheckOptions,
) -> Result<crate::regress::TraceReport, EngineError> {
    let name = path.display().to_string();
    let file = match std::fs::File::open(path) {
        Ok(file) => file,
        Err(_) => {
            let mut report = crate::regress::check_file(path, options);
            report.engine = Some(command.text.clone());
            return Ok(report);
        }
    };
    let session = EngineSession::start(command, engine)?;
    let reader =
        crate::trace::TraceReader::new(std::io::BufReader::with_capacity(1 << 16, file), &name);
    let mut answers = EngineAnswers::new(reader, session, engine.window);
    let mut report = crate::regress::check_events(answers.by_ref(), &name, options);
    let run = answers.finish();
    report.engine = Some(command.text.clone());
    report.has_expected_channel = true;
    if let Some(error) = run.error {
        if error.cannot_start() {
            return Err(error);
        }
        report.add_error(error.to_string());
    }
    Ok(report)
}
