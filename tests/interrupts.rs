//! Ctrl-C (SIGINT) and SIGTERM sent to the real binary while it writes its
//! outputs: the unfinished `.NAME.partial-*` files are removed and the exit
//! code is 128 + the signal's number. Each run is held at a point where it
//! is certainly still writing (a recording far too long to finish, a replay
//! blocked on a full stdout pipe nobody reads), so no test depends on how
//! fast the machine is; the waits are generous bounds that only a hang
//! exceeds.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use libtest_mimic::Trial;

use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(interrupted_record_removes_its_partial_file),
        trial!(terminated_record_removes_its_partial_file),
        trial!(interrupted_replay_removes_every_partial_output),
        trial!(terminated_replay_removes_every_partial_output),
    ]
}

/// Not a measurement: a bound that only a hang exceeds.
const LONG_WAIT: Duration = Duration::from_secs(120);

fn partial_files(dir: &Path) -> anyhow::Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial-"))
        .collect();
    names.sort();
    Ok(names)
}

/// Waits until `count` partial files are in `dir` (the run is writing).
fn wait_for_partials(child: &mut Child, dir: &Path, count: usize) -> anyhow::Result<()> {
    let deadline = Instant::now() + LONG_WAIT;
    loop {
        if partial_files(dir)?.len() >= count {
            return Ok(());
        }
        if let Some(status) = child.try_wait()? {
            anyhow::bail!("the run ended ({status}) before its outputs appeared");
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            anyhow::bail!("no {count} partial files in {} in time", dir.display());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sends `signal` and waits for the exit: its code and stderr.
fn signal_and_wait(mut child: Child, signal: i32) -> anyhow::Result<(Option<i32>, String)> {
    let pid = libc::pid_t::try_from(child.id())?;
    // SAFETY: sends a signal to our own child, which has not been waited for.
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
            anyhow::bail!(
                "still running {} s after signal {signal}",
                LONG_WAIT.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        e.read_to_string(&mut stderr)?;
    }
    Ok((status.code(), stderr))
}

fn check_exit(
    what: &str,
    dir: &Path,
    code: Option<i32>,
    stderr: &str,
    signal: i32,
) -> anyhow::Result<()> {
    if code != Some(128 + signal) {
        anyhow::bail!(
            "{what}: exit {code:?} after signal {signal}, want {}: {stderr}",
            128 + signal
        );
    }
    let left: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if !left.is_empty() {
        anyhow::bail!("{what}: left behind {left:?}; stderr: {stderr}");
    }
    if !stderr.contains("interrupted") {
        anyhow::bail!("{what}: stderr does not say it was interrupted: {stderr}");
    }
    Ok(())
}

/// A recording of a hundred million frames on a fine terrain: it is still
/// writing its trace whenever the signal comes.
fn record_until_signal(signal: i32) -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .args(["record", "--scene", "terrain", "--terrain-cells", "128"])
        .args(["--balls", "16", "--frames", "100000000", "-o"])
        .arg(dir.path().join("long.mcap"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    wait_for_partials(&mut child, dir.path(), 1)?;
    let (code, stderr) = signal_and_wait(child, signal)?;
    check_exit("record", dir.path(), code, &stderr, signal)
}

fn interrupted_record_removes_its_partial_file() -> anyhow::Result<()> {
    record_until_signal(libc::SIGINT)
}

fn terminated_record_removes_its_partial_file() -> anyhow::Result<()> {
    record_until_signal(libc::SIGTERM)
}

/// A replay writing a Rerun recording and a Foxglove file, its outcomes to
/// a stdout pipe that is never read: once the pipe is full (the outcomes of
/// the sample's 2,103 sweeps are far more than a pipe holds) it waits, with
/// both files unfinished.
fn replay_until_signal(signal: i32) -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_mini_golf.mcap");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg("replay")
        .arg(&trace)
        .arg("--rrd")
        .arg(dir.path().join("golf.rrd"))
        .arg("--foxglove")
        .arg(dir.path().join("golf.foxglove.mcap"))
        .args(["--outcomes", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    // Held open, unread, until the child has exited.
    let stdout = child.stdout.take();
    wait_for_partials(&mut child, dir.path(), 2)?;
    let (code, stderr) = signal_and_wait(child, signal)?;
    drop(stdout);
    check_exit("replay", dir.path(), code, &stderr, signal)
}

fn interrupted_replay_removes_every_partial_output() -> anyhow::Result<()> {
    replay_until_signal(libc::SIGINT)
}

fn terminated_replay_removes_every_partial_output() -> anyhow::Result<()> {
    replay_until_signal(libc::SIGTERM)
}
