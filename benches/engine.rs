//! The engine protocol's throughput: how many sweeps per second go through
//! the pipe to a trivial engine and back (the protocol's overhead), and
//! through the whole `check --engine` (the core's replay and comparison
//! added).
//!
//! ```text
//! cargo build --release --no-default-features --example trivial_engine
//! cargo bench --no-default-features --bench engine
//! ```
//!
//! The trace is `examples/long_trace.rs` with 100,000 sweeps (8 balls over
//! a 2,048-triangle terrain), in memory. The engines answer "no collision"
//! to everything: `examples/engines/trivial_engine.py` (Python) and
//! `examples/engines/trivial_engine.rs` (compiled). Each measurement runs 3
//! times; the median is printed. Another engine command can be given as
//! arguments: `cargo bench --no-default-features --bench engine -- "CMD"`.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use sweeptrace::engine::{EngineAnswers, EngineCommand, EngineOptions, EngineSession};
use sweeptrace::suite::{CheckOptions, check_events};
use sweeptrace::trace::{EventBody, TraceEvent, TraceReader};

#[path = "../examples/long_trace.rs"]
mod long_trace;

const SWEEPS: u64 = 100_000;
const RUNS: usize = 3;

/// Pipe only: every answer read, nothing judged. Returns the sweeps.
fn pipe_only(bytes: &[u8], command: &EngineCommand, options: EngineOptions) -> u64 {
    let session = EngineSession::start(command, options).expect("engine starts");
    let mut answers = EngineAnswers::new(
        TraceReader::new(bytes, "bench.mcap"),
        session,
        options.window,
    );
    let mut answered = 0;
    for event in answers.by_ref() {
        if let Ok(TraceEvent {
            body: EventBody::Expected(_),
            ..
        }) = event
        {
            answered += 1;
        }
    }
    let run = answers.finish();
    assert!(run.error.is_none(), "engine fault: {:?}", run.error);
    answered
}

/// The whole check: replay through the core and compare every answer.
fn full_check(bytes: &[u8], command: &EngineCommand, options: EngineOptions) -> u64 {
    let session = EngineSession::start(command, options).expect("engine starts");
    let mut answers = EngineAnswers::new(
        TraceReader::new(bytes, "bench.mcap"),
        session,
        options.window,
    );
    let report = check_events(answers.by_ref(), "bench.mcap", &CheckOptions::default());
    let run = answers.finish();
    assert!(run.error.is_none(), "engine fault: {:?}", run.error);
    report.compared
}

/// The median time of `RUNS` runs of `f`, which must handle `SWEEPS` sweeps.
fn median(mut f: impl FnMut() -> u64) -> Duration {
    let mut times: Vec<Duration> = (0..RUNS)
        .map(|_| {
            let start = Instant::now();
            let n = f();
            let elapsed = start.elapsed();
            assert_eq!(n, SWEEPS, "every sweep answered");
            elapsed
        })
        .collect();
    times.sort();
    times[RUNS / 2]
}

/// The floor: reading and decoding the trace alone.
fn read_only(bytes: &[u8]) -> u64 {
    TraceReader::new(bytes, "bench.mcap")
        .filter(|e| {
            matches!(
                e,
                Ok(TraceEvent {
                    body: EventBody::Sweep(_),
                    ..
                })
            )
        })
        .count() as u64
}

fn compiled_engine() -> Option<PathBuf> {
    // benches run from target/release/deps/; examples live in target/release/examples/.
    let exe = std::env::current_exe().ok()?;
    let path = exe
        .parent()?
        .parent()?
        .join("examples")
        .join("trivial_engine");
    path.exists().then_some(path)
}

fn main() {
    let mut engines: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    if engines.is_empty() {
        engines.push("python3 examples/engines/trivial_engine.py".to_string());
        match compiled_engine() {
            Some(path) => engines.push(path.display().to_string()),
            None => eprintln!(
                "the compiled trivial engine is not built: cargo build --release --no-default-features --example trivial_engine"
            ),
        }
    }
    let bytes = long_trace::write_long_trace(std::io::Cursor::new(Vec::new()), SWEEPS, 7)
        .expect("writing to memory")
        .into_inner();
    let floor = median(|| read_only(&bytes));
    println!(
        "trace: {SWEEPS} sweeps, {} bytes; reading it alone: {:.0} ms ({:.0} sweeps/s)",
        bytes.len(),
        floor.as_secs_f64() * 1e3,
        SWEEPS as f64 / floor.as_secs_f64()
    );
    let core = median(|| {
        let report = check_events(
            TraceReader::new(bytes.as_slice(), "bench.mcap"),
            "bench.mcap",
            &CheckOptions::default(),
        );
        report.sweeps
    });
    println!(
        "check without an engine (the core's replay alone): {:.0} ms ({:.0} sweeps/s)",
        core.as_secs_f64() * 1e3,
        SWEEPS as f64 / core.as_secs_f64()
    );
    let options = EngineOptions::default();
    for text in &engines {
        let command = EngineCommand::parse(text).expect("engine command");
        let pipe = median(|| pipe_only(&bytes, &command, options));
        let check = median(|| full_check(&bytes, &command, options));
        println!("engine `{text}` (window {}):", options.window);
        println!(
            "  through the pipe:      {:>7.0} ms  {:>9.0} sweeps/s",
            pipe.as_secs_f64() * 1e3,
            SWEEPS as f64 / pipe.as_secs_f64()
        );
        println!(
            "  check --engine (all):  {:>7.0} ms  {:>9.0} sweeps/s",
            check.as_secs_f64() * 1e3,
            SWEEPS as f64 / check.as_secs_f64()
        );
    }
}
