//! Trace files: write → read round trips, every container flavour, the
//! Python-written fixture, every error of the format page, `info` rendering.

use std::collections::BTreeMap;
use std::io::Cursor;

use libtest_mimic::{Completion, Trial};
use mcap::records::MessageHeader;
use mcap::{Compression, WriteOptions};
use rand::{Rng, SeedableRng};
use sweeptrace::core::{Facing, Kind};
use sweeptrace::trace::info::{collect_info, render_info_json, render_info_text};
use sweeptrace::trace::{
    EventBody, EventHeader, OutcomeMsg, ReadLimits, ReadStats, SceneMsg, SweepMsg, TraceError,
    TraceEvent, TraceReader, TraceWriter, write_trace_file,
};

use crate::ensure;
use crate::support::scene_t;
use crate::support::{event, write_event};
use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(enum_names_in_words_are_their_serde_names),
        trial!(round_trip_default_writer),
        trial!(writer_output_is_deterministic),
        trial!(reads_unchunked),
        trial!(reads_lz4_chunks),
        trial!(reads_uncompressed_chunks),
        trial!(reads_without_summary_or_indexes),
        trial!(reads_unchunked_without_summary),
        trial!(python_fixture_exact_values),
        trial!(foreign_channels_skipped_and_counted),
        trial!(error_truncated_every_cut),
        trial!(error_truncated_chunked),
        trial!(error_corrupt_zstd_chunk),
        trial!(error_corrupt_uncompressed_chunk),
        trial!(error_not_json),
        trial!(error_missing_field),
        trial!(error_mistyped_field),
        trial!(error_null_for_number),
        trial!(error_number_out_of_range),
        trial!(error_vertex_index_out_of_range),
        trial!(error_radius_not_positive),
        trial!(error_margin_not_below_radius),
        trial!(error_sweep_before_scene),
        trial!(error_oversized_scene),
        trial!(error_huge_declared_record),
        trial!(error_huge_declared_chunk),
        trial!(error_out_of_order_log_time),
        trial!(error_wrong_message_encoding),
        trial!(error_bad_outcome_alpha),
        trial!(random_corruption_never_panics),
        trial!(writer_refuses_invalid_messages),
        trial!(writer_refuses_a_triangle_the_scene_does_not_have),
        trial!(write_trace_file_is_atomic),
        trial!(info_renders_python_fixture),
        trial!(info_reports_partial_trace),
        trial!(python_reads_our_trace),
    ]
}

// ---------------------------------------------------------------- helpers

const FIXTURE: &str = "tests/fixtures/python_written.mcap";

pub fn triangle_scene() -> SceneMsg {
    SceneMsg {
        name: Some("triangle".into()),
        ..scene_t(0.0)
    }
}

fn sweep(frame: u64, ball: u32) -> SweepMsg {
    SweepMsg {
        frame,
        ball,
        radius: 0.5,
        p0: [1.0 + frame as f64 * 0.01, 1.0, 3.0],
        p1: [1.0, 1.0, -3.0],
    }
}

fn outcome(frame: u64) -> OutcomeMsg {
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

/// The events a sample trace holds: one scene, `frames` frames of two
/// balls, an expected outcome per frame for ball 0, a second scene midway.
pub fn sample_events(frames: u64) -> Vec<TraceEvent> {
    let mut events = Vec::new();
    let mut index = 0;
    let mut push = |e: TraceEvent| {
        events.push(e);
    };
    push(event(0, index, EventBody::Scene(triangle_scene())));
    index += 1;
    for frame in 0..frames {
        let t = 1_000 + frame * 1_000_000;
        if frame == frames / 2 {
            let mut scene = triangle_scene();
            scene.name = Some("second".to_string());
            scene.margin = 0.125;
            scene.facing = Facing::Strict;
            push(event(t, index, EventBody::Scene(scene)));
            index += 1;
        }
        for ball in 0..2 {
            push(event(t, index, EventBody::Sweep(sweep(frame, ball))));
            index += 1;
        }
        push(event(t, index, EventBody::Expected(outcome(frame))));
        index += 1;
    }
    events
}

pub fn default_opts() -> WriteOptions {
    sweeptrace::trace::default_write_options()
}
pub fn unchunked() -> WriteOptions {
    default_opts().use_chunks(false)
}
pub fn lz4() -> WriteOptions {
    default_opts()
        .compression(Some(Compression::Lz4))
        .chunk_size(Some(4096))
}
fn uncompressed_chunks() -> WriteOptions {
    default_opts().compression(None)
}
fn no_summary() -> WriteOptions {
    default_opts()
        .emit_summary_records(false)
        .emit_summary_offsets(false)
        .emit_statistics(false)
        .emit_chunk_indexes(false)
        .emit_message_indexes(false)
        .emit_metadata_indexes(false)
        .emit_attachment_indexes(false)
        .repeat_channels(false)
        .repeat_schemas(false)
}

pub fn write_events(events: &[TraceEvent], opts: WriteOptions) -> anyhow::Result<Vec<u8>> {
    let mut w = TraceWriter::with_options(Cursor::new(Vec::new()), opts)?;
    for e in events {
        write_event(&mut w, e)?;
    }
    Ok(w.finish()?.into_inner())
}

/// Every event, the error that ended reading (if any) and the stats.
pub fn read_all(bytes: &[u8]) -> (Vec<TraceEvent>, Option<TraceError>, ReadStats) {
    read_all_with(bytes, ReadLimits::default())
}

fn read_all_with(
    bytes: &[u8],
    limits: ReadLimits,
) -> (Vec<TraceEvent>, Option<TraceError>, ReadStats) {
    let mut reader = TraceReader::with_limits(bytes, "test.mcap", limits);
    let mut events = Vec::new();
    let mut error = None;
    for e in reader.by_ref() {
        match e {
            Ok(e) => events.push(e),
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    (events, error, reader.stats().clone())
}

/// A trace written with the raw `mcap` writer: our three channels plus
/// `/foreign`; each message is (topic, log_time, JSON bytes).
pub fn raw_trace(messages: &[(&str, u64, &[u8])]) -> Vec<u8> {
    raw_trace_with(messages, "json")
}

pub fn raw_trace_with(messages: &[(&str, u64, &[u8])], encoding: &str) -> Vec<u8> {
    let mut w = default_opts()
        .create(Cursor::new(Vec::new()))
        .expect("writer");
    let mut ids = BTreeMap::new();
    for (topic, schema) in [
        ("/scene", "sweeptrace.Scene"),
        ("/sweep", "sweeptrace.Sweep"),
        ("/expected", "sweeptrace.Outcome"),
    ] {
        let s = w.add_schema(schema, "jsonschema", b"{}").expect("schema");
        ids.insert(
            topic,
            w.add_channel(s, topic, encoding, &BTreeMap::new())
                .expect("channel"),
        );
    }
    ids.insert(
        "/foreign",
        w.add_channel(0, "/foreign", "cdr", &BTreeMap::new())
            .expect("channel"),
    );
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

pub const SCENE_JSON: &[u8] =
    br#"{"name":"t","vertices":[[0,0,0],[4,0,0],[0,4,0]],"triangles":[[0,1,2]]}"#;

/// Reads `bytes`, expects an error, checks its message contains every `needle`.
pub fn expect_error(
    bytes: &[u8],
    needles: &[&str],
) -> anyhow::Result<(Vec<TraceEvent>, TraceError)> {
    let (events, error, _) = read_all(bytes);
    let Some(error) = error else {
        anyhow::bail!(
            "expected an error, read {} events without one",
            events.len()
        );
    };
    let text = error.to_string();
    for needle in needles {
        ensure!(
            text.contains(needle),
            "error `{text}` does not mention `{needle}`"
        );
    }
    Ok((events, error))
}

/// The first difference between two event lists, if any.
pub fn same(got: &[TraceEvent], want: &[TraceEvent]) -> anyhow::Result<()> {
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        ensure!(g == w, "event {i} differs:\n got {g:?}\nwant {w:?}");
    }
    ensure!(
        got.len() == want.len(),
        "read {} events, wrote {}",
        got.len(),
        want.len()
    );
    Ok(())
}

// ---------------------------------------------------------------- round trips

fn round_trip_default_writer() -> anyhow::Result<()> {
    let events = sample_events(20);
    let bytes = write_events(&events, default_opts())?;
    let (got, error, stats) = read_all(&bytes);
    ensure!(error.is_none(), "error: {error:?}");
    same(&got, &events)?;
    ensure!(
        stats.messages == events.len() as u64,
        "messages {}",
        stats.messages
    );
    ensure!(stats.chunks >= 1, "not chunked");
    ensure!(
        stats.compression.iter().eq(["zstd"]),
        "compression {:?}",
        stats.compression
    );
    ensure!(stats.has_summary, "no summary");
    ensure!(
        stats.bytes == bytes.len() as u64,
        "bytes {} of {}",
        stats.bytes,
        bytes.len()
    );
    ensure!(
        stats.library == format!("sweeptrace {}", env!("CARGO_PKG_VERSION")),
        "library {}",
        stats.library
    );
    let meta = stats.metadata.iter().find(|(n, _)| n == "sweeptrace");
    ensure!(
        meta.and_then(|(_, m)| m.get("format_version"))
            .map(String::as_str)
            == Some("1"),
        "metadata {:?}",
        stats.metadata
    );
    ensure!(
        stats.metadata.len() == 1,
        "metadata repeated: {:?}",
        stats.metadata
    );
    for (topic, schema) in [
        ("/scene", "sweeptrace.Scene"),
        ("/sweep", "sweeptrace.Sweep"),
        ("/expected", "sweeptrace.Outcome"),
    ] {
        let c = stats
            .channels
            .get(topic)
            .context(format!("no channel {topic}"))?;
        ensure!(
            c.schema_name == schema
                && c.schema_encoding == "jsonschema"
                && c.message_encoding == "json",
            "{topic}: {c:?}"
        );
    }
    ensure!(
        stats.channels["/sweep"].messages == 40,
        "sweeps {:?}",
        stats.channels["/sweep"]
    );
    ensure!(
        stats.skipped_by_topic.is_empty(),
        "skipped {:?}",
        stats.skipped_by_topic
    );
    Ok(())
}

fn writer_output_is_deterministic() -> anyhow::Result<()> {
    let events = sample_events(50);
    let a = write_events(&events, default_opts())?;
    let b = write_events(&events, default_opts())?;
    ensure!(a == b, "two writes of the same trace differ");
    Ok(())
}

fn reads_unchunked() -> anyhow::Result<()> {
    flavour(unchunked(), &[])
}

fn reads_lz4_chunks() -> anyhow::Result<()> {
    flavour(lz4(), &["lz4"])
}

fn reads_uncompressed_chunks() -> anyhow::Result<()> {
    flavour(uncompressed_chunks(), &["none"])
}

fn reads_without_summary_or_indexes() -> anyhow::Result<()> {
    flavour(no_summary(), &["zstd"])
}

fn reads_unchunked_without_summary() -> anyhow::Result<()> {
    flavour(no_summary().use_chunks(false), &[])
}

fn flavour(opts: WriteOptions, compression: &[&str]) -> anyhow::Result<()> {
    let events = sample_events(300);
    let bytes = write_events(&events, opts)?;
    let (got, error, stats) = read_all(&bytes);
    ensure!(error.is_none(), "error: {error:?}");
    ensure!(
        got.len() == events.len(),
        "read {} of {} events",
        got.len(),
        events.len()
    );
    same(&got, &events)?;
    ensure!(
        stats.compression.iter().eq(compression.iter()),
        "compression {:?}",
        stats.compression
    );
    ensure!(
        (stats.chunks == 0) == compression.is_empty(),
        "chunks {}",
        stats.chunks
    );
    Ok(())
}

fn python_fixture_exact_values() -> anyhow::Result<()> {
    let bytes = std::fs::read(FIXTURE).map_err(|e| anyhow::anyhow!("{FIXTURE}: {e}"))?;
    check_python_fixture(&bytes)
}

/// The values `scripts/write_python_fixture.py` writes, in either encoding.
pub fn check_python_fixture(bytes: &[u8]) -> anyhow::Result<()> {
    let (events, error, stats) = read_all(bytes);
    ensure!(error.is_none(), "error: {error:?}");
    ensure!(events.len() == 10, "{} events", events.len());
    let TraceEvent {
        header: EventHeader {
            log_time_nanos: 0,
            index: 0,
        },
        body: EventBody::Scene(scene),
    } = &events[0]
    else {
        anyhow::bail!("first event {:?}", events[0]);
    };
    ensure!(*scene == triangle_scene(), "scene {scene:?}");
    let frame_nanos = 16_666_667;
    let sweeps: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            TraceEvent {
                header,
                body: EventBody::Sweep(sweep),
            } => Some((header.log_time_nanos, header.index, *sweep)),
            _ => None,
        })
        .collect();
    let want = [
        (
            frame_nanos,
            1,
            SweepMsg {
                frame: 0,
                ball: 0,
                radius: 0.5,
                p0: [1.0, 1.0, 3.0],
                p1: [1.0, 1.0, -3.0],
            },
        ),
        (
            2 * frame_nanos,
            4,
            SweepMsg {
                frame: 1,
                ball: 0,
                radius: 0.5,
                p0: [2.0, -0.3, 3.0],
                p1: [2.0, -0.3, -3.0],
            },
        ),
        (
            3 * frame_nanos,
            7,
            SweepMsg {
                frame: 2,
                ball: 0,
                radius: 0.5,
                p0: [-0.3, -0.2, 3.0],
                p1: [-0.3, -0.2, -3.0],
            },
        ),
        (
            4 * frame_nanos,
            10,
            SweepMsg {
                frame: 3,
                ball: 0,
                radius: 0.5,
                p0: [10.0, 10.0, 3.0],
                p1: [10.0, 10.0, 2.0],
            },
        ),
        (
            4 * frame_nanos,
            13,
            SweepMsg {
                frame: 3,
                ball: 1,
                radius: 0.25,
                p0: [1.0, 1.0, 1.0],
                p1: [1.0, 1.0, 0.0],
            },
        ),
    ];
    ensure!(sweeps == want, "sweeps {sweeps:?}");
    let outcomes: Vec<_> = events
        .iter()
        .filter_map(|e| match &e.body {
            EventBody::Expected(outcome) => Some(*outcome),
            _ => None,
        })
        .collect();
    let face = OutcomeMsg {
        frame: 0,
        ball: 0,
        alpha: 5.0 / 12.0,
        kind: Kind::Face,
        triangle: Some(Some(0)),
        feature: None,
        normal: Some(Some([0.0, 0.0, 1.0])),
        contact: None,
    };
    let edge = OutcomeMsg {
        frame: 1,
        alpha: 13.0 / 30.0,
        kind: Kind::Edge,
        feature: Some(Some(0)),
        normal: None,
        ..face
    };
    let vertex = OutcomeMsg {
        frame: 2,
        alpha: 0.44226,
        kind: Kind::Vertex,
        triangle: None,
        feature: None,
        normal: None,
        ..face
    };
    let none = OutcomeMsg::miss(3, face.ball);
    ensure!(
        outcomes == [face, edge, vertex, none],
        "outcomes {outcomes:?}"
    );
    ensure!(
        stats.compression.iter().eq(["lz4"]),
        "compression {:?}",
        stats.compression
    );
    ensure!(
        stats.library == "python fixture for sweeptrace",
        "library {}",
        stats.library
    );
    ensure!(
        stats.metadata
            == vec![(
                "recorder".to_string(),
                BTreeMap::from([
                    ("engine".to_string(), "python".to_string()),
                    ("units".to_string(), "m".to_string())
                ])
            )],
        "metadata {:?}",
        stats.metadata
    );
    Ok(())
}

fn foreign_channels_skipped_and_counted() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/foreign", 0, b"\x00\x01binary"),
        ("/scene", 1, SCENE_JSON),
        ("/foreign", 2, b"more"),
        (
            "/sweep",
            3,
            br#"{"frame":0,"radius":0.5,"p0":[0,0,1],"p1":[0,0,0]}"#,
        ),
        ("/foreign", 4, b"x"),
    ]);
    let (events, error, stats) = read_all(&bytes);
    ensure!(error.is_none(), "error: {error:?}");
    ensure!(events.len() == 2, "{} events", events.len());
    ensure!(
        events[0].header.index == 1 && events[1].header.index == 3,
        "indices {events:?}"
    );
    ensure!(stats.messages == 5, "messages {}", stats.messages);
    ensure!(
        stats.skipped_by_topic.get("/foreign") == Some(&3),
        "skipped {:?}",
        stats.skipped_by_topic
    );
    ensure!(
        stats.channels["/foreign"].messages == 3,
        "channels {:?}",
        stats.channels
    );
    Ok(())
}

// ---------------------------------------------------------------- errors

fn error_truncated_every_cut() -> anyhow::Result<()> {
    let events = sample_events(4);
    let bytes = write_events(&events, unchunked())?;
    let mut saw_partial = false;
    for cut in 0..bytes.len() {
        let (got, error, stats) = read_all(&bytes[..cut]);
        let Some(error) = error else {
            anyhow::bail!("cut at {cut} of {}: no error", bytes.len());
        };
        ensure!(
            got.as_slice() == &events[..got.len()],
            "cut at {cut}: events read differ from those written"
        );
        if let TraceError::Truncated { messages, .. } = &error {
            ensure!(
                *messages == got.len() as u64,
                "cut at {cut}: {error} but {} events",
                got.len()
            );
            ensure!(stats.messages == got.len() as u64, "stats");
            let text = error.to_string();
            ensure!(
                text.contains("test.mcap")
                    && text.contains("truncated")
                    && text.contains(&format!("after {} complete messages", got.len())),
                "message: {text}"
            );
            saw_partial |= !got.is_empty() && got.len() < events.len();
        } else if cut >= 8 {
            anyhow::bail!("cut at {cut}: not reported as truncated: {error}");
        }
    }
    ensure!(saw_partial, "no cut yielded a partial read");
    Ok(())
}

fn error_truncated_chunked() -> anyhow::Result<()> {
    let events = sample_events(400);
    let bytes = write_events(&events, lz4())?;
    let (full, _, stats) = read_all(&bytes);
    ensure!(
        stats.chunks > 3,
        "want several chunks, got {}",
        stats.chunks
    );
    let cut = bytes.len() * 2 / 3;
    let (got, error, _) = read_all(&bytes[..cut]);
    let error = error.context("no error")?;
    ensure!(
        matches!(error, TraceError::Truncated { .. }),
        "not truncated: {error}"
    );
    ensure!(
        !got.is_empty() && got.len() < full.len(),
        "read {} events",
        got.len()
    );
    ensure!(
        error
            .to_string()
            .contains(&format!("after {} complete messages", got.len())),
        "{error}"
    );
    Ok(())
}

/// Offset of the first chunk record (opcode 0x06) of a file.
pub fn first_chunk(bytes: &[u8]) -> Option<(usize, usize)> {
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let op = bytes[at];
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().ok()?) as usize;
        if op == 0x06 {
            return Some((at, len));
        }
        at += 9 + len;
    }
    None
}

fn error_corrupt_zstd_chunk() -> anyhow::Result<()> {
    corrupt_chunk(default_opts())
}

fn error_corrupt_uncompressed_chunk() -> anyhow::Result<()> {
    corrupt_chunk(uncompressed_chunks())
}

fn corrupt_chunk(opts: WriteOptions) -> anyhow::Result<()> {
    let events = sample_events(30);
    let mut bytes = write_events(&events, opts)?;
    let (start, len) = first_chunk(&bytes).context("no chunk")?;
    // A byte inside the records, well past the chunk header.
    let at = start + 9 + len - len / 3;
    bytes[at] ^= 0x5a;
    let (got, error) = expect_error(&bytes, &["test.mcap", "corrupt", "chunk 0"])?;
    ensure!(
        got.is_empty(),
        "{} events were read from a corrupt chunk",
        got.len()
    );
    ensure!(matches!(error, TraceError::Corrupt { .. }), "{error:?}");
    Ok(())
}

fn error_not_json() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        ("/sweep", 1, b"{frame: 3, radius"),
    ]);
    let (events, _) = expect_error(
        &bytes,
        &["test.mcap", "`/sweep`", "message 1", "not valid JSON"],
    )?;
    ensure!(
        events.len() == 1,
        "the scene before the bad message was not yielded"
    );
    Ok(())
}

fn error_missing_field() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        ("/sweep", 1, br#"{"frame":3,"p0":[0,0,1],"p1":[0,0,0]}"#),
    ]);
    expect_error(
        &bytes,
        &[
            "test.mcap",
            "`/sweep`",
            "frame 3",
            "message 1",
            "`radius`",
            "missing",
        ],
    )?;
    let bytes = raw_trace(&[("/scene", 0, br#"{"vertices":[[0,0,0]]}"#)]);
    expect_error(&bytes, &["`/scene`", "message 0", "`triangles`"])?;
    Ok(())
}

fn error_mistyped_field() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        (
            "/sweep",
            1,
            br#"{"frame":7,"radius":"big","p0":[0,0,1],"p1":[0,0,0]}"#,
        ),
    ]);
    expect_error(&bytes, &["`/sweep`", "frame 7", "`radius`", "invalid type"])?;
    let bytes = raw_trace(&[(
        "/scene",
        0,
        br#"{"vertices":[[0,0,0]],"triangles":[[0,1,-2]]}"#,
    )]);
    expect_error(&bytes, &["`/scene`", "`triangles[0][2]`"])?;
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        (
            "/expected",
            1,
            br#"{"frame":2,"alpha":0.5,"kind":"corner"}"#,
        ),
    ]);
    expect_error(&bytes, &["`/expected`", "frame 2", "`kind`"])?;
    Ok(())
}

fn error_null_for_number() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        (
            "/sweep",
            1,
            br#"{"frame":9,"radius":0.5,"p0":[1,null,2],"p1":[0,0,0]}"#,
        ),
    ]);
    expect_error(&bytes, &["`/sweep`", "frame 9", "`p0[1]`", "null"])?;
    let bytes = raw_trace(&[(
        "/scene",
        0,
        br#"{"vertices":[[0,0,0],[1,0,null]],"triangles":[]}"#,
    )]);
    expect_error(&bytes, &["`/scene`", "`vertices[1][2]`", "null"])?;
    Ok(())
}

fn error_number_out_of_range() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        (
            "/sweep",
            1,
            br#"{"frame":4,"radius":0.5,"p0":[1e400,0,2],"p1":[0,0,0]}"#,
        ),
    ]);
    expect_error(&bytes, &["`/sweep`", "frame 4", "`p0[0]`"])?;
    Ok(())
}

fn error_vertex_index_out_of_range() -> anyhow::Result<()> {
    let bytes = raw_trace(&[(
        "/scene",
        0,
        br#"{"vertices":[[0,0,0],[4,0,0],[0,4,0]],"triangles":[[0,1,2],[2,1,7]]}"#,
    )]);
    expect_error(
        &bytes,
        &[
            "test.mcap",
            "`/scene`",
            "message 0",
            "`triangles[1][2]`",
            "7",
            "out of range",
        ],
    )?;
    Ok(())
}

fn error_radius_not_positive() -> anyhow::Result<()> {
    for radius in ["0", "-0.5", "0.0"] {
        let sweep = format!(r#"{{"frame":11,"radius":{radius},"p0":[0,0,1],"p1":[0,0,0]}}"#);
        let bytes = raw_trace(&[("/scene", 0, SCENE_JSON), ("/sweep", 1, sweep.as_bytes())]);
        expect_error(
            &bytes,
            &["test.mcap", "`/sweep`", "frame 11", "`radius`", "> 0"],
        )?;
    }
    Ok(())
}

fn error_margin_not_below_radius() -> anyhow::Result<()> {
    let scene = br#"{"vertices":[[0,0,0],[4,0,0],[0,4,0]],"triangles":[[0,1,2]],"margin":0.5}"#;
    let bytes = raw_trace(&[
        ("/scene", 0, scene),
        (
            "/sweep",
            1,
            br#"{"frame":5,"radius":0.5,"p0":[0,0,1],"p1":[0,0,0]}"#,
        ),
    ]);
    expect_error(&bytes, &["frame 5", "`radius`", "margin"])?;
    let bytes = raw_trace(&[(
        "/scene",
        0,
        br#"{"vertices":[],"triangles":[],"margin":-1}"#,
    )]);
    expect_error(&bytes, &["`/scene`", "`margin`"])?;
    Ok(())
}

fn error_sweep_before_scene() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        (
            "/sweep",
            0,
            br#"{"frame":12,"radius":0.5,"p0":[0,0,1],"p1":[0,0,0]}"#,
        ),
        ("/scene", 1, SCENE_JSON),
    ]);
    let (_, error) = expect_error(
        &bytes,
        &["test.mcap", "`/sweep`", "frame 12", "before any `/scene`"],
    )?;
    ensure!(
        matches!(error, TraceError::SweepBeforeScene { .. }),
        "{error:?}"
    );
    Ok(())
}

fn error_oversized_scene() -> anyhow::Result<()> {
    let mut scene = triangle_scene();
    scene.vertices = (0..200).map(|i| [i as f64, 0.5, 0.25]).collect();
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &scene)?;
    let bytes = w.finish()?.into_inner();
    let limits = ReadLimits {
        scene_bytes: 1000,
        ..ReadLimits::default()
    };
    let (events, error, _) = read_all_with(&bytes, limits);
    ensure!(events.is_empty(), "events {events:?}");
    let error = error.context("no error")?;
    let text = error.to_string();
    ensure!(
        matches!(error, TraceError::MessageTooLarge { .. }),
        "{error:?}"
    );
    ensure!(
        text.contains("`/scene`")
            && text.contains("message 0")
            && text.contains("limit of 1000 bytes"),
        "{text}"
    );
    Ok(())
}

/// Minimal MCAP pieces to hand-craft files whose sizes lie.
fn record(op: u8, body: &[u8]) -> Vec<u8> {
    let mut out = vec![op];
    out.extend((body.len() as u64).to_le_bytes());
    out.extend(body);
    out
}

fn magic_and_header() -> Vec<u8> {
    let mut out = b"\x89MCAP0\r\n".to_vec();
    let mut header = Vec::new();
    header.extend(0u32.to_le_bytes()); // profile ""
    header.extend(0u32.to_le_bytes()); // library ""
    out.extend(record(0x01, &header));
    out
}

fn error_huge_declared_record() -> anyhow::Result<()> {
    // A message record declaring a terabyte (a scene "with a billion triangles").
    let mut bytes = magic_and_header();
    bytes.push(0x05);
    bytes.extend((1u64 << 40).to_le_bytes());
    bytes.extend([0u8; 64]);
    let (_, error) = expect_error(
        &bytes,
        &["test.mcap", "declares 1099511627776 bytes", "limit"],
    )?;
    ensure!(matches!(error, TraceError::TooLarge { .. }), "{error:?}");
    Ok(())
}

fn error_huge_declared_chunk() -> anyhow::Result<()> {
    let mut chunk = Vec::new();
    chunk.extend(0u64.to_le_bytes()); // message start time
    chunk.extend(0u64.to_le_bytes()); // message end time
    chunk.extend((1u64 << 40).to_le_bytes()); // uncompressed size: 1 TiB
    chunk.extend(0u32.to_le_bytes()); // crc
    chunk.extend(4u32.to_le_bytes());
    chunk.extend(b"zstd");
    chunk.extend(16u64.to_le_bytes()); // compressed size
    chunk.extend([0u8; 16]);
    let mut bytes = magic_and_header();
    bytes.extend(record(0x06, &chunk));
    let (_, error) = expect_error(
        &bytes,
        &["test.mcap", "chunk 0 (uncompressed)", "1099511627776"],
    )?;
    ensure!(matches!(error, TraceError::TooLarge { .. }), "{error:?}");
    Ok(())
}

fn error_out_of_order_log_time() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        (
            "/sweep",
            2_000,
            br#"{"frame":1,"radius":0.5,"p0":[0,0,1],"p1":[0,0,0]}"#,
        ),
        ("/foreign", 10, b"foreign topics may be in any order"),
        (
            "/sweep",
            1_000,
            br#"{"frame":0,"radius":0.5,"p0":[0,0,1],"p1":[0,0,0]}"#,
        ),
    ]);
    let (events, _) = expect_error(
        &bytes,
        &["`/sweep`", "frame 0", "message 3", "1000", "2000", "order"],
    )?;
    ensure!(events.len() == 2, "{} events", events.len());
    Ok(())
}

fn error_wrong_message_encoding() -> anyhow::Result<()> {
    let bytes = raw_trace_with(&[("/scene", 0, SCENE_JSON)], "protobuf");
    expect_error(
        &bytes,
        &["test.mcap", "`/scene`", "`protobuf`", "`json` or `cbor`"],
    )?;
    // The names are exact: `JSON` is not `json`.
    let bytes = raw_trace_with(&[("/scene", 0, SCENE_JSON)], "JSON");
    expect_error(&bytes, &["`/scene`", "`JSON`"])?;
    Ok(())
}

fn error_bad_outcome_alpha() -> anyhow::Result<()> {
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        ("/expected", 1, br#"{"frame":6,"alpha":1.5,"kind":"none"}"#),
    ]);
    expect_error(&bytes, &["`/expected`", "frame 6", "`alpha`"])?;
    let bytes = raw_trace(&[
        ("/scene", 0, SCENE_JSON),
        (
            "/expected",
            1,
            br#"{"frame":6,"alpha":0.5,"kind":"edge","feature":3}"#,
        ),
    ]);
    expect_error(&bytes, &["`/expected`", "frame 6", "`feature`"])?;
    Ok(())
}

fn random_corruption_never_panics() -> anyhow::Result<()> {
    let events = sample_events(40);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5eed_7ace);
    let mut seen = BTreeMap::new();
    for opts in [default_opts(), unchunked(), lz4(), uncompressed_chunks()] {
        let bytes = write_events(&events, opts)?;
        for _ in 0..300 {
            let mut b = bytes.clone();
            for _ in 0..rng.random_range(1..4) {
                let i = rng.random_range(0..b.len());
                b[i] = rng.random();
            }
            if rng.random_bool(0.3) {
                b.truncate(rng.random_range(0..b.len()));
            }
            // Must terminate without panicking; errors are fine, as long as
            // each says where it happened.
            let (events, error, _) = read_all(&b);
            if let Some(error) = error {
                error_names_where(&error, events.len() as u64)?;
                *seen.entry(variant_name(&error)).or_insert(0) += 1;
            }
        }
    }
    // The corruption reaches every layer: the container, the end of the
    // file and the messages.
    ensure!(
        ["Corrupt", "Truncated", "Json"]
            .iter()
            .all(|v| seen.contains_key(*v)),
        "errors seen: {seen:?}"
    );
    Ok(())
}

/// The name of the error's variant, from its `Debug` form (`Corrupt { .. }`).
pub fn variant_name(error: &TraceError) -> String {
    let debug = format!("{error:?}");
    debug
        .split([' ', '{', '('])
        .next()
        .unwrap_or("")
        .to_string()
}

/// The error read from `test.mcap` after `read` good messages names the
/// file and, where it has one, the message (channel and index, which is at
/// least `read`) or the number of complete messages before it.
pub fn error_names_where(error: &TraceError, read: u64) -> anyhow::Result<()> {
    let text = error.to_string();
    ensure!(
        text.starts_with("test.mcap: "),
        "does not start with the file name: {text}"
    );
    if let Some(at) = error.message_at() {
        ensure!(
            at.file == "test.mcap"
                && at.index >= read
                && text.contains(&format!("channel `{}`", at.channel))
                && text.contains(&format!("message {}", at.index)),
            "the message is not named: {text} ({at:?}, {read} read)"
        );
        return Ok(());
    }
    match error {
        TraceError::Io { messages, .. }
        | TraceError::Truncated { messages, .. }
        | TraceError::Corrupt { messages, .. }
        | TraceError::FieldTooLong { messages, .. } => ensure!(
            *messages >= read && text.contains(&format!("after {messages} complete messages")),
            "the position is not named: {text} ({read} read)"
        ),
        TraceError::TooLarge { what, .. } => {
            ensure!(!what.is_empty(), "what is too large is not named: {text}")
        }
        TraceError::WrongEncoding { channel, .. } => ensure!(
            text.contains(&format!("channel `{channel}`")),
            "the channel is not named: {text}"
        ),
        TraceError::UnknownChannel { index, .. } => ensure!(
            *index >= read && text.contains(&format!("message {index}")),
            "the message is not named: {text} ({read} read)"
        ),
        // A corrupted magic: nothing was read, the file is named.
        TraceError::NotMcap { .. } => ensure!(read == 0, "{text} after {read} messages"),
        _ => anyhow::bail!("unexpected error while reading: {text}"),
    }
    Ok(())
}

fn writer_refuses_invalid_messages() -> anyhow::Result<()> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    let e = w
        .sweep(0, &sweep(3, 0))
        .err()
        .context("sweep before scene accepted")?;
    ensure!(
        matches!(e, TraceError::SweepBeforeScene { .. }) && e.to_string().contains("frame 3"),
        "{e}"
    );
    w.scene(0, &triangle_scene())?;
    let mut s = sweep(4, 0);
    s.radius = f64::NAN;
    let e = w.sweep(1, &s).err().context("NaN radius accepted")?;
    ensure!(
        e.to_string().contains("`radius`") && e.to_string().contains("frame 4"),
        "{e}"
    );
    let mut s = sweep(4, 0);
    s.p1[2] = f64::INFINITY;
    let e = w.sweep(1, &s).err().context("infinite p1 accepted")?;
    ensure!(e.to_string().contains("`p1[2]`"), "{e}");
    let mut scene = triangle_scene();
    scene.triangles.push([0, 1, 3]);
    let e = w.scene(1, &scene).err().context("bad index accepted")?;
    ensure!(e.to_string().contains("`triangles[1][2]`"), "{e}");
    w.sweep(10, &sweep(5, 0))?;
    let e = w
        .sweep(5, &sweep(6, 0))
        .err()
        .context("time going back accepted")?;
    ensure!(matches!(e, TraceError::OutOfOrder { .. }), "{e}");
    // The rejected messages were not written: the trace still reads cleanly.
    let bytes = w.finish()?.into_inner();
    let (events, error, _) = read_all(&bytes);
    ensure!(error.is_none() && events.len() == 2, "{events:?} {error:?}");
    Ok(())
}

/// The C writer refused an `/expected` triangle beyond the scene's that the
/// Rust writer wrote; both check it now (`validate_triangle`). The reader
/// still reads such a trace: a recording engine's bad index is judged.
fn writer_refuses_a_triangle_the_scene_does_not_have() -> anyhow::Result<()> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    // Before any scene there is nothing to check it against.
    w.expected(0, &OutcomeMsg::hit(0, 0, 0.5, Kind::Face).triangle(7))?;
    w.scene(1, &triangle_scene())?;
    w.expected(1, &OutcomeMsg::hit(1, 0, 0.5, Kind::Face).triangle(0))?;
    let e = w
        .expected(1, &OutcomeMsg::hit(2, 0, 0.5, Kind::Face).triangle(1))
        .err()
        .context("triangle 1 of a 1-triangle scene accepted")?;
    ensure!(
        matches!(e, TraceError::Invalid { .. })
            && e.to_string().contains("`triangle`")
            && e.to_string()
                .contains("index 1 is out of range (the scene has 1 triangles)")
            && e.to_string().contains("frame 2"),
        "{e}"
    );
    let bytes = w.finish()?.into_inner();
    let (events, error, _) = read_all(&bytes);
    ensure!(error.is_none() && events.len() == 3, "{events:?} {error:?}");
    Ok(())
}

fn write_trace_file_is_atomic() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("run.mcap");
    let events = sample_events(5);
    write_trace_file(&path, |w| -> Result<(), TraceError> {
        for e in &events {
            write_event(w, e)?;
        }
        Ok(())
    })?;
    let bytes = std::fs::read(&path)?;
    ensure!(
        bytes == write_events(&events, default_opts())?,
        "file differs from in-memory write"
    );
    let (got, error, _) = read_all(&bytes);
    ensure!(error.is_none() && got == events, "read back: {error:?}");

    // A failing recording leaves the old file untouched and no temporary file.
    let result = write_trace_file(&path, |w| -> Result<(), TraceError> {
        w.scene(0, &triangle_scene())?;
        w.sweep(
            1,
            &SweepMsg {
                radius: -1.0,
                ..sweep(0, 0)
            },
        )?;
        Ok(())
    });
    ensure!(result.is_err(), "invalid sweep accepted");
    ensure!(std::fs::read(&path)? == bytes, "old file changed");
    let fresh = dir.path().join("never.mcap");
    let _ = write_trace_file(&fresh, |_| {
        Err::<(), _>(TraceError::SweepBeforeScene {
            at: Box::new(sweeptrace::trace::MessageAt {
                file: "x".into(),
                channel: "/sweep".into(),
                index: 0,
                frame: None,
            }),
        })
    });
    ensure!(!fresh.exists(), "failed recording left a file");
    let entries: Vec<_> = std::fs::read_dir(dir.path())?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    ensure!(entries == ["run.mcap"], "directory holds {entries:?}");
    Ok(())
}

fn info_renders_python_fixture() -> anyhow::Result<()> {
    let bytes = std::fs::read(FIXTURE).map_err(|e| anyhow::anyhow!("{FIXTURE}: {e}"))?;
    let (info, error) = collect_info(TraceReader::new(bytes.as_slice(), "python_written.mcap"));
    ensure!(error.is_none(), "{error:?}");
    let text = render_info_text(&info);
    for needle in [
        "trace:       python_written.mcap",
        &format!(
            "file:        {} bytes, 1 chunk, compression lz4, summary present",
            bytes.len()
        ),
        "library:     python fixture for sweeptrace",
        "scenes:      1",
        "`triangle` (message 0, log_time 0 ns): 3 vertices, 1 triangle, 0 degenerate, margin 0, facing non_strict",
        "sweeps:      5 (2 balls: 0, 1)",
        "frames:      0 to 3",
        "log_time:    0 ns to 66666668 ns",
        "expected:    present, 4 outcomes (edge 1, face 1, none 1, vertex 1)",
        "  /debug  (no schema) [- / json]  4 messages, skipped",
        "  /sweep  sweeptrace.Sweep [jsonschema / json]  5 messages",
        "  recorder: engine = \"python\", units = \"m\"",
    ] {
        ensure!(text.contains(needle), "report lacks `{needle}`:\n{text}");
    }
    ensure!(!text.contains("incomplete"), "{text}");
    let json: serde_json::Value = serde_json::from_str(&render_info_json(&info))?;
    ensure!(json["sweeps"] == 5 && json["expected"] == 4, "{json}");
    ensure!(json["stats"]["skipped_by_topic"]["/debug"] == 4, "{json}");
    ensure!(json["scenes"][0]["triangles"] == 1, "{json}");

    // Degenerate triangles are counted; no expected channel is reported absent.
    let mut scene = triangle_scene();
    scene.triangles.push([0, 0, 1]);
    scene.vertices.push([8.0, 0.0, 0.0]);
    scene.triangles.push([0, 1, 3]);
    let mut w = TraceWriter::with_options(Cursor::new(Vec::new()), default_opts())?;
    w.scene(0, &scene)?;
    let bytes = w.finish()?.into_inner();
    let (info, _) = collect_info(TraceReader::new(bytes.as_slice(), "d.mcap"));
    let text = render_info_text(&info);
    ensure!(
        text.contains("4 vertices, 3 triangles, 2 degenerate"),
        "{text}"
    );
    ensure!(
        text.contains("sweeptrace: format_version = \"1\""),
        "{text}"
    );
    // The writer registers all three channels; with no outcome written the
    // channel is present but empty.
    ensure!(text.contains("expected:    present, 0 outcomes"), "{text}");
    Ok(())
}

fn info_reports_partial_trace() -> anyhow::Result<()> {
    let bytes = write_events(&sample_events(10), unchunked())?;
    let cut = &bytes[..bytes.len() / 2];
    let (info, error) = collect_info(TraceReader::new(cut, "cut.mcap"));
    let error = error.context("no error")?;
    ensure!(matches!(error, TraceError::Truncated { .. }), "{error}");
    let text = render_info_text(&info);
    ensure!(
        text.contains("incomplete:  cut.mcap: the file is truncated"),
        "{text}"
    );
    ensure!(info.sweeps > 0, "partial report counted no sweep");
    Ok(())
}

fn python_reads_our_trace() -> anyhow::Result<Completion> {
    if let Err(skipped) = crate::support::python_with_mcap()? {
        return Ok(skipped);
    }
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("py.mcap");
    let events = sample_events(30);
    std::fs::write(&path, write_events(&events, default_opts())?)?;
    crate::support::read_with_python(
        &path,
        &["--scenes", "2", "--sweeps", "60", "--expected", "30"],
    )?;
    // And it can fail.
    ensure!(
        crate::support::read_with_python(&path, &["--sweeps", "61"]).is_err(),
        "script accepted a wrong count"
    );
    Ok(Completion::Completed)
}

/// The names the reports write (`as_str`, `Display`) are the names the JSON
/// and the trace format write (serde), for every variant, and read back.
fn enum_names_in_words_are_their_serde_names() -> anyhow::Result<()> {
    use sweeptrace::core::FragileReason;
    use sweeptrace::core::record::Verdict;
    fn same<T>(v: T, words: &str) -> anyhow::Result<()>
    where
        T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug,
    {
        let json = serde_json::to_value(&v)?;
        ensure!(
            json == words,
            "{v:?}: serde writes {json}, the words say `{words}`"
        );
        let back: T = serde_json::from_value(json).map_err(|e| anyhow::anyhow!("{v:?}: {e}"))?;
        ensure!(back == v, "{v:?} reads back as {back:?}");
        Ok(())
    }
    for k in [Kind::None, Kind::Face, Kind::Edge, Kind::Vertex] {
        same(k, k.as_str())?;
        ensure!(k.to_string() == k.as_str(), "{k:?}: Display");
    }
    for f in [Facing::Strict, Facing::NonStrict] {
        same(f, f.as_str())?;
        ensure!(f.to_string() == f.as_str(), "{f:?}: Display");
    }
    for v in Verdict::ALL {
        let json = serde_json::to_value(v)?;
        ensure!(
            json == v.as_str(),
            "{v:?}: serde writes {json}, the words say `{}`",
            v.as_str()
        );
    }
    for r in FragileReason::ALL {
        let json = serde_json::to_value(r)?;
        ensure!(
            json == r.as_str(),
            "{r:?}: serde writes {json}, the words say `{}`",
            r.as_str()
        );
    }
    Ok(())
}
