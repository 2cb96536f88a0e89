//! The `sweeptrace` command line: parses arguments, calls the library,
//! prints. This is the one place that turns an outcome into an exit code.

mod cli;

use std::process::ExitCode;

use cli::Exit;

fn main() -> ExitCode {
    // Like other command-line tools, stop quietly when the reader of our
    // output goes away (`sweeptrace replay --outcomes - T | head`).
    #[cfg(unix)]
    // SAFETY: called once at startup, before any thread is spawned;
    // SIG_DFL is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    bounded_allocator();
    #[cfg(unix)]
    interrupts::handle();
    let args = cli::parse();
    let outcome = cli::run(args).unwrap_or_else(|err| {
        eprintln!("error: {err:#}");
        Exit::Error
    });
    ExitCode::from(outcome.exit_code())
}

/// Keeps glibc's heap from growing with a long run: large buffers (a
/// recording's columns, chunks and their encodings, 1 MiB and more) are
/// mapped and unmapped on their own instead of reusing heap space that then
/// stays fragmented, and at most two arenas (one per core of the machines
/// measured) are kept instead of up to eight per core, each holding its own
/// free memory. Measured on `replay --rrd` of a 1.86 M-sweep session:
/// 205 MB max RSS before, 178 MB after (BENCHMARKS.md).
fn bounded_allocator() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: called once at startup, before any thread is spawned; mallopt
    // only changes the allocator's tunables (an unknown value is refused,
    // not an error).
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
        libc::mallopt(libc::M_ARENA_MAX, 2);
    }
}

/// SIGINT (Ctrl-C) and SIGTERM: the unfinished outputs are removed
/// ([`sweeptrace::atomic::remove_pending_files`]), the running engine's
/// process group is stopped ([`sweeptrace::engine::stop_running_engines`]:
/// SIGTERM, SIGKILL after a short grace) and the process exits with 128 +
/// the signal's number (130, 143), as a shell reports a process ended by
/// it.
#[cfg(unix)]
mod interrupts {
    /// Blocks the two signals in every thread (called before any other
    /// thread starts, so all inherit the mask; an engine, a child process,
    /// is given an empty mask when it starts, since `std::process::Command`
    /// leaves it ours) and waits for them on a thread of its own. If that thread cannot be started, the
    /// signals keep their default action.
    pub fn handle() {
        // SAFETY: `set` is initialised by sigemptyset before use; the calls
        // only read and write the local set and this thread's mask.
        let set = unsafe {
            let mut set: libc::sigset_t = std::mem::zeroed();
            libc::sigemptyset(&mut set);
            libc::sigaddset(&mut set, libc::SIGINT);
            libc::sigaddset(&mut set, libc::SIGTERM);
            set
        };
        // SAFETY: a valid set; the old mask is not needed.
        unsafe { libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) };
        let waiter = std::thread::Builder::new()
            .name("signals".to_string())
            .spawn(move || wait(set));
        if waiter.is_err() {
            // SAFETY: as above.
            unsafe { libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut()) };
        }
    }

    fn wait(set: libc::sigset_t) {
        loop {
            let mut signal: libc::c_int = 0;
            // SAFETY: `set` is a valid signal set and `signal` a valid out pointer.
            if unsafe { libc::sigwait(&set, &mut signal) } != 0 {
                continue;
            }
            // The outputs first: from now on none is renamed into place,
            // whatever the engine's end makes the other threads do.
            let removed = sweeptrace::atomic::remove_pending_files();
            let engines = sweeptrace::engine::stop_running_engines(sweeptrace::engine::STOP_GRACE);
            let name = if signal == libc::SIGINT {
                "SIGINT"
            } else {
                "SIGTERM"
            };
            eprintln!(
                "\ninterrupted ({name}): {}{}",
                match removed.len() {
                    0 => "no unfinished output to remove".to_string(),
                    1 => "removed the unfinished output".to_string(),
                    n => format!("removed the {n} unfinished outputs"),
                },
                match engines {
                    0 => String::new(),
                    1 => "; stopped the engine and its process group".to_string(),
                    n => format!("; stopped the {n} engines and their process groups"),
                }
            );
            // SAFETY: ends the process at once, without running destructors
            // or atexit handlers of other threads' state (the outputs are
            // removed and none can be renamed into place any more).
            unsafe { libc::_exit(128 + signal) };
        }
    }
}
