//! The memory of `replay --rrd` does not follow the trace's length: the
//! peak resident memory of the command, measured by the kernel for that
//! one child process (`wait4`), on a session and on one three times as
//! long. What a replay holds besides its bounded buffers (the footer's
//! index of the chunks, the temporary file's index of its parts) grows by
//! a few MB over that length; anything kept per sweep (rows, results,
//! summaries) would add tens of MB.

use libtest_mimic::Trial;

use crate::support::bin;
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![trial!(replay_memory_does_not_follow_the_trace_length)]
}

/// Frames of the shorter session (64 balls on a 2,048-triangle terrain:
/// about 57 k sweeps, enough to fill the logger's buffer several times).
const SHORT_FRAMES: u32 = 600;

/// How much more the three-times-longer session may take, in MiB. Measured
/// (debug build): 88 and 102 MiB, the difference the footer's index of the
/// extra chunks, the temporary file's index of its parts and how full the
/// queues happen to be; keeping 400 bytes per sweep (a row's columns
/// rather than its chunk) would add 54 MiB.
#[cfg(unix)]
const ALLOWED_GROWTH_MIB: libc::c_long = 25;

/// Records the terrain session of `frames` frames into `path`.
#[cfg(unix)]
fn record(path: &std::path::Path, frames: u32) -> anyhow::Result<()> {
    let out = bin()
        .args(["record", "--scene", "terrain", "--terrain-cells", "32"])
        .args(["--balls", "64", "--frames", &frames.to_string(), "-o"])
        .arg(path)
        .output()?;
    anyhow::ensure!(
        out.status.success(),
        "record: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(())
}

/// Peak resident memory (KiB) of `replay TRACE --rrd OUT`, as the kernel
/// counted it for that process.
#[cfg(unix)]
fn replay_peak_kib(trace: &std::path::Path, out: &std::path::Path) -> anyhow::Result<libc::c_long> {
    let child = bin()
        .arg("replay")
        .arg(trace)
        .arg("--rrd")
        .arg(out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()?;
    let pid = libc::pid_t::try_from(child.id())?;
    let mut stderr = child.stderr.expect("piped");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut stderr, &mut text);
        text
    });
    let mut status: libc::c_int = 0;
    // SAFETY: all-zero bytes are a valid `rusage`.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `pid` is our child, not waited for yet (its `Child` handle
    // is dropped without waiting); both pointers are valid.
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    anyhow::ensure!(waited == pid, "wait4: {}", std::io::Error::last_os_error());
    let text = reader.join().unwrap_or_default();
    anyhow::ensure!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "replay failed: {text}"
    );
    // Linux counts ru_maxrss in KiB.
    Ok(usage.ru_maxrss)
}

#[cfg(unix)]
fn replay_memory_does_not_follow_the_trace_length() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let mut peaks = Vec::new();
    for frames in [SHORT_FRAMES, 3 * SHORT_FRAMES] {
        let trace = dir.path().join(format!("s{frames}.mcap"));
        record(&trace, frames)?;
        let out = dir.path().join(format!("s{frames}.rrd"));
        peaks.push(replay_peak_kib(&trace, &out)?);
        std::fs::remove_file(&out)?;
    }
    let (short, long) = (peaks[0] / 1024, peaks[1] / 1024);
    anyhow::ensure!(
        long <= short + ALLOWED_GROWTH_MIB,
        "replay --rrd took {short} MiB at {SHORT_FRAMES} frames and {long} MiB at {} frames: \
         more than {ALLOWED_GROWTH_MIB} MiB more for a trace three times as long",
        3 * SHORT_FRAMES
    );
    Ok(())
}

#[cfg(not(unix))]
fn replay_memory_does_not_follow_the_trace_length() -> anyhow::Result<()> {
    Ok(())
}
