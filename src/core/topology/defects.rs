//! The defects: flipped windings (found with the edges), cracks,
//! T-junctions, degenerate and sliver triangles, duplicate triangles,
//! near-coincident vertices and non-manifold edges.

use std::collections::{HashMap, HashSet};

use nalgebra::Point3;
use serde::Serialize;

use super::distance::{Place, point_segment_distance};
use super::edges::{BoundaryEdge, Edge};
use super::{Builder, NEAR_FRACTION, SLIVER_RATIO, sub};
use crate::core::options::DEGENERATE_TOLERANCE;

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
#[non_exhaustive]
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
    /// The defect's place: its triangles (flipped, degenerate, sliver,
    /// duplicate triangle), its edges (crack, non-manifold edge, the
    /// T-junction's edge) or its vertices (duplicate vertex). `vertices`
    /// are the mesh's positions.
    fn places(&self, vertices: &[Point3<f64>]) -> Vec<Place> {
        let at = |i: u32| vertices.get(i as usize).copied();
        let v = &self.vertices;
        match self.kind {
            DefectKind::Flipped
            | DefectKind::Degenerate
            | DefectKind::Sliver
            | DefectKind::DuplicateTriangle => v
                .chunks_exact(3)
                .filter_map(|t| Some(Place::Triangle(at(t[0])?, at(t[1])?, at(t[2])?)))
                .collect(),
            DefectKind::Crack => v
                .chunks_exact(2)
                .filter_map(|e| Some(Place::Segment(at(e[0])?, at(e[1])?)))
                .collect(),
            DefectKind::TJunction => v
                .get(1..3)
                .and_then(|e| Some(Place::Segment(at(e[0])?, at(e[1])?)))
                .into_iter()
                .collect(),
            DefectKind::NonManifoldEdge => v
                .get(0..2)
                .and_then(|e| Some(Place::Segment(at(e[0])?, at(e[1])?)))
                .into_iter()
                .collect(),
            DefectKind::DuplicateVertex => {
                v.iter().filter_map(|&i| at(i).map(Place::Point)).collect()
            }
        }
    }

    /// Distance from `point` to the defect's place: its triangles (flipped,
    /// degenerate, sliver, duplicate triangle), its edges (crack,
    /// non-manifold edge, the T-junction's edge) or its vertices
    /// (duplicate vertex). `vertices` are the mesh's positions.
    pub fn distance(&self, vertices: &[Point3<f64>], point: &Point3<f64>) -> f64 {
        self.places(vertices)
            .iter()
            .map(|place| place.distance_to_point(point))
            .fold(f64::INFINITY, f64::min)
    }

    /// Distance from the segment `p q` (a ball centre's path) to the
    /// defect's place (as in [`Defect::distance`]): 0 when it passes
    /// through one of its triangles.
    pub fn distance_to_segment(
        &self,
        vertices: &[Point3<f64>],
        p: &Point3<f64>,
        q: &Point3<f64>,
    ) -> f64 {
        self.places(vertices)
            .iter()
            .map(|place| place.distance_to_segment(p, q))
            .fold(f64::INFINITY, f64::min)
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

/// A hash grid of cell size `cell` over points (the keys of the cells).
fn cell_of(p: &[f64; 3], origin: &[f64; 3], cell: f64) -> [i64; 3] {
    [0, 1, 2].map(|k| ((p[k] - origin[k]) / cell).floor() as i64)
}

impl Builder<'_> {
    /// Degenerate and sliver triangles (same rule as the mesh), then
    /// duplicates; marks what the adjacency uses.
    pub(super) fn triangles_alone(&mut self) {
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

    /// Cracks and T-junctions among the boundary edges, found through a
    /// hash grid; returns the welded vertices at the ends of crack edges.
    pub(super) fn cracks_and_t_junctions(
        &mut self,
        boundary: &[BoundaryEdge],
        near: f64,
    ) -> HashSet<u32> {
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
    pub(super) fn duplicate_vertices(
        &mut self,
        edges: &[Edge],
        crack_vertices: &HashSet<u32>,
        near: f64,
    ) {
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
