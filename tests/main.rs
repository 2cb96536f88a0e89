//! The one integration-test binary (heavy crates link once).
//!
//! Each module exposes `tests() -> Vec<Trial>`; trace files under `traces/`
//! are found at run time and become test cases of their own.

use libtest_mimic::{Arguments, Failed, Trial};

mod alt_engine;
mod check;
mod core_cases;
mod core_decisions;
mod core_random;
mod oracle;
mod prefetch;
mod record;
mod replay;
mod repro;
mod support;
mod trace_io;

/// Builds a trial from a function returning `Result<(), String>`.
pub fn trial(name: &str, f: impl FnOnce() -> Result<(), String> + Send + 'static) -> Trial {
    Trial::test(name, move || f().map_err(Failed::from))
}

fn main() {
    let args = Arguments::from_args();
    let mut trials: Vec<Trial> = Vec::new();
    // Register test modules below (one line each).
    trials.extend(core_cases::tests());
    trials.extend(core_decisions::tests());
    trials.extend(core_random::tests());
    trials.extend(check::tests());
    trials.extend(trace_io::tests());
    trials.extend(replay::tests());
    trials.extend(record::tests());
    trials.extend(prefetch::tests());
    trials.extend(repro::tests());
    trials.extend(alt_engine::tests());
    libtest_mimic::run(&args, trials).exit();
}
