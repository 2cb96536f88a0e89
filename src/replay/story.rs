//! One sweep explained ([`explain_sweep`]): everything the `sweep` command
//! tells about a sweep, computed here so that a library user gets the same
//! story the command renders.

use crate::conventions::NormalRule;
use crate::core::crossing::{Crossing, all_crossings};
use crate::core::record::{CollectRecords, TestRecord};
use crate::core::topology::{EdgeClass, Topology};
use crate::core::{
    Broadphase, Feature, Mesh, Options, Outcome, Sweep, SweepError, sweep_mesh_with,
};

use super::ghost::GhostContact;
use super::normals::SceneNormals;
use super::replayer::{SweepResult, feature_class};
use super::tunnel::{
    Through, Tunnel, TunnelScene, defects_within_reach, sweep_end, tunnel_during_sweep,
};

/// Where an edge or vertex hit is in the mesh's topology ([`hit_place`]).
#[derive(Clone, Debug, PartialEq)]
pub struct HitPlace {
    /// The class of the edge (or the vertex, [`feature_class`]).
    pub class: EdgeClass,
    /// In words: `edge 17.2: an internal flat edge shared with triangle 18`.
    pub text: String,
}

/// The place of `outcome`'s edge or vertex hit in `topology`; `None` for a
/// face hit, a miss, or a feature the topology does not have.
pub fn hit_place(topology: &Topology, outcome: &Outcome) -> Option<HitPlace> {
    let hit = outcome.hit.as_ref()?;
    let (triangle, feature) = (hit.triangle, hit.feature);
    let class = feature_class(topology, triangle, feature)?;
    let text = match feature {
        Feature::Face => return None,
        Feature::Edge(i) => {
            let edge = topology.triangle_edge(triangle, i)?;
            let other = edge.triangles().find(|&t| t != triangle);
            let shared = other.map_or(String::new(), |o| format!(" shared with triangle {o}"));
            let what = match class {
                EdgeClass::Boundary => "a boundary edge (no other triangle has it)".to_string(),
                EdgeClass::Flat => format!("an internal flat edge{shared}"),
                EdgeClass::Convex => format!("a convex edge{shared}"),
                EdgeClass::Concave => format!("a concave edge{shared}"),
                EdgeClass::NonManifold => {
                    "a non-manifold edge (three or more triangles have it)".to_string()
                }
            };
            format!("edge {triangle}.{i}: {what}")
        }
        Feature::Vertex(i) => {
            let v = topology.triangle_vertex(triangle, i)?;
            let edges = topology.edges_at(v).count();
            format!(
                "vertex {triangle}.{i} (mesh vertex {v}): a {class} vertex (the most telling class of its {})",
                crate::numbers::counted(edges as u64, "edge", "edges")
            )
        }
    };
    Some(HitPlace { class, text })
}

/// One sweep's whole story ([`explain_sweep`]).
#[derive(Clone, Debug)]
pub struct SweepStory {
    /// The core's outcome, with the normal the conventions report.
    pub outcome: Outcome,
    /// Every test's record (every triangle tested: no broad phase).
    pub records: Vec<TestRecord>,
    /// For an edge or vertex hit, its place in the mesh's topology.
    pub place: Option<HitPlace>,
    /// Where the ball's centre went through a triangle front to back (or a
    /// flipped one back to front), as `check` and `replay` find it: from a
    /// replayed trace, since the ball's previous sweep too.
    pub tunnels: Vec<Tunnel>,
    /// The defects within `ρ` of the centre's path, nearest first.
    pub within_reach: Vec<Through>,
    /// How many defects the mesh has (`None` without a topology).
    pub defects: Option<usize>,
    /// The trace's expectation as a ghost contact, when it is one (from a
    /// replayed trace).
    pub ghost: Option<GhostContact>,
    /// The triangles the centre's path passes through, either way, up to
    /// where the outcome stops it.
    pub crossings: Vec<Crossing>,
}

/// Explains `sweep` against `mesh`: every test run and recorded, the
/// outcome with the normal `normal` reports, where an edge or vertex hit
/// lies in `topology`, the tunnels, the defects within reach and the
/// triangles the centre's path crosses. `replayed`: the same sweep as a
/// replay of its trace gave it (its tunnels include one since the ball's
/// previous sweep, and its expectation may be a ghost contact); without
/// it, the tunnels of this sweep alone. Without a topology (a mesh whose
/// edges cannot be classified) there is no place, tunnel or defect.
///
/// The error is the core's, for an invalid sweep.
pub fn explain_sweep(
    mesh: &Mesh,
    topology: Option<&Topology>,
    sweep: &Sweep,
    options: &Options,
    normal: NormalRule,
    replayed: Option<&SweepResult>,
) -> Result<SweepStory, SweepError> {
    let mut records = CollectRecords::default();
    let outcome = sweep_mesh_with(mesh, sweep, options, Broadphase::Exhaustive, &mut records)?;
    let outcome = match topology {
        Some(t) if normal != NormalRule::Face => {
            SceneNormals::new(normal, mesh, t).apply(sweep, outcome)
        }
        _ => outcome,
    };
    let tunnel_scene = topology.map(|topology| TunnelScene {
        mesh,
        topology,
        rho: sweep.radius - options.margin,
    });
    let tunnels = match (replayed, &tunnel_scene) {
        (Some(r), _) => r.tunnels.clone(),
        (None, Some(scene)) => tunnel_during_sweep(scene, sweep, &outcome)
            .into_iter()
            .collect(),
        (None, None) => Vec::new(),
    };
    let within_reach = tunnel_scene
        .as_ref()
        .map(|scene| defects_within_reach(scene, sweep, &outcome))
        .unwrap_or_default();
    Ok(SweepStory {
        place: topology.and_then(|t| hit_place(t, &outcome)),
        crossings: all_crossings(mesh, &sweep.p0, &sweep_end(sweep, &outcome)),
        ghost: replayed.and_then(SweepResult::ghost),
        defects: topology.map(|t| t.defects().len()),
        tunnels,
        within_reach,
        records: records.records,
        outcome,
    })
}
