//! Replay throughput on generated traces (`examples/long_trace.rs`).
//!
//! Run: `cargo bench --bench replay` (the `.rrd` part needs the default
//! `viewer` feature; without it only the floor and the outcomes are run).
//!
//! On the same in-memory traces: the read-and-decode floor (the trace
//! reader alone), replay to outcomes (JSON lines into a sink, as
//! `replay --outcomes`), replay to an `.rrd` file at each detail level (as
//! `replay --rrd`), and replay time against the trace's length. Every
//! replay uses rayon's global pool (one thread per core), as the command
//! does by default.

use std::hint::black_box;
use std::io::Write;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use sweeptrace::replay::{
    DEFAULT_BATCH_EVENTS, Detail, PipelineOptions, ReplayEvent, ReplayOptions,
    replay_events_parallel, run_pipeline_unrecorded,
};
use sweeptrace::trace::TraceReader;
use sweeptrace::trace::prefetch::{DEFAULT_PREFETCH_CHUNK, DEFAULT_PREFETCH_DEPTH, prefetch};

#[path = "../examples/long_trace.rs"]
mod long_trace;

const LENGTHS: [u64; 3] = [1_000, 10_000, 100_000];
/// Length of the trace the detail levels are compared on (`candidates` and
/// `all` log every test, hundreds of times slower than `primary`: at 10^4
/// sweeps a run takes tens of seconds).
#[cfg(feature = "viewer")]
const RRD_SWEEPS: u64 = 1_000;

fn trace(sweeps: u64) -> Vec<u8> {
    long_trace::write_long_trace(std::io::Cursor::new(Vec::new()), sweeps, 7)
        .expect("writing to memory")
        .into_inner()
}

/// Reads and decodes every message; returns how many.
fn floor(bytes: &[u8]) -> usize {
    let mut n = 0;
    for event in TraceReader::new(bytes, "bench.mcap") {
        black_box(event.expect("valid trace"));
        n += 1;
    }
    n
}

/// Replays to outcome lines written into a sink; returns the sweeps.
fn outcomes(bytes: &[u8]) -> u64 {
    let options = ReplayOptions::default();
    let mut sink = std::io::BufWriter::new(std::io::sink());
    let mut n = 0;
    // As the command does: decode on a thread of its own (the copy of the
    // bytes, a memcpy, lets the reader thread own them).
    let read_ahead = prefetch(
        TraceReader::new(std::io::Cursor::new(bytes.to_vec()), "bench.mcap"),
        DEFAULT_PREFETCH_CHUNK,
        DEFAULT_PREFETCH_DEPTH,
    )
    .expect("reader thread");
    let mut events = replay_events_parallel(read_ahead, options, DEFAULT_BATCH_EVENTS, None);
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .expect("worker threads");
    // The command's own pipeline: the outcome lines built on the workers.
    let pipeline = PipelineOptions {
        outcome_lines: true,
        batch_events: DEFAULT_BATCH_EVENTS,
    };
    let result: Result<(), Box<dyn std::error::Error>> =
        run_pipeline_unrecorded(&mut events, &pool, pipeline, |event, line| {
            if let ReplayEvent::Sweep(_) = event? {
                sink.write_all(line.ok_or("no outcome line")?.as_bytes())?;
                sink.write_all(b"\n")?;
                n += 1;
            }
            Ok(())
        });
    result.expect("valid trace");
    n
}

#[cfg(feature = "viewer")]
fn rrd(bytes: &[u8], detail: Detail, path: &std::path::Path) -> u64 {
    use sweeptrace::viz;

    let options = ReplayOptions {
        explain: Some(detail),
        ..ReplayOptions::default()
    };
    let id = viz::recording_id(&[bytes, detail.as_str().as_bytes()]);
    // The command's own recording (a file with its footer, the rows
    // spilled beside it until the end, as `replay --rrd`).
    let target = viz::RecordingTarget {
        file: Some(path.to_path_buf()),
        ..viz::RecordingTarget::default()
    };
    let mut recording = viz::Recording::open(&id, "bench", target, viz::LoggerOptions::default())
        .expect("recording");
    let read_ahead = prefetch(
        TraceReader::new(std::io::Cursor::new(bytes.to_vec()), "bench.mcap"),
        DEFAULT_PREFETCH_CHUNK,
        DEFAULT_PREFETCH_DEPTH,
    )
    .expect("reader thread");
    let mut events = replay_events_parallel(read_ahead, options, DEFAULT_BATCH_EVENTS, None);
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .expect("worker threads");
    let mut n = 0;
    // The command's own pipeline (outcome lines off: the recording alone).
    let result: Result<(), Box<dyn std::error::Error>> = sweeptrace::replay::run_pipeline(
        &mut events,
        &pool,
        Some(recording.logger()),
        PipelineOptions::default(),
        |event, _| {
            if let ReplayEvent::Sweep(_) = event? {
                n += 1;
            }
            Ok(())
        },
    );
    result.expect("valid trace");
    recording
        .finish(|_, _| {})
        .expect("recording")
        .commit()
        .expect("recording");
    n
}

fn bench(c: &mut Criterion) {
    let traces: Vec<(u64, Vec<u8>)> = LENGTHS.iter().map(|&n| (n, trace(n))).collect();
    for (n, bytes) in &traces {
        eprintln!(
            "trace of {n} sweeps: {} bytes, {} messages",
            bytes.len(),
            floor(bytes)
        );
    }

    let mut g = c.benchmark_group("replay");
    g.sample_size(10);
    for (n, bytes) in &traces {
        g.throughput(Throughput::Elements(*n));
        g.bench_with_input(BenchmarkId::new("floor", n), bytes, |b, t| {
            b.iter(|| black_box(floor(t)))
        });
        g.bench_with_input(BenchmarkId::new("outcomes", n), bytes, |b, t| {
            b.iter(|| black_box(outcomes(t)))
        });
    }
    #[cfg(feature = "viewer")]
    {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("bench.rrd");
        for (n, bytes) in &traces {
            g.throughput(Throughput::Elements(*n));
            g.bench_with_input(BenchmarkId::new("rrd-primary", n), bytes, |b, t| {
                b.iter(|| black_box(rrd(t, Detail::Primary, &path)))
            });
        }
        let bytes = trace(RRD_SWEEPS);
        g.throughput(Throughput::Elements(RRD_SWEEPS));
        for detail in [Detail::Candidates, Detail::All] {
            g.bench_with_input(
                BenchmarkId::new(format!("rrd-{detail}"), RRD_SWEEPS),
                &bytes,
                |b, t| b.iter(|| black_box(rrd(t, detail, &path))),
            );
        }
    }
    #[cfg(not(feature = "viewer"))]
    let _ = Detail::Primary;
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
