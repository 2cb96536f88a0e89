//! Fuzz target: `sweeptrace::fuzzing::check_trace_reader` (its documentation says what
//! is checked). The committed corpus runs on stable in `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = sweeptrace::fuzzing::check_trace_reader(data) {
        panic!("{broken}");
    }
});
