//! What can go wrong with an engine.

/// A fault of the engine or of talking to it. Every message names the
/// engine's command and, where there is one, the sweep that was due.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EngineError {
    /// The `--engine` command line cannot be split into words.
    #[error("the engine command `{command}` cannot be read: {reason}")]
    BadCommand {
        /// The command as given.
        command: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The engine's program could not be started (not found, not
    /// executable), or it exited with the shell's "cannot execute" / "not
    /// found" status (126, 127) before answering anything.
    #[error("the engine `{command}` cannot be started: {reason}{}", tail_text(.stderr_tail))]
    CannotStart {
        /// The command.
        command: String,
        /// Why.
        reason: String,
        /// Its last stderr lines (empty when it never ran).
        stderr_tail: Vec<String>,
    },
    /// The engine exited (or closed its output) while sweeps awaited its
    /// answers, or exited with a failure status at the end.
    #[error(
        "the engine `{command}` {how} after answering {answered} sweeps{}{}",
        due.map(|(f, b)| format!(", while frame {f}, ball {b} awaited its answer")).unwrap_or_default(),
        tail_text(.stderr_tail)
    )]
    Exited {
        /// The command.
        command: String,
        /// `exited with status 1`, `was killed by signal 11`, `closed its output`.
        how: String,
        /// Answers read before.
        answered: u64,
        /// The sweep (frame, ball) that was due, if any.
        due: Option<(u64, u32)>,
        /// Its last stderr lines.
        stderr_tail: Vec<String>,
    },
    /// A line of the engine's output is not an outcome.
    #[error(
        "the engine `{command}` printed a line that is not an outcome (output line {line_number}, {}): {reason}: `{line}`{}",
        due.map(|(f, b)| format!("where the answer to frame {f}, ball {b} was due")).unwrap_or_else(|| "after every sweep was answered".to_string()),
        tail_text(.stderr_tail)
    )]
    NotAnOutcome {
        /// The command.
        command: String,
        /// Line number of the engine's output, from 1.
        line_number: u64,
        /// The line (cut to 200 characters).
        line: String,
        /// What is wrong with it (the JSON error, with the field).
        reason: String,
        /// The sweep (frame, ball) that was due, if any.
        due: Option<(u64, u32)>,
        /// Its last stderr lines.
        stderr_tail: Vec<String>,
    },
    /// The engine answered another sweep than the one due (answers come in
    /// the order of the sweeps).
    #[error(
        "the engine `{command}` answered frame {answered_frame}, ball {answered_ball} (output line {line_number}) where the answer to frame {due_frame}, ball {due_ball} was due (answers come in the order of the sweeps, one per sweep)"
    )]
    WrongSweep {
        /// The command.
        command: String,
        /// Line number of the engine's output, from 1.
        line_number: u64,
        /// Frame of the answer.
        answered_frame: u64,
        /// Ball of the answer.
        answered_ball: u32,
        /// Frame of the sweep that was due.
        due_frame: u64,
        /// Ball of the sweep that was due.
        due_ball: u32,
    },
    /// No answer within the timeout; the engine was stopped.
    #[error(
        "the engine `{command}` did not answer frame {frame}, ball {ball} within {seconds} s (--engine-timeout); it was stopped after answering {answered} sweeps{}",
        tail_text(.stderr_tail)
    )]
    Timeout {
        /// The command.
        command: String,
        /// The timeout, in seconds.
        seconds: f64,
        /// Frame of the sweep that was due.
        frame: u64,
        /// Ball of the sweep that was due.
        ball: u32,
        /// Answers read before.
        answered: u64,
        /// Its last stderr lines.
        stderr_tail: Vec<String>,
    },
    /// The engine did not exit within the timeout once its input was closed.
    #[error(
        "the engine `{command}` answered every sweep but did not exit within {seconds} s of the end of its input; it was stopped"
    )]
    DoesNotExit {
        /// The command.
        command: String,
        /// The timeout, in seconds.
        seconds: f64,
    },
    /// Reading from or writing to the engine failed.
    #[error("the engine `{command}`: {what}: {}", crate::error_text::full_text(.cause))]
    Io {
        /// The command.
        command: String,
        /// What was being done.
        what: &'static str,
        /// The error.
        cause: std::io::Error,
    },
}

impl EngineError {
    /// Whether the engine could not be started at all (exit status 125 of
    /// the command line: `git bisect run` skips such a commit).
    pub fn cannot_start(&self) -> bool {
        matches!(
            self,
            EngineError::CannotStart { .. } | EngineError::BadCommand { .. }
        )
    }
}

/// The engine's last stderr lines, indented under the message.
fn tail_text(tail: &[String]) -> String {
    if tail.is_empty() {
        return String::new();
    }
    let mut s = String::from(" (its last stderr lines below)");
    for line in tail {
        s.push_str("\n    | ");
        s.push_str(line);
    }
    s
}
