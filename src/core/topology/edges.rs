//! The weld (vertices at one position are one vertex) and the undirected
//! edges between welded vertices: their triangles, windings and classes.

use std::collections::HashMap;

use nalgebra::Vector3;
use serde::Serialize;

use super::defects::{Defect, DefectKind};
use super::{Builder, FLAT_DIHEDRAL_SINE, NEAR_FRACTION, Topology, sub};

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

fn position_key(p: &[f64; 3]) -> [u64; 3] {
    // `+ 0.0` turns -0.0 into +0.0, so both weld.
    p.map(|c| (c + 0.0).to_bits())
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

/// `half` sorted (by undirected key, then triangle, then slot): placed by
/// the key's lower vertex (a counting sort over the `vertex_count` welded
/// vertices), then each vertex's few half-edges sorted. The same order as
/// sorting the whole, in time linear in the half-edges.
fn sort_half_edges(half: Vec<(u64, u32, u8)>, vertex_count: usize) -> Vec<(u64, u32, u8)> {
    let lower = |h: &(u64, u32, u8)| (h.0 >> 32) as usize;
    let mut start = vec![0u32; vertex_count + 1];
    for h in &half {
        start[lower(h) + 1] += 1;
    }
    for v in 0..vertex_count {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut sorted = vec![(0u64, 0u32, 0u8); half.len()];
    for h in half {
        let v = lower(&h);
        sorted[next[v] as usize] = h;
        next[v] += 1;
    }
    for v in 0..vertex_count {
        sorted[start[v] as usize..start[v + 1] as usize].sort_unstable();
    }
    sorted
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
pub(super) struct BoundaryEdge {
    /// Input vertex indices, in the triangle's direction.
    pub(super) ends: [u32; 2],
    pub(super) triangle: u32,
}

impl Builder<'_> {
    fn weld(&mut self) {
        // Keys computed once, then sorted with their index: equal positions
        // side by side, the lowest index first.
        let mut order: Vec<([u64; 3], u32)> = self
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| (position_key(v), i as u32))
            .collect();
        order.sort_unstable();
        self.weld = vec![0; self.vertices.len()];
        let mut start = 0;
        while start < order.len() {
            let key = order[start].0;
            let mut end = start + 1;
            while end < order.len() && order[end].0 == key {
                end += 1;
            }
            for &(_, i) in &order[start..end] {
                self.weld[i as usize] = order[start].1;
            }
            self.welded_vertex_count += 1;
            start = end;
        }
    }

    /// Degenerate and sliver triangles (same rule as the mesh), then
    pub(super) fn build(mut self) -> Topology {
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
        let half = sort_half_edges(half, self.vertices.len());
        // Windings: unite the two triangles of every manifold edge.
        let mut forest = ParityForest::new(n);
        for run in runs(&half) {
            if run.len() == 2 {
                let (x, y) = (half[run.start], half[run.start + 1]);
                let same_direction = (x.2 >> 2) == (y.2 >> 2);
                forest.union(x.1, y.1, u8::from(same_direction));
            }
        }
        let is_flipped = self.flipped(&mut forest);
        drop(forest);

        // Edges and their classes, from each triangle's unit normal
        // (computed once, not once per edge).
        let normals: Vec<Vector3<f64>> = (0..n as u32).map(|t| self.cross(t).normalize()).collect();
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
                    let (fx, fy) = (is_flipped[x.1 as usize], is_flipped[y.1 as usize]);
                    if (x.2 >> 2) == (y.2 >> 2) {
                        if fx && !fy {
                            neighbours_of.push((x.1, y.1));
                        } else if fy && !fx {
                            neighbours_of.push((y.1, x.1));
                        }
                    }
                    self.dihedral(&normals, (x.1, fx), (y.1, (y.2 & 3) as usize, fy))
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
        drop(normals);

        // Flipped triangles with the neighbours they contradict.
        let flipped: Vec<u32> = (0..n as u32).filter(|&t| is_flipped[t as usize]).collect();
        drop(is_flipped);
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
    /// piece's lowest triangle), as a flag per triangle. Counted in vectors
    /// indexed by the piece's root.
    fn flipped(&self, forest: &mut ParityForest) -> Vec<bool> {
        const UNSET: u8 = u8::MAX;
        let n = self.triangles.len();
        // Per root: triangles of parity 0 and 1, and the lowest's parity.
        let mut count = vec![[0u32; 2]; n];
        let mut lowest = vec![UNSET; n];
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
            count[root as usize][p as usize] += 1;
            if lowest[root as usize] == UNSET {
                lowest[root as usize] = p;
            }
        }
        (0..n)
            .map(|t| {
                let (root, p) = parity_of[t];
                let c = count[root as usize];
                self.usable[t]
                    && c != [0, 0]
                    && p == match c[0].cmp(&c[1]) {
                        std::cmp::Ordering::Less => 0,
                        std::cmp::Ordering::Greater => 1,
                        std::cmp::Ordering::Equal => 1 - lowest[root as usize],
                    }
            })
            .collect()
    }

    /// The class of the manifold edge between `x` and `y` (`y`'s edge in
    /// slot `y_slot`), with the flipped ones turned over first.
    /// `normals` are the triangles' unit normals by their own winding.
    fn dihedral(
        &self,
        normals: &[Vector3<f64>],
        (x, fx): (u32, bool),
        (y, y_slot, fy): (u32, usize, bool),
    ) -> EdgeClass {
        let sign = |f: bool| if f { -1.0 } else { 1.0 };
        let nx = normals[x as usize] * sign(fx);
        let ny = normals[y as usize] * sign(fy);
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
}
