//! The running engine: a child process, a writer thread feeding its stdin,
//! a reader thread splitting its stdout into lines, a thread keeping the
//! last lines of its stderr, and (Unix) a thread waiting for the engine to
//! exit.
//!
//! The engine leads a process group of its own, registered process-wide
//! ([`super::groups`]) while it runs. It starts with no signal blocked (the
//! command line blocks SIGINT and SIGTERM in its own threads, and a child
//! inherits the mask). Its exit is noticed by itself, not only through the
//! end of its stdout, which a process it started may hold open; the
//! leader is reaped only after its whole group was killed, so that nothing
//! it started outlives it and the group's id cannot be another's when it
//! is signalled.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::trace::{ContactMsg, ContactsMsg, OutcomeMsg, SceneMsg, SweepMsg};

use super::groups::{self, Group};
use super::protocol::{
    MAX_ANSWER_BYTES, contact_line, parse_answer, parse_contacts, scene_line, sweep_line,
};
use super::{EngineCommand, EngineError, EngineOptions, STDERR_TAIL_LINES};

/// What the reader thread saw on the engine's stdout.
enum Output {
    Line(Vec<u8>),
    TooLong,
    End,
    Failed(std::io::Error),
    /// The engine (the group's leader) has exited; it is not reaped yet.
    /// Its stdout may still be open, held by a process it started.
    LeaderExited,
}

/// The last lines of the engine's stderr, shared with the thread reading it.
#[derive(Clone, Default)]
struct StderrTail {
    lines: Arc<Mutex<(VecDeque<String>, bool)>>,
}

impl StderrTail {
    fn push(&self, line: String) {
        if let Ok(mut guard) = self.lines.lock() {
            let (lines, _) = &mut *guard;
            if lines.len() == STDERR_TAIL_LINES {
                lines.pop_front();
            }
            lines.push_back(line);
        }
    }

    fn close(&self) {
        if let Ok(mut guard) = self.lines.lock() {
            guard.1 = true;
        }
    }

    /// The lines so far, after waiting up to `wait` for the stream's end
    /// (an engine that crashed has usually written its last words).
    fn snapshot(&self, wait: Duration) -> Vec<String> {
        let deadline = Instant::now() + wait;
        loop {
            let closed = self.lines.lock().map(|g| g.1).unwrap_or(true);
            if closed || Instant::now() >= deadline {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        self.lines
            .lock()
            .map(|g| g.0.iter().cloned().collect())
            .unwrap_or_default()
    }
}

/// A running engine. Dropping it stops the engine if it still runs, and
/// every process left in its process group.
pub struct EngineSession {
    command: EngineCommand,
    options: EngineOptions,
    child: Child,
    /// Set once the engine has exited (by the thread waiting for it).
    exited: Arc<AtomicBool>,
    /// Once reaped: how it ended (`None` inside when the wait failed).
    reaped: Option<Option<ExitStatus>>,
    to_engine: Option<Sender<String>>,
    from_engine: Receiver<Output>,
    stderr: StderrTail,
    /// Output lines read, for messages.
    lines_read: u64,
    /// Answers read.
    answered: u64,
}

impl std::fmt::Debug for EngineSession {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EngineSession")
            .field("command", &self.command.text)
            .field("answered", &self.answered)
            .finish_non_exhaustive()
    }
}

impl EngineSession {
    /// Starts the engine. [`EngineError::CannotStart`] when its program
    /// cannot be run.
    pub fn start(
        command: &EngineCommand,
        options: EngineOptions,
    ) -> Result<EngineSession, EngineError> {
        let mut engine = Command::new(&command.program);
        engine
            .args(&command.arguments)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        // A process group of its own, so that stopping the engine stops
        // what it started too (an engine run through `sh -c` is the shell's
        // child: killing the shell alone would leave it running).
        #[cfg(unix)]
        {
            use std::os::unix::process::CommandExt;
            engine.process_group(0);
            // The command line blocks SIGINT and SIGTERM in every thread
            // (a thread of its own waits for them), and `Command` leaves
            // the child that mask: an engine would ignore `kill`, `timeout`
            // and a CI runner's SIGTERM.
            // SAFETY: the closure runs in the child between fork and exec,
            // and calls only sigemptyset and sigprocmask, which are
            // async-signal-safe, on a set of its own.
            unsafe {
                engine.pre_exec(|| {
                    let mut set: libc::sigset_t = std::mem::zeroed();
                    libc::sigemptyset(&mut set);
                    if libc::sigprocmask(libc::SIG_SETMASK, &set, std::ptr::null_mut()) != 0 {
                        return Err(std::io::Error::last_os_error());
                    }
                    Ok(())
                });
            }
        }
        // Started and registered under the registry's lock: a signal that
        // ends this process finds every engine it started.
        let mut registry = groups::lock();
        let mut child = engine.spawn().map_err(|e| EngineError::CannotStart {
            command: command.text.clone(),
            reason: format!("{}: {e}", command.program),
            stderr_tail: Vec::new(),
        })?;
        let exited = Arc::new(AtomicBool::new(false));
        registry.push(Group {
            id: child.id(),
            exited: exited.clone(),
        });
        drop(registry);
        let io_error = |what, cause| EngineError::Io {
            command: command.text.clone(),
            what,
            cause,
        };
        let missing = || std::io::Error::other("the pipe was not created");
        let stdin = child
            .stdin
            .take()
            .ok_or_else(|| io_error("stdin", missing()))?;
        let stdout = child
            .stdout
            .take()
            .ok_or_else(|| io_error("stdout", missing()))?;
        let stderr = child
            .stderr
            .take()
            .ok_or_else(|| io_error("stderr", missing()))?;
        let (to_engine, lines_to_write) = mpsc::channel::<String>();
        let (output, from_engine) = mpsc::channel::<Output>();
        let tail = StderrTail::default();
        let spawn = |name: &str, f: Box<dyn FnOnce() + Send>| {
            std::thread::Builder::new()
                .name(name.to_string())
                .spawn(f)
                .map_err(|e| io_error("starting a thread", e))
        };
        #[cfg(unix)]
        let leader = (child.id(), exited.clone(), output.clone());
        let session = EngineSession {
            command: command.clone(),
            options,
            child,
            exited,
            reaped: None,
            to_engine: Some(to_engine),
            from_engine,
            stderr: tail.clone(),
            lines_read: 0,
            answered: 0,
        };
        spawn(
            "engine stdin",
            Box::new(move || write_lines(stdin, lines_to_write)),
        )?;
        spawn(
            "engine stdout",
            Box::new(move || read_lines(stdout, output)),
        )?;
        spawn("engine stderr", Box::new(move || keep_tail(stderr, tail)))?;
        #[cfg(unix)]
        spawn(
            "engine exit",
            Box::new(move || wait_for_leader(leader.0, &leader.1, &leader.2)),
        )?;
        // The threads run until the pipes close; a failure to start one
        // drops the session, which stops the engine.
        Ok(session)
    }

    /// The command.
    pub fn command(&self) -> &EngineCommand {
        &self.command
    }

    /// Answers read so far.
    pub fn answered(&self) -> u64 {
        self.answered
    }

    /// Sends a scene (the engine does not answer it).
    pub fn send_scene(&mut self, scene: &SceneMsg) -> Result<(), EngineError> {
        let line = scene_line(scene).map_err(|e| self.io("encoding a scene", e.into()))?;
        self.send(line);
        Ok(())
    }

    /// Sends a sweep; its answer comes later, in order ([`Self::next_answer`]).
    pub fn send_sweep(&mut self, sweep: &SweepMsg) -> Result<(), EngineError> {
        let line = sweep_line(sweep).map_err(|e| self.io("encoding a sweep", e.into()))?;
        self.send(line);
        Ok(())
    }

    /// Sends a contact query; its answer comes later, in order with the
    /// sweeps' ([`Self::next_contacts`]).
    pub fn send_contact(&mut self, contact: &ContactMsg) -> Result<(), EngineError> {
        let line =
            contact_line(contact).map_err(|e| self.io("encoding a contact query", e.into()))?;
        self.send(line);
        Ok(())
    }

    fn send(&mut self, line: String) {
        // A writer that has gone (the engine closed its input) shows up as
        // the engine's exit or silence when its answer is awaited.
        if let Some(tx) = &self.to_engine {
            let _ = tx.send(line);
        }
    }

    fn io(&self, what: &'static str, cause: std::io::Error) -> EngineError {
        EngineError::Io {
            command: self.command.text.clone(),
            what,
            cause,
        }
    }

    /// The answer to the sweep `due` (frame, ball): the engine's next output
    /// line, which must be an outcome of that sweep, within the timeout.
    pub fn next_answer(&mut self, due: (u64, u32)) -> Result<OutcomeMsg, EngineError> {
        self.next_line(due, parse_answer, |a| (a.frame, a.ball))
    }

    /// The answer to the contact query `due` (frame, ball): the engine's
    /// next output line, which must be the contacts of that query, within
    /// the timeout.
    pub fn next_contacts(&mut self, due: (u64, u32)) -> Result<ContactsMsg, EngineError> {
        self.next_line(due, parse_contacts, |c| (c.frame, c.ball))
    }

    /// The engine's next output line, parsed by `parse` as the answer to
    /// `due` (whose frame and ball `key` reads), within the timeout.
    fn next_line<T>(
        &mut self,
        due: (u64, u32),
        parse: fn(&[u8]) -> Result<T, String>,
        key: fn(&T) -> (u64, u32),
    ) -> Result<T, EngineError> {
        let deadline = Instant::now() + self.options.timeout;
        match self.receive(deadline) {
            Ok(Output::Line(line)) => {
                self.lines_read += 1;
                let answer =
                    parse(&line).map_err(|reason| self.not_an_outcome(&line, reason, Some(due)))?;
                let (answered_frame, answered_ball) = key(&answer);
                if (answered_frame, answered_ball) != due {
                    return Err(EngineError::WrongSweep {
                        command: self.command.text.clone(),
                        line_number: self.lines_read,
                        answered_frame,
                        answered_ball,
                        due_frame: due.0,
                        due_ball: due.1,
                    });
                }
                self.answered += 1;
                Ok(answer)
            }
            Ok(Output::TooLong) => {
                self.lines_read += 1;
                Err(self.not_an_outcome(
                    b"",
                    format!("it is longer than {MAX_ANSWER_BYTES} bytes"),
                    Some(due),
                ))
            }
            Ok(Output::Failed(e)) => Err(self.io("reading its output", e)),
            Ok(Output::End | Output::LeaderExited) | Err(RecvTimeoutError::Disconnected) => {
                Err(self.ended(Some(due)))
            }
            Err(RecvTimeoutError::Timeout) => {
                self.stop();
                Err(EngineError::Timeout {
                    command: self.command.text.clone(),
                    seconds: self.options.timeout.as_secs_f64(),
                    frame: due.0,
                    ball: due.1,
                    answered: self.answered,
                    stderr_tail: self.stderr.snapshot(Duration::from_millis(200)),
                })
            }
        }
    }

    /// The engine's next output before `deadline`. When the engine exits,
    /// what is left of its group is killed and its output read on: what
    /// it wrote before it exited is still there, and the end of its output
    /// follows, even when a process it started held it open.
    fn receive(&mut self, deadline: Instant) -> Result<Output, RecvTimeoutError> {
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.from_engine.recv_timeout(left) {
                Ok(Output::LeaderExited) => self.kill_what_it_left(),
                other => return other,
            }
        }
    }

    fn not_an_outcome(
        &mut self,
        line: &[u8],
        reason: String,
        due: Option<(u64, u32)>,
    ) -> EngineError {
        let text = String::from_utf8_lossy(line);
        let cut: String = text.trim_end().chars().take(200).collect();
        self.stop();
        EngineError::NotAnOutcome {
            command: self.command.text.clone(),
            line_number: self.lines_read,
            line: cut,
            reason,
            due,
            stderr_tail: self.stderr.snapshot(Duration::from_millis(200)),
        }
    }

    /// The engine closed its output: how it ended.
    fn ended(&mut self, due: Option<(u64, u32)>) -> EngineError {
        let status = self.wait_for_exit(self.options.timeout);
        let stderr_tail = self.stderr.snapshot(Duration::from_millis(500));
        let how = match status {
            Some(s) => describe_status(s),
            None => {
                self.stop();
                "closed its output".to_string()
            }
        };
        let shell_cannot_run = status
            .and_then(|s| s.code())
            .is_some_and(|c| c == 126 || c == 127);
        if self.answered == 0 && shell_cannot_run {
            return EngineError::CannotStart {
                command: self.command.text.clone(),
                reason: how,
                stderr_tail,
            };
        }
        EngineError::Exited {
            command: self.command.text.clone(),
            how,
            answered: self.answered,
            due,
            stderr_tail,
        }
    }

    /// Closes the engine's input and waits for it to exit: every sweep has
    /// been answered, so any further output line, a failure status or not
    /// exiting within the timeout is a fault.
    pub fn finish(mut self) -> Result<(), EngineError> {
        self.to_engine = None;
        let deadline = Instant::now() + self.options.timeout;
        match self.receive(deadline) {
            Ok(Output::Line(line)) => {
                self.lines_read += 1;
                let reason = "every sweep was already answered".to_string();
                return Err(self.not_an_outcome(&line, reason, None));
            }
            Ok(Output::TooLong) => {
                self.lines_read += 1;
                let reason = "every sweep was already answered".to_string();
                return Err(self.not_an_outcome(b"", reason, None));
            }
            Ok(Output::Failed(e)) => return Err(self.io("reading its output", e)),
            Ok(Output::End | Output::LeaderExited) | Err(RecvTimeoutError::Disconnected) => {}
            Err(RecvTimeoutError::Timeout) => {
                self.stop();
                return Err(EngineError::DoesNotExit {
                    command: self.command.text.clone(),
                    seconds: self.options.timeout.as_secs_f64(),
                });
            }
        }
        let left = deadline.saturating_duration_since(Instant::now());
        match self.wait_for_exit(left) {
            Some(status) if status.success() => Ok(()),
            Some(_) => Err(self.ended(None)),
            None => {
                self.stop();
                Err(EngineError::DoesNotExit {
                    command: self.command.text.clone(),
                    seconds: self.options.timeout.as_secs_f64(),
                })
            }
        }
    }

    /// Waits up to `limit` for the engine to exit; then kills what is
    /// left of its group and reaps it.
    fn wait_for_exit(&mut self, limit: Duration) -> Option<ExitStatus> {
        let deadline = Instant::now() + limit;
        loop {
            if let Some(reaped) = self.reaped {
                return reaped;
            }
            if self.leader_exited() {
                return self.reap();
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Whether the engine has exited (it may not be reaped yet).
    fn leader_exited(&mut self) -> bool {
        if self.exited.load(Ordering::SeqCst) {
            return true;
        }
        // Without a thread waiting for it (not Unix), ask.
        #[cfg(not(unix))]
        if let Ok(Some(_)) = self.child.try_wait() {
            return true;
        }
        false
    }

    /// Kills the processes left in the engine's group once the engine has
    /// exited (those it started, which may hold its stdout open).
    fn kill_what_it_left(&mut self) {
        if self.reaped.is_none() {
            // The leader is not reaped: its pid keeps the group's id.
            self.kill_group();
        }
    }

    /// SIGKILL to the engine's whole process group (its id is the
    /// leader's pid, `process_group(0)`), when the leader is not reaped.
    fn kill_group(&mut self) {
        #[cfg(unix)]
        if let Ok(group) = libc::pid_t::try_from(self.child.id()) {
            // SAFETY: killpg only sends a signal; no memory is involved.
            unsafe {
                libc::killpg(group, libc::SIGKILL);
            }
        }
        #[cfg(not(unix))]
        let _ = self.child.kill();
    }

    /// Kills the engine's group (the engine if it still runs, and always
    /// what it started) and reaps the engine, once; how it ended.
    fn reap(&mut self) -> Option<ExitStatus> {
        if let Some(reaped) = self.reaped {
            return reaped;
        }
        // Under the registry's lock: the signal thread never signals the
        // group once its id may be another's.
        let mut registry = groups::lock();
        self.kill_group();
        let status = self.child.wait().ok();
        groups::remove(&mut registry, self.child.id());
        drop(registry);
        self.reaped = Some(status);
        status
    }

    /// Stops the engine (if it still runs) with every process of its group,
    /// and reaps it.
    fn stop(&mut self) {
        self.to_engine = None;
        self.reap();
    }
}

impl Drop for EngineSession {
    fn drop(&mut self) {
        self.stop();
    }
}

/// `exited with status 1`, `was killed by signal 9 (SIGKILL)`.
fn describe_status(status: ExitStatus) -> String {
    if let Some(code) = status.code() {
        return format!("exited with status {code}");
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = status.signal() {
            let name = match signal {
                6 => " (SIGABRT)",
                9 => " (SIGKILL)",
                11 => " (SIGSEGV)",
                13 => " (SIGPIPE)",
                15 => " (SIGTERM)",
                _ => "",
            };
            return format!("was killed by signal {signal}{name}");
        }
    }
    format!("ended ({status})")
}

/// The thread waiting for the engine (the group's leader) to exit: it
/// says so without reaping it (`WNOWAIT`), so the leader's pid keeps the
/// group's id until [`EngineSession`] has killed the group and reaps it.
/// Ends when the engine has exited or has been reaped already.
#[cfg(unix)]
fn wait_for_leader(pid: u32, exited: &AtomicBool, output: &Sender<Output>) {
    let id = libc::id_t::from(pid);
    loop {
        // SAFETY: `info` is a valid out pointer, zeroed as waitid expects.
        let done = unsafe {
            let mut info: libc::siginfo_t = std::mem::zeroed();
            libc::waitid(libc::P_PID, id, &mut info, libc::WEXITED | libc::WNOWAIT)
        };
        if done == 0 {
            exited.store(true, Ordering::SeqCst);
            let _ = output.send(Output::LeaderExited);
            return;
        }
        if std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted {
            // ECHILD: reaped already.
            return;
        }
    }
}

/// The writer thread: lines to the engine's stdin, flushed whenever no
/// further line is waiting, so the engine never waits for a sweep that sits
/// in our buffer.
fn write_lines(stdin: ChildStdin, lines: Receiver<String>) {
    block_sigpipe_in_this_thread();
    let mut out = BufWriter::with_capacity(1 << 16, stdin);
    while let Ok(line) = lines.recv() {
        if out.write_all(line.as_bytes()).is_err() {
            return;
        }
        let mut more = true;
        while more {
            match lines.try_recv() {
                Ok(line) => {
                    if out.write_all(line.as_bytes()).is_err() {
                        return;
                    }
                }
                Err(_) => more = false,
            }
        }
        if out.flush().is_err() {
            return;
        }
    }
    // The sender is gone: closing stdin tells the engine the input ended.
    let _ = out.flush();
}

/// A write to an engine that has exited must fail with `EPIPE` here, not
/// end this process: the command line restores SIGPIPE's default action
/// (to end quietly under `| head`), and a write to a closed pipe raises
/// SIGPIPE in the writing thread, where it is blocked.
fn block_sigpipe_in_this_thread() {
    #[cfg(unix)]
    // SAFETY: `set` is initialised by sigemptyset before use; blocking a
    // signal in the calling thread has no other effect.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGPIPE);
        libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut());
    }
}

/// The reader thread: the engine's stdout, line by line.
fn read_lines(stdout: impl Read, output: Sender<Output>) {
    let mut reader = BufReader::with_capacity(1 << 16, stdout);
    loop {
        let mut line = Vec::new();
        let limit = MAX_ANSWER_BYTES as u64 + 1;
        match (&mut reader).take(limit).read_until(b'\n', &mut line) {
            Ok(0) => {
                let _ = output.send(Output::End);
                return;
            }
            Ok(n) if n as u64 == limit && line.last() != Some(&b'\n') => {
                let _ = output.send(Output::TooLong);
                return;
            }
            Ok(_) => {
                if output.send(Output::Line(line)).is_err() {
                    return;
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => {
                let _ = output.send(Output::Failed(e));
                return;
            }
        }
    }
}

/// The stderr thread: keeps the last lines (each cut to 300 characters).
fn keep_tail(stderr: impl Read, tail: StderrTail) {
    let mut reader = BufReader::new(stderr);
    let mut line = Vec::new();
    loop {
        line.clear();
        match (&mut reader).take(1 << 16).read_until(b'\n', &mut line) {
            Ok(0) | Err(_) => break,
            Ok(_) => {
                let text = String::from_utf8_lossy(&line);
                tail.push(text.trim_end().chars().take(300).collect());
            }
        }
    }
    tail.close();
}
