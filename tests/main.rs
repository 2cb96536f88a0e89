//! The one integration-test binary (heavy crates link once).
//!
//! Each module exposes `tests() -> Vec<Trial>`; trace files under `traces/`
//! are found at run time and become test cases of their own.

use libtest_mimic::{Arguments, Completion, Failed, Trial};

mod alt_engine;
mod bisect;
mod check;
mod conform;
mod core_cases;
mod core_decisions;
mod core_random;
mod engine;
mod error_messages;
mod faults;
mod first_hour;
mod foxglove;
mod fuzz_corpus;
mod help;
mod interrupts;
mod oracle;
mod out_of_order;
mod outputs;
mod prefetch;
mod rapier;
// The Rapier recorder example, run by `rapier` (its `main` is unused here).
#[allow(dead_code)]
#[path = "../examples/rapier_record.rs"]
mod rapier_record;
mod record;
mod replay;
mod repro;
mod scanned;
mod support;
mod trace_io;
mod tunnel;

/// What a test function returns on success: `()`, or a [`Completion`] for a
/// test that finds at run time that it cannot run here and says why
/// (shown as `ignored (reason)` and counted as ignored).
pub trait TrialResult {
    /// Whether the test ran to the end or was skipped.
    fn into_completion(self) -> Completion;
}

impl TrialResult for () {
    fn into_completion(self) -> Completion {
        Completion::Completed
    }
}

impl TrialResult for Completion {
    fn into_completion(self) -> Completion {
        self
    }
}

/// Builds a trial from a function returning `Result<(), String>` (or
/// `Result<Completion, String>`).
pub fn trial<T: TrialResult>(
    name: &str,
    f: impl FnOnce() -> Result<T, String> + Send + 'static,
) -> Trial {
    Trial::ignorable_test(name, move || {
        f().map(TrialResult::into_completion).map_err(Failed::from)
    })
}

/// Registers the test function `f` under the name `module::f`, so that the
/// name a run prints and filters on is the function's own:
/// `trial!(f)`, or `trial!(f, timeout = LIMIT)` to fail a test that has not
/// returned after `LIMIT` instead of hanging the run.
#[macro_export]
macro_rules! trial {
    ($f:ident) => {
        $crate::trial(&$crate::test_name(module_path!(), stringify!($f)), $f)
    };
    ($f:ident, timeout = $limit:expr) => {
        $crate::trial(
            &$crate::test_name(module_path!(), stringify!($f)),
            move || $crate::support::with_timeout($limit, $f),
        )
    };
}

/// `module::function`, from `module_path!()` (which starts with this
/// binary's crate name, left out) and the function's name.
pub fn test_name(module_path: &str, function: &str) -> String {
    let module = module_path
        .split_once("::")
        .map_or(module_path, |(_, module)| module);
    format!("{module}::{function}")
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
    trials.extend(outputs::tests());
    trials.extend(tunnel::tests());
    trials.extend(repro::tests());
    trials.extend(alt_engine::tests());
    trials.extend(scanned::tests());
    trials.extend(foxglove::tests());
    trials.extend(engine::tests());
    trials.extend(conform::tests());
    trials.extend(bisect::tests());
    trials.extend(rapier::tests());
    trials.extend(faults::tests());
    trials.extend(error_messages::tests());
    trials.extend(out_of_order::tests());
    trials.extend(fuzz_corpus::tests());
    trials.extend(interrupts::tests());
    trials.extend(help::tests());
    trials.extend(first_hour::tests());
    libtest_mimic::run(&args, trials).exit();
}
