//! Scenes from Wavefront OBJ files (triangulated by `tobj`).

use super::scenes::SceneMesh;

/// Why a Wavefront OBJ file could not be used as a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ObjError {
    /// The file could not be opened (the wording every command gives
    /// for a file it cannot open).
    #[error("{path}: cannot open: {}", crate::error_text::full_text(.cause))]
    Open {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The file could not be read.
    #[error("cannot read {path}: {}", crate::error_text::full_text(.cause))]
    Io {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The file is larger than an OBJ file this reads
    /// ([`MAX_OBJ_BYTES`]): not read further (`/dev/zero`, a wrong file).
    #[error("{path} is larger than {} MiB: not a Wavefront OBJ file this reads", MAX_OBJ_BYTES >> 20)]
    TooLarge {
        /// The file.
        path: String,
    },
    /// The OBJ parser refused the file.
    #[error("{path} is not a valid Wavefront OBJ file: {reason}")]
    Parse {
        /// The file.
        path: String,
        /// What the parser reported.
        reason: String,
    },
    /// The file parsed but holds no triangle.
    #[error("{path} holds no triangle (no `f` lines with three or more vertices)")]
    NoTriangles {
        /// The file.
        path: String,
    },
}

/// The largest Wavefront OBJ file read (256 MiB: some millions of
/// triangles); a larger input is an error, not a read without end.
pub const MAX_OBJ_BYTES: u64 = 256 * 1024 * 1024;

/// Loads a Wavefront OBJ file (through `tobj`) as a scene named after the
/// file's stem. Polygons are triangulated as fans; every object and group
/// of the file goes into one mesh; materials, normals, texture coordinates,
/// points and lines are ignored. Faces are counter-clockwise seen from the
/// front, as in the OBJ convention. Coordinates are read as `f32`.
pub fn load_obj(path: &std::path::Path) -> Result<SceneMesh, ObjError> {
    let shown = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|cause| ObjError::Open {
        path: shown.clone(),
        cause,
    })?;
    let mut reader = std::io::BufReader::new(file);
    let mut scene = obj_from_reader(&mut reader).map_err(|e| match e {
        ObjError::Parse { reason, .. } => ObjError::Parse {
            path: shown.clone(),
            reason,
        },
        ObjError::NoTriangles { .. } => ObjError::NoTriangles {
            path: shown.clone(),
        },
        ObjError::Io { cause, .. } => ObjError::Io {
            path: shown.clone(),
            cause,
        },
        ObjError::TooLarge { .. } => ObjError::TooLarge {
            path: shown.clone(),
        },
        other => other,
    })?;
    scene.name = path
        .file_stem()
        .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned());
    Ok(scene)
}

/// Parses Wavefront OBJ text from a reader (see [`load_obj`]); errors name
/// the source `<input>`, and a parse error its line (`line 2 (`v 1 zero
/// 0`): ...`).
pub fn obj_from_reader(reader: &mut impl std::io::BufRead) -> Result<SceneMesh, ObjError> {
    use std::io::Read;
    let mut text = Vec::new();
    reader
        .take(MAX_OBJ_BYTES + 1)
        .read_to_end(&mut text)
        .map_err(|cause| ObjError::Io {
            path: "<input>".into(),
            cause,
        })?;
    if text.len() as u64 > MAX_OBJ_BYTES {
        return Err(ObjError::TooLarge {
            path: "<input>".into(),
        });
    }
    match parse(&text) {
        Err(ObjError::Parse { path, reason }) => {
            let reason = match first_failing_line(&text) {
                Some((number, line)) => format!("line {number} (`{line}`): {reason}"),
                None => reason,
            };
            Err(ObjError::Parse { path, reason })
        }
        other => other,
    }
}

/// The first line (from 1) at which the file stops parsing, with its text
/// (shortened): the shortest prefix of whole lines that does not parse
/// ends with it. The parser reports no line itself; a prefix that parses
/// keeps parsing with fewer lines, so a binary search over the lines finds
/// it with a logarithmic number of parses (on the error path only).
fn first_failing_line(text: &[u8]) -> Option<(usize, String)> {
    let mut ends: Vec<usize> = text
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i + 1)
        .collect();
    if ends.last().is_none_or(|&e| e < text.len()) {
        ends.push(text.len());
    }
    let fails = |k: usize| matches!(parse(&text[..ends[k]]), Err(ObjError::Parse { .. }));
    let last = ends.len().checked_sub(1)?;
    if !fails(last) {
        return None;
    }
    let (mut lo, mut hi) = (0usize, last);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let start = if lo == 0 { 0 } else { ends[lo - 1] };
    let line = String::from_utf8_lossy(&text[start..ends[lo]]);
    let line = line.trim();
    let shown: String = line.chars().take(60).collect();
    let shown = if shown.len() < line.len() {
        format!("{shown}...")
    } else {
        shown
    };
    Some((lo + 1, shown))
}

/// Parses a whole OBJ text.
fn parse(mut text: &[u8]) -> Result<SceneMesh, ObjError> {
    let reader = &mut text;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let no_materials =
        |_: &std::path::Path| -> tobj::MTLLoadResult { Ok((Vec::new(), Default::default())) };
    let (models, _materials) =
        tobj::load_obj_buf(reader, &options, no_materials).map_err(|e| ObjError::Parse {
            path: "<input>".into(),
            reason: e.to_string(),
        })?;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let offset = vertices.len() as u64;
        let count = mesh.positions.len() / 3;
        vertices.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]),
        );
        for t in mesh.indices.chunks_exact(3) {
            let t = [t[0], t[1], t[2]].map(u64::from);
            if t.iter().any(|&i| i >= count as u64) {
                return Err(ObjError::Parse {
                    path: "<input>".into(),
                    reason: format!(
                        "a face of object `{}` refers to a vertex that does not exist",
                        model.name
                    ),
                });
            }
            triangles.push(t.map(|i| i + offset));
        }
    }
    if triangles.is_empty() {
        return Err(ObjError::NoTriangles {
            path: "<input>".into(),
        });
    }
    Ok(SceneMesh {
        name: "mesh".into(),
        vertices,
        triangles,
    })
}

/// How much of a file [`obj_instead_of_trace`] reads.
const OBJ_PROBE_BYTES: u64 = 1 << 16;

/// When the file at `path`, given where a trace is expected, is a
/// Wavefront OBJ file (text whose lines are OBJ statements, with a vertex
/// among them, judged on its first 64 KiB), the error that says so and
/// what to use instead: `level.obj: this is an OBJ file: use `mesh` or
/// `--mesh` (...)`. `None` for anything else, the MCAP magic included.
pub fn obj_instead_of_trace(path: &std::path::Path) -> Option<String> {
    use std::io::Read;
    let mut head = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(OBJ_PROBE_BYTES)
        .read_to_end(&mut head)
        .ok()?;
    if !looks_like_obj(&head) {
        return None;
    }
    let shown = path.display();
    Some(format!(
        "{shown}: this is an OBJ file: use `mesh` or `--mesh` (`sweeptrace mesh {shown}`, \
         `sweeptrace sweep --mesh {shown} --from X,Y,Z --to X,Y,Z`, \
         `sweeptrace record --mesh {shown}` to record a trace over it)"
    ))
}

/// Whether `head`, the start of a file, is OBJ text: every complete line
/// blank, a comment or an OBJ statement, at least one of them a vertex.
fn looks_like_obj(head: &[u8]) -> bool {
    const STATEMENTS: &[&str] = &[
        "v", "vn", "vt", "vp", "f", "l", "p", "o", "g", "s", "mtllib", "usemtl",
    ];
    if head.starts_with(b"\x89MCAP") || head.contains(&0) {
        return false;
    }
    // The last line may be cut by the probe's end: only complete ones.
    let complete = match head.iter().rposition(|&b| b == b'\n') {
        Some(end) if head.len() as u64 >= OBJ_PROBE_BYTES => &head[..end],
        _ => head,
    };
    let Ok(text) = std::str::from_utf8(complete) else {
        return false;
    };
    let mut vertex = false;
    for line in text.lines().map(str::trim) {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let keyword = line.split_whitespace().next().unwrap_or("");
        if !STATEMENTS.contains(&keyword) {
            return false;
        }
        vertex |= keyword == "v";
    }
    vertex
}
