//! Output files: written under a temporary name and renamed, except where
//! renaming would do harm (a device or a named pipe is written directly; a
//! symbolic link keeps pointing at the finished file).

use libtest_mimic::Trial;

use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial(
            "outputs::symlink_target_keeps_the_link",
            symlink_target_keeps_the_link,
        ),
        trial(
            "outputs::named_pipe_is_written_directly",
            named_pipe_is_written_directly,
        ),
    ]
}

fn sample_trace() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_cube_corner_margin.mcap")
}

fn replay_outcomes(target: &std::path::Path) -> Result<std::process::Output, String> {
    std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg("replay")
        .arg(sample_trace())
        .arg("--outcomes")
        .arg(target)
        .output()
        .map_err(|e| e.to_string())
}

/// `--outcomes link.jsonl` where the link points at another file: the link
/// stays a link and the file it points at holds the outcomes.
fn symlink_target_keeps_the_link() -> Result<(), String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let real = dir.path().join("real.jsonl");
    let link = dir.path().join("link.jsonl");
    std::fs::write(&real, "old\n").map_err(|e| e.to_string())?;
    std::os::unix::fs::symlink(&real, &link).map_err(|e| e.to_string())?;
    let out = replay_outcomes(&link)?;
    if !out.status.success() {
        return Err(format!(
            "replay failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let meta = std::fs::symlink_metadata(&link).map_err(|e| e.to_string())?;
    if !meta.file_type().is_symlink() {
        return Err("the symbolic link was replaced by a file".into());
    }
    let text = std::fs::read_to_string(&real).map_err(|e| e.to_string())?;
    if !(text.starts_with("{\"frame\":") && text.lines().count() > 100) {
        return Err(format!(
            "the linked file holds {} lines",
            text.lines().count()
        ));
    }
    Ok(())
}

/// `--outcomes fifo`: the pipe is written to (a reader receives every line)
/// and is still a pipe afterwards, not a regular file renamed over it.
fn named_pipe_is_written_directly() -> Result<(), String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let fifo = dir.path().join("outcomes.fifo");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .map_err(|e| format!("mkfifo: {e}"))?;
    if !status.success() {
        return Err("mkfifo failed".into());
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).map_err(|e| e.to_string()))
    };
    let out = replay_outcomes(&fifo)?;
    let text = reader.join().map_err(|_| "reader panicked")??;
    if !out.status.success() {
        return Err(format!(
            "replay failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    use std::os::unix::fs::FileTypeExt;
    let meta = std::fs::symlink_metadata(&fifo).map_err(|e| e.to_string())?;
    if !meta.file_type().is_fifo() {
        return Err("the named pipe was replaced by a file".into());
    }
    if text.lines().count() < 100 {
        return Err(format!("the reader got {} lines", text.lines().count()));
    }
    Ok(())
}
