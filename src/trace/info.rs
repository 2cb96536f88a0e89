//! What `sweeptrace info` reports about a trace, and its rendering.
//!
//! [`collect_info`] reads a whole trace (streaming) into a [`TraceInfo`];
//! [`render_info_text`] and [`render_info_json`] are pure functions of it.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::io::Read;

use serde::Serialize;

use super::error::TraceError;
use super::messages::{EXPECTED_TOPIC, TRACE_TOPICS};
use super::read::{EventBody, EventHeader, ReadStats, TraceReader};
use crate::core::topology::{EdgeCounts, Topology};
use crate::core::{Mesh, MeshError};
use crate::numbers::counted;

/// Scenes listed one by one; beyond this only their number is kept.
pub const MAX_LISTED_SCENES: usize = 64;
/// Distinct balls listed; beyond this only `balls_truncated` is set.
pub const MAX_LISTED_BALLS: usize = 1024;

/// One scene of a trace.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneSummary {
    /// Index of its message in the file.
    pub index: u64,
    /// Its `log_time`.
    pub log_time_nanos: u64,
    /// Its name, if any.
    pub name: Option<String>,
    /// Number of vertices.
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of degenerate triangles (left out of every test).
    pub degenerate: usize,
    /// Why no mesh can be built from it (e.g. every triangle degenerate).
    pub mesh_error: Option<String>,
    /// Its margin.
    pub margin: f64,
    /// Its facing rule.
    pub facing: String,
    /// Its edges by class (`None` when no topology can be built: an index
    /// out of range, a non-finite coordinate).
    pub edges: Option<EdgeCounts>,
    /// Its number of mesh defects (see `sweeptrace mesh`).
    pub defects: Option<usize>,
}

/// Everything `sweeptrace info` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceInfo {
    /// File name.
    pub file: String,
    /// The first scenes (at most [`MAX_LISTED_SCENES`]).
    pub scenes: Vec<SceneSummary>,
    /// Number of scenes.
    pub scene_count: u64,
    /// Number of sweeps.
    pub sweeps: u64,
    /// Distinct balls (at most [`MAX_LISTED_BALLS`]).
    pub balls: BTreeSet<u32>,
    /// Whether more balls were seen than listed.
    pub balls_truncated: bool,
    /// Smallest and largest frame of the sweeps and expected outcomes.
    pub frames: Option<(u64, u64)>,
    /// Smallest and largest `log_time` of the trace messages, in nanoseconds.
    pub log_time_nanos: Option<(u64, u64)>,
    /// Whether the file has an `/expected` channel.
    pub expected_present: bool,
    /// Number of expected outcomes.
    pub expected: u64,
    /// Number of contact queries (`/contact`).
    #[serde(skip_serializing_if = "is_zero")]
    pub contacts: u64,
    /// Number of engine contact answers (`/expected_contacts`).
    #[serde(skip_serializing_if = "is_zero")]
    pub expected_contacts: u64,
    /// Expected outcomes by kind.
    pub expected_by_kind: BTreeMap<String, u64>,
    /// Who computed them (the `sweeptrace.expected_source` record), if known.
    pub expected_source: Option<super::ExpectedSource>,
    /// What the reader saw: channels, chunks, compression, bytes, metadata.
    pub stats: ReadStats,
    /// The size of the file, when known (the reader's `stats.bytes` counts
    /// the bytes read, fewer when reading stopped early).
    pub file_bytes: Option<u64>,
    /// The error that ended reading early, if any (the rest of the report
    /// covers the messages before it).
    pub error: Option<String>,
}

fn widen(range: &mut Option<(u64, u64)>, v: u64) {
    *range = Some(match *range {
        None => (v, v),
        Some((lo, hi)) => (lo.min(v), hi.max(v)),
    });
}

/// Reads a whole trace and summarises it. On an error the summary covers
/// the messages before it, and the error is returned alongside.
pub fn collect_info<R: Read>(mut reader: TraceReader<R>) -> (TraceInfo, Option<TraceError>) {
    let mut info = TraceInfo {
        file: reader.source_name().to_string(),
        scenes: Vec::new(),
        scene_count: 0,
        sweeps: 0,
        balls: BTreeSet::new(),
        balls_truncated: false,
        frames: None,
        log_time_nanos: None,
        expected_present: false,
        expected: 0,
        contacts: 0,
        expected_contacts: 0,
        expected_by_kind: BTreeMap::new(),
        expected_source: None,
        stats: ReadStats::default(),
        file_bytes: None,
        error: None,
    };
    let mut error = None;
    for event in reader.by_ref() {
        let event = match event {
            Ok(event) => event,
            Err(err) => {
                info.error = Some(err.to_string());
                error = Some(err);
                break;
            }
        };
        let EventHeader {
            log_time_nanos,
            index,
        } = event.header;
        widen(&mut info.log_time_nanos, log_time_nanos);
        match event.body {
            EventBody::Scene(scene) => {
                info.scene_count += 1;
                if info.scenes.len() < MAX_LISTED_SCENES {
                    let vertices = scene.vertices.len();
                    let triangles = scene.triangles.len();
                    let topology = Topology::new(&scene.vertices, &scene.triangles).ok();
                    let (degenerate, mesh_error) = match Mesh::new(scene.vertices, &scene.triangles)
                    {
                        Ok(mesh) => (mesh.degenerate().len(), None),
                        Err(err @ MeshError::Empty { degenerate, .. }) => {
                            (degenerate, Some(err.to_string()))
                        }
                        Err(err) => (0, Some(err.to_string())),
                    };
                    info.scenes.push(SceneSummary {
                        index,
                        log_time_nanos,
                        name: scene.name,
                        vertices,
                        triangles,
                        degenerate,
                        mesh_error,
                        margin: scene.margin,
                        facing: scene.facing.as_str().to_string(),
                        edges: topology.as_ref().map(Topology::edge_counts),
                        defects: topology.as_ref().map(|t| t.defects().len()),
                    });
                }
            }
            EventBody::Sweep(sweep) => {
                info.sweeps += 1;
                widen(&mut info.frames, sweep.frame);
                if info.balls.len() < MAX_LISTED_BALLS || info.balls.contains(&sweep.ball) {
                    info.balls.insert(sweep.ball);
                } else {
                    info.balls_truncated = true;
                }
            }
            EventBody::Contact(contact) => {
                info.contacts += 1;
                widen(&mut info.frames, contact.frame);
            }
            EventBody::ExpectedContacts(contacts) => {
                info.expected_contacts += 1;
                widen(&mut info.frames, contacts.frame);
            }
            EventBody::Expected(outcome) => {
                info.expected += 1;
                widen(&mut info.frames, outcome.frame);
                *info
                    .expected_by_kind
                    .entry(outcome.kind.as_str().to_string())
                    .or_default() += 1;
            }
        }
    }
    info.stats = reader.stats().clone();
    info.expected_source = info.stats.expected_source.clone();
    info.expected_present = info.stats.channels.contains_key(EXPECTED_TOPIC);
    (info, error)
}

fn seconds(nanos: u64) -> String {
    format!("{:.3} s", nanos as f64 / 1e9)
}

/// The human-readable report.
pub fn render_info_text(info: &TraceInfo) -> String {
    let mut out = String::new();
    write_container(&mut out, info);
    write_scenes(&mut out, info);
    write_sweeps(&mut out, info);
    write_expected(&mut out, info);
    write_channels(&mut out, &info.stats);
    if let Some(err) = &info.error {
        let _ = writeln!(out, "incomplete:  {err}");
    }
    out
}

/// The file: its name, size, chunks and summary, the reading order and
/// the writing library.
fn write_container(out: &mut String, info: &TraceInfo) {
    let s = &info.stats;
    let compression = if s.compression.is_empty() && info.error.is_some() {
        // Reading stopped before a complete chunk: whether the rest of the
        // file holds chunks is not known.
        "no complete chunk read".to_string()
    } else if s.compression.is_empty() {
        "not chunked".to_string()
    } else {
        let list: Vec<&str> = s.compression.iter().map(String::as_str).collect();
        format!(
            "{}, compression {}",
            counted(s.chunks, "chunk", "chunks"),
            list.join(", ")
        )
    };
    let _ = writeln!(out, "trace:       {}", info.file);
    let _ = writeln!(
        out,
        "file:        {}, {compression}, summary {}",
        match info.file_bytes {
            Some(size) if size != s.bytes => format!("{size} bytes ({} read)", s.bytes),
            Some(size) => format!("{size} bytes"),
            // Read to its end: every byte was read.
            None if info.error.is_none() => format!("{} bytes", s.bytes),
            None => format!("{} bytes read", s.bytes),
        },
        if s.has_summary { "present" } else { "absent" }
    );
    if s.read_through_chunk_indexes {
        let _ = writeln!(
            out,
            "messages:    out of log-time order across chunks (they overlap in time); \
             read in log-time order through the chunk indexes"
        );
    }
    let library = if s.library.is_empty() {
        "(none)"
    } else {
        s.library.as_str()
    };
    let _ = writeln!(out, "library:     {library}");
}

/// The scenes, one line each (two with the mesh's edges).
fn write_scenes(out: &mut String, info: &TraceInfo) {
    let _ = writeln!(out, "scenes:      {}", info.scene_count);
    for scene in &info.scenes {
        let name = scene
            .name
            .as_deref()
            .map(|n| format!("`{}`", crate::error_text::escaped(n)))
            .unwrap_or_else(|| "(unnamed)".to_string());
        let _ = write!(
            out,
            "  {name} (message {}, log_time {} ns): {}, {}, {} degenerate, margin {}, facing {}",
            scene.index,
            scene.log_time_nanos,
            counted(scene.vertices as u64, "vertex", "vertices"),
            counted(scene.triangles as u64, "triangle", "triangles"),
            scene.degenerate,
            scene.margin,
            scene.facing
        );
        if let Some(err) = &scene.mesh_error {
            let _ = write!(out, " (unusable: {err})");
        }
        out.push('\n');
        if let (Some(e), Some(defects)) = (&scene.edges, scene.defects) {
            let _ = writeln!(
                out,
                "    edges: {} boundary, {} convex, {} flat, {} concave, {} non_manifold; {} (see `sweeptrace mesh`)",
                e.boundary,
                e.convex,
                e.flat,
                e.concave,
                e.non_manifold,
                counted(defects as u64, "mesh defect", "mesh defects")
            );
        }
    }
    if info.scene_count > info.scenes.len() as u64 {
        let _ = writeln!(
            out,
            "  ... and {} more",
            info.scene_count - info.scenes.len() as u64
        );
    }
}

/// The sweeps and their balls, and the frames and `log_time`s they span.
fn write_sweeps(out: &mut String, info: &TraceInfo) {
    let balls: Vec<String> = info.balls.iter().map(u32::to_string).collect();
    let more = if info.balls_truncated { ", ..." } else { "" };
    let _ = writeln!(
        out,
        "sweeps:      {}{}",
        info.sweeps,
        if info.balls.is_empty() {
            String::new()
        } else {
            format!(
                " ({}: {}{more})",
                counted(info.balls.len() as u64, "ball", "balls"),
                balls.join(", ")
            )
        }
    );
    if info.contacts > 0 || info.expected_contacts > 0 {
        let _ = writeln!(
            out,
            "contacts:    {} ({} answered by the recording engine)",
            counted(info.contacts, "query", "queries"),
            info.expected_contacts
        );
    }
    match info.frames {
        Some((lo, hi)) => {
            let _ = writeln!(out, "frames:      {lo} to {hi}");
        }
        None => {
            let _ = writeln!(out, "frames:      (none)");
        }
    }
    match info.log_time_nanos {
        Some((lo, hi)) => {
            let _ = writeln!(
                out,
                "log_time:    {lo} ns to {hi} ns ({} to {}, span {})",
                seconds(lo),
                seconds(hi),
                seconds(hi - lo)
            );
        }
        None => {
            let _ = writeln!(out, "log_time:    (no messages)");
        }
    }
}

/// The `/expected` outcomes by kind, and who computed them.
fn write_expected(out: &mut String, info: &TraceInfo) {
    if info.expected_present {
        let kinds: Vec<String> = info
            .expected_by_kind
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        let kinds = if kinds.is_empty() {
            String::new()
        } else {
            format!(" ({})", kinds.join(", "))
        };
        let _ = writeln!(
            out,
            "expected:    present, {}{kinds}",
            counted(info.expected, "outcome", "outcomes")
        );
    } else {
        let _ = writeln!(out, "expected:    absent");
    }
    if let Some(source) = &info.expected_source {
        let _ = writeln!(out, "expected by: {source}");
    }
}

/// The trace channels' encoding, every channel, and the metadata records.
fn write_channels(out: &mut String, s: &ReadStats) {
    if let Some(line) = encoding_line(s) {
        let _ = writeln!(out, "encoding:    {line}");
    }
    let _ = writeln!(out, "channels:");
    for (topic, c) in &s.channels {
        let ours = TRACE_TOPICS.contains(&topic.as_str());
        let schema = if c.schema_name.is_empty() {
            "(no schema)".to_string()
        } else {
            c.schema_name.clone()
        };
        let note = if ours { "" } else { ", skipped" };
        let _ = writeln!(
            out,
            "  {topic}  {schema} [{} / {}]  {}{note}",
            if c.schema_encoding.is_empty() {
                "-"
            } else {
                c.schema_encoding.as_str()
            },
            c.message_encoding,
            counted(c.messages, "message", "messages")
        );
    }
    if s.metadata.is_empty() {
        let _ = writeln!(out, "metadata:    (none)");
    } else {
        let _ = writeln!(out, "metadata:");
        for (name, map) in &s.metadata {
            let pairs: Vec<String> = map.iter().map(|(k, v)| format!("{k} = {v:?}")).collect();
            let _ = writeln!(out, "  {name}: {}", pairs.join(", "));
        }
    }
}

/// The message encodings of the trace channels: `cbor` when they all use
/// one, else each with its channels (`cbor (/scene, /sweep), json
/// (/expected)`); `None` without a trace channel.
fn encoding_line(stats: &ReadStats) -> Option<String> {
    let mut by_encoding: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (topic, c) in &stats.channels {
        if TRACE_TOPICS.contains(&topic.as_str()) {
            by_encoding
                .entry(c.message_encoding.as_str())
                .or_default()
                .push(topic);
        }
    }
    match by_encoding.len() {
        0 => None,
        1 => by_encoding.into_keys().next().map(str::to_string),
        _ => Some(
            by_encoding
                .iter()
                .map(|(encoding, topics)| format!("{encoding} ({})", topics.join(", ")))
                .collect::<Vec<_>>()
                .join(", "),
        ),
    }
}

/// The report as one pretty-printed JSON object.
pub fn render_info_json(info: &TraceInfo) -> String {
    serde_json::to_string_pretty(info)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}
