//! The `sweeptrace.expected_source` metadata record (docs/TRACE_FORMAT.md,
//! *Expected source*): written by the Rust writer, `record` and `bless`,
//! read back, shown by `info` and `check` (text and JSON), absent from old
//! traces without changing how they read, refused when malformed, and read
//! by Python's `mcap` as an independent client.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use libtest_mimic::{Completion, Trial};
use mcap::records::{MessageHeader, Metadata};
use sweeptrace::core::Kind;
use sweeptrace::suite::{CheckOptions, Status, check_file, render_json, render_text};
use sweeptrace::trace::info::collect_info;
use sweeptrace::trace::source::EXPECTED_SOURCE_METADATA;
use sweeptrace::trace::{
    ExpectedSource, OutcomeMsg, SceneMsg, SweepMsg, TraceError, TraceEvent, TraceReader,
    TraceWriter, write_trace_file,
};

use crate::engine::example_engine_command;
use crate::support::run_bin;
use crate::support::scene_t;
use crate::{ensure, os, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(writer_and_reader_round_trip),
        trial!(writer_refuses_invalid_sources_and_a_second_one),
        trial!(write_trace_file_with_a_bad_source_leaves_no_file),
        trial!(old_trace_without_it_reads_as_before),
        trial!(malformed_records_are_errors_naming_the_file),
        trial!(info_shows_it),
        trial!(check_shows_it_in_text_and_json),
        trial!(check_engine_says_the_engine_answered),
        trial!(record_names_sweeptrace_and_bless_replaces_the_source),
        trial!(python_reads_the_record),
    ]
}

fn rapier() -> ExpectedSource {
    ExpectedSource::new("rapier3d-f64", "0.36.1").setting("fix_internal_edges", false)
}

const RAPIER_TEXT: &str = "rapier3d-f64 0.36.1 (fix_internal_edges = false)";

fn scene() -> SceneMsg {
    SceneMsg {
        name: Some("triangle".into()),
        ..scene_t(0.0)
    }
}

fn sweep(frame: u64) -> SweepMsg {
    SweepMsg {
        frame,
        ball: 0,
        radius: 0.5,
        p0: [1.0, 1.0, 3.0],
        p1: [1.0, 1.0, -3.0],
    }
}

/// The core's answer to [`sweep`] on [`scene`].
fn face_hit(frame: u64) -> OutcomeMsg {
    OutcomeMsg {
        frame,
        ball: 0,
        alpha: 5.0 / 12.0,
        kind: Kind::Face,
        triangle: Some(Some(0)),
        feature: Some(None),
        normal: Some(Some([0.0, 0.0, 1.0])),
        contact: None,
    }
}

/// Three sweeps with matching expectations, written by the project's
/// writer with `source` (if any) before the first message.
fn trace_bytes(source: Option<&ExpectedSource>) -> anyhow::Result<Vec<u8>> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    if let Some(source) = source {
        w.expected_source(source)?;
    }
    w.scene(0, &scene())?;
    for frame in 0..3 {
        let t = 1_000 + frame * 1_000_000;
        w.sweep(t, &sweep(frame))?;
        w.expected(t, &face_hit(frame))?;
    }
    Ok(w.finish()?.into_inner())
}

/// A trace written with the `mcap` crate directly, with the metadata
/// records `records` before its messages (the project's writer refuses a
/// malformed expected source, other writers may not).
fn raw_trace(records: &[BTreeMap<String, String>]) -> anyhow::Result<Vec<u8>> {
    let err = |e: mcap::McapError| anyhow::Error::from(e);
    let mut w = mcap::WriteOptions::new()
        .create(Cursor::new(Vec::new()))
        .map_err(err)?;
    for entries in records {
        w.write_metadata(&Metadata {
            name: EXPECTED_SOURCE_METADATA.to_string(),
            metadata: entries.clone(),
        })
        .map_err(err)?;
    }
    let scene_channel = w
        .add_channel(0, "/scene", "json", &BTreeMap::new())
        .map_err(err)?;
    let sweep_channel = w
        .add_channel(0, "/sweep", "json", &BTreeMap::new())
        .map_err(err)?;
    let json = |e: serde_json::Error| anyhow::Error::from(e);
    for (sequence, (channel_id, data)) in [
        (scene_channel, serde_json::to_vec(&scene()).map_err(json)?),
        (sweep_channel, serde_json::to_vec(&sweep(0)).map_err(json)?),
    ]
    .into_iter()
    .enumerate()
    {
        w.write_to_known_channel(
            &MessageHeader {
                channel_id,
                sequence: sequence as u32,
                log_time: sequence as u64,
                publish_time: sequence as u64,
            },
            &data,
        )
        .map_err(err)?;
    }
    w.finish().map_err(err)?;
    Ok(w.into_inner().into_inner())
}

fn entries(pairs: &[(&str, &str)]) -> BTreeMap<String, String> {
    pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// Every event of `bytes`, the reader's source, or the first error.
fn read(
    bytes: &[u8],
    name: &str,
) -> (
    Vec<TraceEvent>,
    Option<ExpectedSource>,
    Option<TraceError>,
    usize,
) {
    let mut reader = TraceReader::new(bytes, name);
    let mut events = Vec::new();
    let mut error = None;
    for event in reader.by_ref() {
        match event {
            Ok(e) => events.push(e),
            Err(e) => error = Some(e),
        }
    }
    let records = reader
        .stats()
        .metadata
        .iter()
        .filter(|(n, _)| n == EXPECTED_SOURCE_METADATA)
        .count();
    (events, reader.expected_source().cloned(), error, records)
}

fn writer_and_reader_round_trip() -> anyhow::Result<()> {
    let source = rapier()
        .setting("dt", 1.0 / 60.0)
        .setting("solver", "pgs, 4 iterations");
    let bytes = trace_bytes(Some(&source))?;
    let (events, read_back, error, records) = read(&bytes, "r.mcap");
    ensure!(error.is_none(), "{error:?}");
    ensure!(events.len() == 7, "{} events", events.len());
    ensure!(read_back.as_ref() == Some(&source), "{read_back:?}");
    ensure!(records == 1, "{records} records");
    // The indexed reader (used by check and bless) reads it the same way.
    let mut indexed = TraceReader::new_indexed(Cursor::new(bytes.as_slice()), "r.mcap");
    let count = indexed.by_ref().filter(Result::is_ok).count();
    ensure!(
        count == 7 && indexed.expected_source() == Some(&source),
        "{count} events, {:?}",
        indexed.expected_source()
    );
    // The record's entries, as any MCAP reader sees them.
    let (_, map) = indexed
        .stats()
        .metadata
        .iter()
        .find(|(n, _)| n == EXPECTED_SOURCE_METADATA)
        .context("no record")?;
    let want = entries(&[
        ("engine", "rapier3d-f64"),
        ("version", "0.36.1"),
        ("setting.dt", &(1.0f64 / 60.0).to_string()),
        ("setting.fix_internal_edges", "false"),
        ("setting.solver", "pgs, 4 iterations"),
    ]);
    ensure!(map == &want, "{map:?}");
    // Deterministic, like the rest of the writer's output.
    ensure!(trace_bytes(Some(&source))? == bytes, "two writes differ");
    Ok(())
}

fn writer_refuses_invalid_sources_and_a_second_one() -> anyhow::Result<()> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    let cases = [
        (ExpectedSource::new("", "1"), "`engine` is empty"),
        (
            ExpectedSource::new("e".repeat(129), "1"),
            "`engine` is 129 bytes, above the limit of 128",
        ),
        (
            ExpectedSource::new("e", "v".repeat(129)),
            "`version` is 129 bytes",
        ),
        (
            ExpectedSource::new("e", "1").setting("k", "v".repeat(1025)),
            "`setting.k` is 1025 bytes, above the limit of 1024",
        ),
        (ExpectedSource::new("e", "1").setting("", "x"), "empty name"),
        (ExpectedSource::new("e\ttab", "1"), "control character"),
        (
            (0..65).fold(ExpectedSource::new("e", "1"), |s, i| {
                s.setting(format!("s{i}"), i)
            }),
            "65 settings, above the limit of 64",
        ),
    ];
    for (source, want) in cases {
        let err = w
            .expected_source(&source)
            .err()
            .with_context(|| format!("accepted {source:?}"))?;
        let text = err.to_string();
        ensure!(
            matches!(err, TraceError::ExpectedSource { .. })
                && text.contains("sweeptrace.expected_source")
                && text.contains(want),
            "{text} (want {want})"
        );
    }
    // `metadata` under the record's name goes through the same checks.
    let err = w
        .metadata(EXPECTED_SOURCE_METADATA, entries(&[("engin", "x")]))
        .err()
        .context("metadata accepted a bad record")?;
    ensure!(err.to_string().contains("unknown key `engin`"), "{err}");
    w.expected_source(&rapier())?;
    let err = w
        .expected_source(&rapier())
        .err()
        .context("a second source was accepted")?;
    ensure!(err.to_string().contains("already written"), "{err}");
    w.scene(0, &scene())?;
    let bytes = w.finish()?.into_inner();
    let (_, read_back, error, records) = read(&bytes, "w.mcap");
    ensure!(error.is_none(), "{error:?}");
    ensure!(
        read_back == Some(rapier()) && records == 1,
        "refused sources were written: {read_back:?}, {records} records"
    );
    Ok(())
}

fn write_trace_file_with_a_bad_source_leaves_no_file() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("bad.mcap");
    let result = write_trace_file(&path, |w| -> Result<(), TraceError> {
        w.scene(0, &scene())?;
        w.expected_source(&ExpectedSource::new("", "1"))
    });
    let err = result.err().context("an empty engine name was accepted")?;
    let text = err.to_string();
    ensure!(
        text.starts_with(&path.display().to_string()) && text.contains("`engine` is empty"),
        "{text}"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path())?
        .filter_map(Result::ok)
        .map(|e| e.file_name())
        .collect();
    ensure!(left.is_empty(), "files left: {left:?}");
    // A good one is in the renamed file.
    let path = dir.path().join("good.mcap");
    write_trace_file(&path, |w| -> Result<(), TraceError> {
        w.expected_source(&rapier())?;
        w.scene(0, &scene())
    })?;
    let bytes = std::fs::read(&path)?;
    let (_, read_back, error, _) = read(&bytes, "good.mcap");
    ensure!(
        error.is_none() && read_back == Some(rapier()),
        "{read_back:?} {error:?}"
    );
    Ok(())
}

fn repository_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn old_trace_without_it_reads_as_before() -> anyhow::Result<()> {
    // A trace written before the record existed (a sample as committed
    // then, kept as a fixture), and one
    // written now without a source: no source, the same events and reports.
    let old =
        repository_file("tests/fixtures/before_expected_source/record_cube_corner_margin.mcap");
    let bytes = std::fs::read(&old)?;
    let (events, source, error, _) = read(&bytes, "old.mcap");
    ensure!(error.is_none(), "{error:?}");
    ensure!(source.is_none(), "{source:?}");
    ensure!(!events.is_empty(), "no event");
    let (info, error) = collect_info(TraceReader::new(bytes.as_slice(), "old.mcap"));
    ensure!(error.is_none(), "{error:?}");
    let text = sweeptrace::trace::info::render_info_text(&info);
    ensure!(!text.contains("expected by"), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&sweeptrace::trace::info::render_info_json(&info))?;
    ensure!(json["expected_source"].is_null(), "{json}");
    let report = check_file(&old, &CheckOptions::default());
    ensure!(report.status() == Status::Ok, "{}", render_text(&report));
    let text = render_text(&report);
    ensure!(
        !text.contains("expectations from") && text.lines().count() == 1,
        "{text}"
    );
    let json: serde_json::Value = serde_json::from_str(&render_json(&[report], 0))?;
    ensure!(
        json["traces"][0]
            .as_object()
            .is_some_and(|o| o.contains_key("expected_source"))
            && json["traces"][0]["expected_source"].is_null(),
        "{json}"
    );
    let (new_events, ..) = read(&trace_bytes(None)?, "new.mcap");
    let (with_source, ..) = read(&trace_bytes(Some(&rapier()))?, "new.mcap");
    ensure!(
        new_events == with_source,
        "the record changes the events read"
    );
    Ok(())
}

fn malformed_records_are_errors_naming_the_file() -> anyhow::Result<()> {
    let good = entries(&[("engine", "e"), ("version", "1")]);
    let cases: Vec<(Vec<BTreeMap<String, String>>, &str)> = vec![
        (vec![entries(&[("version", "1")])], "no `engine` key"),
        (vec![entries(&[("engine", "")])], "`engine` is empty"),
        (
            vec![entries(&[("engine", "e"), ("fix_internal_edges", "true")])],
            "unknown key `fix_internal_edges`",
        ),
        (
            vec![entries(&[("engine", "e"), ("setting.", "1")])],
            "empty name",
        ),
        (
            vec![entries(&[("engine", "e"), ("version", "1\n2")])],
            "`version` holds a control character",
        ),
        (vec![good.clone(), good.clone()], "the file holds two"),
    ];
    let dir = tempfile::tempdir()?;
    for (records, want) in cases {
        let bytes = raw_trace(&records)?;
        let (_, _, error, _) = read(&bytes, "bad.mcap");
        let error = error.with_context(|| format!("no error for {records:?}"))?;
        let text = error.to_string();
        ensure!(
            matches!(error, TraceError::ExpectedSource { .. })
                && text.starts_with("bad.mcap: metadata record `sweeptrace.expected_source`: ")
                && text.contains(want),
            "{text} (want {want})"
        );
        // The commands: `info` and `check` exit 2 with the message.
        let path = dir.path().join("bad.mcap");
        std::fs::write(&path, &bytes)?;
        let (code, stdout, stderr) = run_bin(os!("info", path.as_os_str()))?;
        ensure!(
            code == 2 && stderr.contains(want) && stderr.contains("bad.mcap"),
            "info: exit {code}\n{stdout}\n{stderr}"
        );
        let (code, stdout, stderr) = run_bin(os!("check", path.as_os_str()))?;
        ensure!(
            code == 2 && stdout.contains(want) && stdout.starts_with("ERROR "),
            "check: exit {code}\n{stdout}\n{stderr}"
        );
    }
    // The same records, well-formed, read.
    let (_, source, error, _) = read(&raw_trace(&[good])?, "good.mcap");
    ensure!(
        error.is_none() && source == Some(ExpectedSource::new("e", "1")),
        "{source:?} {error:?}"
    );
    Ok(())
}

fn info_shows_it() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("rapier.mcap");
    std::fs::write(&path, trace_bytes(Some(&rapier()))?)?;
    let (code, stdout, stderr) = run_bin(os!("info", path.as_os_str()))?;
    ensure!(code == 0, "exit {code}\n{stderr}");
    ensure!(
        stdout.contains(&format!("\nexpected by: {RAPIER_TEXT}\n")),
        "{stdout}"
    );
    let (code, stdout, stderr) = run_bin(os!("info", path.as_os_str(), "--json"))?;
    ensure!(code == 0, "exit {code}\n{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout)?;
    ensure!(
        json["expected_source"]
            == serde_json::json!({
                "engine": "rapier3d-f64",
                "version": "0.36.1",
                "settings": {"fix_internal_edges": "false"}
            }),
        "{json}"
    );
    Ok(())
}

fn check_shows_it_in_text_and_json() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("rapier.mcap");
    std::fs::write(&path, trace_bytes(Some(&rapier()))?)?;
    let report = check_file(&path, &CheckOptions::default());
    ensure!(report.expected_source == Some(rapier()), "{report:?}");
    let (code, stdout, stderr) = run_bin(os!("check", path.as_os_str()))?;
    ensure!(code == 0, "exit {code}\n{stdout}\n{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    ensure!(
        lines.len() == 2
            && lines[0].starts_with("ok ")
            && lines[1] == format!("  expectations from {RAPIER_TEXT}"),
        "{stdout}"
    );
    let (code, stdout, stderr) = run_bin(os!("check", path.as_os_str(), "--json"))?;
    ensure!(code == 0, "exit {code}\n{stdout}\n{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout)?;
    let source = &json["traces"][0]["expected_source"];
    ensure!(
        source["engine"] == "rapier3d-f64"
            && source["version"] == "0.36.1"
            && source["settings"]["fix_internal_edges"] == "false",
        "{json}"
    );
    // A failing trace keeps the line under its status line.
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.expected_source(&rapier())?;
    w.scene(0, &scene())?;
    w.sweep(1, &sweep(0))?;
    let mut wrong = face_hit(0);
    wrong.alpha = 0.5;
    w.expected(1, &wrong)?;
    let bytes = w.finish()?.into_inner();
    let report = sweeptrace::check_reader(bytes.as_slice(), "fail.mcap", &CheckOptions::default());
    let text = render_text(&report);
    let lines: Vec<&str> = text.lines().collect();
    ensure!(
        report.status() == Status::Fail
            && lines[0].starts_with("FAIL fail.mcap")
            && lines[1] == format!("  expectations from {RAPIER_TEXT}"),
        "{text}"
    );
    Ok(())
}

fn check_engine_says_the_engine_answered() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("rapier.mcap");
    std::fs::write(&path, trace_bytes(Some(&rapier()))?)?;
    let engine = example_engine_command("");
    let (code, stdout, stderr) = run_bin(os!("check", path.as_os_str(), "--engine", &engine))?;
    ensure!(code == 0, "exit {code}\n{stdout}\n{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    ensure!(
        lines.len() == 2
            && lines[1]
                == format!(
                    "  expectations from the engine command `{engine}` (answers to every \
                     sweep; the trace's /expected is not used)"
                ),
        "{stdout}"
    );
    // Against the trace's expectations, they are the trace's own.
    let (code, stdout, stderr) = run_bin(os!(
        "check",
        path.as_os_str(),
        "--engine",
        &engine,
        "--against",
        "expected",
        "--json"
    ))?;
    ensure!(code == 0, "exit {code}\n{stdout}\n{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout)?;
    let report = &json["traces"][0];
    ensure!(
        report["expected_source"]["engine"] == "rapier3d-f64"
            && report["engine"]["against"] == "expected",
        "{json}"
    );
    let (code, stdout, _) = run_bin(os!(
        "check",
        path.as_os_str(),
        "--engine",
        &engine,
        "--against",
        "expected"
    ))?;
    ensure!(
        code == 0 && stdout.contains(&format!("\n  expectations from {RAPIER_TEXT}\n")),
        "{stdout}"
    );
    Ok(())
}

fn record_names_sweeptrace_and_bless_replaces_the_source() -> anyhow::Result<()> {
    let version = env!("CARGO_PKG_VERSION");
    let dir = tempfile::tempdir()?;
    let recorded = dir.path().join("recorded.mcap");
    let (code, stdout, stderr) = run_bin(os!(
        "record",
        "--scene",
        "cube",
        "--frames",
        "20",
        "--margin",
        "0.05",
        "--facing",
        "strict",
        "-o",
        recorded.as_os_str()
    ))?;
    ensure!(code == 0, "record: exit {code}\n{stdout}\n{stderr}");
    let bytes = std::fs::read(&recorded)?;
    let (_, source, error, records) = read(&bytes, "recorded.mcap");
    let want = ExpectedSource::new("sweeptrace", version)
        .setting("margin", "0.05")
        .setting("facing", "strict");
    ensure!(
        error.is_none() && records == 1 && source.as_ref() == Some(&want),
        "{source:?} {error:?} {records}"
    );
    // The record comes before every message: a streaming reader has it
    // with the first event.
    let mut reader = TraceReader::new(bytes.as_slice(), "recorded.mcap");
    reader.next().context("no event")??;
    ensure!(
        reader.expected_source() == Some(&want),
        "not before the first message"
    );

    // Bless a trace whose expectations came from Rapier: they come from
    // sweeptrace now, with the scene's margin and facing.
    let input = dir.path().join("rapier.mcap");
    std::fs::write(&input, trace_bytes(Some(&rapier()))?)?;
    let blessed = dir.path().join("blessed.mcap");
    let (code, stdout, stderr) =
        run_bin(os!("bless", input.as_os_str(), "-o", blessed.as_os_str()))?;
    ensure!(code == 0, "bless: exit {code}\n{stdout}\n{stderr}");
    let want = ExpectedSource::new("sweeptrace", version)
        .setting("margin", "0")
        .setting("facing", "non_strict");
    ensure!(
        stderr.contains(&format!(
            "  expectations from {want}\n  they were from {RAPIER_TEXT}\n"
        )),
        "{stderr}"
    );
    let bytes = std::fs::read(&blessed)?;
    let (events, source, error, records) = read(&bytes, "blessed.mcap");
    ensure!(
        error.is_none() && records == 1 && source.as_ref() == Some(&want),
        "{source:?} {error:?} {records} records"
    );
    ensure!(events.len() == 7, "{} events", events.len());
    // A trace without a source gets one too.
    let plain = dir.path().join("plain.mcap");
    std::fs::write(&plain, trace_bytes(None)?)?;
    let (code, _, stderr) = run_bin(os!("bless", plain.as_os_str(), "--in-place"))?;
    ensure!(code == 0 && !stderr.contains("were from"), "{stderr}");
    let bytes = std::fs::read(&plain)?;
    let (_, source, error, _) = read(&bytes, "plain.mcap");
    ensure!(
        error.is_none() && source.as_ref() == Some(&want),
        "{source:?} {error:?}"
    );
    Ok(())
}

fn python_reads_the_record() -> anyhow::Result<Completion> {
    if let Err(skipped) = crate::support::python_with_mcap()? {
        return Ok(skipped);
    }
    let dir = tempfile::tempdir()?;
    let with = dir.path().join("with.mcap");
    let source = rapier().setting("dt", "0.01");
    std::fs::write(&with, trace_bytes(Some(&source))?)?;
    let without = dir.path().join("without.mcap");
    std::fs::write(&without, trace_bytes(None)?)?;
    let script = repository_file("scripts/read_with_python.py");
    let run = |trace: &Path, extra: &[&str]| -> anyhow::Result<(bool, String)> {
        let out = std::process::Command::new("python3")
            .arg(&script)
            .arg(trace)
            .args(extra)
            .output()?;
        Ok((
            out.status.success(),
            format!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ),
        ))
    };
    let exact = [
        "--sweeps",
        "3",
        "--expected",
        "3",
        "--engine",
        "rapier3d-f64",
        "--engine-version",
        "0.36.1",
        "--setting",
        "fix_internal_edges=false",
        "--setting",
        "dt=0.01",
    ];
    let (ok, output) = run(&with, &exact)?;
    ensure!(ok, "the script refused the record: {output}");
    // And it can fail: a wrong value, a missing setting, a wrong engine,
    // a record where none is expected, none where one is.
    let wrong_value: Vec<&str> = exact
        .iter()
        .map(|a| if *a == "dt=0.01" { "dt=0.02" } else { a })
        .collect();
    for (trace, args) in [
        (&with, wrong_value),
        (&with, exact[..exact.len() - 2].to_vec()),
        (&with, vec!["--engine", "parry3d-f64"]),
        (&with, vec!["--no-expected-source"]),
        (&without, vec!["--engine", "rapier3d-f64"]),
    ] {
        let (ok, output) = run(trace, &args)?;
        ensure!(
            !ok && output.contains("sweeptrace.expected_source"),
            "the script accepted {args:?}: {output}"
        );
    }
    let (ok, output) = run(&without, &["--no-expected-source"])?;
    ensure!(ok, "{output}");
    // A malformed record written by another writer fails the script too.
    let bad = dir.path().join("bad.mcap");
    let raw = raw_trace(&[entries(&[("engine", "e"), ("engin", "x")])])?;
    std::fs::write(&bad, raw)?;
    let (ok, output) = run(&bad, &[])?;
    ensure!(!ok && output.contains("unknown key 'engin'"), "{output}");
    Ok(Completion::Completed)
}
