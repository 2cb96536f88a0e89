//! Checking another engine directly: the engine runs as a child process
//! and answers the sweeps of a trace over its standard input and output, in
//! JSON lines (the protocol of `docs/ENGINE_PROTOCOL.md`).
//!
//! - [`EngineCommand`]: the command line that starts the engine;
//! - [`EngineSession`]: the running engine: a
//!   writer thread feeding its stdin, a reader thread parsing its stdout,
//!   the last lines of its stderr kept for the error messages, a timeout on
//!   every answer;
//! - [`stop_running_engines`]: every running engine's process group
//!   stopped, for a process ending on a signal (the command line's signal
//!   thread calls it);
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
mod groups;
mod process;
pub mod protocol;

pub(crate) use answers::AnswerSink;
pub use answers::{EngineAnswers, EngineRun};
pub use command::EngineCommand;
pub use error::EngineError;
pub use groups::{STOP_GRACE, stop_running_engines};
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
    /// Whether the engine answers contact queries: a trace's `/contact`
    /// queries are then sent to it and its answers replace the trace's
    /// `/expected_contacts` (`check --engine-contacts`).
    pub contacts: bool,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions {
            timeout: DEFAULT_TIMEOUT,
            window: DEFAULT_WINDOW,
            contacts: false,
        }
    }
}
