//! The colors (RGBA, 8 bits each) of what both recordings draw, the Rerun
//! recording (`viz`) and the Foxglove file (`foxglove`), so the two look
//! alike.

/// The mesh.
pub const MESH_COLOR: [u8; 4] = [170, 175, 185, 255];
/// The mesh's triangle edges.
pub const WIREFRAME_COLOR: [u8; 4] = [45, 50, 60, 255];
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
