//! `check --engine`: the engine protocol against the example engines and
//! against engines that fail in each way the protocol names (each such
//! test finishes in seconds, under a time limit against hangs).

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::time::Duration;

use libtest_mimic::Trial;
use sweeptrace::trace::{SweepMsg, TraceWriter};

use crate::support::run_bin;
use crate::support::scene_t;
use crate::{ensure, os, trial};

const LIMIT: Duration = Duration::from_secs(60);

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(example_engine_passes_the_sample_traces, timeout = LIMIT),
        trial!(
            wrong_engine_report_explains_the_missed_vertex,
            timeout = LIMIT
        ),
        trial!(engine_not_found_exits_125, timeout = LIMIT),
        trial!(engine_crash_shows_its_stderr_tail, timeout = LIMIT),
        trial!(engine_garbage_line_is_an_error, timeout = LIMIT),
        trial!(engine_wrong_frame_is_an_error, timeout = LIMIT),
        trial!(engine_timeout_stops_it, timeout = LIMIT),
        trial!(
            engine_started_through_a_shell_is_stopped_with_its_children,
            timeout = LIMIT
        ),
        trial!(
            engine_extra_output_after_the_end_is_an_error,
            timeout = LIMIT
        ),
        trial!(engine_json_report_names_the_engine, timeout = LIMIT),
        trial!(
            against_expected_compares_answers_with_the_trace,
            timeout = LIMIT
        ),
    ]
}

/// The example engines' script.
pub fn example_engine() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/sweep_engine.py")
}

/// `python3 <example engine> <extra>` as one `--engine` argument.
pub fn example_engine_command(extra: &str) -> String {
    format!("python3 '{}' {extra}", example_engine().display())
}

/// Triangle T of SEMANTICS.md with the sweeps of its worked examples 1 to 3
/// (face, edge, vertex) and a miss.
pub fn worked_examples_trace() -> Vec<u8> {
    let scene = scene_t(0.0);
    let sweeps = [
        ([1.0, 1.0, 3.0], [1.0, 1.0, -3.0]),
        ([2.0, -0.3, 3.0], [2.0, -0.3, -3.0]),
        ([-0.3, -0.2, 3.0], [-0.3, -0.2, -3.0]),
        ([10.0, 10.0, 3.0], [11.0, 10.0, 3.0]),
    ];
    let mut w = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
    w.scene(0, &scene).expect("scene");
    for (frame, (p0, p1)) in sweeps.into_iter().enumerate() {
        let sweep = SweepMsg {
            frame: frame as u64,
            ball: 0,
            radius: 0.5,
            p0,
            p1,
        };
        w.sweep(1_000_000 * (frame as u64 + 1), &sweep)
            .expect("sweep");
    }
    w.finish().expect("finish").into_inner()
}

/// A temporary directory holding the worked examples' trace and `engine.py`
/// with `source`.
fn setup(source: &str) -> anyhow::Result<(tempfile::TempDir, PathBuf, String)> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("examples.mcap");
    std::fs::write(&trace, worked_examples_trace())?;
    let engine = dir.path().join("engine.py");
    std::fs::write(&engine, source)?;
    let command = format!("python3 '{}'", engine.display());
    Ok((dir, trace, command))
}

/// An engine that answers the first `good` sweeps with "no hit", then does
/// `then` (Python statements; `m` is the sweep, `out` stdout).
fn faulty_engine(good: u64, then: &str) -> String {
    format!(
        "import json, sys\n\
         out = sys.stdout\n\
         answered = 0\n\
         for line in sys.stdin:\n    \
             m = json.loads(line)\n    \
             if m['type'] != 'sweep':\n        continue\n    \
             if answered >= {good}:\n        {then}\n    \
             out.write(json.dumps({{'frame': m['frame'], 'ball': m['ball'], 'alpha': 1.0, 'kind': 'none'}}) + '\\n')\n    \
             out.flush()\n    \
             answered += 1\n"
    )
}

fn example_engine_passes_the_sample_traces() -> anyhow::Result<()> {
    let traces = Path::new(env!("CARGO_MANIFEST_DIR")).join("traces");
    let cube = traces.join("record_cube_corner_margin.mcap");
    let strict = traces.join("record_box_strict.mcap");
    let engine = example_engine_command("");
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        cube.as_os_str(),
        strict.as_os_str(),
        "--engine",
        &engine
    ))?;
    ensure!(code == 0, "exit {code}, want 0:\n{stdout}\n{stderr}");
    ensure!(
        stdout.matches("\nok ").count() + usize::from(stdout.starts_with("ok ")) == 2,
        "both traces ok:\n{stdout}"
    );
    Ok(())
}

fn wrong_engine_report_explains_the_missed_vertex() -> anyhow::Result<()> {
    let (_dir, trace, _) = setup("")?;
    let engine = example_engine_command("--bug skip-vertex");
    let (code, stdout, stderr) = run_bin(os!("check", trace.as_os_str(), "--engine", &engine))?;
    ensure!(code == 1, "exit {code}, want 1:\n{stdout}\n{stderr}");
    for want in [
        "1 of 4 compared sweeps diverges (none -> vertex: 1)",
        "first divergence: frame 2, ball 0",
        "kind: engine none, core vertex",
        "primary: vertex 0.0",
        "the engine answered no collision",
    ] {
        ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    }
    // The correct engine agrees on the same trace.
    let engine = example_engine_command("");
    let (code, stdout, _) = run_bin(os!("check", trace.as_os_str(), "--engine", &engine))?;
    ensure!(code == 0, "the correct engine: exit {code}:\n{stdout}");
    Ok(())
}

fn engine_not_found_exits_125() -> anyhow::Result<()> {
    let (dir, trace, _) = setup("")?;
    let missing = dir.path().join("build/engine");
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        trace.as_os_str(),
        "--engine",
        missing.as_os_str()
    ))?;
    ensure!(code == 125, "exit {code}, want 125:\n{stdout}\n{stderr}");
    ensure!(
        stderr.contains("cannot be started") && stderr.contains("build/engine"),
        "the message names the engine: {stderr}"
    );
    Ok(())
}

fn engine_crash_shows_its_stderr_tail() -> anyhow::Result<()> {
    let then =
        "sys.stderr.write('reading the vertex table\\nboom: index 7 out of range\\n'); sys.exit(3)";
    let (_dir, trace, command) = setup(&faulty_engine(2, then))?;
    let (code, stdout, stderr) = run_bin(os!("check", trace.as_os_str(), "--engine", &command))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    for want in [
        "ERROR",
        "exited with status 3 after answering 2 sweeps, while frame 2, ball 0 awaited its answer",
        "| reading the vertex table",
        "| boom: index 7 out of range",
    ] {
        ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    }
    Ok(())
}

fn engine_garbage_line_is_an_error() -> anyhow::Result<()> {
    let then = "out.write('collision at 0.4\\n'); out.flush(); continue";
    let (_dir, trace, command) = setup(&faulty_engine(1, then))?;
    let (code, stdout, stderr) = run_bin(os!("check", trace.as_os_str(), "--engine", &command))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    for want in [
        "printed a line that is not an outcome (output line 2, where the answer to frame 1, ball 0 was due)",
        "it is not valid JSON",
        "`collision at 0.4`",
    ] {
        ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    }
    Ok(())
}

fn engine_wrong_frame_is_an_error() -> anyhow::Result<()> {
    let then = "m['frame'] += 1";
    let (_dir, trace, command) = setup(&faulty_engine(3, then))?;
    let (code, stdout, stderr) = run_bin(os!("check", trace.as_os_str(), "--engine", &command))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    let want =
        "answered frame 4, ball 0 (output line 4) where the answer to frame 3, ball 0 was due";
    ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    Ok(())
}

fn engine_timeout_stops_it() -> anyhow::Result<()> {
    // It never answers the first sweep: whether the timeout runs out while
    // Python starts or while it sleeps, the message is the same (the test
    // does not depend on how fast the engine starts).
    let then = "import time; time.sleep(60)";
    let (_dir, trace, command) = setup(&faulty_engine(0, then))?;
    let start = std::time::Instant::now();
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        trace.as_os_str(),
        "--engine",
        &command,
        "--engine-timeout",
        "0.5"
    ))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    let want = "did not answer frame 0, ball 0 within 0.5 s (--engine-timeout); it was stopped after answering 0 sweeps";
    ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    // Stopped, not waited for: far less than the engine's 60 s sleep.
    ensure!(
        start.elapsed() < Duration::from_secs(30),
        "the engine was waited for: {:?}",
        start.elapsed()
    );
    Ok(())
}

/// An engine run through `sh -c` that never answers: stopping it at the
/// timeout stops the shell's child too (the whole process group).
fn engine_started_through_a_shell_is_stopped_with_its_children() -> anyhow::Result<()> {
    let (dir, trace, _) = setup("")?;
    let pid_file = dir.path().join("child.pid");
    // The shell starts a long sleep in the background, writes its pid,
    // then waits for it (never answering).
    let command = format!(
        "sh -c 'sleep 300 & echo $! > \"{}\"; wait'",
        pid_file.display()
    );
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        trace.as_os_str(),
        "--engine",
        &command,
        "--engine-timeout",
        "1"
    ))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    let pid: i32 = std::fs::read_to_string(&pid_file)
        .map_err(|e| anyhow::anyhow!("the shell wrote no pid: {e}"))?
        .trim()
        .parse()
        .map_err(|e| anyhow::anyhow!("pid: {e}"))?;
    // Killed by the time check returned; it may take a moment to be reaped
    // by init, so look at its state rather than at its existence.
    let alive = |pid: i32| {
        std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .map(|s| !s.contains(") Z "))
            .unwrap_or(false)
    };
    for _ in 0..100 {
        if !alive(pid) {
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    // Do not leave it behind even when the test fails.
    // SAFETY: sends a signal to a pid this test's engine started.
    unsafe {
        libc::kill(pid, libc::SIGKILL);
    }
    Err(anyhow::anyhow!(
        "the engine's child {pid} still runs after check returned"
    ))
}

fn engine_extra_output_after_the_end_is_an_error() -> anyhow::Result<()> {
    // Answers every sweep, then prints one more line when its input ends.
    let source = format!("{}out.write('done\\n')\n", faulty_engine(100, "pass"));
    let (_dir, trace, command) = setup(&source)?;
    let (code, stdout, stderr) = run_bin(os!("check", trace.as_os_str(), "--engine", &command))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    let want =
        "(output line 5, after every sweep was answered): every sweep was already answered: `done`";
    ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    Ok(())
}

fn engine_json_report_names_the_engine() -> anyhow::Result<()> {
    let (_dir, trace, command) = setup(&faulty_engine(100, "pass"))?;
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        trace.as_os_str(),
        "--engine",
        &command,
        "--json"
    ))?;
    ensure!(code == 1, "exit {code}, want 1:\n{stdout}\n{stderr}");
    let doc: serde_json::Value = serde_json::from_str(&stdout)?;
    let report = &doc["traces"][0];
    ensure!(
        report["engine"]["command"] == command.as_str() && report["engine"]["against"] == "core",
        "engine: {report}"
    );
    ensure!(
        report["compared"] == 4 && report["divergent"] == 3,
        "counts: {report}"
    );
    ensure!(doc["exit_code"] == 1, "exit_code: {doc}");
    Ok(())
}

fn against_expected_compares_answers_with_the_trace() -> anyhow::Result<()> {
    let trace = Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_cube_corner_margin.mcap");
    // The trace's expectations were recorded by the core with margin 0.05:
    // the correct engine decides every sweep the same.
    let engine = example_engine_command("");
    let (code, stdout, _) = run_bin(os!(
        "check",
        trace.as_os_str(),
        "--engine",
        &engine,
        "--against",
        "expected"
    ))?;
    ensure!(code == 0, "the correct engine: exit {code}:\n{stdout}");
    let engine = example_engine_command("--bug ignore-margin");
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        trace.as_os_str(),
        "--engine",
        &engine,
        "--against",
        "expected"
    ))?;
    ensure!(code == 1, "exit {code}, want 1:\n{stdout}\n{stderr}");
    for want in [
        "first divergence: frame 29, ball 0",
        "kind: expected none, engine vertex",
        "the core found:",
    ] {
        ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    }
    // A trace without expectations has nothing to compare with.
    let (_dir, bare, _) = setup("")?;
    let (code, stdout, _) = run_bin(os!(
        "check",
        bare.as_os_str(),
        "--engine",
        &example_engine_command(""),
        "--against",
        "expected",
        "--json"
    ))?;
    ensure!(code == 2, "no expectations: exit {code}:\n{stdout}");
    let doc: serde_json::Value = serde_json::from_str(&stdout)?;
    ensure!(
        doc["traces"][0]["status"] == "no_expectations"
            && doc["traces"][0]["engine"]["against"] == "expected",
        "report: {doc}"
    );
    Ok(())
}
