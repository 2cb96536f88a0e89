//! The colors (RGBA, 8 bits each) of what both recordings draw, the Rerun
//! recording (`viz`) and the Foxglove file (`foxglove`), so the two look
//! alike, and how many defect labels they draw.

/// A scene's defects are labelled in the 3D views when it has at most this
/// many; beyond, their labels would cover the mesh (a modelled scene can
/// have dozens of T-junctions where parts meet), so only the markers are
/// drawn and each defect's label is in the data (the Rerun viewer shows it
/// on hover and can switch the labels on; the Foxglove entity lists them in
/// its metadata).
pub const MAX_DRAWN_DEFECT_LABELS: usize = 4;

/// The mesh.
pub const MESH_COLOR: [u8; 4] = [170, 175, 185, 255];
/// The mesh's flat internal edges (two triangles in one plane): faint,
/// they are where most of a mesh's edges are and the least interesting.
pub const FLAT_EDGE_COLOR: [u8; 4] = [45, 50, 60, 90];
/// The mesh's convex edges (a ridge seen from the front).
pub const CONVEX_EDGE_COLOR: [u8; 4] = [40, 80, 220, 255];
/// The mesh's concave edges (a valley seen from the front).
pub const CONCAVE_EDGE_COLOR: [u8; 4] = [0, 160, 120, 255];
/// The mesh's boundary edges (one triangle only): loud.
pub const BOUNDARY_EDGE_COLOR: [u8; 4] = [255, 165, 0, 255];
/// The mesh's non-manifold edges (three triangles or more): loud.
pub const NON_MANIFOLD_EDGE_COLOR: [u8; 4] = [150, 40, 255, 255];
/// The marker of a mesh defect (flipped triangle, crack, ...).
pub const DEFECT_COLOR: [u8; 4] = [255, 0, 170, 255];
/// The ball at the start of its sweep.
pub const P0_COLOR: [u8; 4] = [80, 140, 255, 90];
/// The ball at the end of its sweep.
pub const P1_COLOR: [u8; 4] = [160, 160, 160, 60];
/// The ball at the contact.
pub const CONTACT_BALL_COLOR: [u8; 4] = [255, 140, 0, 140];
/// The swept volume and the path.
pub const SWEEP_COLOR: [u8; 4] = [120, 170, 255, 255];
/// The contact point.
pub const HIT_COLOR: [u8; 4] = [230, 40, 40, 255];
/// The nearest miss (the viewer only).
#[cfg_attr(not(feature = "viewer"), allow(dead_code))]
pub const MISS_COLOR: [u8; 4] = [240, 200, 40, 255];
/// The reported normal.
pub const NORMAL_COLOR: [u8; 4] = [40, 200, 80, 255];
/// The expected outcome, where it diverges.
pub const EXPECTED_COLOR: [u8; 4] = [230, 60, 230, 255];
/// The marker where a ball's centre went through a triangle (the viewer
/// only).
#[cfg_attr(not(feature = "viewer"), allow(dead_code))]
pub const TUNNEL_COLOR: [u8; 4] = [255, 0, 90, 255];
/// A ghost contact's mark: the point and its (tilted) normal.
pub const GHOST_COLOR: [u8; 4] = [0, 215, 255, 255];
/// The faces' normal drawn beside a ghost contact's normal.
pub const FACE_NORMAL_COLOR: [u8; 4] = [245, 245, 245, 255];
