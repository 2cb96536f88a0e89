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

use std::collections::{HashMap, HashSet};

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::error::MeshError;
use super::options::{DEGENERATE_TOLERANCE, GRAZING_COSINE};

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

/// No triangle in this slot.
const NONE: u32 = u32::MAX;

/// What kind of edge an undirected edge is.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumIter,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum EdgeClass {
    /// One triangle only: the mesh ends here (a hole, or the rim of an open
    /// surface).
    Boundary,
    /// Two triangles folded away from their fronts (a ridge seen from the
    /// front, the outside of a cube).
    Convex,
    /// Two triangles in one plane, within [`FLAT_DIHEDRAL_SINE`]: an internal
    /// edge, where an engine reporting the geometric contact normal bumps a
    /// rolling ball ("ghost contact").
    Flat,
    /// Two triangles folded toward their fronts (a valley seen from the
    /// front, the inside of a box).
    Concave,
    /// Three or more triangles.
    NonManifold,
}

impl EdgeClass {
    /// `boundary`, `convex`, `flat`, `concave` or `non_manifold`.
    pub fn as_str(self) -> &'static str {
        self.into()
    }
}

/// Edges counted by class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct EdgeCounts {
    /// [`EdgeClass::Boundary`] edges.
    pub boundary: u64,
    /// [`EdgeClass::Convex`] edges.
    pub convex: u64,
    /// [`EdgeClass::Flat`] edges.
    pub flat: u64,
    /// [`EdgeClass::Concave`] edges.
    pub concave: u64,
    /// [`EdgeClass::NonManifold`] edges.
    pub non_manifold: u64,
}

impl EdgeCounts {
    fn add(&mut self, class: EdgeClass) {
        *match class {
            EdgeClass::Boundary => &mut self.boundary,
            EdgeClass::Convex => &mut self.convex,
            EdgeClass::Flat => &mut self.flat,
            EdgeClass::Concave => &mut self.concave,
            EdgeClass::NonManifold => &mut self.non_manifold,
        } += 1;
    }

    /// Every edge.
    pub fn total(&self) -> u64 {
        self.boundary + self.convex + self.flat + self.concave + self.non_manifold
    }

    /// The count of `class`.
    pub fn of(&self, class: EdgeClass) -> u64 {
        match class {
            EdgeClass::Boundary => self.boundary,
            EdgeClass::Convex => self.convex,
            EdgeClass::Flat => self.flat,
            EdgeClass::Concave => self.concave,
            EdgeClass::NonManifold => self.non_manifold,
        }
    }
}

/// One undirected edge between two welded vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// Its welded vertices (the lowest input index at each position), lower
    /// first.
    pub vertices: [u32; 2],
    /// Input indices of its first two triangles (the second is
    /// `u32::MAX` for a boundary edge; a non-manifold edge lists all of
    /// its triangles in its [`DefectKind::NonManifoldEdge`] defect).
    pub triangles: [u32; 2],
    /// Its class.
    pub class: EdgeClass,
}

impl Edge {
    /// The triangles of the edge (one or two; the first two of a
    /// non-manifold edge).
    pub fn triangles(&self) -> impl Iterator<Item = u32> + '_ {
        self.triangles.iter().copied().filter(|&t| t != NONE)
    }
}

/// What is wrong.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumIter,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum DefectKind {
    /// Wound against its neighbours (a shared edge traversed in the same
    /// direction by both): its front faces the wrong way, so a one-sided
    /// test lets a ball through it from the side its neighbours face.
    Flipped,
    /// Two boundary edges that nearly coincide (an unwelded seam or a
    /// hairline gap): a ball rolling across meets two edges instead of a
    /// face.
    Crack,
    /// A vertex on the interior of another triangle's boundary edge: the
    /// two sides do not share that edge, so it is tested as two boundaries.
    TJunction,
    /// No area (a repeated index or collinear vertices): left out of every
    /// test.
    Degenerate,
    /// Altitude tiny against the longest edge ([`SLIVER_RATIO`]).
    Sliver,
    /// The same three vertices as an earlier triangle, with the same
    /// winding: the two are always hit together and the tie rules pick one.
    DuplicateTriangle,
    /// Two vertices near-coincident but not at the same position (and not
    /// already part of a crack or joined by an edge).
    DuplicateVertex,
    /// An edge shared by three or more triangles.
    NonManifoldEdge,
}

impl DefectKind {
    /// The defect's name (`flipped`, `t_junction`, ...).
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// Whether it changes what the collision tests report (flipped, crack,
    /// T-junction, non-manifold edge, duplicate triangle); the others are
    /// warnings.
    pub fn changes_collisions(self) -> bool {
        matches!(
            self,
            DefectKind::Flipped
                | DefectKind::Crack
                | DefectKind::TJunction
                | DefectKind::NonManifoldEdge
                | DefectKind::DuplicateTriangle
        )
    }
}

/// One defect of a mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Defect {
    /// What is wrong.
    pub kind: DefectKind,
    /// Input indices of the triangles involved: the flipped, degenerate or
    /// sliver triangle; both triangles of a crack (the first edge's, then
    /// the second's) or of a duplicate pair (the earlier first); the
    /// triangle whose edge the T-junction's vertex lies on, then the
    /// triangles at that vertex; every triangle of a non-manifold edge; the
    /// triangles at duplicate vertices (at most a few).
    pub triangles: Vec<u32>,
    /// Input indices of the vertices involved: a triangle's three; a
    /// crack's two edges (`a0, b0, a1, b1`, matched ends in order); a
    /// T-junction's vertex, then the edge's two ends; a non-manifold
    /// edge's two ends; the two duplicate vertices.
    pub vertices: Vec<u32>,
    /// Where it is: a triangle's centroid, the middle of a crack's first
    /// edge or of a non-manifold edge, the T-junction's vertex, the middle
    /// of two duplicate vertices.
    pub position: [f64; 3],
    /// Flipped: the neighbours whose winding it contradicts.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub neighbours: Vec<u32>,
    /// The distance that made it a defect: a crack's or duplicate vertex's
    /// largest gap, a T-junction's vertex from the edge, a sliver's
    /// altitude over its longest edge.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
}

impl Defect {
    /// Distance from `point` to the defect's place: its triangles (flipped,
    /// degenerate, sliver, duplicate triangle), its edges (crack,
    /// non-manifold edge, the T-junction's edge) or its vertices
    /// (duplicate vertex). `vertices` are the mesh's positions.
    pub fn distance(&self, vertices: &[Point3<f64>], point: &Point3<f64>) -> f64 {
        let at = |i: u32| vertices.get(i as usize).copied();
        let v = &self.vertices;
        let mut best = f64::INFINITY;
        match self.kind {
            DefectKind::Flipped
            | DefectKind::Degenerate
            | DefectKind::Sliver
            | DefectKind::DuplicateTriangle => {
                for t in v.chunks_exact(3) {
                    if let (Some(a), Some(b), Some(c)) = (at(t[0]), at(t[1]), at(t[2])) {
                        best = best.min(point_triangle_distance(point, &a, &b, &c));
                    }
                }
            }
            DefectKind::Crack => {
                for e in v.chunks_exact(2) {
                    if let (Some(a), Some(b)) = (at(e[0]), at(e[1])) {
                        best = best.min(point_segment_distance(point, &a, &b));
                    }
                }
            }
            DefectKind::TJunction => {
                if let (Some(a), Some(b)) = (at(v[1]), at(v[2])) {
                    best = point_segment_distance(point, &a, &b);
                }
            }
            DefectKind::NonManifoldEdge => {
                if let (Some(a), Some(b)) = (at(v[0]), at(v[1])) {
                    best = point_segment_distance(point, &a, &b);
                }
            }
            DefectKind::DuplicateVertex => {
                for &i in v {
                    if let Some(p) = at(i) {
                        best = best.min((p - point).norm());
                    }
                }
            }
        }
        best
    }
}

/// An input index of a defect's list, `?` where the list is shorter than
/// its kind promises (never, for a defect [`Topology::new`] found).
struct Index(Option<u32>);

impl std::fmt::Display for Index {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(i) => write!(f, "{i}"),
            None => f.write_str("?"),
        }
    }
}

/// The defect in a few words, naming its triangles or vertices by input
/// index: `flipped triangle 812`, `crack between triangles 40 and 41`.
impl std::fmt::Display for Defect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t = |i: usize| Index(self.triangles.get(i).copied());
        let v = |i: usize| Index(self.vertices.get(i).copied());
        match self.kind {
            DefectKind::Flipped => write!(f, "flipped triangle {}", t(0)),
            DefectKind::Crack => write!(f, "crack between triangles {} and {}", t(0), t(1)),
            DefectKind::TJunction => write!(
                f,
                "T-junction: vertex {} on an edge of triangle {}",
                v(0),
                t(0)
            ),
            DefectKind::Degenerate => write!(f, "degenerate triangle {}", t(0)),
            DefectKind::Sliver => write!(f, "sliver triangle {}", t(0)),
            DefectKind::DuplicateTriangle => {
                write!(f, "triangle {} duplicates triangle {}", t(1), t(0))
            }
            DefectKind::DuplicateVertex => {
                write!(f, "vertices {} and {} nearly coincide", v(0), v(1))
            }
            DefectKind::NonManifoldEdge => write!(
                f,
                "edge {}-{} shared by {} triangles",
                v(0),
                v(1),
                self.triangles.len()
            ),
        }
    }
}

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

fn position_key(p: &[f64; 3]) -> [u64; 3] {
    // `+ 0.0` turns -0.0 into +0.0, so both weld.
    p.map(|c| (c + 0.0).to_bits())
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2])
}

/// Closest distance from `p` to the segment `a b`.
pub(crate) fn point_segment_distance(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).norm()
}

/// Closest distance from `p` to the triangle `a b c` (its edges when it has
/// no area).
fn point_triangle_distance(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> f64 {
    let edges = point_segment_distance(p, a, b)
        .min(point_segment_distance(p, b, c))
        .min(point_segment_distance(p, c, a));
    let cross = (b - a).cross(&(c - a));
    let area2 = cross.norm();
    if area2.is_nan() || area2 <= 0.0 {
        return edges;
    }
    let n = cross / area2;
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(u, v)| n.dot(&(*v - *u).cross(&(p - *u))) >= 0.0);
    if inside {
        n.dot(&(p - a)).abs().min(edges)
    } else {
        edges
    }
}

/// Union-find over triangles with the parity of their windings: two
/// triangles across a manifold edge traversed in opposite directions have
/// the same parity, in the same direction opposite parities.
struct ParityForest {
    parent: Vec<u32>,
    parity: Vec<u8>,
    size: Vec<u32>,
}

impl ParityForest {
    fn new(n: usize) -> ParityForest {
        ParityForest {
            parent: (0..n as u32).collect(),
            parity: vec![0; n],
            size: vec![1; n],
        }
    }

    fn find(&mut self, x: u32) -> (u32, u8) {
        let mut root = x;
        let mut p = 0u8;
        while self.parent[root as usize] != root {
            p ^= self.parity[root as usize];
            root = self.parent[root as usize];
        }
        // Path compression, each node's parity now relative to the root.
        let (mut y, mut py) = (x, p);
        while self.parent[y as usize] != y {
            let next = self.parent[y as usize];
            let pn = py ^ self.parity[y as usize];
            self.parent[y as usize] = root;
            self.parity[y as usize] = py;
            y = next;
            py = pn;
        }
        (root, p)
    }

    fn union(&mut self, a: u32, b: u32, relation: u8) {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra == rb {
            // A non-orientable component: the first assignment stays.
            return;
        }
        let (big, small) = if self.size[ra as usize] >= self.size[rb as usize] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        self.parent[small as usize] = big;
        self.parity[small as usize] = pa ^ pb ^ relation;
        self.size[big as usize] += self.size[small as usize];
    }
}

/// A hash grid of cell size `cell` over points (the keys of the cells).
fn cell_of(p: &[f64; 3], origin: &[f64; 3], cell: f64) -> [i64; 3] {
    [0, 1, 2].map(|k| ((p[k] - origin[k]) / cell).floor() as i64)
}

/// The ranges of equal keys in sorted half-edges.
fn runs(half: &[(u64, u32, u8)]) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let mut start = 0;
    std::iter::from_fn(move || {
        if start >= half.len() {
            return None;
        }
        let mut end = start + 1;
        while end < half.len() && half[end].0 == half[start].0 {
            end += 1;
        }
        let run = start..end;
        start = end;
        Some(run)
    })
}

/// The ends of a boundary edge, with the triangle it belongs to.
#[derive(Clone, Copy)]
struct BoundaryEdge {
    /// Input vertex indices, in the triangle's direction.
    ends: [u32; 2],
    triangle: u32,
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

    fn weld(&mut self) {
        let mut order: Vec<u32> = (0..self.vertices.len() as u32).collect();
        order.sort_unstable_by_key(|&i| (position_key(&self.vertices[i as usize]), i));
        self.weld = vec![0; self.vertices.len()];
        let mut start = 0;
        while start < order.len() {
            let key = position_key(&self.vertices[order[start] as usize]);
            let mut end = start + 1;
            while end < order.len() && position_key(&self.vertices[order[end] as usize]) == key {
                end += 1;
            }
            for &i in &order[start..end] {
                self.weld[i as usize] = order[start];
            }
            self.welded_vertex_count += 1;
            start = end;
        }
    }

    /// Degenerate and sliver triangles (same rule as the mesh), then
    /// duplicates; marks what the adjacency uses.
    fn triangles_alone(&mut self) {
        let n = self.triangles.len();
        self.usable = vec![true; n];
        for t in 0..n as u32 {
            let idx = self.tri(t);
            let repeated = idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2];
            let [a, b, c] = idx.map(|i| *self.position(i));
            let area2 = self.cross(t).norm();
            let longest = sub(&b, &a)
                .norm_squared()
                .max(sub(&c, &b).norm_squared())
                .max(sub(&a, &c).norm_squared());
            if repeated
                || area2.is_nan()
                || area2 <= DEGENERATE_TOLERANCE * longest
                || !area2.is_finite()
            {
                self.usable[t as usize] = false;
                self.defects.push(Defect {
                    kind: DefectKind::Degenerate,
                    triangles: vec![t],
                    vertices: idx.to_vec(),
                    position: self.centroid(t),
                    neighbours: Vec::new(),
                    gap: None,
                });
            } else if area2 < SLIVER_RATIO * longest {
                self.defects.push(Defect {
                    kind: DefectKind::Sliver,
                    triangles: vec![t],
                    vertices: idx.to_vec(),
                    position: self.centroid(t),
                    neighbours: Vec::new(),
                    gap: Some(area2 / longest.sqrt()),
                });
            }
        }
        // Duplicates: the same welded vertices in the same cyclic order.
        let mut keys: Vec<([u32; 3], u32)> = (0..n as u32)
            .filter(|&t| self.usable[t as usize])
            .map(|t| {
                let w = self.welded_tri(t);
                let r = (0..3).min_by_key(|&k| w[k]).unwrap_or(0);
                ([w[r], w[(r + 1) % 3], w[(r + 2) % 3]], t)
            })
            .collect();
        keys.sort_unstable();
        for pair in keys.windows(2) {
            if pair[0].0 == pair[1].0 {
                // Runs: each later one is a duplicate of the run's first.
                let first = keys[keys.partition_point(|k| k.0 < pair[0].0)].1;
                let dup = pair[1].1;
                self.usable[dup as usize] = false;
                let mut vertices = self.tri(first).to_vec();
                vertices.extend(self.tri(dup));
                self.defects.push(Defect {
                    kind: DefectKind::DuplicateTriangle,
                    triangles: vec![first, dup],
                    vertices,
                    position: self.centroid(dup),
                    neighbours: Vec::new(),
                    gap: None,
                });
            }
        }
    }

    fn build(mut self) -> Topology {
        self.weld();
        self.triangles_alone();
        let n = self.triangles.len();

        // Half-edges: (undirected key, triangle, slot | direction << 2).
        let mut half: Vec<(u64, u32, u8)> = Vec::with_capacity(3 * n);
        for t in 0..n as u32 {
            if !self.usable[t as usize] {
                continue;
            }
            let w = self.welded_tri(t);
            for slot in 0..3u8 {
                let (a, b) = (w[slot as usize], w[(slot as usize + 1) % 3]);
                let (lo, hi, forward) = if a < b { (a, b, 1) } else { (b, a, 0) };
                half.push((
                    (u64::from(lo) << 32) | u64::from(hi),
                    t,
                    slot | (forward << 2),
                ));
            }
        }
        half.sort_unstable();
        // Windings: unite the two triangles of every manifold edge.
        let mut forest = ParityForest::new(n);
        for run in runs(&half) {
            if run.len() == 2 {
                let (x, y) = (half[run.start], half[run.start + 1]);
                let same_direction = (x.2 >> 2) == (y.2 >> 2);
                forest.union(x.1, y.1, u8::from(same_direction));
            }
        }
        let flipped_set = self.flipped(&mut forest);
        drop(forest);

        // Edges and their classes.
        let mut edges = Vec::with_capacity(half.len() / 2 + 1);
        let mut counts = EdgeCounts::default();
        let mut neighbours_of: Vec<(u32, u32)> = Vec::new();
        let mut boundary: Vec<BoundaryEdge> = Vec::new();
        let mut lengths: Vec<f64> = Vec::with_capacity(half.len() / 2 + 1);
        for run in runs(&half) {
            let key = half[run.start].0;
            let vertices = [(key >> 32) as u32, key as u32];
            lengths.push(sub(self.position(vertices[0]), self.position(vertices[1])).norm());
            let class = match run.len() {
                1 => {
                    let (_, t, info) = half[run.start];
                    let slot = (info & 3) as usize;
                    let idx = self.tri(t);
                    boundary.push(BoundaryEdge {
                        ends: [idx[slot], idx[(slot + 1) % 3]],
                        triangle: t,
                    });
                    EdgeClass::Boundary
                }
                2 => {
                    let (x, y) = (half[run.start], half[run.start + 1]);
                    let (fx, fy) = (flipped_set.contains(&x.1), flipped_set.contains(&y.1));
                    if (x.2 >> 2) == (y.2 >> 2) {
                        if fx && !fy {
                            neighbours_of.push((x.1, y.1));
                        } else if fy && !fx {
                            neighbours_of.push((y.1, x.1));
                        }
                    }
                    self.dihedral(x.1, fx, y.1, (y.2 & 3) as usize, fy)
                }
                _ => {
                    let triangles: Vec<u32> = half[run.clone()].iter().map(|h| h.1).collect();
                    let (_, t, info) = half[run.start];
                    let slot = (info & 3) as usize;
                    let idx = self.tri(t);
                    self.defects.push(Defect {
                        kind: DefectKind::NonManifoldEdge,
                        triangles,
                        vertices: vec![idx[slot], idx[(slot + 1) % 3]],
                        position: self.midpoint(vertices[0], vertices[1]),
                        neighbours: Vec::new(),
                        gap: None,
                    });
                    EdgeClass::NonManifold
                }
            };
            counts.add(class);
            edges.push(Edge {
                vertices,
                triangles: [
                    half[run.start].1,
                    if run.len() > 1 {
                        half[run.start + 1].1
                    } else {
                        NONE
                    },
                ],
                class,
            });
        }
        drop(half);

        // Flipped triangles with the neighbours they contradict.
        let mut flipped: Vec<u32> = flipped_set.into_iter().collect();
        flipped.sort_unstable();
        neighbours_of.sort_unstable();
        for &t in &flipped {
            let lo = neighbours_of.partition_point(|p| p.0 < t);
            let hi = neighbours_of.partition_point(|p| p.0 <= t);
            self.defects.push(Defect {
                kind: DefectKind::Flipped,
                triangles: vec![t],
                vertices: self.tri(t).to_vec(),
                position: self.centroid(t),
                neighbours: neighbours_of[lo..hi].iter().map(|p| p.1).collect(),
                gap: None,
            });
        }

        let near = if lengths.is_empty() {
            0.0
        } else {
            let mid = lengths.len() / 2;
            let (_, median, _) = lengths.select_nth_unstable_by(mid, f64::total_cmp);
            NEAR_FRACTION * *median
        };
        drop(lengths);
        let boundary_loops = self.boundary_loops(&boundary);
        let crack_vertices = self.cracks_and_t_junctions(&boundary, near);
        self.duplicate_vertices(&edges, &crack_vertices, near);

        let mut defects = std::mem::take(&mut self.defects);
        defects.sort_by(|a, b| (a.kind, &a.triangles).cmp(&(b.kind, &b.triangles)));
        defects.shrink_to_fit();
        edges.shrink_to_fit();
        let corners: Vec<[u32; 3]> = (0..n as u32).map(|t| self.welded_tri(t)).collect();
        // The edges at each welded vertex, counted then placed (CSR).
        let mut vertex_edge_start = vec![0u32; self.vertices.len() + 1];
        for e in &edges {
            for v in e.vertices {
                vertex_edge_start[v as usize + 1] += 1;
            }
        }
        for v in 0..self.vertices.len() {
            vertex_edge_start[v + 1] += vertex_edge_start[v];
        }
        let mut next = vertex_edge_start.clone();
        let mut vertex_edges = vec![0u32; 2 * edges.len()];
        for (i, e) in edges.iter().enumerate() {
            for v in e.vertices {
                vertex_edges[next[v as usize] as usize] = i as u32;
                next[v as usize] += 1;
            }
        }
        Topology {
            corners,
            vertex_edge_start,
            vertex_edges,
            triangle_count: n,
            vertex_count: self.vertices.len(),
            welded_vertex_count: self.welded_vertex_count,
            weld: self.weld,
            edges,
            counts,
            boundary_loops,
            defects,
            flipped,
            near_distance: near,
        }
    }

    /// The minority winding of each connected piece: the triangles whose
    /// flip makes the piece consistent (on a tie, the side without the
    /// piece's lowest triangle).
    fn flipped(&self, forest: &mut ParityForest) -> HashSet<u32> {
        let n = self.triangles.len();
        // Per root: triangles of parity 0 and 1, and the lowest's parity.
        let mut count: HashMap<u32, [u32; 2]> = HashMap::new();
        let mut lowest: HashMap<u32, u8> = HashMap::new();
        let mut parity_of = vec![(0u32, 0u8); n];
        for t in 0..n as u32 {
            if !self.usable[t as usize] {
                continue;
            }
            let (root, p) = forest.find(t);
            parity_of[t as usize] = (root, p);
            if forest.size[root as usize] == 1 {
                continue;
            }
            count.entry(root).or_default()[p as usize] += 1;
            lowest.entry(root).or_insert(p);
        }
        let minority: HashMap<u32, u8> = count
            .iter()
            .map(|(&root, c)| match c[0].cmp(&c[1]) {
                std::cmp::Ordering::Less => (root, 0),
                std::cmp::Ordering::Greater => (root, 1),
                std::cmp::Ordering::Equal => (root, 1 - lowest.get(&root).copied().unwrap_or(0)),
            })
            .collect();
        (0..n as u32)
            .filter(|&t| {
                self.usable[t as usize] && {
                    let (root, p) = parity_of[t as usize];
                    minority.get(&root) == Some(&p)
                }
            })
            .collect()
    }

    /// The class of the manifold edge between `x` and `y` (`y`'s edge in
    /// slot `y_slot`), with the flipped ones turned over first.
    fn dihedral(&self, x: u32, fx: bool, y: u32, y_slot: usize, fy: bool) -> EdgeClass {
        let sign = |f: bool| if f { -1.0 } else { 1.0 };
        let nx = self.cross(x).normalize() * sign(fx);
        let ny = self.cross(y).normalize() * sign(fy);
        let sine = nx.cross(&ny).norm();
        if nx.dot(&ny) > 0.0 && sine <= FLAT_DIHEDRAL_SINE {
            return EdgeClass::Flat;
        }
        let yi = self.tri(y);
        let opposite = self.position(yi[(y_slot + 2) % 3]);
        let on_edge = self.position(yi[y_slot]);
        if nx.dot(&sub(opposite, on_edge)) <= 0.0 {
            EdgeClass::Convex
        } else {
            EdgeClass::Concave
        }
    }

    fn boundary_loops(&self, boundary: &[BoundaryEdge]) -> usize {
        let mut ids: HashMap<u32, u32> = HashMap::new();
        let mut parent: Vec<u32> = Vec::new();
        fn root(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        for e in boundary {
            let [a, b] = e.ends.map(|v| {
                let w = self.weld[v as usize];
                *ids.entry(w).or_insert_with(|| {
                    parent.push(parent.len() as u32);
                    parent.len() as u32 - 1
                })
            });
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra != rb {
                parent[ra as usize] = rb;
            }
        }
        (0..parent.len() as u32)
            .filter(|&i| root(&mut parent, i) == i)
            .count()
    }

    /// Cracks and T-junctions among the boundary edges, found through a
    /// hash grid; returns the welded vertices at the ends of crack edges.
    fn cracks_and_t_junctions(&mut self, boundary: &[BoundaryEdge], near: f64) -> HashSet<u32> {
        let mut crack_vertices = HashSet::new();
        if boundary.len() < 2 || near.is_nan() || near <= 0.0 {
            return crack_vertices;
        }
        let mut lengths: Vec<f64> = boundary
            .iter()
            .map(|e| sub(self.position(e.ends[0]), self.position(e.ends[1])).norm())
            .collect();
        let mid = lengths.len() / 2;
        let cell = lengths
            .select_nth_unstable_by(mid, f64::total_cmp)
            .1
            .max(near * 4.0);
        let origin = *self.position(boundary[0].ends[0]);
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, e) in boundary.iter().enumerate() {
            let (a, b) = (self.position(e.ends[0]), self.position(e.ends[1]));
            let lo = [0, 1, 2].map(|k| a[k].min(b[k]) - near);
            let hi = [0, 1, 2].map(|k| a[k].max(b[k]) + near);
            let (clo, chi) = (cell_of(&lo, &origin, cell), cell_of(&hi, &origin, cell));
            for x in clo[0]..=chi[0] {
                for y in clo[1]..=chi[1] {
                    for z in clo[2]..=chi[2] {
                        grid.entry([x, y, z]).or_default().push(i as u32);
                    }
                }
            }
        }
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for list in grid.values() {
            for (k, &i) in list.iter().enumerate() {
                for &j in &list[k + 1..] {
                    pairs.push((i.min(j), i.max(j)));
                }
            }
        }
        drop(grid);
        pairs.sort_unstable();
        pairs.dedup();
        let point = |v: u32| Point3::from(*self.position(v));
        let weld = |v: u32| self.weld[v as usize];
        let mut t_junctions: Vec<(u32, u32, u32, f64)> = Vec::new(); // (welded vertex, edge, vertex, gap)
        let mut cracks: Vec<(u32, u32, bool, f64)> = Vec::new();
        for &(i, j) in &pairs {
            let (e, f) = (boundary[i as usize], boundary[j as usize]);
            if e.triangle == f.triangle {
                continue;
            }
            let [ea, eb] = e.ends;
            let [fa, fb] = f.ends;
            let close = |u: u32, v: u32| (point(u) - point(v)).norm();
            // Crack: the ends match pairwise, within `near`, not both exactly.
            for (swap, (u0, u1)) in [(false, (fa, fb)), (true, (fb, fa))] {
                let (d0, d1) = (close(ea, u0), close(eb, u1));
                let exact = weld(ea) == weld(u0) && weld(eb) == weld(u1);
                if d0 <= near && d1 <= near && !exact {
                    cracks.push((i, j, swap, d0.max(d1)));
                }
            }
            // T-junction: an end of one on the interior of the other.
            for (edge, other, [a, b]) in [(i, f, e.ends), (j, e, f.ends)] {
                for v in other.ends {
                    if weld(v) == weld(a) || weld(v) == weld(b) {
                        continue;
                    }
                    let p = point(v);
                    let gap = point_segment_distance(&p, &point(a), &point(b));
                    if gap <= near && close(v, a) > near && close(v, b) > near {
                        t_junctions.push((weld(v), edge, v, gap));
                    }
                }
            }
        }
        for (i, j, swap, gap) in cracks {
            let (e, f) = (boundary[i as usize], boundary[j as usize]);
            let f_ends = if swap { [f.ends[1], f.ends[0]] } else { f.ends };
            for v in e.ends.iter().chain(&f_ends) {
                crack_vertices.insert(weld(*v));
            }
            self.defects.push(Defect {
                kind: DefectKind::Crack,
                triangles: vec![e.triangle, f.triangle],
                vertices: vec![e.ends[0], e.ends[1], f_ends[0], f_ends[1]],
                position: self.midpoint(e.ends[0], e.ends[1]),
                neighbours: Vec::new(),
                gap: Some(gap),
            });
        }
        t_junctions.sort_by_key(|a| (a.0, a.1));
        t_junctions.dedup_by(|a, b| (a.0, a.1) == (b.0, b.1));
        for (w, edge, v, gap) in t_junctions {
            let e = boundary[edge as usize];
            let mut triangles = vec![e.triangle];
            let mut at_vertex: Vec<u32> = boundary
                .iter()
                .filter(|b| b.ends.iter().any(|&u| weld(u) == w))
                .map(|b| b.triangle)
                .collect();
            at_vertex.sort_unstable();
            at_vertex.dedup();
            triangles.extend(at_vertex);
            self.defects.push(Defect {
                kind: DefectKind::TJunction,
                triangles,
                vertices: vec![v, e.ends[0], e.ends[1]],
                position: *self.position(v),
                neighbours: Vec::new(),
                gap: Some(gap),
            });
        }
        crack_vertices
    }

    /// Pairs of used vertices within `near` of each other (not at the same
    /// position, not joined by an edge, not both at the ends of crack
    /// edges), through a hash grid of cells far larger than `near`.
    fn duplicate_vertices(&mut self, edges: &[Edge], crack_vertices: &HashSet<u32>, near: f64) {
        if near.is_nan() || near <= 0.0 {
            return;
        }
        let mut used = vec![false; self.vertices.len()];
        for (t, tri) in self.triangles.iter().enumerate() {
            if self.usable[t] {
                for &v in tri {
                    used[self.weld[v as usize] as usize] = true;
                }
            }
        }
        // Cells a thousand times `near`, the grid shifted by an irrational
        // fraction so that vertices on a regular lattice sit inside cells,
        // not on their faces (only speed depends on this).
        let cell = near / NEAR_FRACTION;
        let first = used.iter().position(|&u| u).unwrap_or(0);
        let base = self.vertices.get(first).copied().unwrap_or([0.0; 3]);
        let origin = [
            base[0] - 0.381_966 * cell,
            base[1] - 0.276_393 * cell,
            base[2] - 0.414_214 * cell,
        ];
        let mut cells: Vec<([i64; 3], u32)> = (0..self.vertices.len() as u32)
            .filter(|&v| used[v as usize])
            .map(|v| (cell_of(self.position(v), &origin, cell), v))
            .collect();
        drop(used);
        cells.sort_unstable();
        let mut found: Vec<(u32, u32, f64)> = Vec::new();
        let range_of = |key: [i64; 3]| {
            let lo = cells.partition_point(|c| c.0 < key);
            let hi = cells.partition_point(|c| c.0 <= key);
            lo..hi
        };
        let mut start = 0;
        while start < cells.len() {
            let key = cells[start].0;
            let mut end = start + 1;
            while end < cells.len() && cells[end].0 == key {
                end += 1;
            }
            for k in start..end {
                let u = cells[k].1;
                let pu = self.position(u);
                for &(_, v) in &cells[k + 1..end] {
                    let d = sub(pu, self.position(v)).norm();
                    if d <= near {
                        found.push((u.min(v), u.max(v), d));
                    }
                }
                // Neighbouring cells, only across faces within `near`.
                let mut steps = [[0i64; 3]; 3];
                let mut n_steps = [1usize; 3];
                for axis in 0..3 {
                    let local = pu[axis] - origin[axis] - key[axis] as f64 * cell;
                    if local <= near {
                        steps[axis][n_steps[axis]] = -1;
                        n_steps[axis] += 1;
                    }
                    if cell - local <= near {
                        steps[axis][n_steps[axis]] = 1;
                        n_steps[axis] += 1;
                    }
                }
                for &sx in &steps[0][..n_steps[0]] {
                    for &sy in &steps[1][..n_steps[1]] {
                        for &sz in &steps[2][..n_steps[2]] {
                            if (sx, sy, sz) == (0, 0, 0) {
                                continue;
                            }
                            let other = [key[0] + sx, key[1] + sy, key[2] + sz];
                            for &(_, v) in &cells[range_of(other)] {
                                let d = sub(pu, self.position(v)).norm();
                                if u < v && d <= near {
                                    found.push((u, v, d));
                                }
                            }
                        }
                    }
                }
            }
            start = end;
        }
        drop(cells);
        found.sort_by_key(|a| (a.0, a.1));
        found.dedup_by(|a, b| (a.0, a.1) == (b.0, b.1));
        let joined = |u: u32, v: u32| {
            let key = [u.min(v), u.max(v)];
            edges.binary_search_by(|e| e.vertices.cmp(&key)).is_ok()
        };
        for (u, v, d) in found {
            if joined(u, v) || (crack_vertices.contains(&u) && crack_vertices.contains(&v)) {
                continue;
            }
            let mut triangles: Vec<u32> = (0..self.triangles.len() as u32)
                .filter(|&t| {
                    self.usable[t as usize] && self.welded_tri(t).iter().any(|&w| w == u || w == v)
                })
                .take(8)
                .collect();
            triangles.sort_unstable();
            self.defects.push(Defect {
                kind: DefectKind::DuplicateVertex,
                triangles,
                vertices: vec![u, v],
                position: self.midpoint(u, v),
                neighbours: Vec::new(),
                gap: Some(d),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w × h` grid of unit squares at z = 0, two triangles each, fronts +z.
    fn floor(w: u64, h: u64) -> (Vec<[f64; 3]>, Vec<[u64; 3]>) {
        let mut v = Vec::new();
        for j in 0..=h {
            for i in 0..=w {
                v.push([i as f64, j as f64, 0.0]);
            }
        }
        let mut t = Vec::new();
        for j in 0..h {
            for i in 0..w {
                let a = j * (w + 1) + i;
                t.push([a, a + 1, a + w + 2]);
                t.push([a, a + w + 2, a + w + 1]);
            }
        }
        (v, t)
    }

    fn kinds(t: &Topology) -> Vec<DefectKind> {
        t.defects().iter().map(|d| d.kind).collect()
    }

    #[test]
    fn clean_floor_is_flat_with_one_boundary_loop() {
        let (v, t) = floor(3, 2);
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![]);
        let c = topo.edge_counts();
        // 3×2 squares: 10 boundary edges, 7 inner grid edges + 6 diagonals.
        assert_eq!(c.boundary, 10);
        assert_eq!(c.flat, 13);
        assert_eq!(c.total(), 23);
        assert_eq!(topo.boundary_loops(), 1);
        assert!(!topo.changes_collisions());
    }

    #[test]
    fn triangle_edges_and_vertices_by_class() {
        // 2×2 squares: vertex 4 is the centre, every edge at it internal.
        let (v, t) = floor(2, 2);
        let topo = Topology::new(&v, &t).unwrap();
        // Triangle 0 is (0, 1, 4): edge 0 on the rim, edge 1 inside the
        // square 1, edge 2 the diagonal shared with triangle 1.
        assert_eq!(topo.triangle_edge_class(0, 0), Some(EdgeClass::Boundary));
        assert_eq!(topo.triangle_edge_class(0, 2), Some(EdgeClass::Flat));
        let diagonal = topo.triangle_edge(0, 2).unwrap();
        assert_eq!(diagonal.triangles, [0, 1]);
        assert_eq!(topo.triangle_edge_class(0, 3), None);
        assert_eq!(topo.triangle_edge_class(99, 0), None);
        assert_eq!(topo.triangle_vertex(0, 2), Some(4));
        assert_eq!(topo.edges_at(4).count(), 6);
        assert!(topo.vertex_is_flat_or_concave(4));
        assert!(!topo.vertex_is_flat_or_concave(0));
        assert!(!topo.vertex_is_flat_or_concave(99));

        // Fold the far column up about x = 1: its edges along x = 1 turn
        // concave (a valley seen from +z), the centre stays internal.
        let (mut v, t) = floor(2, 2);
        for p in &mut v {
            if p[0] > 1.5 {
                p[2] = 1.0;
            }
        }
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(
            topo.edge_between(1, 4).map(|e| e.class),
            Some(EdgeClass::Concave)
        );
        assert!(topo.vertex_is_flat_or_concave(4));
        // Folded down instead, a ridge: the centre meets a convex edge.
        let (mut v, t) = floor(2, 2);
        for p in &mut v {
            if p[0] > 1.5 {
                p[2] = -1.0;
            }
        }
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(
            topo.edge_between(4, 1).map(|e| e.class),
            Some(EdgeClass::Convex)
        );
        assert!(!topo.vertex_is_flat_or_concave(4));
    }

    #[test]
    fn one_flipped_triangle_is_the_minority() {
        let (v, mut t) = floor(3, 3);
        t[9].swap(1, 2);
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::Flipped]);
        let d = &topo.defects()[0];
        assert_eq!(d.triangles, vec![9]);
        assert_eq!(d.neighbours.len(), 3);
        assert_eq!(topo.flipped(), &[9]);
        assert_eq!(d.to_string(), "flipped triangle 9");
        // Its edges are classified as if it were turned over: still flat.
        assert_eq!(topo.edge_counts().flat, topo.edge_counts().total() - 12);
    }

    #[test]
    fn cube_edges_are_convex_and_flat() {
        let s = crate::sim::scenes::cube();
        let topo = Topology::new(&s.vertices, &s.triangles).unwrap();
        assert_eq!(kinds(&topo), vec![]);
        let c = topo.edge_counts();
        assert_eq!((c.convex, c.flat, c.boundary), (12, 6, 0));
        assert_eq!(topo.boundary_loops(), 0);
        // Turned inside out, the same edges are concave.
        let inside: Vec<[u64; 3]> = s.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let topo = Topology::new(&s.vertices, &inside).unwrap();
        assert_eq!(topo.edge_counts().concave, 12);
    }

    #[test]
    fn unwelded_seam_is_a_crack_not_duplicate_vertices() {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0 + 1e-5, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0 + 1e-5, 1.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::Crack]);
        let d = &topo.defects()[0];
        let mut tris = d.triangles.clone();
        tris.sort_unstable();
        assert_eq!(tris, vec![0, 3]);
    }

    #[test]
    fn t_junction_sliver_duplicate_and_fin() {
        // T-junction: a big triangle's edge (0,1)-(2,1) against two small
        // ones meeting at (1,1).
        let v = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [3, 4, 5], [4, 2, 5]];
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::TJunction]);
        assert_eq!(topo.defects()[0].triangles[0], 1);
        assert_eq!(topo.defects()[0].vertices[0], 4);

        let (mut v, mut t) = floor(2, 2);
        t.push(t[3]);
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::DuplicateTriangle]);
        assert_eq!(topo.defects()[0].triangles, vec![3, 8]);
        t.pop();

        // A fin on the diagonal of the first square.
        v.push([0.5, 0.5, 1.0]);
        t.push([0, 4, 9]);
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::NonManifoldEdge]);
        assert_eq!(topo.defects()[0].triangles, vec![0, 1, 8]);

        let v = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1e-4, 0.0]];
        let topo = Topology::new(&v, &[[0, 1, 2]]).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::Sliver]);
        let topo = Topology::new(&v, &[[0, 1, 1]]).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::Degenerate]);
    }

    #[test]
    fn near_coincident_vertices_are_reported_once() {
        let (mut v, mut t) = floor(2, 1);
        // A separate triangle whose corner is 1e-5 from the floor's corner (0,0).
        v.push([1e-5, -1e-5, 0.0]);
        v.push([-1.0, -2.0, 0.0]);
        v.push([0.5, -2.0, 0.0]);
        let n = v.len() as u64;
        t.push([n - 3, n - 2, n - 1]);
        let topo = Topology::new(&v, &t).unwrap();
        assert_eq!(kinds(&topo), vec![DefectKind::DuplicateVertex]);
        assert_eq!(topo.defects()[0].vertices, vec![0, n as u32 - 3]);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            Topology::new(&[[0.0; 3]], &[[0, 0, 1]]),
            Err(MeshError::IndexOutOfRange { .. })
        ));
        assert!(matches!(
            Topology::new(&[[f64::NAN, 0.0, 0.0]], &[]),
            Err(MeshError::NonFiniteVertex { .. })
        ));
    }
}
