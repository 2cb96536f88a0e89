//! Traces whose chunks overlap in log time, as a multi-threaded recorder
//! writes them, written by another library (Python's `mcap`, through
//! `scripts/write_out_of_order.py`): with a summary they are read in
//! log-time order through the chunk indexes; without one they give the
//! out-of-order error naming the file, channel and frame.

use std::path::{Path, PathBuf};

use libtest_mimic::{Completion, Trial};
use sweeptrace::trace::{TraceError, TraceEvent, TraceReader};

use crate::{ensure, os, trial};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(overlapping_chunks_written_by_python),
        trial!(overlapping_chunks_have_every_contact_query_drawn),
    ]
}

/// The sample trace the overlapping files are made from.
fn source() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_cube_corner_margin.mcap")
}

/// Every event of a reader, without the message indexes (which follow the
/// reading order), and the error that ended it.
fn events_of<R: std::io::Read>(
    reader: TraceReader<R>,
) -> (Vec<TraceEvent>, Option<TraceError>, bool) {
    let mut reader = reader;
    let mut events = Vec::new();
    let mut error = None;
    for item in reader.by_ref() {
        match item {
            Ok(mut event) => {
                event.header.index = 0;
                events.push(event);
            }
            Err(err) => error = Some(err),
        }
    }
    let indexed = reader.stats().read_through_chunk_indexes;
    (events, error, indexed)
}

fn open(path: &Path) -> anyhow::Result<std::io::BufReader<std::fs::File>> {
    std::fs::File::open(path)
        .map(std::io::BufReader::new)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

fn overlapping_chunks_written_by_python() -> anyhow::Result<Completion> {
    if let Err(skipped) = crate::support::python_with_mcap()? {
        return Ok(skipped);
    }
    let dir = tempfile::tempdir()?;
    let with_summary = dir.path().join("overlapping.mcap");
    let without_summary = dir.path().join("overlapping_no_summary.mcap");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/write_out_of_order.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(source())
        .arg(&with_summary)
        .arg(&without_summary)
        .output()?;
    ensure!(
        out.status.success(),
        "the script failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );

    // The original, read in file order: the events every reading must give.
    let (want, error, indexed) = events_of(TraceReader::new_indexed(open(&source())?, "original"));
    ensure!(error.is_none(), "the original does not read: {error:?}");
    ensure!(!indexed, "an ordinary trace was read through its indexes");
    ensure!(want.len() > 100, "the original has {} events", want.len());

    // With a summary: the same events in the same order, through the indexes.
    let name = with_summary.display().to_string();
    let (got, error, indexed) = events_of(TraceReader::new_indexed(open(&with_summary)?, &name));
    ensure!(error.is_none(), "the file with a summary fails: {error:?}");
    ensure!(
        indexed,
        "the file with a summary was not read through its indexes"
    );
    ensure!(
        got == want,
        "read through the indexes, {} events differ from the original's {} (first difference at {:?})",
        got.len(),
        want.len(),
        got.iter().zip(&want).position(|(a, b)| a != b)
    );
    // Read as a stream (no seeking), the same file is out of order: this is
    // the file the indexes are needed for.
    let bytes = std::fs::read(&with_summary)?;
    let (_, error, _) = events_of(TraceReader::new(bytes.as_slice(), &name));
    ensure!(
        matches!(error, Some(TraceError::OutOfOrder { .. })),
        "the streamed file is not out of order: {error:?}"
    );
    // The commands: info says how it was read, check passes.
    let (code, stdout, stderr) = crate::support::run_bin(os!("info", &with_summary))?;
    ensure!(
        code == 0
            && stdout.contains("2 chunks")
            && stdout.contains("messages:    out of log-time order across chunks"),
        "info: exit {code}: {stdout}{stderr}"
    );
    let (code, stdout, stderr) = crate::support::run_bin(os!("info", &with_summary, "--json"))?;
    ensure!(
        code == 0 && stdout.contains("\"read_through_chunk_indexes\": true"),
        "info --json: exit {code}: {stdout}{stderr}"
    );
    let (code, stdout, stderr) = crate::support::run_bin(os!("check", &with_summary))?;
    ensure!(
        code == 0 && stdout.starts_with("ok "),
        "check: exit {code}: {stdout}{stderr}"
    );

    // Without a summary: the out-of-order error, naming the file, the
    // channel and the frame.
    let name = without_summary.display().to_string();
    let (_, error, indexed) = events_of(TraceReader::new_indexed(open(&without_summary)?, &name));
    ensure!(
        !indexed,
        "a file without a summary was read through indexes"
    );
    match error {
        Some(TraceError::OutOfOrder { at, .. }) => ensure!(
            at.file == name && at.channel == "/sweep" && at.frame == Some(1),
            "the error is at {at}"
        ),
        other => anyhow::bail!("without a summary: {other:?}"),
    }
    let (code, stdout, stderr) = crate::support::run_bin(os!("check", &without_summary))?;
    ensure!(
        code == 2
            && stdout.contains(&format!("ERROR {name}: channel `/sweep`, frame 1"))
            && stdout.contains("is earlier than the previous message's"),
        "check without a summary: exit {code}: {stdout}{stderr}"
    );
    if let Some(repeated) = sweeptrace::fuzzing::repeated_segment(&stdout) {
        anyhow::bail!("check repeats `{repeated}`: {stdout}");
    }
    Ok(Completion::Completed)
}

/// A contact trace whose chunks overlap in time: `replay` draws every
/// contact query into the recording and the Foxglove file, and `check
/// --engine` asks the engine every one, as `check` judges them all (the second read, for the queries, goes through the
/// chunk indexes like the first; in file order it stopped silently at the
/// first message out of order, 1,006 of 2,238 queries drawn).
fn overlapping_chunks_have_every_contact_query_drawn() -> anyhow::Result<Completion> {
    if let Err(skipped) = crate::support::python_with_mcap()? {
        return Ok(skipped);
    }
    let dir = tempfile::tempdir()?;
    let source = crate::contacts::record(dir.path(), &[])?;
    let overlapping = dir.path().join("overlapping.mcap");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/write_out_of_order.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(&source)
        .arg(&overlapping)
        .arg(dir.path().join("no_summary.mcap"))
        .output()?;
    ensure!(
        out.status.success(),
        "the script failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (code, stdout, stderr) = crate::support::run_bin(os!("info", &overlapping))?;
    ensure!(
        code == 0 && stdout.contains("messages:    out of log-time order across chunks"),
        "info: exit {code}: {stdout}{stderr}"
    );
    let (rrd, foxglove) = (dir.path().join("o.rrd"), dir.path().join("o.foxglove.mcap"));
    let (code, _, stderr) = crate::support::run_bin(os!(
        "replay",
        &overlapping,
        "--rrd",
        &rrd,
        "--foxglove",
        &foxglove
    ))?;
    ensure!(code == 0, "replay: {stderr}");
    for line in [
        "contacts: 2238 queries drawn (1816 contacts",
        "contacts in the Foxglove file: 2238 queries drawn (1816 contacts",
    ] {
        ensure!(stderr.contains(line), "no {line:?} in: {stderr}");
    }
    // An engine is asked every sweep and query in log-time order, as
    // `check` reads them (in file order the trace was refused as out of
    // order).
    let engine = crate::engine::example_engine_command("");
    let (code, stdout, stderr) = crate::support::run_bin(os!(
        "check",
        &overlapping,
        "--engine",
        &engine,
        "--engine-contacts"
    ))?;
    ensure!(
        code == 0 && stdout.contains("contacts: 2238 queries, 2238 compared, 0 diverge"),
        "check --engine: exit {code}: {stdout}{stderr}"
    );
    Ok(Completion::Completed)
}
