//! The one integration-test binary (heavy crates link once).
//!
//! Each module exposes `tests() -> Vec<Trial>`; trace files under `traces/`
//! are found at run time and become test cases of their own.

use libtest_mimic::{Arguments, Completion, Failed, Trial};

mod alt_engine;
mod architecture;
mod bisect;
mod bless_select;
mod cbor;
mod check;
mod conform;
mod contacts;
mod core_cases;
mod core_decisions;
mod core_random;
mod docs;
mod engine;
mod engine_faults;
mod error_messages;
mod exact;
mod expected_source;
mod faults;
mod first_hour;
mod first_hour_again;
mod foxglove;
mod fuzz_corpus;
mod help;
mod interrupts;
mod jolt;
mod junit;
mod lean;
mod memory;
mod mesh;
mod oracle;
mod out_of_order;
mod outputs;
mod precision;
mod prefetch;
mod primary_skips;
mod rapier;
mod rapier_js;
// The Rapier recorder example, run by `rapier` (its `main` is unused here).
mod edge_class;
mod ghost;
mod ghost_marks;
#[allow(dead_code)]
#[path = "../examples/rapier_record.rs"]
mod rapier_record;
mod record;
mod replay;
mod repro;
mod scanned;
mod suite_config;
mod support;
mod sweep_story;
mod trace_io;
mod tunnel;
mod tunnel_through;
mod verdicts;

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

/// Builds a trial from a function returning `anyhow::Result<()>` (or
/// `anyhow::Result<Completion>`); a failure prints the error with its
/// context chain. (A `String` error is accepted too, for code not moved
/// to `anyhow` yet.)
pub fn trial<T: TrialResult, E: support::Fail>(
    name: &str,
    f: impl FnOnce() -> Result<T, E> + Send + 'static,
) -> Trial {
    Trial::ignorable_test(name, move || {
        let completion = f()
            .map(TrialResult::into_completion)
            .map_err(|e| Failed::from(e.message()))?;
        if let Completion::Ignored { reason } = &completion {
            let reason = reason.as_deref().unwrap_or("(no reason given)");
            let first = reason.lines().next().unwrap_or(reason).to_string();
            if let Ok(mut skipped) = SKIPPED.lock() {
                *skipped.entry(first).or_insert(0) += 1;
            }
        }
        Ok(completion)
    })
}

/// The tests that found at run time that they cannot run here, by reason
/// (its first line): summarised after the run, so that "N ignored" says
/// why without scrolling back.
static SKIPPED: std::sync::Mutex<std::collections::BTreeMap<String, usize>> =
    std::sync::Mutex::new(std::collections::BTreeMap::new());

/// The summary of [`SKIPPED`], or nothing when every test could run.
fn print_skipped() {
    let Ok(skipped) = SKIPPED.lock() else { return };
    if skipped.is_empty() {
        return;
    }
    let total: usize = skipped.values().sum();
    println!(
        "{total} {} skipped because {} cannot run here (not failures; CI installs \
         what they need and requires them):",
        if total == 1 { "test was" } else { "tests were" },
        if total == 1 { "it" } else { "they" },
    );
    for (reason, count) in skipped.iter() {
        println!("  {count} × {reason}");
    }
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
    trials.extend(suite_config::tests());
    trials.extend(trace_io::tests());
    trials.extend(cbor::tests());
    trials.extend(contacts::tests());
    trials.extend(replay::tests());
    trials.extend(memory::tests());
    trials.extend(primary_skips::tests());
    trials.extend(record::tests());
    trials.extend(prefetch::tests());
    trials.extend(outputs::tests());
    trials.extend(tunnel::tests());
    trials.extend(tunnel_through::tests());
    trials.extend(edge_class::tests());
    trials.extend(ghost::tests());
    trials.extend(ghost_marks::tests());
    trials.extend(repro::tests());
    trials.extend(alt_engine::tests());
    trials.extend(scanned::tests());
    trials.extend(foxglove::tests());
    trials.extend(engine::tests());
    trials.extend(engine_faults::tests());
    trials.extend(conform::tests());
    trials.extend(junit::tests());
    trials.extend(verdicts::tests());
    trials.extend(bisect::tests());
    trials.extend(rapier::tests());
    trials.extend(faults::tests());
    trials.extend(error_messages::tests());
    trials.extend(expected_source::tests());
    trials.extend(out_of_order::tests());
    trials.extend(fuzz_corpus::tests());
    trials.extend(interrupts::tests());
    trials.extend(help::tests());
    trials.extend(first_hour::tests());
    trials.extend(bless_select::tests());
    trials.extend(first_hour_again::tests());
    trials.extend(sweep_story::tests());
    trials.extend(lean::tests());
    trials.extend(mesh::tests());
    trials.extend(jolt::tests());
    trials.extend(rapier_js::tests());
    trials.extend(precision::tests());
    trials.extend(architecture::tests());
    trials.extend(docs::tests());
    let trials = mark_slow(trials);
    let conclusion = libtest_mimic::run(&args, trials);
    print_skipped();
    conclusion.exit();
}

/// The trials that take seconds each on their own (a 100,000-sweep oracle,
/// a connect timeout, recordings replayed several ways): kind `slow`, and
/// ignored when `SWEEPTRACE_QUICK=1`, for a fast inner loop. CI runs them.
const SLOW: &[&str] = &[
    "outputs::unreachable_viewer_is_a_clear_error",
    "outputs::killed_mid_write_leaves_the_target_intact",
    "core_random::oracle_agreement_100k_sweeps",
    "core_random::primary_collector_equals_collecting_every_record",
    "core_random::bvh_equals_exhaustive",
    "replay::threads_do_not_change_the_outputs",
    "replay::spilled_recording_holds_the_same_rows",
    "replay::flush_by_bytes_keeps_the_content",
    "memory::replay_memory_does_not_follow_the_trace_length",
    "jolt::clean_jolt_passes_check_under_its_inferred_config",
    "jolt::broken_jolt_variants_fail_check_naming_the_difference",
    "jolt::jolt_conforms_under_its_config_and_its_broken_variants_do_not",
    "jolt::jolt_config_is_what_infer_config_prints",
    "jolt::jolt_with_back_faces_is_judged_two_sided_under_sides_two",
    "jolt::a_calibrated_accuracy_catches_a_bias_single_precision_excuses",
    "jolt::every_seeded_bug_fails_conform_and_check",
    "jolt::jolts_contacts_pass_and_its_ghosts_show_with_collide_with_all",
    "rapier_js::rapier_answers_every_sample_sweep_within_its_measured_failures",
    "rapier_js::rapier_stop_at_penetration_switch_changes_the_starts_only",
    "rapier_js::rapier_passes_the_miss_rules_of_conform_under_its_table",
    "rapier_js::rapier_config_is_what_infer_config_prints",
    "rapier_js::rapier_without_stop_at_penetration_fails_only_named_limitations_and_conforms",
];

fn mark_slow(trials: Vec<Trial>) -> Vec<Trial> {
    let quick = std::env::var_os("SWEEPTRACE_QUICK").is_some_and(|v| v == "1");
    let missing: Vec<&str> = SLOW
        .iter()
        .copied()
        .filter(|name| !trials.iter().any(|t| t.name() == *name))
        .collect();
    let mut out: Vec<Trial> = trials
        .into_iter()
        .map(|t| {
            if SLOW.contains(&t.name()) {
                t.with_kind("slow").with_ignored_flag(quick)
            } else {
                t
            }
        })
        .collect();
    // A renamed test would silently leave the list.
    out.push(trial("main::slow_list_names_registered_tests", move || {
        if missing.is_empty() {
            Ok(())
        } else {
            Err(anyhow::anyhow!(
                "SLOW names no registered test: {missing:?}"
            ))
        }
    }));
    out
}
