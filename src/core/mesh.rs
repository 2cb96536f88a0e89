//! A validated triangle mesh with everything the tests precompute:
//! per triangle its front normal, per triangle edge its standard frame,
//! and a bounding volume hierarchy over the triangles.

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde::Serialize;

use super::bvh::Bvh;
use super::error::MeshError;
use super::options::DEGENERATE_TOLERANCE;

/// The standard frame of one triangle edge `(v0, v1)`: `v0` at the origin,
/// `v1` at `(L, 0, 0)`, `+y` the triangle's front normal, `+z = x × y`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandardFrame {
    /// Rotation part of the transform from world to edge coordinates.
    pub edge_from_world_rotation: Rotation3<f64>,
    /// `v0` in world coordinates (the frame's origin).
    pub origin_in_world: Point3<f64>,
    /// Length `L` of the edge.
    pub length: f64,
}

impl StandardFrame {
    /// Builds the frame of the edge `v0 → v1` of a triangle with front normal
    /// `normal` (unit, perpendicular to the edge).
    pub fn new(v0: Point3<f64>, v1: Point3<f64>, normal: Vector3<f64>) -> Self {
        let edge = v1 - v0;
        let length = edge.norm();
        let x = edge / length;
        // Remove the rounding residue so the frame is orthonormal.
        let y = (normal - x * x.dot(&normal)).normalize();
        let z = x.cross(&y);
        let m = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
        StandardFrame {
            edge_from_world_rotation: Rotation3::from_matrix_unchecked(m),
            origin_in_world: v0,
            length,
        }
    }

    /// A world point in edge coordinates.
    #[inline]
    pub fn to_edge(&self, p_in_world: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.edge_from_world_rotation * (p_in_world - self.origin_in_world))
    }

    /// An edge-frame point in world coordinates.
    #[inline]
    pub fn to_world(&self, p_in_edge: &Point3<f64>) -> Point3<f64> {
        self.origin_in_world + self.edge_from_world_rotation.inverse() * p_in_edge.coords
    }

    /// The rigid transform that maps edge coordinates to world coordinates.
    pub fn world_from_edge(&self) -> Isometry3<f64> {
        let rotation =
            UnitQuaternion::from_rotation_matrix(&self.edge_from_world_rotation.inverse());
        Isometry3::from_parts(Translation3::from(self.origin_in_world.coords), rotation)
    }

    /// The rigid transform that maps world coordinates to edge coordinates.
    pub fn edge_from_world(&self) -> Isometry3<f64> {
        self.world_from_edge().inverse()
    }

    /// The frame of the same edge for the front normal `-n`: `+y` and `+z`
    /// negated (a half turn about the edge), so a point's `x` and its
    /// distance from the edge's line are unchanged.
    pub fn mirrored(&self) -> Self {
        let mut m = *self.edge_from_world_rotation.matrix();
        for row in 1..3 {
            for column in 0..3 {
                m[(row, column)] = -m[(row, column)];
            }
        }
        StandardFrame {
            edge_from_world_rotation: Rotation3::from_matrix_unchecked(m),
            ..*self
        }
    }
}

/// One usable triangle with its precomputed data.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// Index of the triangle in the input (degenerate ones keep their slot).
    pub index: u32,
    /// Vertex indices `(a, b, c)`.
    pub vertex_indices: [u32; 3],
    /// Vertex positions `(a, b, c)`.
    pub vertices: [Point3<f64>; 3],
    /// Unit front normal `normalize((b - a) × (c - a))`.
    pub normal: Vector3<f64>,
    /// Standard frame of edge `i`, which joins vertex `i` and `(i + 1) mod 3`.
    pub edges: [StandardFrame; 3],
    /// Whether this is the triangle seen from its back
    /// ([`Triangle::mirrored`]): `normal` is then `-n`.
    pub back: bool,
}

impl Triangle {
    /// The triangle seen from its back (`sides = two`, a path moving
    /// toward the back): the same index, vertices and edges, its normal
    /// `-n` and its edge frames [mirrored](StandardFrame::mirrored). Every
    /// test of SEMANTICS.md then treats the back as the front.
    pub fn mirrored(&self) -> Triangle {
        Triangle {
            normal: -self.normal,
            edges: self.edges.map(|e| e.mirrored()),
            back: !self.back,
            ..*self
        }
    }
}

/// What the fast query's skip tests read of a triangle: its front normal
/// and first vertex (the same values as its [`Triangle`] record, so a skip
/// decided from here is the one the record gives), and its input index.
/// Kept apart from the records, in the same order, so that the candidates
/// the query skips cost 56 bytes each to read instead of a whole record.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plane {
    /// [`Triangle::normal`].
    pub(crate) normal: Vector3<f64>,
    /// [`Triangle::vertices`]`[0]`.
    pub(crate) v0: Point3<f64>,
    /// [`Triangle::index`].
    pub(crate) index: u32,
    /// The largest distance from `v0` to the triangle's other vertices,
    /// rounded up to single precision (it fills the record's padding): the
    /// triangle lies within this distance of `v0`, which lets a contact
    /// query pass it by without reading its whole record.
    pub(crate) extent: f32,
}

impl Plane {
    fn of(triangle: &Triangle) -> Plane {
        let [a, b, c] = triangle.vertices;
        let far = (b - a).norm().max((c - a).norm());
        let mut extent = far as f32;
        if f64::from(extent) < far {
            extent = extent.next_up();
        }
        Plane {
            normal: triangle.normal,
            v0: a,
            index: triangle.index,
            extent,
        }
    }
}

/// A triangle left out because it has no area.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DegenerateTriangle {
    /// Index of the triangle in the input.
    pub index: usize,
    /// Why it was left out.
    pub reason: DegenerateReason,
}

/// Why a triangle is degenerate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DegenerateReason {
    /// Two of its vertex indices are equal.
    RepeatedIndex,
    /// Its area is zero or below the tolerance (collinear vertices).
    ZeroArea,
}

impl std::fmt::Display for DegenerateTriangle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let why = match self.reason {
            DegenerateReason::RepeatedIndex => "repeated vertex index",
            DegenerateReason::ZeroArea => "zero or near-zero area",
        };
        write!(f, "triangle {} is degenerate ({why})", self.index)
    }
}

/// Sizes of what a mesh holds for the query, in bytes ([`Mesh::bytes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshBytes {
    /// One node of the BVH.
    pub node: usize,
    /// Every node of the BVH (what the traversal reads).
    pub nodes: usize,
    /// One triangle's record ([`Triangle`]).
    pub triangle: usize,
    /// Every triangle's record.
    pub triangles: usize,
    /// One triangle's plane, what the skip tests read (kept apart from the
    /// records).
    pub plane: usize,
    /// Every triangle's plane.
    pub planes: usize,
    /// The BVH's two index maps (position ↔ input index; not read by the
    /// traversal).
    pub index_maps: usize,
}

/// A validated triangle mesh, ready for sweeps.
#[derive(Clone, Debug)]
pub struct Mesh {
    vertices: Vec<Point3<f64>>,
    input_triangle_count: usize,
    triangles: Vec<Triangle>,
    /// Each triangle's [`Plane`], in the order of `triangles`.
    planes: Vec<Plane>,
    degenerate: Vec<DegenerateTriangle>,
    bvh: Bvh,
}

/// Reorders `items` in place so that `items[k]` becomes the old
/// `items[order[k]]`; `order` is a permutation of `0..items.len()`. Follows
/// each cycle of the permutation once, with one saved element per cycle.
fn permute_into_order<T: Copy>(items: &mut [T], order: &[u32]) {
    debug_assert_eq!(items.len(), order.len());
    let mut placed = vec![false; items.len()];
    for start in 0..items.len() {
        if placed[start] {
            continue;
        }
        let saved = items[start];
        let mut k = start;
        loop {
            placed[k] = true;
            let from = order[k] as usize;
            if from == start {
                items[k] = saved;
                break;
            }
            items[k] = items[from];
            k = from;
        }
    }
}

impl Mesh {
    /// Builds a mesh from vertices and vertex-index triples.
    ///
    /// Indices out of range and non-finite coordinates are errors;
    /// degenerate triangles are left out and listed in [`Mesh::degenerate`].
    pub fn new(vertices: Vec<[f64; 3]>, triangles: &[[u64; 3]]) -> Result<Mesh, MeshError> {
        if vertices.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "vertex count",
                limit: u32::MAX as usize,
            });
        }
        if triangles.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "triangle count",
                limit: u32::MAX as usize,
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
        let vertices: Vec<Point3<f64>> = vertices.into_iter().map(Point3::from).collect();
        let mut usable = Vec::with_capacity(triangles.len());
        let mut degenerate = Vec::new();
        for (t, tri) in triangles.iter().enumerate() {
            for &i in tri {
                if i >= vertices.len() as u64 {
                    return Err(MeshError::IndexOutOfRange {
                        triangle: t,
                        index: i,
                        vertex_count: vertices.len(),
                    });
                }
            }
            let idx = [tri[0] as u32, tri[1] as u32, tri[2] as u32];
            if idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2] {
                degenerate.push(DegenerateTriangle {
                    index: t,
                    reason: DegenerateReason::RepeatedIndex,
                });
                continue;
            }
            let [a, b, c] = idx.map(|i| vertices[i as usize]);
            let cross = (b - a).cross(&(c - a));
            let longest = (b - a)
                .norm_squared()
                .max((c - b).norm_squared())
                .max((a - c).norm_squared());
            let area2 = cross.norm();
            if area2.is_nan() || area2 <= DEGENERATE_TOLERANCE * longest || !area2.is_finite() {
                degenerate.push(DegenerateTriangle {
                    index: t,
                    reason: DegenerateReason::ZeroArea,
                });
                continue;
            }
            let normal = cross / area2;
            let edges = [
                StandardFrame::new(a, b, normal),
                StandardFrame::new(b, c, normal),
                StandardFrame::new(c, a, normal),
            ];
            usable.push(Triangle {
                index: t as u32,
                vertex_indices: idx,
                vertices: [a, b, c],
                normal,
                edges,
                back: false,
            });
        }
        if usable.is_empty() {
            return Err(MeshError::Empty {
                triangles: triangles.len(),
                degenerate: degenerate.len(),
            });
        }
        let input_triangle_count = triangles.len();
        let bvh = Bvh::build(&usable);
        // Store triangles in BVH leaf order so leaves are contiguous ranges,
        // permuted in place: a copy would hold the largest array of the mesh
        // twice while building.
        permute_into_order(&mut usable, bvh.order());
        let planes = usable.iter().map(Plane::of).collect();
        Ok(Mesh {
            vertices,
            input_triangle_count,
            triangles: usable,
            planes,
            degenerate,
            bvh,
        })
    }

    /// The vertices, as given.
    pub fn vertices(&self) -> &[Point3<f64>] {
        &self.vertices
    }

    /// The usable triangles, in the order the BVH stores them (use
    /// [`Triangle::index`] for the input index).
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// Number of triangles in the input, degenerate ones included.
    pub fn input_triangle_count(&self) -> usize {
        self.input_triangle_count
    }

    /// The triangles left out, with their input index and reason.
    pub fn degenerate(&self) -> &[DegenerateTriangle] {
        &self.degenerate
    }

    /// The usable triangle with input index `index`, if any.
    pub fn triangle_by_index(&self, index: u32) -> Option<&Triangle> {
        self.bvh.position_of(index).map(|p| &self.triangles[p])
    }

    /// Each triangle's [`Plane`], in the order of [`Mesh::triangles`].
    pub(crate) fn planes(&self) -> &[Plane] {
        &self.planes
    }

    pub(crate) fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Builds the BVH over the mesh's triangles again and returns how many
    /// triangles it orders: the BVH build alone, for the benchmark that
    /// compares other per-scene work with it.
    #[doc(hidden)]
    pub fn build_bvh_again(&self) -> usize {
        Bvh::build(&self.triangles).order().len()
    }

    /// The bytes the query reads: the tree's nodes, the triangles' planes
    /// and records (for the benchmark's per-node figures).
    pub fn bytes(&self) -> MeshBytes {
        let (node, nodes) = self.bvh.node_bytes();
        let triangle = std::mem::size_of::<Triangle>();
        MeshBytes {
            node,
            nodes,
            triangle,
            triangles: triangle * self.triangles.len(),
            plane: std::mem::size_of::<Plane>(),
            planes: std::mem::size_of::<Plane>() * self.planes.len(),
            index_maps: self.bvh.map_bytes(),
        }
    }

    /// Axis-aligned bounds of the mesh (`min`, `max`).
    pub fn bounds(&self) -> (Point3<f64>, Point3<f64>) {
        self.bvh.root_bounds()
    }
}

#[cfg(test)]
mod tests {
    use rand::seq::SliceRandom;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::permute_into_order;

    /// The in-place reordering gives what the copy `order.map(|i| items[i])`
    /// gives, for seeded random permutations of every size up to 300
    /// (identity, single cycles and many short cycles among them).
    #[test]
    fn permute_into_order_equals_the_copy() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for n in 0..300usize {
            let items: Vec<u64> = (0..n).map(|_| rng.random()).collect();
            let mut order: Vec<u32> = (0..n as u32).collect();
            if n % 3 != 0 {
                order.shuffle(&mut rng);
            }
            let copied: Vec<u64> = order.iter().map(|&i| items[i as usize]).collect();
            let mut permuted = items.clone();
            permute_into_order(&mut permuted, &order);
            assert_eq!(permuted, copied, "n = {n}");
        }
    }
}
