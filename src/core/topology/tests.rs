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

#[test]
fn defects_along_a_path_within_its_radius() {
    let (v, mut t) = floor(3, 3);
    // Triangle 9: (1,1), (2,2), (1,2), wound the other way.
    t[9].swap(1, 2);
    let topo = Topology::new(&v, &t).unwrap();
    let vertices: Vec<Point3<f64>> = v.iter().map(|p| Point3::from(*p)).collect();
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    // Straight down through it.
    let through = topo.defects_along(&vertices, &p(1.2, 1.6, 1.0), &p(1.2, 1.6, -1.0), 0.1);
    assert_eq!(through.len(), 1);
    assert_eq!(through[0].0.triangles, vec![9]);
    assert_eq!(through[0].1, 0.0);
    // Down beside it, 0.3 left of its edge x = 1: out of reach at 0.2, in
    // reach at 0.5.
    let (a, b) = (p(0.7, 1.5, 1.0), p(0.7, 1.5, -1.0));
    assert!(topo.defects_along(&vertices, &a, &b, 0.2).is_empty());
    let near = topo.defects_along(&vertices, &a, &b, 0.5);
    assert_eq!(near.len(), 1);
    assert!((near[0].1 - 0.3).abs() < 1e-12, "{}", near[0].1);
    // Level over it, 0.25 above: the segment's distance, not its ends'.
    let over = topo.defects_along(&vertices, &p(0.0, 1.8, 0.25), &p(3.0, 1.8, 0.25), 0.3);
    assert_eq!(over.len(), 1);
    assert!((over[0].1 - 0.25).abs() < 1e-12, "{}", over[0].1);
}
