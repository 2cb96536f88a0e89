//! The CBOR message encoding: written and read through the library, mixed
//! with JSON in one file, its errors located, through `record`, `replay`
//! and `bless`, and against Python's `mcap` + `cbor2` as an independent
//! writer and reader.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

use libtest_mimic::{Completion, Trial};
use mcap::WriteOptions;
use mcap::records::MessageHeader;
use rand::{Rng, SeedableRng};
use sweeptrace::trace::info::{collect_info, render_info_text};
use sweeptrace::trace::{
    Encoding, EventBody, OutcomeMsg, SceneMsg, SweepMsg, TraceError, TraceEvent, TraceReader,
    TraceWriter,
};

use crate::support::run_bin;
use crate::support::{event, write_event};
use crate::trace_io::{
    default_opts, error_names_where, lz4, read_all, same, sample_events, triangle_scene, unchunked,
    variant_name,
};
use crate::{ensure, os, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(cbor_round_trip_every_flavour),
        trial!(cbor_floats_round_trip_bit_for_bit),
        trial!(cbor_is_compact_and_reads_the_same_as_json),
        trial!(cbor_and_json_channels_mixed_in_one_file),
        trial!(cbor_errors_name_the_field_as_json_errors_do),
        trial!(cbor_truncated_or_garbled_message_is_located),
        trial!(cbor_random_corruption_never_panics),
        trial!(cbor_seeded_message_validation),
        trial!(cbor_record_replay_outcomes_match_json),
        trial!(cbor_bless_keeps_the_encoding),
        trial!(cbor_python_writes_we_read),
        trial!(cbor_python_reads_ours),
    ]
}

fn write_events_as(
    events: &[TraceEvent],
    opts: WriteOptions,
    encoding: Encoding,
) -> anyhow::Result<Vec<u8>> {
    let mut w = TraceWriter::with_encoding(Cursor::new(Vec::new()), opts, encoding)?;
    ensure!(
        w.encoding() == encoding,
        "writer encoding {:?}",
        w.encoding()
    );
    for e in events {
        write_event(&mut w, e)?;
    }
    Ok(w.finish()?.into_inner())
}

/// A trace written with the raw `mcap` writer, each of our channels in the
/// encoding given; messages are (topic, log_time, bytes).
fn raw_mixed(encodings: &[(&str, &str)], messages: &[(&str, u64, Vec<u8>)]) -> Vec<u8> {
    let mut w = default_opts()
        .create(Cursor::new(Vec::new()))
        .expect("writer");
    let mut ids = BTreeMap::new();
    for (topic, encoding) in encodings {
        let s = w.add_schema("s", "jsonschema", b"{}").expect("schema");
        ids.insert(
            *topic,
            w.add_channel(s, topic, encoding, &BTreeMap::new())
                .expect("channel"),
        );
    }
    for (seq, (topic, t, data)) in messages.iter().enumerate() {
        let header = MessageHeader {
            channel_id: ids[topic],
            sequence: seq as u32,
            log_time: *t,
            publish_time: *t,
        };
        w.write_to_known_channel(&header, data).expect("write");
    }
    w.finish().expect("finish");
    w.into_inner().into_inner()
}

fn cbor<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    Encoding::Cbor.encode(msg).expect("encodes")
}

fn json<T: serde::Serialize>(msg: &T) -> Vec<u8> {
    Encoding::Json.encode(msg).expect("encodes")
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

// ---------------------------------------------------------------- library

fn cbor_round_trip_every_flavour() -> anyhow::Result<()> {
    let events = sample_events(300);
    for (opts, what) in [
        (default_opts(), "default"),
        (unchunked(), "unchunked"),
        (lz4(), "lz4"),
    ] {
        let bytes = write_events_as(&events, opts, Encoding::Cbor)?;
        let (got, error, stats) = read_all(&bytes);
        ensure!(error.is_none(), "{what}: {error:?}");
        same(&got, &events).map_err(|e| anyhow::anyhow!("{what}: {e}"))?;
        for topic in ["/scene", "/sweep", "/expected"] {
            let c = &stats.channels[topic];
            ensure!(
                c.message_encoding == "cbor" && c.schema_encoding == "jsonschema",
                "{what}: {topic}: {c:?}"
            );
        }
    }
    // Deterministic, like the JSON writer.
    let a = write_events_as(&events, default_opts(), Encoding::Cbor)?;
    let b = write_events_as(&events, default_opts(), Encoding::Cbor)?;
    ensure!(a == b, "two CBOR writes of the same events differ");
    Ok(())
}

fn cbor_floats_round_trip_bit_for_bit() -> anyhow::Result<()> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0xcb0a);
    let mut any = || loop {
        // Any finite double, from its bits: subnormals, -0.0, huge and tiny.
        let x = f64::from_bits(rng.random());
        if x.is_finite() && x.abs() < 1e150 {
            return x;
        }
    };
    let mut events = vec![event(
        0,
        0,
        EventBody::Scene(SceneMsg {
            name: Some("random".to_string()),
            vertices: (0..300).map(|_| [any(), any(), any()]).collect(),
            triangles: vec![[0, 1, 2], [297, 298, 299]],
            margin: 0.0,
            facing: Default::default(),
        }),
    )];
    for frame in 0..500u64 {
        events.push(event(
            frame,
            frame + 1,
            EventBody::Sweep(SweepMsg {
                frame,
                ball: 3,
                radius: any().abs().max(f64::MIN_POSITIVE),
                p0: [any(), any(), any()],
                p1: [any(), any(), any()],
            }),
        ));
    }
    let bytes = write_events_as(&events, default_opts(), Encoding::Cbor)?;
    let (got, error, _) = read_all(&bytes);
    ensure!(error.is_none(), "{error:?}");
    // `==` on f64 would take -0.0 for 0.0: compare the bits.
    let bits = |events: &[TraceEvent]| -> Vec<u64> {
        let mut out = Vec::new();
        for e in events {
            match &e.body {
                EventBody::Scene(scene) => {
                    out.extend(scene.vertices.iter().flatten().map(|x| x.to_bits()))
                }
                EventBody::Sweep(sweep) => {
                    out.push(sweep.radius.to_bits());
                    out.extend(sweep.p0.iter().chain(&sweep.p1).map(|x| x.to_bits()));
                }
                EventBody::Expected(_) | EventBody::Contact(_) | EventBody::ExpectedContacts(_) => {
                }
            }
        }
        out
    };
    ensure!(bits(&got) == bits(&events), "a float changed on the way");
    Ok(())
}

fn cbor_is_compact_and_reads_the_same_as_json() -> anyhow::Result<()> {
    let events = sample_events(200);
    let json_bytes = write_events_as(&events, default_opts().compression(None), Encoding::Json)?;
    let cbor_bytes = write_events_as(&events, default_opts().compression(None), Encoding::Cbor)?;
    let (from_json, e1, _) = read_all(&json_bytes);
    let (from_cbor, e2, _) = read_all(&cbor_bytes);
    ensure!(e1.is_none() && e2.is_none(), "{e1:?} {e2:?}");
    same(&from_cbor, &from_json)?;
    // The message bytes themselves: a sweep's 7 numbers of full precision
    // (as a simulation writes them) as 9 bytes each against their shortest
    // decimal text (a short decimal such as `1.0` is shorter in JSON).
    let s = SweepMsg {
        frame: 17,
        ball: 3,
        radius: 0.1 + 0.2,
        p0: [1.0 / 3.0, -2.0 / 7.0, 0.5 + 1e-12],
        p1: [1.0 / 9.0, 22.0 / 7.0, -0.1],
    };
    ensure!(
        cbor(&s).len() < json(&s).len(),
        "CBOR sweep {} bytes, JSON {}",
        cbor(&s).len(),
        json(&s).len()
    );
    Ok(())
}

fn cbor_and_json_channels_mixed_in_one_file() -> anyhow::Result<()> {
    let scene = triangle_scene();
    let outcome = OutcomeMsg::hit(1, 0, 5.0 / 12.0, sweeptrace::Kind::Face)
        .triangle(0)
        .normal([0.0, 0.0, 1.0]);
    let bytes = raw_mixed(
        &[
            ("/scene", "json"),
            ("/sweep", "cbor"),
            ("/expected", "json"),
        ],
        &[
            ("/scene", 0, json(&scene)),
            ("/sweep", 1, cbor(&sweep(1))),
            ("/expected", 1, json(&outcome)),
            ("/sweep", 2, cbor(&sweep(2))),
        ],
    );
    let (got, error, stats) = read_all(&bytes);
    ensure!(error.is_none(), "{error:?}");
    let want = vec![
        event(0, 0, EventBody::Scene(scene)),
        event(1, 1, EventBody::Sweep(sweep(1))),
        event(1, 2, EventBody::Expected(outcome)),
        event(2, 3, EventBody::Sweep(sweep(2))),
    ];
    same(&got, &want)?;
    ensure!(
        stats.channels["/sweep"].message_encoding == "cbor"
            && stats.channels["/scene"].message_encoding == "json",
        "{:?}",
        stats.channels
    );
    let (info, _) = collect_info(TraceReader::new(bytes.as_slice(), "mixed.mcap"));
    let text = render_info_text(&info);
    ensure!(
        text.contains("encoding:    cbor (/sweep), json (/expected, /scene)")
            && text.contains("  /sweep  s [jsonschema / cbor]  2 messages"),
        "{text}"
    );
    // One encoding: said once.
    let only = write_events_as(&sample_events(2), default_opts(), Encoding::Cbor)?;
    let (info, _) = collect_info(TraceReader::new(only.as_slice(), "only.mcap"));
    ensure!(
        render_info_text(&info).contains("encoding:    cbor\n"),
        "{}",
        render_info_text(&info)
    );
    Ok(())
}

/// Reads a trace of a JSON scene and one CBOR message on `topic`, expects
/// an error mentioning every needle.
fn cbor_error(topic: &str, message: Vec<u8>, needles: &[&str]) -> anyhow::Result<TraceError> {
    let bytes = raw_mixed(
        &[
            ("/scene", "json"),
            ("/sweep", "cbor"),
            ("/expected", "cbor"),
        ],
        &[("/scene", 0, json(&triangle_scene())), (topic, 1, message)],
    );
    let (events, error, _) = read_all(&bytes);
    let error = error.with_context(|| format!("no error; read {events:?}"))?;
    let text = error.to_string();
    for needle in needles {
        ensure!(
            text.contains(needle),
            "`{text}` does not mention `{needle}`"
        );
    }
    ensure!(
        events.len() == 1,
        "the scene before the error was not yielded"
    );
    Ok(error)
}

/// A CBOR map from (key, CBOR value bytes) pairs.
fn map(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let mut out = vec![0xa0 + entries.len() as u8];
    for (key, value) in entries {
        out.push(0x60 + key.len() as u8);
        out.extend(key.as_bytes());
        out.extend(*value);
    }
    out
}

const ZERO3: &[u8] = &[0x83, 0x00, 0x00, 0x00];

fn cbor_errors_name_the_field_as_json_errors_do() -> anyhow::Result<()> {
    // Missing field.
    let m = map(&[("frame", &[0x03]), ("p0", ZERO3), ("p1", ZERO3)]);
    cbor_error(
        "/sweep",
        m,
        &[
            "test.mcap",
            "`/sweep`",
            "frame 3",
            "message 1",
            "`radius`",
            "missing",
        ],
    )?;
    // null for a number.
    let m = map(&[
        ("frame", &[0x09]),
        ("radius", &[0xf9, 0x38, 0x00]),
        ("p0", &[0x83, 0x01, 0xf6, 0x02]),
        ("p1", ZERO3),
    ]);
    cbor_error("/sweep", m, &["frame 9", "`p0[1]`", "null"])?;
    // Mistyped: text for a number, a negative vertex index, an unknown kind.
    let m = map(&[
        ("frame", &[0x07]),
        ("radius", &[0x63, b'b', b'i', b'g']),
        ("p0", ZERO3),
        ("p1", ZERO3),
    ]);
    cbor_error("/sweep", m, &["frame 7", "`radius`", "invalid type"])?;
    let m = map(&[
        ("frame", &[0x02]),
        ("alpha", &[0xfb, 0x3f, 0xe0, 0, 0, 0, 0, 0, 0]),
        ("kind", &[0x66, b'c', b'o', b'r', b'n', b'e', b'r']),
    ]);
    cbor_error("/expected", m, &["`/expected`", "frame 2", "`kind`"])?;
    // An unknown field is refused, as in JSON.
    let mut s = serde_json::to_value(sweep(4))?;
    s["raduis"] = serde_json::json!(0.5);
    cbor_error("/sweep", cbor(&s), &["frame 4", "`raduis`", "not a field"])?;
    // Validation is shared: NaN is a CBOR float, and not finite.
    let mut s = sweep(5);
    s.p1[2] = f64::NAN;
    cbor_error("/sweep", cbor(&s), &["frame 5", "`p1[2]`", "finite"])?;
    let mut s = sweep(6);
    s.radius = -1.0;
    cbor_error("/sweep", cbor(&s), &["frame 6", "`radius`"])?;
    // A vertex index out of range in a CBOR scene.
    let mut scene = triangle_scene();
    scene.triangles.push([0, 1, 3]);
    let bytes = raw_mixed(&[("/scene", "cbor")], &[("/scene", 0, cbor(&scene))]);
    let (_, error, _) = read_all(&bytes);
    let text = error.map(|e| e.to_string()).unwrap_or_default();
    ensure!(
        text.contains("`/scene`") && text.contains("`triangles[1][2]`"),
        "{text}"
    );
    Ok(())
}

fn cbor_truncated_or_garbled_message_is_located() -> anyhow::Result<()> {
    let whole = cbor(&sweep(12));
    // Cut anywhere: the message is not valid CBOR; the frame is named when
    // it can still be read (the writer puts it first).
    for cut in 1..whole.len() {
        let error = cbor_error(
            "/sweep",
            whole[..cut].to_vec(),
            &["test.mcap", "`/sweep`", "message 1", "not valid CBOR"],
        )?;
        let at = error.message_at().context("no position")?;
        ensure!(at.index == 1, "{at:?}");
    }
    // A reserved byte, trailing bytes, a tag.
    cbor_error("/sweep", vec![0x1c], &["message 1", "not valid CBOR"])?;
    let mut trailing = whole.clone();
    trailing.extend([0x00, 0x00]);
    cbor_error(
        "/sweep",
        trailing,
        &["frame 12", "not valid CBOR", "2 bytes after"],
    )?;
    cbor_error("/sweep", vec![0xc1, 0x00], &["message 1", "tag"])?;
    // JSON text on a CBOR channel is not CBOR.
    cbor_error("/sweep", json(&sweep(1)), &["message 1", "`/sweep`"])?;

    // Through the binary: exit 2, the error located, no panic.
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("garbled.mcap");
    let mut garbled = whole.clone();
    garbled.truncate(whole.len() - 3);
    let bytes = raw_mixed(
        &[("/scene", "cbor"), ("/sweep", "cbor")],
        &[
            ("/scene", 0, cbor(&triangle_scene())),
            ("/sweep", 1, cbor(&sweep(11))),
            ("/sweep", 2, garbled),
        ],
    );
    std::fs::write(&path, bytes)?;
    for args in [
        vec!["info"],
        vec!["replay", "--outcomes", "-"],
        vec!["check"],
    ] {
        let mut all: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
        all.insert(1, path.as_os_str());
        let (code, out, err) = run_bin(&all)?;
        // `check` reports a trace's error in its report.
        let err = format!("{out}{err}");
        ensure!(
            code == 2
                && err.contains("garbled.mcap")
                && err.contains("`/sweep`")
                && err.contains("message 2")
                && err.contains("not valid CBOR")
                && !err.contains("panicked"),
            "{args:?}: exit {code}: {err}"
        );
    }
    Ok(())
}

fn cbor_random_corruption_never_panics() -> anyhow::Result<()> {
    let events = sample_events(40);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0xcb0c);
    let mut seen = BTreeMap::new();
    // Uncompressed chunks, so that flipped bytes reach the messages.
    for opts in [default_opts().compression(None), unchunked()] {
        let bytes = write_events_as(&events, opts, Encoding::Cbor)?;
        for _ in 0..400 {
            let mut b = bytes.clone();
            for _ in 0..rng.random_range(1..4) {
                let i = rng.random_range(0..b.len());
                b[i] = rng.random();
            }
            let (events, error, _) = read_all(&b);
            if let Some(error) = error {
                error_names_where(&error, events.len() as u64)?;
                *seen.entry(variant_name(&error)).or_insert(0) += 1;
            }
        }
    }
    ensure!(seen.contains_key("Json"), "no message error seen: {seen:?}");
    Ok(())
}

/// The fuzz target's properties over mutated CBOR messages: every error
/// names the file and channel, every message that validates survives a
/// round trip through both encodings and runs through the core.
fn cbor_seeded_message_validation() -> anyhow::Result<()> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0xcb0d);
    let seeds = [
        cbor(&triangle_scene()),
        cbor(&sweep(3)),
        cbor(&OutcomeMsg::miss(2, 1)),
        cbor(
            &OutcomeMsg::hit(1, 0, 0.25, sweeptrace::Kind::Vertex)
                .triangle(0)
                .feature(2)
                .contact([0.0, 0.0, 0.0]),
        ),
    ];
    for _ in 0..3000 {
        let mut m = seeds[rng.random_range(0..seeds.len())].clone();
        for _ in 0..rng.random_range(1..4) {
            match rng.random_range(0..3) {
                0 => {
                    let i = rng.random_range(0..m.len());
                    m[i] = rng.random();
                }
                1 => m.truncate(rng.random_range(0..m.len())),
                _ => {
                    let i = rng.random_range(0..=m.len());
                    m.insert(i, rng.random());
                }
            }
            if m.is_empty() {
                break;
            }
        }
        sweeptrace::fuzzing::check_message_validation(&m)
            .map_err(|e| anyhow::anyhow!("{m:02x?}: {e}"))?;
    }
    Ok(())
}

// ---------------------------------------------------------------- commands

fn record(dir: &Path, name: &str, encoding: &str) -> anyhow::Result<std::path::PathBuf> {
    let path = dir.join(name);
    let (code, _, err) = run_bin(os![
        "record",
        "--scene",
        "terrain",
        "--terrain-cells",
        "16",
        "--balls",
        "3",
        "--seed",
        "5",
        "--frames",
        "120",
        "--encoding",
        encoding,
        "-o",
        path.to_str().context("path")?,
    ])?;
    ensure!(
        code == 0,
        "record --encoding {encoding}: exit {code}: {err}"
    );
    Ok(path)
}

fn encodings_of(path: &Path) -> anyhow::Result<BTreeMap<String, String>> {
    let bytes = std::fs::read(path)?;
    let (_, error, stats) = read_all(&bytes);
    ensure!(error.is_none(), "{}: {error:?}", path.display());
    Ok(stats
        .channels
        .iter()
        .map(|(topic, c)| (topic.clone(), c.message_encoding.clone()))
        .collect())
}

fn cbor_record_replay_outcomes_match_json() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let json_trace = record(dir.path(), "j.mcap", "json")?;
    let cbor_trace = record(dir.path(), "c.mcap", "cbor")?;
    let encodings = encodings_of(&cbor_trace)?;
    ensure!(
        encodings.values().all(|e| e == "cbor") && encodings.len() == 3,
        "{encodings:?}"
    );
    ensure!(
        encodings_of(&json_trace)?.values().all(|e| e == "json"),
        "the default is no longer JSON"
    );
    let outcomes = |trace: &Path| -> anyhow::Result<String> {
        let (code, out, err) = run_bin(os!["replay", trace.as_os_str(), "--outcomes", "-"])?;
        ensure!(code == 0, "replay: exit {code}: {err}");
        Ok(out)
    };
    let (from_json, from_cbor) = (outcomes(&json_trace)?, outcomes(&cbor_trace)?);
    ensure!(
        from_json.lines().count() > 300,
        "{} outcome lines",
        from_json.lines().count()
    );
    ensure!(
        from_json == from_cbor,
        "the outcome lines differ between the JSON and the CBOR trace"
    );
    // The expectations read back the same: check passes on both.
    for trace in [&json_trace, &cbor_trace] {
        let (code, out, err) = run_bin(os!["check", trace.as_os_str()])?;
        ensure!(
            code == 0,
            "check {}: exit {code}: {out}{err}",
            trace.display()
        );
    }
    let (code, out, _) = run_bin(os!["info", cbor_trace.as_os_str()])?;
    ensure!(
        code == 0 && out.contains("encoding:    cbor") && out.contains("[jsonschema / cbor]"),
        "{out}"
    );
    Ok(())
}

fn cbor_bless_keeps_the_encoding() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    for encoding in ["cbor", "json"] {
        let trace = record(dir.path(), &format!("in-{encoding}.mcap"), encoding)?;
        let out = dir.path().join(format!("out-{encoding}.mcap"));
        let (code, _, err) = run_bin(os!["bless", trace.as_os_str(), "-o", out.as_os_str()])?;
        ensure!(code == 0, "bless {encoding}: exit {code}: {err}");
        let encodings = encodings_of(&out)?;
        ensure!(
            encodings.get("/expected").map(String::as_str) == Some(encoding)
                && encodings.get("/sweep").map(String::as_str) == Some(encoding),
            "{encoding}: {encodings:?}"
        );
        let (code, stdout, err) = run_bin(os!["check", out.as_os_str()])?;
        ensure!(code == 0, "check after bless: exit {code}: {stdout}{err}");
        // The same expectations as the recording's.
        let read = |p: &Path| -> anyhow::Result<Vec<OutcomeMsg>> {
            let bytes = std::fs::read(p)?;
            let (events, error, _) = read_all(&bytes);
            ensure!(error.is_none(), "{error:?}");
            Ok(events
                .into_iter()
                .filter_map(|e| match e.body {
                    EventBody::Expected(outcome) => Some(outcome),
                    _ => None,
                })
                .collect())
        };
        ensure!(
            read(&trace)? == read(&out)?,
            "{encoding}: blessed outcomes differ"
        );
    }
    Ok(())
}

// ---------------------------------------------------------------- Python

fn python_with_cbor() -> anyhow::Result<Result<(), Completion>> {
    crate::support::python_with_modules(&["mcap", "cbor2"], "pip install mcap==1.6.0 cbor2==6.2.1")
}

fn cbor_python_writes_we_read() -> anyhow::Result<Completion> {
    if let Err(skipped) = python_with_cbor()? {
        return Ok(skipped);
    }
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("python_cbor.mcap");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/write_python_fixture.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(&path)
        .args(["--encoding", "cbor"])
        .output()?;
    ensure!(
        out.status.success(),
        "script failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&path)?;
    let (_, _, stats) = read_all(&bytes);
    ensure!(
        stats.channels["/sweep"].message_encoding == "cbor",
        "{:?}",
        stats.channels
    );
    // Every value as the JSON fixture's (Python wrote integers for the
    // triangles and floats for the coordinates).
    crate::trace_io::check_python_fixture(&bytes)?;
    Ok(Completion::Completed)
}

fn cbor_python_reads_ours() -> anyhow::Result<Completion> {
    if let Err(skipped) = python_with_cbor()? {
        return Ok(skipped);
    }
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("ours.mcap");
    let events = sample_events(30);
    std::fs::write(
        &path,
        write_events_as(&events, default_opts(), Encoding::Cbor)?,
    )?;
    crate::support::read_with_python(
        &path,
        &[
            "--encoding",
            "cbor",
            "--scenes",
            "2",
            "--sweeps",
            "60",
            "--expected",
            "30",
        ],
    )?;
    // And it can fail: the channels are not JSON.
    ensure!(
        crate::support::read_with_python(&path, &["--sweeps", "60"]).is_err(),
        "the script took CBOR for JSON"
    );
    Ok(Completion::Completed)
}
