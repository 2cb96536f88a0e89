//! Built-in scenes: small meshes to try the core on and to record from.

use serde::{Deserialize, Serialize};

/// A named mesh as plain data (what a trace's `/scene` message holds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneMesh {
    /// Name of the scene.
    pub name: String,
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Vertex-index triples, counter-clockwise seen from the front.
    pub triangles: Vec<[u64; 3]>,
}

/// The unit cube `[-1, 1]³` as 12 outward-facing triangles.
pub fn cube() -> SceneMesh {
    let mut vertices = Vec::with_capacity(8);
    for i in 0..8 {
        let c = |bit: usize| if i & bit != 0 { 1.0 } else { -1.0 };
        vertices.push([c(1), c(2), c(4)]);
    }
    // Vertex index = x + 2y + 4z with bits set for +1.
    let quads: [[u64; 4]; 6] = [
        [1, 3, 7, 5], // +x
        [0, 4, 6, 2], // -x
        [2, 6, 7, 3], // +y
        [0, 1, 5, 4], // -y
        [4, 5, 7, 6], // +z
        [0, 2, 3, 1], // -z
    ];
    let mut triangles = Vec::with_capacity(12);
    for [a, b, c, d] in quads {
        triangles.push([a, b, c]);
        triangles.push([a, c, d]);
    }
    SceneMesh { name: "cube".into(), vertices, triangles }
}

/// The triangle `(0,0,0), (4,0,0), (0,4,0)` of SEMANTICS.md's worked
/// examples, front normal `+z`.
pub fn triangle() -> SceneMesh {
    SceneMesh {
        name: "triangle".into(),
        vertices: vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    }
}

/// Names of the built-in scenes [`by_name`] knows.
pub const NAMES: &[&str] = &["cube", "triangle"];

/// A built-in scene by name.
pub fn by_name(name: &str) -> Option<SceneMesh> {
    match name {
        "cube" => Some(cube()),
        "triangle" => Some(triangle()),
        _ => None,
    }
}

impl SceneMesh {
    /// Builds the collision mesh.
    pub fn to_mesh(&self) -> Result<crate::core::Mesh, crate::core::MeshError> {
        crate::core::Mesh::new(self.vertices.clone(), &self.triangles)
    }
}
