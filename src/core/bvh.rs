//! Bounding volume hierarchy over a mesh's triangles (the broadphase).
//!
//! Built as a binary tree of axis-aligned boxes by median split on the
//! longest axis of the triangles' centroids, leaves of at most [`LEAF_SIZE`]
//! triangles stored as contiguous ranges; then collapsed into a tree of
//! [`WIDTH`] children per node, the largest (by surface area) internal child
//! opened first. A node holds its children's boxes side by side (one
//! coordinate of the eight children per array, `f32` rounded outward, so
//! every box contains the exact one) and their indices: the eight boxes
//! are tested together, from one node of four cache lines fetched at once.
//! Eight children rather than four make the chain of nodes a sweep waits
//! for one after the other a third shorter (5.6 nodes opened instead of
//! 8.4 for a falling ball on 10^6 triangles). The collapse keeps the binary
//! tree's leaves and their order, so the triangle order (the mesh's storage
//! order) is the median split's.
//!
//! A sweep visits the leaves whose box, grown by the detection radius, the
//! path segment enters, nearer children first, and stops descending where
//! the entry lies beyond the best `α` found so far. What it enters it asks
//! the memory for as soon as it knows (the lines of a child node, the
//! triangle records of a leaf), before visiting the nearer ones. Traversal
//! allocates nothing.

use nalgebra::{Point3, Vector3};

use super::mesh::Triangle;

/// Most triangles per leaf.
pub const LEAF_SIZE: usize = 4;
/// Children per node.
pub const WIDTH: usize = 8;
/// Stack of the traversal: a node pushes at most `WIDTH - 1` entries more
/// than it pops, and the tree is no deeper than the binary tree it was
/// collapsed from (at most 31 levels for `u32` triangle positions, median
/// split halving each level).
const STACK_DEPTH: usize = WIDTH * 32;

/// What a traversal does with what it finds ([`Bvh::traverse_with`]).
pub trait Visit {
    /// Visits a leaf: its range of triangle positions. Returns the new
    /// cutoff (it may only shrink).
    fn leaf(&mut self, range: std::ops::Range<usize>) -> f64;

    /// A node was opened and its `boxes` child boxes tested.
    #[inline]
    fn node(&mut self, _boxes: usize) {}

    /// A leaf was entered within the cutoff: it is visited later unless
    /// the cutoff shrinks below its entry first (a time to fetch its
    /// triangles).
    #[inline]
    fn entered(&mut self, _range: std::ops::Range<usize>) {}
}

/// Asks for the cache lines of `*item` to be fetched, without waiting for
/// them (nothing where there is no prefetch instruction).
#[inline(always)]
pub fn prefetch<T>(item: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let start = item as *const T as *const i8;
        let mut offset = 0;
        while offset < std::mem::size_of::<T>() {
            // SAFETY: a prefetch reads nothing the program sees and
            // cannot fault; the address is within (or just past) `*item`.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
            offset += 64;
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = item;
}

/// One node: the boxes of its (up to) [`WIDTH`] children, and what each is.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    /// `lo[axis][child]`: the children's boxes' lower corners, rounded down.
    lo: [[f32; WIDTH]; 3],
    /// `hi[axis][child]`: upper corners, rounded up.
    hi: [[f32; WIDTH]; 3],
    /// Internal child: its node index. Leaf child: its first triangle
    /// position.
    child: [u32; WIDTH],
    /// Leaf child: its number of triangles (`1..=LEAF_SIZE`). Internal
    /// child: 0.
    count: [u8; WIDTH],
    /// How many of the slots are used (`1..=WIDTH`).
    len: u8,
}

/// A node of the binary tree the build makes first.
#[derive(Clone, Copy, Debug)]
struct BinaryNode {
    lo: Point3<f64>,
    hi: Point3<f64>,
    /// Leaf: first triangle. Internal: index of the left child (the right
    /// child follows it).
    first: u32,
    /// Leaf: number of triangles (> 0). Internal: 0.
    count: u32,
}

impl BinaryNode {
    fn half_area(&self) -> f64 {
        let e = self.hi - self.lo;
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// The largest `f32` not above `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// The smallest `f32` not below `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}

/// The hierarchy.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Exact bounds of the whole mesh.
    bounds: (Point3<f64>, Point3<f64>),
    /// Position in BVH order → index into the triangle list it was built from.
    order: Vec<u32>,
    /// Input triangle index → position in BVH order (`u32::MAX` if unused).
    position_by_index: Vec<u32>,
}

/// Builds the binary tree by median split; returns its nodes (the root
/// first) and the triangle order.
fn build_binary(triangles: &[Triangle]) -> (Vec<BinaryNode>, Vec<u32>) {
    let n = triangles.len();
    let mut boxes = Vec::with_capacity(n);
    let mut centroids = Vec::with_capacity(n);
    for t in triangles {
        let [a, b, c] = t.vertices;
        boxes.push((a.inf(&b).inf(&c), a.sup(&b).sup(&c)));
        centroids.push(Point3::from((a.coords + b.coords + c.coords) / 3.0));
    }
    let mut order: Vec<u32> = (0..n as u32).collect();
    let empty = BinaryNode {
        lo: Point3::origin(),
        hi: Point3::origin(),
        first: 0,
        count: 0,
    };
    let mut nodes = Vec::with_capacity(2 * n / LEAF_SIZE + 2);
    nodes.push(empty);
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
        nodes[node].lo = lo;
        nodes[node].hi = hi;
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
        nodes.push(empty);
        nodes.push(empty);
        nodes[node].first = left as u32;
        nodes[node].count = 0;
        work.push((left + 1, start + mid, end));
        work.push((left, start, start + mid));
    }
    (nodes, order)
}

/// Collapses the binary tree into nodes of up to [`WIDTH`] children, in
/// depth-first order (a node's children after it).
fn collapse(binary: &[BinaryNode]) -> Vec<Node> {
    let mut nodes: Vec<Node> = Vec::with_capacity(binary.len() / 2 + 1);
    // (binary node, wide node to fill); the root's children are the binary
    // root itself when it is a leaf.
    let mut work = vec![(0usize, 0usize)];
    nodes.push(empty_node());
    while let Some((b, w)) = work.pop() {
        let mut children: Vec<usize> = if binary[b].count > 0 {
            vec![b]
        } else {
            let l = binary[b].first as usize;
            vec![l, l + 1]
        };
        // Open the internal child of largest surface area until the node is
        // full or only leaves remain.
        while children.len() < WIDTH {
            let widest = children
                .iter()
                .enumerate()
                .filter(|&(_, &c)| binary[c].count == 0)
                .max_by(|a, b| {
                    binary[*a.1]
                        .half_area()
                        .total_cmp(&binary[*b.1].half_area())
                })
                .map(|(k, _)| k);
            let Some(k) = widest else { break };
            let l = binary[children[k]].first as usize;
            children[k] = l;
            children.insert(k + 1, l + 1);
        }
        let mut node = empty_node();
        node.len = children.len() as u8;
        for (slot, &c) in children.iter().enumerate() {
            let bn = &binary[c];
            for axis in 0..3 {
                node.lo[axis][slot] = round_down(bn.lo[axis]);
                node.hi[axis][slot] = round_up(bn.hi[axis]);
            }
            if bn.count > 0 {
                node.child[slot] = bn.first;
                node.count[slot] = bn.count as u8;
            } else {
                let index = nodes.len();
                nodes.push(empty_node());
                node.child[slot] = index as u32;
                node.count[slot] = 0;
                work.push((c, index));
            }
        }
        nodes[w] = node;
    }
    nodes
}

fn empty_node() -> Node {
    Node {
        lo: [[0.0; WIDTH]; 3],
        hi: [[0.0; WIDTH]; 3],
        child: [0; WIDTH],
        count: [0; WIDTH],
        len: 0,
    }
}

impl Bvh {
    /// Builds the hierarchy over `triangles`.
    pub fn build(triangles: &[Triangle]) -> Bvh {
        let (binary, order) = build_binary(triangles);
        let bounds = (binary[0].lo, binary[0].hi);
        let nodes = collapse(&binary);
        drop(binary);
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
            bounds,
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

    /// Bytes of one node, and of all the nodes (the array the traversal
    /// reads; the two index maps are not read by it).
    pub fn node_bytes(&self) -> (usize, usize) {
        let one = std::mem::size_of::<Node>();
        (one, one * self.nodes.len())
    }

    /// Bytes of the two index maps (position ↔ input index).
    pub fn map_bytes(&self) -> usize {
        4 * (self.order.len() + self.position_by_index.len())
    }

    /// Bounds of the whole mesh (exact, not rounded to `f32`).
    pub fn root_bounds(&self) -> (Point3<f64>, Point3<f64>) {
        self.bounds
    }

    /// Visits every leaf whose box lies within `radius` of `centre` (the
    /// distance from the point to the box, computed in `f64` from the boxes
    /// rounded outward; pass a radius with a margin for the rounding of the
    /// distance), in no particular order.
    pub fn within(
        &self,
        centre: &Point3<f64>,
        radius: f64,
        mut leaf: impl FnMut(std::ops::Range<usize>),
    ) {
        let limit = radius * radius;
        let mut stack = [0u32; STACK_DEPTH];
        let mut len = 0usize;
        let mut node_index = 0u32;
        loop {
            let node = &self.nodes[node_index as usize];
            let mut distance = [0.0f64; WIDTH];
            for axis in 0..3 {
                let p = centre[axis];
                for (c, d2) in distance.iter_mut().enumerate() {
                    let below = node.lo[axis][c] as f64 - p;
                    let above = p - node.hi[axis][c] as f64;
                    let d = below.max(above).max(0.0);
                    *d2 += d * d;
                }
            }
            for (c, &d2) in distance.iter().enumerate().take(node.len as usize) {
                if d2 > limit {
                    continue;
                }
                let (child, count) = (node.child[c], node.count[c]);
                if count == 0 {
                    prefetch(&self.nodes[child as usize]);
                    stack[len] = child;
                    len += 1;
                } else {
                    leaf(child as usize..child as usize + count as usize);
                }
            }
            if len == 0 {
                return;
            }
            len -= 1;
            node_index = stack[len];
        }
    }

    /// Visits, nearer first, every leaf whose box grown by `grow` is entered
    /// by the segment `p0 + t d`, `t ∈ [0, 1]`, at some `t ≤ cutoff`.
    /// `leaf` receives the range of triangle positions and returns the new
    /// cutoff (it may only shrink).
    #[inline]
    pub fn traverse(
        &self,
        p0: &Point3<f64>,
        d: &Vector3<f64>,
        grow: f64,
        cutoff: f64,
        leaf: impl FnMut(std::ops::Range<usize>) -> f64,
    ) {
        struct Leaves<F>(F);
        impl<F: FnMut(std::ops::Range<usize>) -> f64> Visit for Leaves<F> {
            #[inline]
            fn leaf(&mut self, range: std::ops::Range<usize>) -> f64 {
                (self.0)(range)
            }
        }
        self.traverse_with(p0, d, grow, cutoff, &mut Leaves(leaf));
    }

    /// [`Bvh::traverse`] with a [`Visit`]or, which is also told of every
    /// node opened and of every leaf entered before it is visited.
    #[inline]
    pub fn traverse_with(
        &self,
        p0: &Point3<f64>,
        d: &Vector3<f64>,
        grow: f64,
        mut cutoff: f64,
        visit: &mut impl Visit,
    ) {
        let inv = Vector3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        // (child, count, entry): a node (count 0) or a leaf range.
        let mut stack = [(0u32, 0u8, 0.0f64); STACK_DEPTH];
        let mut len = 0usize;
        let mut node_index = 0u32;
        loop {
            let node = &self.nodes[node_index as usize];
            visit.node(node.len as usize);
            let entries = entries(node, p0, d, &inv, grow);
            // The entered children within the cutoff, nearest last, pushed
            // so that the nearest is popped first.
            let base = len;
            for (slot, &t) in entries.iter().enumerate().take(node.len as usize) {
                if t <= cutoff {
                    let item = (node.child[slot], node.count[slot], t);
                    // Fetch what the child holds while the nearer ones are
                    // visited.
                    if item.1 == 0 {
                        prefetch(&self.nodes[item.0 as usize]);
                    } else {
                        let start = item.0 as usize;
                        visit.entered(start..start + item.1 as usize);
                    }
                    let mut k = len;
                    while k > base && stack[k - 1].2 < t {
                        stack[k] = stack[k - 1];
                        k -= 1;
                    }
                    stack[k] = item;
                    len += 1;
                }
            }
            // Next node: pop leaves (visiting them) until a node within the
            // cutoff comes up.
            loop {
                if len == 0 {
                    return;
                }
                len -= 1;
                let (child, count, t) = stack[len];
                if t > cutoff {
                    continue;
                }
                if count == 0 {
                    node_index = child;
                    break;
                }
                let start = child as usize;
                cutoff = visit.leaf(start..start + count as usize).min(cutoff);
            }
        }
    }
}

/// Entry parameter of the segment `p0 + t d` into each child box of `node`
/// grown by `grow`, clamped to `[0, 1]`; infinite where the segment misses
/// it. `inv` is `1 / d` by component.
#[inline]
fn entries(
    node: &Node,
    p0: &Point3<f64>,
    d: &Vector3<f64>,
    inv: &Vector3<f64>,
    grow: f64,
) -> [f64; WIDTH] {
    let mut t0 = [0.0f64; WIDTH];
    let mut t1 = [1.0f64; WIDTH];
    let mut outside = [false; WIDTH];
    for axis in 0..3 {
        let (p, inv) = (p0[axis], inv[axis]);
        if d[axis] == 0.0 {
            for (c, out) in outside.iter_mut().enumerate() {
                let lo = node.lo[axis][c] as f64 - grow;
                let hi = node.hi[axis][c] as f64 + grow;
                *out |= p < lo || p > hi;
            }
        } else {
            for c in 0..WIDTH {
                let a = (node.lo[axis][c] as f64 - grow - p) * inv;
                let b = (node.hi[axis][c] as f64 + grow - p) * inv;
                let (near, far) = if a <= b { (a, b) } else { (b, a) };
                t0[c] = t0[c].max(near);
                t1[c] = t1[c].min(far);
            }
        }
    }
    let mut out = [f64::INFINITY; WIDTH];
    for c in 0..WIDTH {
        if !outside[c] && t0[c] <= t1[c] {
            out[c] = t0[c];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{WIDTH, round_down, round_up};
    use crate::core::Mesh;
    use crate::core::mesh::Triangle;

    /// A seeded soup of `n` triangles: small ones scattered in a cube,
    /// with some large and some thin ones among them.
    fn random_mesh(rng: &mut ChaCha8Rng, n: usize) -> Mesh {
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for t in 0..n {
            let c = [0; 3].map(|_| rng.random_range(-20.0..20.0));
            let size = match t % 7 {
                0 => 8.0,
                1 => 0.01,
                _ => 1.0,
            };
            for _ in 0..3 {
                vertices.push([0, 1, 2].map(|k| c[k] + size * rng.random_range(-1.0..1.0)));
            }
            let base = 3 * t as u64;
            triangles.push([base, base + 1, base + 2]);
        }
        Mesh::new(vertices, &triangles).expect("random soup")
    }

    fn exact_box(t: &Triangle) -> (Point3<f64>, Point3<f64>) {
        let [a, b, c] = t.vertices;
        (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
    }

    /// Entry of `p0 + t d`, `t ∈ [0, 1]`, into the box grown by `grow`, in
    /// exact-enough f64 with the box never rounded (the oracle).
    fn entry(
        lo: &Point3<f64>,
        hi: &Point3<f64>,
        p0: &Point3<f64>,
        d: &Vector3<f64>,
        grow: f64,
    ) -> Option<f64> {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let (lo, hi) = (lo[k] - grow, hi[k] + grow);
            if d[k] == 0.0 {
                if p0[k] < lo || p0[k] > hi {
                    return None;
                }
            } else {
                let (a, b) = ((lo - p0[k]) / d[k], (hi - p0[k]) / d[k]);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        (t0 <= t1).then_some(t0)
    }

    /// `within` visits every triangle whose exact box lies within the
    /// radius of the point (and, for each visited, its whole leaf once),
    /// on random soups, points and radii.
    #[test]
    fn within_visits_every_triangle_whose_box_is_within_reach() {
        let mut rng = ChaCha8Rng::seed_from_u64(46);
        for n in [1usize, 5, 40, 700] {
            let mesh = random_mesh(&mut rng, n);
            let bvh = mesh.bvh();
            for _ in 0..300 {
                let p = Point3::from([0; 3].map(|_| rng.random_range(-25.0..25.0)));
                let radius = rng.random_range(0.0..6.0);
                let mut visited = vec![0u32; mesh.triangles().len()];
                bvh.within(&p, radius, |range| {
                    for position in range {
                        visited[position] += 1;
                    }
                });
                assert!(visited.iter().all(|&v| v <= 1), "a triangle visited twice");
                let mut near = 0;
                for (position, t) in mesh.triangles().iter().enumerate() {
                    let (lo, hi) = exact_box(t);
                    let d2: f64 = (0..3)
                        .map(|k| {
                            let d = (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0);
                            d * d
                        })
                        .sum();
                    if d2 <= radius * radius {
                        near += 1;
                        assert_eq!(visited[position], 1, "triangle at {position} missed");
                    }
                }
                // Leaves hold their neighbours too, but not the whole mesh
                // every time.
                assert!(visited.iter().sum::<u32>() as usize >= near);
            }
        }
    }

    #[test]
    fn rounding_is_outward() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for _ in 0..100_000 {
            let x: f64 = rng.random_range(-1e3..1e3) * 10f64.powi(rng.random_range(-30..30));
            assert!(
                (round_down(x) as f64) <= x && (round_up(x) as f64) >= x,
                "{x}"
            );
            assert!(round_up(x) <= round_down(x).next_up().next_up(), "{x}");
        }
        for x in [0.0, -0.0, 1.0, 1e300, -1e300, f64::MIN_POSITIVE] {
            assert!(
                (round_down(x) as f64) <= x && (round_up(x) as f64) >= x,
                "{x}"
            );
        }
    }

    /// Every triangle sits in exactly one leaf, and every box of the tree
    /// contains the exact boxes of the triangles below it.
    #[test]
    fn leaves_partition_the_triangles_and_boxes_contain_them() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        for n in [1usize, 2, 3, 4, 5, 7, 16, 17, 100, 1000] {
            let mesh = random_mesh(&mut rng, n);
            let bvh = mesh.bvh();
            let mut seen = vec![0u32; mesh.triangles().len()];
            // (node, box that must contain it)
            let mut work = vec![0usize];
            while let Some(i) = work.pop() {
                let node = &bvh.nodes[i];
                assert!((1..=WIDTH).contains(&(node.len as usize)));
                for slot in 0..node.len as usize {
                    let (lo, hi) = (
                        Point3::from([0, 1, 2].map(|k| node.lo[k][slot] as f64)),
                        Point3::from([0, 1, 2].map(|k| node.hi[k][slot] as f64)),
                    );
                    let mut below = Vec::new();
                    if node.count[slot] > 0 {
                        let first = node.child[slot] as usize;
                        below.extend(first..first + node.count[slot] as usize);
                    } else {
                        work.push(node.child[slot] as usize);
                        // Every triangle below the child: walk its subtree.
                        let mut sub = vec![node.child[slot] as usize];
                        while let Some(j) = sub.pop() {
                            let m = &bvh.nodes[j];
                            for s in 0..m.len as usize {
                                if m.count[s] > 0 {
                                    let f = m.child[s] as usize;
                                    below.extend(f..f + m.count[s] as usize);
                                } else {
                                    sub.push(m.child[s] as usize);
                                }
                            }
                        }
                    }
                    for p in below {
                        let (tl, th) = exact_box(&mesh.triangles()[p]);
                        assert!(
                            (0..3).all(|k| lo[k] <= tl[k] && th[k] <= hi[k]),
                            "n = {n}: box of slot {slot} of node {i} misses triangle {p}"
                        );
                    }
                    if node.count[slot] > 0 {
                        let first = node.child[slot] as usize;
                        for s in &mut seen[first..first + node.count[slot] as usize] {
                            *s += 1;
                        }
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "n = {n}: {seen:?}");
        }
    }

    /// Against brute force on seeded random meshes and segments: the
    /// traversal hands over every triangle whose exact box grown by `grow`
    /// the segment enters at or before the cutoff, each once, and only
    /// triangles whose box meets the box of the path grown by `grow`.
    #[test]
    fn traverse_equals_brute_force() {
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let mut handed_total = 0usize;
        for n in [1usize, 5, 64, 300, 2000] {
            let mesh = random_mesh(&mut rng, n);
            let triangles = mesh.triangles();
            for case in 0..400 {
                let p0 = Point3::from([0; 3].map(|_| rng.random_range(-25.0..25.0)));
                let mut d = Vector3::from([0; 3].map(|_| rng.random_range(-10.0..10.0)));
                // Axis-parallel and degenerate paths too.
                match case % 5 {
                    0 => d.x = 0.0,
                    1 => {
                        d.y = 0.0;
                        d.z = 0.0;
                    }
                    2 if case % 15 == 2 => d = Vector3::zeros(),
                    _ => {}
                }
                let grow = [0.0, 0.25, 2.0][case % 3];
                let cutoff = if case % 4 == 0 { 0.5 } else { 1.0 };
                let mut handed = vec![0u32; triangles.len()];
                mesh.bvh().traverse(&p0, &d, grow, cutoff, |range| {
                    for p in range {
                        handed[p] += 1;
                    }
                    cutoff
                });
                let p1 = p0 + d;
                let (path_lo, path_hi) = (p0.inf(&p1), p0.sup(&p1));
                for (p, t) in triangles.iter().enumerate() {
                    let (lo, hi) = exact_box(t);
                    assert!(handed[p] <= 1, "triangle {p} handed twice");
                    if entry(&lo, &hi, &p0, &d, grow).is_some_and(|e| e <= cutoff) {
                        assert_eq!(handed[p], 1, "n = {n}, case {case}: triangle {p} missed");
                    }
                    if handed[p] == 1 {
                        handed_total += 1;
                        let meets = (0..3)
                            .all(|k| lo[k] - grow <= path_hi[k] && path_lo[k] <= hi[k] + grow);
                        // Leaves hold up to LEAF_SIZE triangles: the others
                        // of an entered leaf may be handed over too, but
                        // never one far from the path (more than a leaf's
                        // extent, which these meshes keep below 40).
                        assert!(
                            meets
                                || (0..3).all(|k| {
                                    lo[k] - grow - 40.0 <= path_hi[k]
                                        && path_lo[k] <= hi[k] + grow + 40.0
                                }),
                            "n = {n}, case {case}: triangle {p} is far from the path"
                        );
                    }
                }
            }
        }
        assert!(
            handed_total > 10_000,
            "too few triangles handed over: {handed_total}"
        );
    }
}
