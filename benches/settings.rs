//! Settings files that scale: a suite's `sweeptrace.toml` of 2 MB with
//! 20,000 `[[traces]]` blocks over a folder of 1,000 traces, read, parsed
//! and resolved for every trace as `check` does (each trace's `exclude`,
//! then its settings).
//!
//! ```text
//! cargo bench --no-default-features --bench settings
//! ```
//!
//! The file and the folder are generated from a seed in a temporary
//! directory: 10 folders of 100 traces (the trace files are empty: only
//! their paths and the folders matter here). Three blocks in four name one
//! trace (`match = "group_3/trace_0342.mcap"`), the fourth a glob
//! (`group_3/trace_034*.mcap`); each block sets `strict` and a tolerance,
//! and one in ten `fields`. Benchmarks: **parse** (the file's text parsed
//! and validated, once), and **check** (what a run of `check` over the
//! folder does: a [`ConfigFiles`] of the run, then each trace's `exclude`
//! and settings).

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, Throughput, criterion_group};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sweeptrace::suite::config::{ConfigFile, ConfigFiles, Overrides};

const BLOCKS: usize = 20_000;
const GROUPS: usize = 10;
const TRACES_PER_GROUP: usize = 100;

/// The text of the settings file.
fn settings_text(seed: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut text = String::from(
        "# A large suite's settings: a block per trace and per family of traces.\n\
         fields = [\"kind\", \"triangle\", \"feature\", \"alpha\", \"normal\", \"contact\"]\n\
         exclude = [\"scratch/**\", \"*.partial.mcap\"]\n\n[tolerances]\nalpha = 1e-6\n",
    );
    for i in 0..BLOCKS {
        let group = rng.random_range(0..GROUPS);
        let trace = rng.random_range(0..TRACES_PER_GROUP * GROUPS);
        let pattern = if i % 4 == 3 {
            format!("group_{group}/trace_{:03}*.mcap", trace / 10)
        } else {
            format!("group_{group}/trace_{trace:04}.mcap")
        };
        let alpha = rng.random_range(1..9);
        text.push_str(&format!(
            "\n[[traces]]\nmatch = \"{pattern}\"\nstrict = {}\ntolerances = {{ alpha = {alpha}e-5, contact = 1e-4 }}\n",
            i % 2 == 0
        ));
        if i % 10 == 0 {
            text.push_str("fields = [\"kind\", \"alpha\"]\n");
        }
    }
    text
}

/// The suite: `.git`, `sweeptrace.toml` and the traces' folders in `dir`;
/// the traces' paths.
fn suite(dir: &Path, text: &str) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir.join(".git")).expect("create .git");
    std::fs::write(dir.join("sweeptrace.toml"), text).expect("write the settings");
    let mut traces = Vec::new();
    for group in 0..GROUPS {
        let folder = dir.join(format!("group_{group}"));
        std::fs::create_dir_all(&folder).expect("create a folder");
        for t in 0..TRACES_PER_GROUP {
            let trace = folder.join(format!("trace_{:04}.mcap", group * TRACES_PER_GROUP + t));
            std::fs::write(&trace, b"").expect("create a trace");
            traces.push(trace);
        }
    }
    traces
}

/// What `check` does with the settings of the suite's traces.
fn check_settings(traces: &[PathBuf]) -> usize {
    let mut files = ConfigFiles::new();
    let mut strict = 0;
    for trace in traces {
        assert!(files.excluded_by(trace).expect("exclude").is_none());
        let settings = files
            .settings_for(trace, &Overrides::default())
            .expect("settings");
        strict += usize::from(settings.strict.value);
    }
    strict
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let text = settings_text(7);
    let traces = suite(dir.path(), &text);
    let path = dir.path().join("sweeptrace.toml");
    eprintln!(
        "settings file: {} bytes, {BLOCKS} [[traces]] blocks; {} traces in {GROUPS} folders",
        text.len(),
        traces.len()
    );
    let mut g = c.benchmark_group("settings");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.bench_function("parse", |b| {
        b.iter(|| black_box(ConfigFile::parse(black_box(&text), &path).expect("parses")))
    });
    g.throughput(Throughput::Elements(traces.len() as u64));
    g.bench_function("check", |b| b.iter(|| black_box(check_settings(&traces))));
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
