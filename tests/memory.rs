//! The memory of `replay --rrd` does not follow the trace's length: the
//! peak resident memory of the command, measured by the kernel for that
//! one process, on a session and on one three times as long, without the
//! footer (`--no-rrd-footer`: the footer's index of the chunks is the one
//! part known to grow with the length, about 7.5 KB a chunk,
//! BENCHMARKS.md). What a replay holds besides its bounded buffers (the
//! temporary file's index of its parts) grows by a few MB over that
//! length; anything kept per sweep (rows, results, summaries) would add
//! tens of MB.

use libtest_mimic::Trial;

use crate::support::bin;
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![trial!(replay_memory_does_not_follow_the_trace_length)]
}

/// Frames of the shorter session (64 balls on a 2,048-triangle terrain:
/// about 114 k sweeps, past the replay's warm-up: at 600 frames its
/// buffers had not all reached their working size, and the peak rose by
/// 24 MiB from 600 to 1,800 frames, then by 3 from 1,800 to 3,000).
const SHORT_FRAMES: u32 = 1200;

/// How much more the three-times-longer session may take, in MiB. Measured
/// (debug build, without the footer): 94 and 101 MiB at 1,200 and 3,600
/// frames (100 and 110 with the crate at -O2; 102 and 107 beside two other
/// tests), the difference the
/// temporary file's index of its parts and how full the queues happen to
/// be; keeping 400 bytes per sweep (seeded: a row's columns rather than its
/// chunk) adds 116 MiB.
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

/// Started from a small process: Linux keeps, at `exec`, the high-water
/// mark of the memory the process had before (`ru_maxrss` is the larger of
/// the two), and a child spawned from this test process starts from this
/// process's memory (`vfork`), that of every test running in it: a child
/// of this process reported 153 and 190 MiB, the test process's own
/// growth, where the replay took 100 and 110. Python runs the replay and
/// prints its children's peak.
#[cfg(unix)]
const PEAK_OF_CHILD: &str = "\
import resource, subprocess, sys
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
if r.returncode != 0:
    sys.exit('replay failed: ' + r.stderr.decode(errors='replace'))
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
";

/// Peak resident memory (KiB) of `replay TRACE --rrd OUT --no-rrd-footer`,
/// as the kernel counted it for that process.
#[cfg(unix)]
fn replay_peak_kib(trace: &std::path::Path, out: &std::path::Path) -> anyhow::Result<libc::c_long> {
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(PEAK_OF_CHILD)
        .arg(bin().get_program())
        .arg("replay")
        .arg(trace)
        .arg("--rrd")
        .arg(out)
        .arg("--no-rrd-footer")
        .output()
        .map_err(|e| anyhow::anyhow!("python3 (which measures the replay) did not start: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    anyhow::ensure!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Linux counts ru_maxrss in KiB.
    stdout
        .trim()
        .parse()
        .map_err(|e| anyhow::anyhow!("the peak printed, {stdout:?}: {e}"))
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
