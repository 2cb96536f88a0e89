//! `sweeptrace mesh`: a mesh's topology (edges by class) and defects, from
//! an OBJ file or the scenes of a trace.

use super::NameFileOnce;
use std::fmt::Write as _;
use std::io::Read;
use std::path::PathBuf;

use anyhow::Context;
use serde::Serialize;

use super::Exit;
use sweeptrace::core::topology::{Defect, DefectKind, EdgeClass, EdgeCounts, Topology};
use sweeptrace::numbers::counted;
use sweeptrace::sim::load_obj;
use sweeptrace::trace::{EventBody, TraceReader};

/// How many defects of each kind the text report lists.
const LISTED_PER_KIND: usize = 3;

/// Arguments of `mesh`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Edge classes (by the dihedral angle between the two triangles' front normals):
  boundary      one triangle only (a hole, the rim of an open surface)
  flat          two coplanar triangles (an internal edge: ghost contacts)
  convex        folded away from the fronts (a ridge, the outside of a cube)
  concave       folded toward the fronts (a valley, the inside of a box)
  non_manifold  three or more triangles

Defects that change collisions: flipped, crack, t_junction,
non_manifold_edge, duplicate_triangle. Warnings: degenerate, sliver,
duplicate_vertex. Thresholds: docs/SEMANTICS.md, \"Mesh topology\".

Exit codes: 0 no defect that changes collisions, 1 such a defect found,
2 bad input (a file that is neither an OBJ file nor a trace, a parse error,
an invalid mesh), 3 a trace that ends early (truncated): the scenes read
before the end are reported.

Examples:
  sweeptrace mesh tests/fixtures/scanned/bunny_res4.obj
  sweeptrace mesh traces/record_mini_golf.mcap --json
  sweeptrace mesh --scene mini_golf"
)]
pub struct Args {
    /// A Wavefront OBJ file, or a trace (MCAP) whose every scene is
    /// checked. Told apart by content: a file starting with the MCAP magic
    /// is a trace, anything else is read as OBJ text.
    #[arg(required_unless_present = "scene")]
    pub file: Option<PathBuf>,
    /// A built-in scene instead of a file (as `sweep` and `record` take
    /// it): `cube`, `triangle`, `mini_golf`, `bowl`, `box` or `terrain`.
    #[arg(long, value_enum, conflicts_with = "file")]
    pub scene: Option<sweeptrace::sim::scenes::BuiltinScene>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The report of one mesh.
#[derive(Debug, Serialize)]
pub struct MeshReport {
    /// The scene's name (the OBJ file's stem, or the trace scene's name).
    pub name: String,
    /// Triangles in the input.
    pub triangles: usize,
    /// Vertices in the input.
    pub vertices: usize,
    /// Distinct vertex positions.
    pub welded_vertices: usize,
    /// Edges counted by class.
    pub edges: EdgeCounts,
    /// Connected chains of boundary edges (holes, rims).
    pub boundary_loops: usize,
    /// Every defect.
    pub defects: Vec<Defect>,
}

impl MeshReport {
    fn new(name: String, topology: &Topology) -> MeshReport {
        MeshReport {
            name,
            triangles: topology.triangle_count(),
            vertices: topology.vertex_count(),
            welded_vertices: topology.welded_vertex_count(),
            edges: topology.edge_counts(),
            boundary_loops: topology.boundary_loops(),
            defects: topology.defects().to_vec(),
        }
    }

    fn changes_collisions(&self) -> bool {
        self.defects.iter().any(|d| d.kind.changes_collisions())
    }
}

fn point(p: &[f64; 3]) -> String {
    format!("({}, {}, {})", p[0], p[1], p[2])
}

fn list(items: &[u32]) -> String {
    items
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// What a ball does at `d`, in words.
pub fn defect_line(d: &Defect) -> String {
    let t = |i: usize| d.triangles.get(i).copied().unwrap_or(0);
    let at = point(&d.position);
    match d.kind {
        DefectKind::Flipped => format!(
            "triangle {} at {at}: a ball from the side its neighbours face passes through it: its winding is opposite to that of {} {}",
            t(0),
            match d.neighbours.len() {
                1 => "its neighbour, triangle".to_string(),
                n => format!("its {n} neighbours, triangles"),
            },
            list(&d.neighbours)
        ),
        DefectKind::Crack => format!(
            "between triangles {} and {} at {at} (gap {:.3e}, vertices {}): a ball rolling across meets two boundary edges instead of one shared edge",
            t(0),
            t(1),
            d.gap.unwrap_or(0.0),
            list(&d.vertices)
        ),
        DefectKind::TJunction => format!(
            "vertex {} at {at} on the edge {}-{} of triangle {} (triangles at the vertex: {}): the two sides share no edge, so a ball there hits boundary edges",
            d.vertices.first().copied().unwrap_or(0),
            d.vertices.get(1).copied().unwrap_or(0),
            d.vertices.get(2).copied().unwrap_or(0),
            t(0),
            list(d.triangles.get(1..).unwrap_or(&[]))
        ),
        DefectKind::Degenerate => format!(
            "triangle {} at {at} has no area: left out of every test",
            t(0)
        ),
        DefectKind::Sliver => format!(
            "triangle {} at {at} (altitude {:.3e}): a ball touching it mostly touches its edges, and its normal is poorly determined",
            t(0),
            d.gap.unwrap_or(0.0)
        ),
        DefectKind::DuplicateTriangle => format!(
            "triangle {} repeats triangle {} at {at}: a ball hits both at once and the tie rules pick the lower",
            t(1),
            t(0)
        ),
        DefectKind::DuplicateVertex => format!(
            "vertices {} at {at}, {:.3e} apart and not welded",
            list(&d.vertices),
            d.gap.unwrap_or(0.0)
        ),
        DefectKind::NonManifoldEdge => format!(
            "edge {} at {at} is shared by {} triangles ({}): a ball touching it is tested against all of them",
            list(&d.vertices),
            d.triangles.len(),
            list(&d.triangles)
        ),
    }
}

/// The text report of the meshes of one file.
pub fn render_text(file: &str, reports: &[MeshReport]) -> String {
    use strum::IntoEnumIterator;
    let mut out = String::new();
    for r in reports {
        let _ = writeln!(
            out,
            "mesh `{}` ({file}): {}, {} ({})",
            sweeptrace::error_text::escaped(&r.name),
            counted(r.triangles as u64, "triangle", "triangles"),
            counted(r.vertices as u64, "vertex", "vertices"),
            counted(
                r.welded_vertices as u64,
                "distinct position",
                "distinct positions"
            )
        );
        let classes: Vec<String> = EdgeClass::iter()
            .map(|c| format!("{} {}", r.edges.of(c), c.as_str()))
            .collect();
        let _ = writeln!(
            out,
            "  edges: {} ({}); {}",
            r.edges.total(),
            classes.join(", "),
            counted(r.boundary_loops as u64, "boundary loop", "boundary loops")
        );
        for kind in DefectKind::iter() {
            let of_kind: Vec<&Defect> = r.defects.iter().filter(|d| d.kind == kind).collect();
            if of_kind.is_empty() {
                continue;
            }
            let _ = writeln!(
                out,
                "  {} {}{}:",
                of_kind.len(),
                kind.as_str(),
                if kind.changes_collisions() {
                    ""
                } else {
                    " (warning)"
                }
            );
            for d in of_kind.iter().take(LISTED_PER_KIND) {
                let _ = writeln!(out, "    {}", defect_line(d));
            }
            if of_kind.len() > LISTED_PER_KIND {
                let _ = writeln!(out, "    ... and {} more", of_kind.len() - LISTED_PER_KIND);
            }
        }
        let serious = r
            .defects
            .iter()
            .filter(|d| d.kind.changes_collisions())
            .count();
        let warnings = r.defects.len() - serious;
        let _ = writeln!(
            out,
            "  verdict: {}",
            if serious > 0 {
                format!(
                    "{} that {} collisions, {}",
                    counted(serious as u64, "defect", "defects"),
                    sweeptrace::numbers::verb(serious as u64, "changes", "change"),
                    counted(warnings as u64, "warning", "warnings")
                )
            } else if warnings > 0 {
                format!(
                    "no defect that changes collisions, {}",
                    counted(warnings as u64, "warning", "warnings")
                )
            } else {
                "clean".to_string()
            }
        );
    }
    out
}

/// The JSON report: `{"file", "meshes": [...]}`, each mesh with `edges`
/// and `defects`.
pub fn render_json(file: &str, reports: &[MeshReport]) -> String {
    #[derive(Serialize)]
    struct Json<'a> {
        file: &'a str,
        meshes: &'a [MeshReport],
    }
    serde_json::to_string_pretty(&Json {
        file,
        meshes: reports,
    })
    .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}

const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Reads the file's meshes and prints the report.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let path = match (&args.file, args.scene) {
        (Some(path), _) => path.clone(),
        (None, Some(scene)) => {
            let scene = scene.mesh();
            let name = format!("the built-in scene `{}`", scene.name);
            let topology = Topology::new(&scene.vertices, &scene.triangles)
                .with_context(|| format!("{name}: the mesh"))?;
            return finish(
                &args,
                &name,
                &[MeshReport::new(scene.name, &topology)],
                None,
            );
        }
        (None, None) => anyhow::bail!("`mesh` needs a file (OBJ or trace) or --scene NAME"),
    };
    let name = path.display().to_string();
    let mut head = [0u8; 8];
    let n = {
        let mut f = super::open_input(&path)?;
        let mut n = 0;
        while n < head.len() {
            let k = f
                .read(&mut head[n..])
                .with_context(|| format!("cannot read {name}"))?;
            if k == 0 {
                break;
            }
            n += k;
        }
        n
    };
    let mut reports = Vec::new();
    let mut truncated = None;
    if head[..n] == *MCAP_MAGIC {
        let file = super::open_input(&path)?;
        let reader = TraceReader::new_indexed(std::io::BufReader::new(file), &name);
        for event in reader {
            let event = match event {
                Ok(event) => event,
                // The scenes before the end are still checked: exit 3.
                Err(err) if err.is_truncation() => {
                    truncated = Some(err);
                    break;
                }
                Err(err) => return Err(err).name_file_once("reading the trace", &name),
            };
            if let EventBody::Scene(scene) = event.body {
                let index = event.header.index;
                let topology = Topology::new(&scene.vertices, &scene.triangles)
                    .with_context(|| format!("{name}: the scene of message {index}"))?;
                let shown = scene.name.unwrap_or_else(|| format!("scene {index}"));
                reports.push(MeshReport::new(shown, &topology));
            }
        }
        if let Some(err) = truncated.as_ref().filter(|_| reports.is_empty()) {
            eprintln!("error: {err}\n0 scenes read before the end: no mesh to check");
            return Ok(Exit::IncompleteInput);
        }
        if reports.is_empty() {
            anyhow::bail!("{name} is a trace without any /scene message: no mesh to check");
        }
    } else {
        let scene = load_obj(&path).map_err(|e| {
            anyhow::anyhow!("{e} (`mesh` reads a Wavefront OBJ file or an MCAP trace)")
        })?;
        let topology = Topology::new(&scene.vertices, &scene.triangles)
            .with_context(|| format!("{name}: the mesh"))?;
        reports.push(MeshReport::new(scene.name, &topology));
    }
    finish(&args, &name, &reports, truncated)
}

/// Prints the reports of `name` and says how the run ends: 3 when the
/// trace was `truncated`, 1 when a mesh has a defect that changes
/// collisions.
fn finish(
    args: &Args,
    name: &str,
    reports: &[MeshReport],
    truncated: Option<sweeptrace::trace::TraceError>,
) -> anyhow::Result<Exit> {
    let report = if args.json {
        render_json(name, reports)
    } else {
        render_text(name, reports)
    };
    print!("{report}");
    if args.json {
        println!();
    }
    if let Some(err) = truncated {
        eprintln!(
            "error: {err}\nthe report covers the {} read before the end",
            sweeptrace::numbers::counted(reports.len() as u64, "scene", "scenes")
        );
        return Ok(Exit::IncompleteInput);
    }
    Ok(if reports.iter().any(MeshReport::changes_collisions) {
        Exit::Differences
    } else {
        Exit::Success
    })
}
