//! The engine's processes under faults and signals (issue 43): an engine
//! that blocks signals, starts a helper, hangs, crashes mid-answer or
//! answers garbage; SIGINT and SIGTERM sent to sweeptrace while its engine
//! is busy or stuck; `check --infer-config` and `bless --engine` with a
//! faulty engine. After each run, no process of the engine's process group
//! is left alive.
//!
//! The engines are small `python3` scripts (some started through `sh -c`)
//! written to a temporary directory. Each writes a file naming its pid, its
//! process group and its blocked signals once it has read its first sweep,
//! so a test knows the group to look for and when the engine is busy. The
//! processes are found by that group id, in /proc (Linux), never by name;
//! every wait is a bound that only a hang exceeds, not a measurement.

use std::path::PathBuf;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use libtest_mimic::Trial;

use crate::support::{bin, run_bin};
use crate::{ensure, os, trial};

const LIMIT: Duration = Duration::from_secs(180);
/// Not a measurement: a bound that only a hang exceeds.
const LONG_WAIT: Duration = Duration::from_secs(60);

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(engine_starts_with_signals_unblocked, timeout = LIMIT),
        trial!(sigint_stops_a_stuck_engine_of_check, timeout = LIMIT),
        trial!(
            sigterm_stops_a_busy_engine_of_check_with_junit,
            timeout = LIMIT
        ),
        trial!(
            sigint_kills_an_engine_that_blocks_signals_in_bless_output,
            timeout = LIMIT
        ),
        trial!(
            sigterm_stops_an_engine_and_its_helper_in_bless_in_place,
            timeout = LIMIT
        ),
        trial!(sigterm_stops_a_stuck_engine_of_conform, timeout = LIMIT),
        trial!(sigint_stops_a_busy_engine_of_conform, timeout = LIMIT),
        trial!(
            engine_exit_is_seen_while_its_helper_holds_stdout,
            timeout = LIMIT
        ),
        trial!(a_hung_engine_is_stopped_with_its_helper, timeout = LIMIT),
        trial!(engine_crash_mid_answer_leaves_no_process, timeout = LIMIT),
        trial!(
            engine_garbage_with_a_helper_leaves_no_process,
            timeout = LIMIT
        ),
        trial!(infer_config_engine_not_found_exits_125, timeout = LIMIT),
        trial!(infer_config_engine_faults_exit_2, timeout = LIMIT),
        trial!(
            bless_engine_triangle_the_scene_lacks_writes_nothing,
            timeout = LIMIT
        ),
    ]
}

/// A temporary directory with the worked examples' trace (four sweeps on
/// triangle T).
struct Setup {
    dir: tempfile::TempDir,
    trace: PathBuf,
}

impl Setup {
    fn new() -> anyhow::Result<Setup> {
        let dir = tempfile::tempdir()?;
        let trace = dir.path().join("examples.mcap");
        std::fs::write(&trace, crate::engine::worked_examples_trace())?;
        Ok(Setup { dir, trace })
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// Writes `engine.py`: answers the first `good` sweeps with "no hit"
    /// (a hit on `triangle` instead, when given), then runs `then` (Python
    /// statements at the sweep that is not answered; `out` is stdout).
    /// Before anything else, on the first sweep, it writes `ready`: its
    /// pid, its process group and its blocked signals (SigBlk, hex).
    /// Returns the `--engine` command (`sh -c` with `wrapper` before the
    /// engine, when given).
    fn engine(&self, good: u64, then: &str, wrapper: Option<&str>) -> anyhow::Result<String> {
        let ready = self.path("ready");
        let source = format!(
            "import json, os, signal, sys, time\n\
             out = sys.stdout\n\
             answered = 0\n\
             def record():\n    \
                 blocked = [l.split()[1] for l in open('/proc/self/status') if l.startswith('SigBlk:')][0]\n    \
                 with open('{ready}.tmp', 'w') as f:\n        \
                     f.write('%d %d %s\\n' % (os.getpid(), os.getpgrp(), blocked))\n    \
                 os.replace('{ready}.tmp', '{ready}')\n\
             for line in sys.stdin:\n    \
                 m = json.loads(line)\n    \
                 if m['type'] != 'sweep':\n        continue\n    \
                 if answered == 0:\n        record()\n    \
                 if answered >= {good}:\n        {then}\n    \
                 out.write(json.dumps({{'frame': m['frame'], 'ball': m['ball'], 'alpha': 1.0, 'kind': 'none'}}) + '\\n')\n    \
                 out.flush()\n    \
                 answered += 1\n",
            ready = ready.display(),
        );
        let script = self.path("engine.py");
        std::fs::write(&script, source)?;
        Ok(match wrapper {
            None => format!("python3 '{}'", script.display()),
            Some(before) => format!("sh -c '{before}; python3 \"{}\"'", script.display()),
        })
    }

    /// `sh -c` statements that start a helper (a long sleep holding the
    /// engine's stdout) and write its pid to `helper`.
    fn helper(&self) -> String {
        format!(
            "sleep 600 & echo $! > \"{}\"",
            self.path("helper").display()
        )
    }

    /// The engine's pid, process group and blocked signals, once `ready`
    /// is written.
    fn ready(&self) -> anyhow::Result<(i32, i32, u64)> {
        let text = std::fs::read_to_string(self.path("ready"))?;
        let words: Vec<&str> = text.split_whitespace().collect();
        ensure!(words.len() == 3, "ready: `{text}`");
        Ok((
            words[0].parse()?,
            words[1].parse()?,
            u64::from_str_radix(words[2], 16)?,
        ))
    }

    fn helper_pid(&self) -> anyhow::Result<i32> {
        Ok(std::fs::read_to_string(self.path("helper"))?
            .trim()
            .parse()?)
    }
}

/// The live (not zombie) processes of the process group `group`.
fn group_members(group: i32) -> Vec<i32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    let mut members = Vec::new();
    for entry in entries.filter_map(Result::ok) {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // `pid (comm) state ppid pgrp ...`: comm may hold anything but
        // ends at the last `)`.
        let Some((_, rest)) = stat.rsplit_once(')') else {
            continue;
        };
        let fields: Vec<&str> = rest.split_whitespace().collect();
        if fields.len() > 2 && fields[0] != "Z" && fields[2] == group.to_string() {
            members.push(pid);
        }
    }
    members
}

/// Waits (a bound only a hang exceeds) until no process of `group` and
/// none of `pids` is alive; kills what is left before failing, so a
/// failing test leaves nothing behind.
fn ensure_gone(group: i32, pids: &[i32]) -> anyhow::Result<()> {
    let alive = |pid: i32| {
        std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .map(|s| {
                s.rsplit_once(')')
                    .is_some_and(|(_, r)| !r.trim_start().starts_with('Z'))
            })
            .unwrap_or(false)
    };
    let deadline = Instant::now() + LONG_WAIT;
    loop {
        let mut left = group_members(group);
        left.extend(pids.iter().copied().filter(|&p| alive(p)));
        if left.is_empty() {
            return Ok(());
        }
        if Instant::now() > deadline {
            // SAFETY: signals only the group and pids this test's engine
            // started (still alive, so their ids are still theirs).
            unsafe {
                libc::killpg(group, libc::SIGKILL);
                for &p in pids {
                    libc::kill(p, libc::SIGKILL);
                }
            }
            anyhow::bail!(
                "the engine's processes {left:?} (group {group}) still run after sweeptrace returned"
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Waits for the engine's `ready` file (it has read its first sweep).
fn wait_ready(child: &mut Child, setup: &Setup) -> anyhow::Result<(i32, i32, u64)> {
    let deadline = Instant::now() + LONG_WAIT;
    loop {
        if let Ok(ready) = setup.ready() {
            return Ok(ready);
        }
        if let Some(status) = child.try_wait()? {
            anyhow::bail!(
                "sweeptrace ended ({status}) before its engine read a sweep: {}",
                stderr_of(child)
            );
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            anyhow::bail!("the engine read no sweep in time");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn stderr_of(child: &mut Child) -> String {
    let mut text = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut text);
    }
    text
}

/// Sends `signal` to sweeptrace and waits for its exit: code and stderr.
fn signal_and_wait(child: &mut Child, signal: i32) -> anyhow::Result<(Option<i32>, String)> {
    let pid = libc::pid_t::try_from(child.id())?;
    // SAFETY: sends a signal to our own child, not waited for yet.
    if unsafe { libc::kill(pid, signal) } != 0 {
        anyhow::bail!("kill: {}", std::io::Error::last_os_error());
    }
    let deadline = Instant::now() + LONG_WAIT;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            anyhow::bail!("sweeptrace still runs after signal {signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Ok((status.code(), stderr_of(child)))
}

/// How the engine behaves once it has read its first sweep.
#[derive(Clone, Copy)]
enum Stuck {
    /// Sleeps (blocked in a system call).
    Sleeping,
    /// Computes forever.
    Busy,
    /// Blocks SIGINT and SIGTERM, then sleeps: only SIGKILL ends it.
    BlockingSignals,
    /// Sleeps, with a helper (started by its `sh -c` wrapper) beside it.
    WithHelper,
}

/// Runs sweeptrace with `args` (the engine's command added with
/// `--engine`), waits until its engine is stuck on the first sweep, sends
/// `signal`, and checks the exit code (128 + signal), that the engine's
/// whole group is gone, and returns the setup and stderr for more checks.
fn interrupt(
    args: &[&std::ffi::OsStr],
    setup: &Setup,
    stuck: Stuck,
    signal: i32,
) -> anyhow::Result<String> {
    let then = match stuck {
        Stuck::Sleeping | Stuck::WithHelper => "time.sleep(600)",
        Stuck::Busy => "while True: pass",
        Stuck::BlockingSignals => {
            "signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM}); time.sleep(600)"
        }
    };
    let helper = setup.helper();
    let wrapper = matches!(stuck, Stuck::WithHelper).then_some(helper.as_str());
    let command = setup.engine(0, then, wrapper)?;
    let mut child = bin()
        .args(args)
        .args(["--engine", &command, "--engine-timeout", "600"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    let (_, group, _) = wait_ready(&mut child, setup)?;
    let helper = match stuck {
        Stuck::WithHelper => vec![setup.helper_pid()?],
        _ => Vec::new(),
    };
    let (code, stderr) = signal_and_wait(&mut child, signal)?;
    let gone = ensure_gone(group, &helper);
    ensure!(
        code == Some(128 + signal),
        "exit {code:?} after signal {signal}, want {}: {stderr}",
        128 + signal
    );
    gone?;
    ensure!(stderr.contains("interrupted"), "stderr: {stderr}");
    Ok(stderr)
}

/// Issue 43, item 2: sweeptrace blocks SIGINT and SIGTERM in its own
/// threads (a thread of its own waits for them); its engine must not
/// inherit that mask, or `kill` and a CI runner's SIGTERM cannot end it.
fn engine_starts_with_signals_unblocked() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let command = setup.engine(100, "pass", None)?;
    let (code, stdout, stderr) =
        run_bin(os!("check", setup.trace.as_os_str(), "--engine", &command))?;
    // The engine answers "no hit" everywhere: three divergences.
    ensure!(code == 1, "exit {code}, want 1:\n{stdout}\n{stderr}");
    let (_, _, blocked) = setup.ready()?;
    let int_term = (1u64 << (libc::SIGINT - 1)) | (1u64 << (libc::SIGTERM - 1));
    ensure!(
        blocked & int_term == 0,
        "the engine started with SIGINT or SIGTERM blocked: SigBlk {blocked:016x}"
    );
    Ok(())
}

fn sigint_stops_a_stuck_engine_of_check() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    interrupt(
        os!("check", setup.trace.as_os_str()),
        &setup,
        Stuck::Sleeping,
        libc::SIGINT,
    )?;
    Ok(())
}

fn sigterm_stops_a_busy_engine_of_check_with_junit() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let report = setup.path("report.xml");
    interrupt(
        os!(
            "check",
            setup.trace.as_os_str(),
            "--junit",
            report.as_os_str()
        ),
        &setup,
        Stuck::Busy,
        libc::SIGTERM,
    )?;
    let partial: Vec<String> = std::fs::read_dir(setup.dir.path())?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("report") || n.contains(".partial-"))
        .collect();
    ensure!(partial.is_empty(), "left behind: {partial:?}");
    Ok(())
}

fn sigint_kills_an_engine_that_blocks_signals_in_bless_output() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let out = setup.path("blessed.mcap");
    interrupt(
        os!("bless", setup.trace.as_os_str(), "-o", out.as_os_str()),
        &setup,
        Stuck::BlockingSignals,
        libc::SIGINT,
    )?;
    ensure!(!out.exists(), "{} was written", out.display());
    Ok(())
}

fn sigterm_stops_an_engine_and_its_helper_in_bless_in_place() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let before = std::fs::read(&setup.trace)?;
    interrupt(
        os!("bless", setup.trace.as_os_str(), "--in-place"),
        &setup,
        Stuck::WithHelper,
        libc::SIGTERM,
    )?;
    ensure!(
        std::fs::read(&setup.trace)? == before,
        "the trace was changed"
    );
    Ok(())
}

fn sigterm_stops_a_stuck_engine_of_conform() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    interrupt(os!("conform"), &setup, Stuck::Sleeping, libc::SIGTERM)?;
    Ok(())
}

fn sigint_stops_a_busy_engine_of_conform() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    interrupt(os!("conform"), &setup, Stuck::Busy, libc::SIGINT)?;
    Ok(())
}

/// Issue 43, item 3: a wrapper whose engine exits (status 3) while a
/// helper it started still holds the engine's stdout. The exit is the
/// fault reported, not a timeout, and the helper does not survive.
fn engine_exit_is_seen_while_its_helper_holds_stdout() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let command = setup.engine(1, "sys.exit(3)", Some(&setup.helper()))?;
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        setup.trace.as_os_str(),
        "--engine",
        &command,
        "--engine-timeout",
        "30"
    ))?;
    let (_, group, _) = setup.ready()?;
    let gone = ensure_gone(group, &[setup.helper_pid()?]);
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    let want =
        "exited with status 3 after answering 1 sweeps, while frame 1, ball 0 awaited its answer";
    ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    gone
}

/// A hung engine with a helper: stopped at the timeout, with the helper.
fn a_hung_engine_is_stopped_with_its_helper() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let command = setup.engine(1, "time.sleep(600)", Some(&setup.helper()))?;
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        setup.trace.as_os_str(),
        "--engine",
        &command,
        "--engine-timeout",
        "3"
    ))?;
    let (_, group, _) = setup.ready()?;
    let gone = ensure_gone(group, &[setup.helper_pid()?]);
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    let want = "within 3 s (--engine-timeout); it was stopped";
    ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    gone
}

/// An engine killed by a signal halfway through writing an answer, its
/// helper holding stdout: an error, and nothing of it left.
fn engine_crash_mid_answer_leaves_no_process() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let then =
        "out.write('{\"frame\": 1, \"ba'); out.flush(); os.kill(os.getpid(), signal.SIGSEGV)";
    let command = setup.engine(1, then, Some(&setup.helper()))?;
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        setup.trace.as_os_str(),
        "--engine",
        &command,
        "--engine-timeout",
        "30"
    ))?;
    let (_, group, _) = setup.ready()?;
    let gone = ensure_gone(group, &[setup.helper_pid()?]);
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    // The half line is what the engine left: it is reported as it is.
    let want = "printed a line that is not an outcome (output line 2, where the answer to frame 1, ball 0 was due)";
    ensure!(stdout.contains(want), "missing `{want}` in:\n{stdout}");
    gone
}

/// Garbage from an engine with a helper: the engine and the helper stop.
fn engine_garbage_with_a_helper_leaves_no_process() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let then = "out.write('collision at 0.4\\n'); out.flush(); time.sleep(600)";
    let command = setup.engine(1, then, Some(&setup.helper()))?;
    let (code, stdout, stderr) =
        run_bin(os!("check", setup.trace.as_os_str(), "--engine", &command))?;
    let (_, group, _) = setup.ready()?;
    let gone = ensure_gone(group, &[setup.helper_pid()?]);
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    ensure!(
        stdout.contains("`collision at 0.4`"),
        "the garbage line is not named:\n{stdout}"
    );
    gone
}

/// Issue 43, item 4: `--infer-config` with an engine that cannot start is
/// exit 125 and no table (it fell back to the trace's own /expected).
fn infer_config_engine_not_found_exits_125() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    let missing = setup.path("build/engine");
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        setup.trace.as_os_str(),
        "--engine",
        missing.as_os_str(),
        "--infer-config"
    ))?;
    ensure!(code == 125, "exit {code}, want 125:\n{stdout}\n{stderr}");
    ensure!(stdout.is_empty(), "a table was printed:\n{stdout}");
    ensure!(
        stderr.contains("cannot be started") && stderr.contains("build/engine"),
        "the message names the engine: {stderr}"
    );
    Ok(())
}

/// Issue 43, item 4: garbage, an exit and a hang are faults of the engine:
/// exit 2, the fault named, no table.
fn infer_config_engine_faults_exit_2() -> anyhow::Result<()> {
    for (then, want) in [
        (
            "out.write('collision at 0.4\\n'); out.flush(); continue",
            "printed a line that is not an outcome",
        ),
        (
            "sys.exit(3)",
            "exited with status 3 after answering 1 sweeps",
        ),
        ("time.sleep(600)", "within 3 s (--engine-timeout)"),
    ] {
        let setup = Setup::new()?;
        let command = setup.engine(1, then, None)?;
        let (code, stdout, stderr) = run_bin(os!(
            "check",
            setup.trace.as_os_str(),
            "--engine",
            &command,
            "--engine-timeout",
            "3",
            "--infer-config"
        ))?;
        ensure!(
            code == 2,
            "`{then}`: exit {code}, want 2:\n{stdout}\n{stderr}"
        );
        ensure!(
            stdout.is_empty(),
            "`{then}`: a table was printed:\n{stdout}"
        );
        ensure!(
            stderr.contains(want),
            "`{then}`: missing `{want}` in:\n{stderr}"
        );
        let (_, group, _) = setup.ready()?;
        ensure_gone(group, &[])?;
    }
    Ok(())
}

/// Issue 43, item 5: an engine naming a triangle the scene lacks cannot be
/// written into a snapshot: exit 2, nothing written (in place, the trace
/// is left as it was).
fn bless_engine_triangle_the_scene_lacks_writes_nothing() -> anyhow::Result<()> {
    let setup = Setup::new()?;
    // Answers sweep 0 right, then a face hit on triangle 99999 (the
    // scene has 1).
    let then = "out.write(json.dumps({'frame': m['frame'], 'ball': m['ball'], 'alpha': 0.5, \
                'kind': 'face', 'triangle': 99999, 'normal': [0.0, 0.0, 1.0]}) + '\\n'); \
                out.flush(); answered += 1; continue";
    let command = setup.engine(1, then, None)?;
    let out = setup.path("snapshot.mcap");
    let (code, stdout, stderr) = run_bin(os!(
        "bless",
        setup.trace.as_os_str(),
        "--engine",
        &command,
        "-o",
        out.as_os_str()
    ))?;
    ensure!(code == 2, "exit {code}, want 2:\n{stdout}\n{stderr}");
    ensure!(!out.exists(), "{} was written", out.display());
    for want in [
        "frame 1, ball 0",
        "field `triangle`: index 99999 is out of range (the scene has 1 triangles)",
        "nothing written",
    ] {
        ensure!(stderr.contains(want), "missing `{want}` in:\n{stderr}");
    }
    let before = std::fs::read(&setup.trace)?;
    let (code, _, stderr) = run_bin(os!(
        "bless",
        setup.trace.as_os_str(),
        "--engine",
        &command,
        "--in-place"
    ))?;
    ensure!(code == 2, "in place: exit {code}, want 2:\n{stderr}");
    ensure!(
        std::fs::read(&setup.trace)? == before,
        "in place: the trace was changed"
    );
    let left: Vec<String> = std::fs::read_dir(setup.dir.path())?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial-"))
        .collect();
    ensure!(left.is_empty(), "left behind: {left:?}");
    Ok(())
}
