//! Mesh topology: which triangles share each edge, what kind of edge it is,
//! and the defects that change what a ball does there (see SEMANTICS.md,
//! "Mesh topology", for every rule and threshold).
//!
//! [`Topology::new`] takes the same input as [`Mesh::new`](super::Mesh::new)
//! (vertices and vertex-index triples) and builds, in one pass of sorting
//! and hashing:
//! - the *weld*: vertices at exactly the same position are one vertex;
//! - the undirected edges between welded vertices, each with its triangles
//!   and its [`EdgeClass`];
//! - the [`Defect`]s: flipped windings, cracks, T-junctions, degenerate and
//!   sliver triangles, duplicate triangles, near-coincident vertices and
//!   non-manifold edges.
//!
//! Near-coincidence (cracks, T-junctions, duplicate vertices) is looked up
//! in spatial hash grids, so the build is near-linear in the mesh's size.
//! The core has no I/O: rendering a report is the command line's business.

use nalgebra::{Point3, Vector3};

use super::error::MeshError;
use super::options::GRAZING_COSINE;

mod defects;
mod distance;
mod edges;
#[cfg(test)]
mod tests;

pub use defects::{Defect, DefectKind};
pub use edges::{Edge, EdgeClass, EdgeCounts};

/// Two triangles sharing an edge are coplanar (the edge is `flat`) when the
/// sine of the angle between their front normals (oriented consistently) is
/// at most this, and the normals point the same way. A ball resting on one
/// of them meets the other at an approach cosine of that sine, which the core
/// already calls grazing ([`GRAZING_COSINE`]): below it the two planes are
/// one plane at the resolution the core decides at.
pub const FLAT_DIHEDRAL_SINE: f64 = GRAZING_COSINE;

/// A usable triangle is a *sliver* when its altitude over its longest edge
/// is below this fraction of that edge (`|(b−a)×(c−a)| < SLIVER_RATIO ·
/// longest²`): its front normal then moves by about `1 / SLIVER_RATIO`
/// times the rounding of its vertices, and a ball touching it touches its
/// edges far more often than its face.
pub const SLIVER_RATIO: f64 = 1e-3;

/// Two points are *near-coincident* (cracks, T-junctions, duplicate
/// vertices) when they are at most `NEAR_FRACTION` times the mesh's median
/// edge length apart (and not at exactly the same position): far below any
/// feature the mesh models on purpose, far above the rounding of a file's
/// coordinates (an `f32` OBJ file is off by about `6e-8` of its extent).
pub const NEAR_FRACTION: f64 = 1e-3;

/// A mesh's topology: its weld, edges by class and defects.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Topology {
    triangle_count: usize,
    vertex_count: usize,
    welded_vertex_count: usize,
    /// Input vertex → its welded vertex (the lowest index at its position).
    weld: Vec<u32>,
    edges: Vec<Edge>,
    counts: EdgeCounts,
    boundary_loops: usize,
    defects: Vec<Defect>,
    /// Input indices of the flipped triangles, ascending.
    flipped: Vec<u32>,
    near_distance: f64,
    /// Per input triangle, its welded corners.
    corners: Vec<[u32; 3]>,
    /// Per welded vertex `v`, its edges are
    /// `vertex_edges[vertex_edge_start[v]..vertex_edge_start[v + 1]]`
    /// (indices into `edges`).
    vertex_edge_start: Vec<u32>,
    vertex_edges: Vec<u32>,
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2])
}

impl Topology {
    /// Builds the topology of the mesh `vertices`, `triangles` (the input of
    /// [`Mesh::new`](super::Mesh::new), with the same errors for a
    /// non-finite coordinate or an index out of range).
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u64; 3]]) -> Result<Topology, MeshError> {
        if vertices.len() >= u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "vertex count",
                limit: u32::MAX as usize - 1,
            });
        }
        if triangles.len() >= u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "triangle count",
                limit: u32::MAX as usize - 1,
            });
        }
        for (i, v) in vertices.iter().enumerate() {
            if !v.iter().all(|c| c.is_finite()) {
                return Err(MeshError::NonFiniteVertex {
                    vertex: i,
                    coordinate: *v,
                });
            }
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i >= vertices.len() as u64) {
                return Err(MeshError::IndexOutOfRange {
                    triangle: t,
                    index,
                    vertex_count: vertices.len(),
                });
            }
        }
        Ok(Builder::new(vertices, triangles).build())
    }

    /// Number of triangles in the input (degenerate ones included).
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Number of vertices in the input.
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Number of distinct vertex positions (after welding).
    pub fn welded_vertex_count(&self) -> usize {
        self.welded_vertex_count
    }

    /// The welded vertex of input vertex `v` (the lowest input index at its
    /// position).
    pub fn welded(&self, v: u32) -> Option<u32> {
        self.weld.get(v as usize).copied()
    }

    /// Every undirected edge between welded vertices, sorted by its
    /// vertices.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Edges counted by class.
    pub fn edge_counts(&self) -> EdgeCounts {
        self.counts
    }

    /// Number of connected chains of boundary edges (a closed mesh has 0,
    /// a hole in it adds one, an open sheet has at least 1).
    pub fn boundary_loops(&self) -> usize {
        self.boundary_loops
    }

    /// Every defect, by kind (in [`DefectKind`]'s order), then by triangle.
    pub fn defects(&self) -> &[Defect] {
        &self.defects
    }

    /// Input indices of the flipped triangles, ascending.
    pub fn flipped(&self) -> &[u32] {
        &self.flipped
    }

    /// Whether a defect that changes collisions was found.
    pub fn changes_collisions(&self) -> bool {
        self.defects.iter().any(|d| d.kind.changes_collisions())
    }

    /// The distance below which two points are near-coincident
    /// ([`NEAR_FRACTION`] times the median edge length).
    pub fn near_distance(&self) -> f64 {
        self.near_distance
    }

    /// The defect nearest `point` within `radius` (`vertices`: the mesh's
    /// positions), preferring one that changes collisions; `None` when no
    /// defect lies that close.
    pub fn defect_near(
        &self,
        vertices: &[Point3<f64>],
        point: &Point3<f64>,
        radius: f64,
    ) -> Option<(usize, &Defect)> {
        let mut best: Option<(bool, f64, usize)> = None;
        for (i, d) in self.defects.iter().enumerate() {
            let distance = d.distance(vertices, point);
            if distance.is_nan() || distance > radius {
                continue;
            }
            let rank = (!d.kind.changes_collisions(), distance, i);
            if best.is_none_or(|b| rank.partial_cmp(&b) == Some(std::cmp::Ordering::Less)) {
                best = Some(rank);
            }
        }
        best.map(|(_, _, i)| (i, &self.defects[i]))
    }

    /// The defects within `radius` of the segment `p q` (a ball centre's
    /// path, `radius` its detection radius: what the ball reaches on its
    /// way), each with its distance, nearest first (those that change
    /// collisions first at the same distance, then in [`Topology::defects`]'
    /// order).
    pub fn defects_along(
        &self,
        vertices: &[Point3<f64>],
        p: &Point3<f64>,
        q: &Point3<f64>,
        radius: f64,
    ) -> Vec<(&Defect, f64)> {
        let mut near: Vec<(usize, f64)> = self
            .defects
            .iter()
            .enumerate()
            .map(|(i, d)| (i, d.distance_to_segment(vertices, p, q)))
            .filter(|&(_, distance)| distance <= radius)
            .collect();
        near.sort_by(|a, b| {
            let ka = !self.defects[a.0].kind.changes_collisions();
            let kb = !self.defects[b.0].kind.changes_collisions();
            a.1.total_cmp(&b.1).then(ka.cmp(&kb)).then(a.0.cmp(&b.0))
        });
        near.into_iter()
            .map(|(i, distance)| (&self.defects[i], distance))
            .collect()
    }

    /// The edge between input vertices `a` and `b` (after welding), if
    /// some usable triangle has it.
    pub fn edge_between(&self, a: u32, b: u32) -> Option<&Edge> {
        let (a, b) = (self.welded(a)?, self.welded(b)?);
        let key = if a < b { [a, b] } else { [b, a] };
        self.edges
            .binary_search_by(|e| e.vertices.cmp(&key))
            .ok()
            .map(|i| &self.edges[i])
    }

    /// Edge `feature` of input triangle `triangle` (the edge joining its
    /// vertices `feature` and `(feature + 1) mod 3`, SEMANTICS.md's
    /// numbering); `None` for a feature above 2, a triangle out of range,
    /// or a triangle left out of the adjacency (degenerate, duplicate).
    pub fn triangle_edge(&self, triangle: u32, feature: u8) -> Option<&Edge> {
        let c = self.corners.get(triangle as usize)?;
        let f = usize::from(feature);
        if f > 2 {
            return None;
        }
        let edge = self.edge_between(c[f], c[(f + 1) % 3])?;
        edge.triangles().any(|t| t == triangle).then_some(edge)
    }

    /// The class of edge `feature` of input triangle `triangle` (see
    /// [`Topology::triangle_edge`]).
    pub fn triangle_edge_class(&self, triangle: u32, feature: u8) -> Option<EdgeClass> {
        self.triangle_edge(triangle, feature).map(|e| e.class)
    }

    /// The welded vertex `feature` (0..2) of input triangle `triangle`.
    pub fn triangle_vertex(&self, triangle: u32, feature: u8) -> Option<u32> {
        self.corners
            .get(triangle as usize)?
            .get(usize::from(feature))
            .copied()
    }

    /// The edges at input vertex `v` (after welding), in the order of
    /// [`Topology::edges`].
    pub fn edges_at(&self, v: u32) -> impl Iterator<Item = &Edge> + '_ {
        let range = self
            .welded(v)
            .and_then(|w| {
                let lo = *self.vertex_edge_start.get(w as usize)? as usize;
                let hi = *self.vertex_edge_start.get(w as usize + 1)? as usize;
                Some(lo..hi)
            })
            .unwrap_or(0..0);
        self.vertex_edges[range]
            .iter()
            .map(|&e| &self.edges[e as usize])
    }

    /// Whether input vertex `v` is inside a smooth or hollow part of the
    /// mesh: it has edges and every one of them is [`EdgeClass::Flat`] or
    /// [`EdgeClass::Concave`] (no boundary, ridge or non-manifold edge
    /// meets it).
    pub fn vertex_is_flat_or_concave(&self, v: u32) -> bool {
        let mut edges = self.edges_at(v).peekable();
        edges.peek().is_some()
            && edges.all(|e| matches!(e.class, EdgeClass::Flat | EdgeClass::Concave))
    }

    /// Bytes the topology holds on the heap (the capacities of its vectors).
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.weld.capacity() * size_of::<u32>()
            + self.corners.capacity() * size_of::<[u32; 3]>()
            + (self.vertex_edge_start.capacity() + self.vertex_edges.capacity()) * size_of::<u32>()
            + self.edges.capacity() * size_of::<Edge>()
            + self.flipped.capacity() * size_of::<u32>()
            + self.defects.capacity() * size_of::<Defect>()
            + self
                .defects
                .iter()
                .map(|d| {
                    (d.triangles.capacity() + d.vertices.capacity() + d.neighbours.capacity())
                        * size_of::<u32>()
                })
                .sum::<usize>()
    }
}

/// The state of one build.
struct Builder<'a> {
    vertices: &'a [[f64; 3]],
    triangles: &'a [[u64; 3]],
    weld: Vec<u32>,
    welded_vertex_count: usize,
    /// Per input triangle: usable in the adjacency (not degenerate, not a
    /// duplicate).
    usable: Vec<bool>,
    defects: Vec<Defect>,
}

impl<'a> Builder<'a> {
    fn new(vertices: &'a [[f64; 3]], triangles: &'a [[u64; 3]]) -> Builder<'a> {
        Builder {
            vertices,
            triangles,
            weld: Vec::new(),
            welded_vertex_count: 0,
            usable: Vec::new(),
            defects: Vec::new(),
        }
    }

    fn tri(&self, t: u32) -> [u32; 3] {
        self.triangles[t as usize].map(|i| i as u32)
    }

    fn welded_tri(&self, t: u32) -> [u32; 3] {
        self.tri(t).map(|i| self.weld[i as usize])
    }

    fn position(&self, v: u32) -> &[f64; 3] {
        &self.vertices[v as usize]
    }

    fn centroid(&self, t: u32) -> [f64; 3] {
        let [a, b, c] = self.tri(t).map(|i| *self.position(i));
        [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
    }

    fn midpoint(&self, a: u32, b: u32) -> [f64; 3] {
        let (a, b) = (self.position(a), self.position(b));
        [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))
    }

    /// `(b - a) × (c - a)` of triangle `t`.
    fn cross(&self, t: u32) -> Vector3<f64> {
        let [a, b, c] = self.tri(t).map(|i| *self.position(i));
        sub(&b, &a).cross(&sub(&c, &a))
    }
}
