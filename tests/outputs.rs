//! Output files: written under a temporary name and renamed, except where
//! renaming would do harm (a device or a named pipe is written directly; a
//! symbolic link keeps pointing at the finished file).

use libtest_mimic::Trial;

use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(symlink_target_keeps_the_link),
        trial!(named_pipe_is_written_directly),
        trial!(full_disk_is_a_clear_error),
        trial!(killed_mid_write_leaves_the_target_intact),
        trial!(killed_bless_and_record_leave_the_target_intact),
        trial!(unreachable_viewer_is_a_clear_error),
        trial!(closed_stdout_ends_quietly),
        trial!(trace_to_a_pipe_is_refused),
    ]
}

fn sample_trace() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_cube_corner_margin.mcap")
}

fn replay_outcomes(target: &std::path::Path) -> anyhow::Result<std::process::Output> {
    std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg("replay")
        .arg(sample_trace())
        .arg("--outcomes")
        .arg(target)
        .output()
        .map_err(anyhow::Error::from)
}

/// `--outcomes link.jsonl` where the link points at another file: the link
/// stays a link and the file it points at holds the outcomes.
fn symlink_target_keeps_the_link() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let real = dir.path().join("real.jsonl");
    let link = dir.path().join("link.jsonl");
    std::fs::write(&real, "old\n")?;
    std::os::unix::fs::symlink(&real, &link)?;
    let out = replay_outcomes(&link)?;
    if !out.status.success() {
        anyhow::bail!("replay failed: {}", String::from_utf8_lossy(&out.stderr));
    }
    let meta = std::fs::symlink_metadata(&link)?;
    if !meta.file_type().is_symlink() {
        return Err(anyhow::anyhow!("the symbolic link was replaced by a file"));
    }
    let text = std::fs::read_to_string(&real)?;
    if !(text.starts_with("{\"frame\":") && text.lines().count() > 100) {
        anyhow::bail!("the linked file holds {} lines", text.lines().count());
    }
    Ok(())
}

/// `--outcomes fifo`: the pipe is written to (a reader receives every line)
/// and is still a pipe afterwards, not a regular file renamed over it.
fn named_pipe_is_written_directly() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let fifo = dir.path().join("outcomes.fifo");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .map_err(|e| anyhow::anyhow!("mkfifo: {e}"))?;
    if !status.success() {
        return Err(anyhow::anyhow!("mkfifo failed"));
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).map_err(anyhow::Error::from))
    };
    let out = replay_outcomes(&fifo)?;
    let text = reader
        .join()
        .map_err(|_| anyhow::anyhow!("reader panicked"))??;
    if !out.status.success() {
        anyhow::bail!("replay failed: {}", String::from_utf8_lossy(&out.stderr));
    }
    use std::os::unix::fs::FileTypeExt;
    let meta = std::fs::symlink_metadata(&fifo)?;
    if !meta.file_type().is_fifo() {
        return Err(anyhow::anyhow!("the named pipe was replaced by a file"));
    }
    if text.lines().count() < 100 {
        anyhow::bail!("the reader got {} lines", text.lines().count());
    }
    Ok(())
}

/// `replay` with every output on a full device (`/dev/full` fails every
/// write with "No space left on device"): it ends within seconds (the SDK's
/// own file writer used to hang here), exits 2 and names the file and the
/// operating system's reason.
fn full_disk_is_a_clear_error() -> anyhow::Result<()> {
    if !std::path::Path::new("/dev/full").exists() {
        return Err(anyhow::anyhow!(
            "/dev/full is missing: this test needs a Linux system"
        ));
    }
    for args in [["--rrd", "/dev/full"], ["--outcomes", "/dev/full"]] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
            .arg("replay")
            .arg(sample_trace())
            .args(args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()?;
        // Not a measurement: a bound that only a hang exceeds.
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
        let status = loop {
            if let Some(status) = child.try_wait()? {
                break status;
            }
            if std::time::Instant::now() > deadline {
                let _ = child.kill();
                anyhow::bail!("replay {args:?} hangs on a full device");
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        };
        let mut stderr = String::new();
        if let Some(mut e) = child.stderr.take() {
            use std::io::Read;
            e.read_to_string(&mut stderr)?;
        }
        if status.code() != Some(2) {
            anyhow::bail!("replay {args:?}: exit {:?}: {stderr}", status.code());
        }
        if !(stderr.contains("/dev/full") && stderr.contains("No space left on device")) {
            anyhow::bail!("replay {args:?}: the error names neither file nor cause: {stderr}");
        }
    }
    Ok(())
}

/// `replay --rrd` killed (SIGKILL) at several moments: the earlier recording
/// under the target name is intact or replaced by a complete new one (never
/// a partial file), and what is left over is a temporary file whose name
/// says what it is, which the next run reports with how to remove it.
fn killed_mid_write_leaves_the_target_intact() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let target = dir.path().join("golf.rrd");
    let trace =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_mini_golf.mcap");
    let replay = |extra: &[&str]| {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"));
        command
            .arg("replay")
            .arg(&trace)
            .arg("--rrd")
            .arg(&target)
            .args(extra)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped());
        command
    };
    let first = replay(&[]).output()?;
    if !first.status.success() {
        anyhow::bail!("{}", String::from_utf8_lossy(&first.stderr));
    }
    let complete = std::fs::read(&target)?;
    // Kill at several points of a run (the delays only vary where the run
    // is when killed; the property must hold at any of them).
    for delay_ms in [0u64, 20, 60, 150, 400] {
        let mut child = replay(&["--detail", "all"]).spawn()?;
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let now = std::fs::read(&target)?;
        // Intact, or a complete recording of the new run (Rerun's decoder
        // reads it to its end): never a partial file.
        if now != complete {
            crate::replay::decode_rrd(&target).map_err(|e| {
                anyhow::anyhow!("after a kill at {delay_ms} ms the target does not decode: {e}")
            })?;
        }
        leftovers_are_reported(dir.path(), "golf.rrd", || replay(&[]).output())
            .map_err(|e| anyhow::anyhow!("after a kill at {delay_ms} ms: {e}"))?;
    }
    Ok(())
}

/// `bless --in-place` and `record -o` killed (SIGKILL) at several
/// moments: the trace under the target name is the earlier one or a
/// complete new one that reads to its end, and what is left over is a
/// `.NAME.partial-*` temporary file, which the next run reports with how
/// to remove it.
fn killed_bless_and_record_leave_the_target_intact() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let target = dir.path().join("golf.mcap");
    let terrain =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_terrain.mcap");
    let commands: [(&str, Vec<std::ffi::OsString>); 2] = [
        (
            "bless --in-place",
            vec!["bless".into(), target.clone().into(), "--in-place".into()],
        ),
        (
            "record",
            vec![
                "record".into(),
                "--scene".into(),
                "terrain".into(),
                "--frames".into(),
                "300".into(),
                "-o".into(),
                target.clone().into(),
            ],
        ),
    ];
    for (what, args) in commands {
        for delay_ms in [0u64, 20, 60, 150, 400] {
            std::fs::copy(&terrain, &target)?;
            let before = std::fs::read(&target)?;
            let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
                .args(&args)
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()?;
            std::thread::sleep(std::time::Duration::from_millis(delay_ms));
            let _ = child.kill();
            let _ = child.wait();
            let now = std::fs::read(&target)?;
            if now != before {
                // A complete new trace: it reads to its end without an error.
                let name = target.display().to_string();
                if let Some(err) =
                    sweeptrace::TraceReader::new(now.as_slice(), &name).find_map(Result::err)
                {
                    anyhow::bail!("{what} killed at {delay_ms} ms left a broken target: {err}");
                }
            }
            leftovers_are_reported(dir.path(), "golf.mcap", || {
                std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
                    .args(["record", "--scene", "cube", "--frames", "3", "-o"])
                    .arg(&target)
                    .output()
            })
            .map_err(|e| anyhow::anyhow!("{what} killed at {delay_ms} ms: {e}"))?;
        }
    }
    Ok(())
}

/// After a killed run writing `target_name` in `dir`: every file left
/// besides the target is a `.TARGET.partial-*` temporary, and when there is
/// one, the next run (`next`) succeeds and reports it with the `rm` command
/// to remove it. The leftovers are removed for the next attempt.
fn leftovers_are_reported(
    dir: &std::path::Path,
    target_name: &str,
    next: impl FnOnce() -> std::io::Result<std::process::Output>,
) -> anyhow::Result<()> {
    let leftovers: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != target_name)
        .collect();
    let temporary = format!(".{target_name}.partial-");
    if let Some(odd) = leftovers.iter().find(|n| !n.starts_with(&temporary)) {
        anyhow::bail!("an unexpected file is left: {odd}");
    }
    if leftovers.is_empty() {
        return Ok(());
    }
    let next = next()?;
    let stderr = String::from_utf8_lossy(&next.stderr);
    if !(next.status.success()
        && stderr.contains("unfinished temporary file")
        && stderr.contains("rm "))
    {
        anyhow::bail!("the next run does not report the leftovers: {stderr}");
    }
    for name in leftovers {
        std::fs::remove_file(dir.join(name))?;
    }
    Ok(())
}

/// `replay --connect` to a viewer that is not there (nothing listens on
/// port 1): the command ends (it used to wait forever), exits 2 and names
/// the address.
fn unreachable_viewer_is_a_clear_error() -> anyhow::Result<()> {
    let url = "rerun+http://127.0.0.1:1/proxy";
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg("replay")
        .arg(sample_trace())
        .args(["--connect", url])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()?;
    // Not a measurement: a bound that only a hang exceeds.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(180);
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            return Err(anyhow::anyhow!(
                "replay --connect hangs on an unreachable viewer"
            ));
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    };
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        e.read_to_string(&mut stderr)?;
    }
    if status.code() != Some(2) || !stderr.contains(url) {
        anyhow::bail!("exit {:?}: {stderr}", status.code());
    }
    // One figure of time, the true one: how long it tried in all (not the
    // SDK's own count next to a different timeout of ours).
    let error = stderr
        .lines()
        .find(|l| l.starts_with("error: "))
        .with_context(|| format!("no error line: {stderr}"))?;
    let words: Vec<&str> = error
        .split_whitespace()
        .map(|w| w.trim_matches(|c: char| "(),;:".contains(c)))
        .collect();
    let number = |w: &str| !w.is_empty() && w.parse::<f64>().is_ok();
    let figures = words
        .iter()
        .enumerate()
        .filter(|(i, w)| {
            let glued = w.strip_suffix('s').is_some_and(number);
            glued || (number(w) && words.get(i + 1) == Some(&"s"))
        })
        .count();
    if figures != 1 || error.contains("within") {
        anyhow::bail!("not one figure of time: {error}");
    }
    Ok(())
}

/// `replay --outcomes -` whose reader goes away at once (`| head -0`): the
/// command ends like other command-line tools, by SIGPIPE, without an
/// error message and without waiting.
fn closed_stdout_ends_quietly() -> anyhow::Result<()> {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg("replay")
        .arg(sample_trace())
        .args(["--outcomes", "-"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()?;
    drop(child.stdout.take());
    // Not a measurement: a bound that only a hang exceeds.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            return Err(anyhow::anyhow!("replay hangs when its stdout is closed"));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        e.read_to_string(&mut stderr)?;
    }
    use std::os::unix::process::ExitStatusExt;
    if status.signal() != Some(SIGPIPE) || stderr.contains("error") {
        anyhow::bail!("status {status:?}, stderr: {stderr}");
    }
    Ok(())
}

/// SIGPIPE's number on Linux.
const SIGPIPE: i32 = 13;

/// `record -o` and `bless -o` to a named pipe: an MCAP trace is written
/// with seeks, so the pipe is refused with exit 2 and a message naming it
/// (the MCAP writer used to panic on a target that cannot seek), and the
/// pipe is left as it was.
fn trace_to_a_pipe_is_refused() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let fifo = dir.path().join("trace.mcap");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .map_err(|e| anyhow::anyhow!("mkfifo: {e}"))?;
    if !status.success() {
        return Err(anyhow::anyhow!("mkfifo failed"));
    }
    let commands: [Vec<std::ffi::OsString>; 2] = [
        vec![
            "record".into(),
            "--scene".into(),
            "cube".into(),
            "--frames".into(),
            "3".into(),
            "-o".into(),
            fifo.clone().into(),
        ],
        vec![
            "bless".into(),
            sample_trace().into(),
            "-o".into(),
            fifo.clone().into(),
        ],
    ];
    for args in commands {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
            .args(&args)
            .output()?;
        let stderr = String::from_utf8_lossy(&out.stderr);
        if out.status.code() != Some(2)
            || !stderr.contains("trace.mcap")
            || !stderr.contains("not a regular file")
        {
            anyhow::bail!("{args:?}: exit {:?}: {stderr}", out.status.code());
        }
        use std::os::unix::fs::FileTypeExt;
        let meta = std::fs::symlink_metadata(&fifo)?;
        if !meta.file_type().is_fifo() {
            anyhow::bail!("{args:?} replaced the pipe");
        }
    }
    Ok(())
}
