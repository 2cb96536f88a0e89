//! Bounding volume hierarchy over a mesh's triangles (the broadphase).
//!
//! A binary tree of axis-aligned boxes built by median split on the longest
//! axis of the triangles' centroids, leaves of at most [`LEAF_SIZE`]
//! triangles stored as contiguous ranges. A sweep visits the leaves whose box,
//! grown by the detection radius, the path segment enters, nearest entry
//! first, and stops descending where the entry lies beyond the best `α`
//! found so far. Traversal allocates nothing.

use nalgebra::{Point3, Vector3};

use super::mesh::Triangle;

/// Most triangles per leaf.
pub const LEAF_SIZE: usize = 4;
const STACK_DEPTH: usize = 96;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f64; 3],
    max: [f64; 3],
    /// Leaf: first triangle. Internal: index of the left child (the right
    /// child follows it).
    first: u32,
    /// Leaf: number of triangles (> 0). Internal: 0.
    count: u32,
}

/// The hierarchy.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Position in BVH order → index into the triangle list it was built from.
    order: Vec<u32>,
    /// Input triangle index → position in BVH order (`u32::MAX` if unused).
    position_by_index: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over `triangles`.
    pub fn build(triangles: &[Triangle]) -> Bvh {
        let n = triangles.len();
        let mut boxes = Vec::with_capacity(n);
        let mut centroids = Vec::with_capacity(n);
        for t in triangles {
            let [a, b, c] = t.vertices;
            boxes.push((a.inf(&b).inf(&c), a.sup(&b).sup(&c)));
            centroids.push(Point3::from((a.coords + b.coords + c.coords) / 3.0));
        }
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF_SIZE + 2);
        nodes.push(Node {
            min: [0.0; 3],
            max: [0.0; 3],
            first: 0,
            count: 0,
        });
        // Iterative build: (node index, start, end).
        let mut work = vec![(0usize, 0usize, n)];
        while let Some((node, start, end)) = work.pop() {
            let slice = &mut order[start..end];
            let (mut lo, mut hi) = boxes[slice[0] as usize];
            let mut clo = centroids[slice[0] as usize];
            let mut chi = clo;
            for &i in slice.iter() {
                let (bl, bh) = boxes[i as usize];
                lo = lo.inf(&bl);
                hi = hi.sup(&bh);
                clo = clo.inf(&centroids[i as usize]);
                chi = chi.sup(&centroids[i as usize]);
            }
            nodes[node].min = lo.coords.into();
            nodes[node].max = hi.coords.into();
            if end - start <= LEAF_SIZE {
                nodes[node].first = start as u32;
                nodes[node].count = (end - start) as u32;
                continue;
            }
            let extent = chi - clo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = (end - start) / 2;
            slice.select_nth_unstable_by(mid, |&i, &j| {
                centroids[i as usize][axis].total_cmp(&centroids[j as usize][axis])
            });
            let left = nodes.len();
            nodes.push(Node {
                min: [0.0; 3],
                max: [0.0; 3],
                first: 0,
                count: 0,
            });
            nodes.push(Node {
                min: [0.0; 3],
                max: [0.0; 3],
                first: 0,
                count: 0,
            });
            nodes[node].first = left as u32;
            nodes[node].count = 0;
            work.push((left + 1, start + mid, end));
            work.push((left, start, start + mid));
        }
        let max_index = triangles
            .iter()
            .map(|t| t.index as usize + 1)
            .max()
            .unwrap_or(0);
        let mut position_by_index = vec![u32::MAX; max_index];
        for (pos, &i) in order.iter().enumerate() {
            position_by_index[triangles[i as usize].index as usize] = pos as u32;
        }
        Bvh {
            nodes,
            order,
            position_by_index,
        }
    }

    /// Position in BVH order → index in the list the tree was built from.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// Position in BVH order of the triangle with input index `index`.
    pub fn position_of(&self, index: u32) -> Option<usize> {
        match self.position_by_index.get(index as usize) {
            Some(&p) if p != u32::MAX => Some(p as usize),
            _ => None,
        }
    }

    /// Bounds of the whole mesh.
    pub fn root_bounds(&self) -> (Point3<f64>, Point3<f64>) {
        let r = &self.nodes[0];
        (Point3::from(r.min), Point3::from(r.max))
    }

    /// Visits, nearest first, every leaf whose box grown by `grow` is entered
    /// by the segment `p0 + t d`, `t ∈ [0, 1]`, at some `t ≤ cutoff`.
    /// `leaf` receives the range of triangle positions and returns the new
    /// cutoff (it may only shrink).
    #[inline]
    pub fn traverse(
        &self,
        p0: &Point3<f64>,
        d: &Vector3<f64>,
        grow: f64,
        mut cutoff: f64,
        mut leaf: impl FnMut(std::ops::Range<usize>) -> f64,
    ) {
        let inv = Vector3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        let mut stack = [(0u32, 0.0f64); STACK_DEPTH];
        let mut len = 0usize;
        if let Some(t) = self.entry(0, p0, d, &inv, grow) {
            stack[0] = (0, t);
            len = 1;
        }
        while len > 0 {
            len -= 1;
            let (index, t_entry) = stack[len];
            if t_entry > cutoff {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let start = node.first as usize;
                cutoff = leaf(start..start + node.count as usize).min(cutoff);
                continue;
            }
            let l = node.first;
            let r = l + 1;
            let tl = self.entry(l, p0, d, &inv, grow);
            let tr = self.entry(r, p0, d, &inv, grow);
            // Push the farther child first so the nearer one is visited first.
            let mut push = |i: u32, t: Option<f64>| {
                if let Some(t) = t
                    && t <= cutoff
                    && len < STACK_DEPTH
                {
                    stack[len] = (i, t);
                    len += 1;
                }
            };
            match (tl, tr) {
                (Some(a), Some(b)) if b < a => {
                    push(l, tl);
                    push(r, tr);
                }
                _ => {
                    push(r, tr);
                    push(l, tl);
                }
            }
        }
    }

    /// Entry parameter of the segment into node `i`'s box grown by `grow`,
    /// clamped to `[0, 1]`, or `None` if the segment misses it.
    #[inline]
    fn entry(
        &self,
        i: u32,
        p0: &Point3<f64>,
        d: &Vector3<f64>,
        inv: &Vector3<f64>,
        grow: f64,
    ) -> Option<f64> {
        let n = &self.nodes[i as usize];
        let mut t0 = 0.0f64;
        let mut t1 = 1.0f64;
        for k in 0..3 {
            let lo = n.min[k] - grow;
            let hi = n.max[k] + grow;
            if d[k] == 0.0 {
                if p0[k] < lo || p0[k] > hi {
                    return None;
                }
            } else {
                let a = (lo - p0[k]) * inv[k];
                let b = (hi - p0[k]) * inv[k];
                let (near, far) = if a <= b { (a, b) } else { (b, a) };
                t0 = t0.max(near);
                t1 = t1.min(far);
                if t0 > t1 {
                    return None;
                }
            }
        }
        Some(t0)
    }
}
