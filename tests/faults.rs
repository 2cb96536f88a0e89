//! Faults of the environment on real file systems: a full disk (a small
//! tmpfs), a read-only file system, a directory removed while a recording
//! is written. Each command must end within seconds with exit 2, a message
//! naming the file and the operating system's reason once, and no file
//! under the target name (the previous one intact where there was one).
//!
//! Mounting needs root (or a user namespace). Where it is impossible the
//! tests are reported as ignored with the reason; in CI (`CI=true`, or
//! `SWEEPTRACE_REQUIRE_MOUNT=1` as `.ci/run` sets) they fail instead.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use libtest_mimic::{Completion, Trial};

use crate::{ensure, trial};
use anyhow::Context as _;

/// Set to `1` (CI does) to make these tests fail, instead of being
/// skipped, where a tmpfs cannot be mounted.
const REQUIRE_MOUNT: &str = "SWEEPTRACE_REQUIRE_MOUNT";

/// A bound that only a hang exceeds (not a measurement).
const LIMIT: Duration = Duration::from_secs(120);

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(full_disk_replay_rrd, timeout = LIMIT),
        trial!(full_disk_replay_outcomes, timeout = LIMIT),
        trial!(full_disk_record, timeout = LIMIT),
        trial!(full_disk_bless, timeout = LIMIT),
        trial!(full_disk_bless_in_place_keeps_the_trace, timeout = LIMIT),
        trial!(read_only_file_system, timeout = LIMIT),
        trial!(directory_removed_during_replay, timeout = LIMIT),
    ]
}

/// A tmpfs mounted on a temporary directory; unmounted when dropped, also
/// when the test fails.
struct Tmpfs {
    dir: tempfile::TempDir,
}

impl Tmpfs {
    /// Mounts a tmpfs of `size_kib` KiB: `Ok(Err(reason))` when this
    /// machine cannot (not root, no mount permission).
    fn mount(size_kib: u64) -> anyhow::Result<Result<Tmpfs, String>> {
        let dir = tempfile::tempdir()?;
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size_kib}k"), "tmpfs"])
            .arg(dir.path())
            .output();
        match out {
            Ok(o) if o.status.success() => Ok(Ok(Tmpfs { dir })),
            Ok(o) => Ok(Err(format!(
                "cannot mount a tmpfs: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ))),
            Err(e) => Ok(Err(format!("cannot run mount: {e}"))),
        }
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Makes the file system read-only.
    fn remount_read_only(&self) -> anyhow::Result<()> {
        let status = Command::new("mount")
            .args(["-o", "remount,ro"])
            .arg(self.path())
            .status()?;
        ensure!(status.success(), "mount -o remount,ro failed");
        Ok(())
    }

    /// Fills the file system but for about `free_kib` KiB.
    fn fill_leaving(&self, free_kib: u64) -> anyhow::Result<()> {
        let stat = Command::new("df")
            .args(["--output=avail", "-k"])
            .arg(self.path())
            .output()?;
        let text = String::from_utf8_lossy(&stat.stdout);
        let available: u64 = text
            .lines()
            .nth(1)
            .and_then(|l| l.trim().parse().ok())
            .with_context(|| format!("cannot read df's output: {text}"))?;
        let filler = available.saturating_sub(free_kib) as usize * 1024;
        std::fs::write(self.path().join("filler"), vec![0u8; filler]).map_err(anyhow::Error::from)
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let unmounted = Command::new("umount")
            .arg(self.dir.path())
            .status()
            .is_ok_and(|s| s.success());
        if !unmounted {
            // Busy (a child still running): detach it now, freed later.
            let _ = Command::new("umount")
                .arg("-l")
                .arg(self.dir.path())
                .status();
        }
    }
}

/// A tmpfs, or the completion of a test that cannot run here: ignored with
/// the reason, or a failure where mounting is required.
fn tmpfs(size_kib: u64) -> anyhow::Result<Result<Tmpfs, Completion>> {
    match Tmpfs::mount(size_kib)? {
        Ok(mount) => Ok(Ok(mount)),
        Err(reason) => {
            let required = std::env::var_os(REQUIRE_MOUNT).is_some_and(|v| v == "1")
                || std::env::var_os("CI").is_some_and(|v| v == "true");
            if required {
                Err(anyhow::anyhow!(
                    "{reason}; CI (or {REQUIRE_MOUNT}=1) requires this test (run it as root)"
                ))
            } else {
                Ok(Err(Completion::ignored_with(format!(
                    "skipped: {reason} (run as root to test real file systems; \
                     {REQUIRE_MOUNT}=1 makes this a failure)"
                ))))
            }
        }
    }
}

/// Unwraps a [`tmpfs`] or returns the test's completion.
macro_rules! mounted {
    ($size_kib:expr) => {
        match tmpfs($size_kib)? {
            Ok(mount) => mount,
            Err(completion) => return Ok(completion),
        }
    };
}

fn repository_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// Runs the binary with `args`, killing it if it has not ended within
/// [`LIMIT`]: exit code and stderr.
fn run_bounded(args: &[&std::ffi::OsStr]) -> anyhow::Result<(i32, String)> {
    let child = crate::support::bin()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    wait_bounded(child, &format!("{args:?}"))
}

fn wait_bounded(mut child: std::process::Child, what: &str) -> anyhow::Result<(i32, String)> {
    let deadline = Instant::now() + LIMIT;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            anyhow::bail!("{what} did not end within {} s", LIMIT.as_secs());
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        e.read_to_string(&mut stderr)?;
    }
    Ok((status.code().unwrap_or(-1), stderr))
}

/// Exit 2, an `error:` line naming `target` and saying `reason` exactly
/// once, and no part of the message repeated.
fn check_error(
    what: &str,
    (code, stderr): &(i32, String),
    target: &Path,
    reason: &str,
) -> anyhow::Result<()> {
    ensure!(*code == 2, "{what}: exit {code}, want 2: {stderr}");
    let error = stderr
        .lines()
        .find(|l| l.starts_with("error: "))
        .with_context(|| format!("{what}: no error line: {stderr}"))?;
    ensure!(
        error.contains(&target.display().to_string()),
        "{what}: the error does not name {}: {error}",
        target.display()
    );
    ensure!(
        error.matches(reason).count() == 1,
        "{what}: the error does not say `{reason}` exactly once: {error}"
    );
    if let Some(repeated) = sweeptrace::fuzzing::repeated_segment(error) {
        anyhow::bail!("{what}: the error repeats `{repeated}`: {error}");
    }
    Ok(())
}

/// The names of the files in `dir`, but `keep`.
fn files_in(dir: &Path, keep: &[&str]) -> anyhow::Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect();
    names.sort();
    Ok(names)
}

const FULL: &str = "No space left on device";

/// `args` with `TARGET` replaced by `target`, `GOLF` by the mini-golf
/// sample trace and `CUBE` by the cube sample trace.
fn arguments(args: &[&str], target: &Path) -> Vec<std::ffi::OsString> {
    args.iter()
        .map(|a| match *a {
            "TARGET" => target.as_os_str().to_owned(),
            "GOLF" => repository_file("traces/record_mini_golf.mcap").into_os_string(),
            "CUBE" => repository_file("traces/record_cube_corner_margin.mcap").into_os_string(),
            other => other.into(),
        })
        .collect()
}

/// Runs `args` with `TARGET` a file named `target_name` on a tmpfs with
/// about 64 KiB free (every output here is larger): exit 2, the file and
/// "No space left on device" named once, nothing left on the disk.
fn onto_full_disk(what: &str, target_name: &str, args: &[&str]) -> anyhow::Result<Completion> {
    let disk = mounted!(512);
    disk.fill_leaving(64)?;
    let target = disk.path().join(target_name);
    let args = arguments(args, &target);
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let result = run_bounded(&args)?;
    check_error(what, &result, &target, FULL)?;
    let left = files_in(disk.path(), &["filler"])?;
    ensure!(
        left.is_empty(),
        "{what}: files left on the full disk: {left:?}"
    );
    Ok(Completion::Completed)
}

/// `replay --rrd` onto a full disk: it used to hang in the SDK's flush.
fn full_disk_replay_rrd() -> anyhow::Result<Completion> {
    onto_full_disk(
        "replay --rrd",
        "golf.rrd",
        &["replay", "GOLF", "--rrd", "TARGET"],
    )
}

/// `replay --outcomes` onto a full disk (the outcomes take about 340 KiB).
fn full_disk_replay_outcomes() -> anyhow::Result<Completion> {
    onto_full_disk(
        "replay --outcomes",
        "outcomes.jsonl",
        &["replay", "GOLF", "--outcomes", "TARGET"],
    )
}

/// `record` onto a full disk (the trace takes about 190 KiB).
fn full_disk_record() -> anyhow::Result<Completion> {
    onto_full_disk(
        "record",
        "golf.mcap",
        &["record", "--scene", "mini_golf", "-o", "TARGET"],
    )
}

/// `bless -o` onto a full disk: the message names the output (it used to
/// name the input).
fn full_disk_bless() -> anyhow::Result<Completion> {
    onto_full_disk(
        "bless -o",
        "blessed.mcap",
        &["bless", "GOLF", "-o", "TARGET"],
    )
}

/// `bless --in-place` of a trace on a disk with room for one copy only:
/// the error names the trace and the trace is left byte for byte as it was.
fn full_disk_bless_in_place_keeps_the_trace() -> anyhow::Result<Completion> {
    let disk = mounted!(512);
    let original = std::fs::read(repository_file("traces/record_mini_golf.mcap"))?;
    let trace = disk.path().join("golf.mcap");
    std::fs::write(&trace, &original)?;
    disk.fill_leaving(64)?;
    let result = run_bounded(crate::os!("bless", &trace, "--in-place"))?;
    check_error("bless --in-place", &result, &trace, FULL)?;
    let now = std::fs::read(&trace)?;
    ensure!(
        now == original,
        "bless --in-place changed the trace on failing"
    );
    let left = files_in(disk.path(), &["filler", "golf.mcap"])?;
    ensure!(left.is_empty(), "files left on the full disk: {left:?}");
    Ok(Completion::Completed)
}

/// Every output into a read-only file system: exit 2 naming the file and
/// "Read-only file system" once; `bless --in-place` keeps the trace.
fn read_only_file_system() -> anyhow::Result<Completion> {
    let disk = mounted!(1024);
    let original = std::fs::read(repository_file("traces/record_cube_corner_margin.mcap"))?;
    let trace = disk.path().join("cube.mcap");
    std::fs::write(&trace, &original)?;
    disk.remount_read_only()?;
    let reason = "Read-only file system";
    for (what, target, args) in [
        (
            "replay --rrd",
            "out.rrd",
            vec!["replay", "CUBE", "--rrd", "TARGET"],
        ),
        (
            "replay --outcomes",
            "out.jsonl",
            vec!["replay", "CUBE", "--outcomes", "TARGET"],
        ),
        (
            "record",
            "out.mcap",
            vec!["record", "--scene", "cube", "--frames", "5", "-o", "TARGET"],
        ),
        (
            "bless -o",
            "blessed.mcap",
            vec!["bless", "CUBE", "-o", "TARGET"],
        ),
        (
            "bless --in-place",
            "cube.mcap",
            vec!["bless", "TARGET", "--in-place"],
        ),
    ] {
        let target = disk.path().join(target);
        let args = arguments(&args, &target);
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let result = run_bounded(&args)?;
        check_error(what, &result, &target, reason)?;
        let left = files_in(disk.path(), &["cube.mcap"])?;
        ensure!(left.is_empty(), "{what}: files left: {left:?}");
    }
    let now = std::fs::read(&trace)?;
    ensure!(now == original, "bless --in-place changed the trace");
    Ok(Completion::Completed)
}

/// The output directory removed (`rm -r`) while `replay --rrd` writes into
/// it: once its temporary file has appeared, the directory goes; the command
/// ends with exit 2 naming the target and the reason, and nothing is
/// created under the target's name (no directory is made again).
fn directory_removed_during_replay() -> anyhow::Result<()> {
    let top = tempfile::tempdir()?;
    let dir = top.path().join("out");
    std::fs::create_dir(&dir)?;
    let target = dir.join("golf.rrd");
    let child = crate::support::bin()
        .arg("replay")
        .arg(repository_file("traces/record_mini_golf.mcap"))
        .args(["--detail", "all", "--threads", "1", "--rrd"])
        .arg(&target)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    // Wait for the temporary file (not a measurement: a bound on a hang).
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let names = files_in(&dir, &[])?;
        if names.iter().any(|n| n.starts_with(".golf.rrd.partial-")) {
            break;
        }
        ensure!(
            Instant::now() < deadline,
            "the temporary file never appeared: {names:?}"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    std::fs::remove_dir_all(&dir)?;
    let result = wait_bounded(child, "replay --rrd into a removed directory")?;
    check_error(
        "replay --rrd into a removed directory",
        &result,
        &target,
        "No such file or directory",
    )?;
    ensure!(!dir.exists(), "the removed directory came back");
    Ok(())
}
