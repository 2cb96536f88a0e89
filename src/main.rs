//! The `sweeptrace` command line: parses arguments, calls the library,
//! prints. This is the one place that turns an outcome into an exit code.

mod cli;

use std::process::ExitCode;

use clap::Parser;
use sweeptrace::run::RunOutcome;

fn main() -> ExitCode {
    // Like other command-line tools, stop quietly when the reader of our
    // output goes away (`sweeptrace replay --outcomes - T | head`).
    #[cfg(unix)]
    // SAFETY: called once at startup, before any thread is spawned;
    // SIG_DFL is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let args = cli::Cli::parse();
    let outcome = cli::run(args).unwrap_or_else(|err| {
        eprintln!("error: {err:#}");
        RunOutcome::Error
    });
    ExitCode::from(outcome.exit_code())
}
