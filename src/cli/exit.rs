//! How a command ended, as one value; [`Exit::exit_code`] is the
//! one place that turns it into the process's exit code (the README's
//! table lists the same codes). The library's reports give their own
//! status (`suite::Status`, `conform::ConformStatus`); the commands map
//! it to an `Exit`.

use serde::Serialize;

/// What a command came to. Ordered by severity: when a command handles
/// several inputs, the most severe outcome is the command's
/// ([`Exit::worst`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Exit {
    /// Everything was processed and nothing differs. Exit code 0.
    Success,
    /// Everything was processed and differences were found (`check`: a
    /// sweep diverges from its expectation; `diff`: the two sides differ).
    /// Exit code 1.
    Differences,
    /// A trace ends early (it is truncated): what was read before the end
    /// was processed and written, the rest is missing. Exit code 3.
    IncompleteInput,
    /// An input could not be processed (a bad argument, a file that cannot
    /// be read or written, an invalid trace, nothing to compare). Exit code 2.
    Error,
    /// The engine to check (`check --engine`, `conform`) cannot be started:
    /// its program is not found or not executable. Exit code 125, which
    /// `git bisect run` takes as "this commit cannot be tested, skip it".
    EngineUnavailable,
}

impl Exit {
    /// The process exit code: 0 success, 1 differences found, 2 error,
    /// 3 incomplete input, 125 the engine cannot be started.
    pub const fn exit_code(self) -> u8 {
        match self {
            Exit::Success => 0,
            Exit::Differences => 1,
            Exit::Error => 2,
            Exit::IncompleteInput => 3,
            Exit::EngineUnavailable => 125,
        }
    }

    /// The most severe of `outcomes` ([`Exit::Success`] when empty).
    pub fn worst(outcomes: impl IntoIterator<Item = Exit>) -> Exit {
        outcomes.into_iter().max().unwrap_or(Exit::Success)
    }
}
