//! Which normal the hits of a scene report under the engine's normal
//! convention ([`NormalRule`]): the face normal, the contact normal, or the
//! contact normal at active edges only, with the scene's active edges.

use crate::core::{EdgeClass, Feature, Mesh, Outcome, Sweep, Topology};

use crate::conventions::{ACTIVE_EDGE_DEGREES, NormalRule};

/// Which normal the hits of a scene report ([`NormalRule`]), with what the
/// rule needs of the scene: for [`NormalRule::ActiveEdges`], each
/// triangle's edges that are not active.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneNormals {
    /// The rule.
    pub rule: NormalRule,
    /// By input triangle: bit `i` set when edge `i` is *not* active (empty
    /// unless the rule is [`NormalRule::ActiveEdges`]).
    inactive: Vec<u8>,
}

impl SceneNormals {
    /// The normals of `rule` over `mesh` and its `topology`.
    pub fn new(rule: NormalRule, mesh: &Mesh, topology: &Topology) -> SceneNormals {
        let inactive = if rule == NormalRule::ActiveEdges {
            inactive_edges(mesh, topology)
        } else {
            Vec::new()
        };
        SceneNormals { rule, inactive }
    }

    /// Whether feature `feature` of `triangle` reports the contact normal.
    pub fn contact_normal_at(&self, triangle: u32, feature: Feature) -> bool {
        let inactive = |edge: u8| {
            self.inactive
                .get(triangle as usize)
                .is_some_and(|bits| bits & (1 << edge) != 0)
        };
        match (self.rule, feature) {
            (_, Feature::Face) | (NormalRule::Face, _) => false,
            (NormalRule::Contact, _) => true,
            (NormalRule::ActiveEdges, Feature::Edge(e)) => !inactive(e),
            // Vertex `v` is where edges `v` and `v + 2 mod 3` meet.
            (NormalRule::ActiveEdges, Feature::Vertex(v)) => !inactive(v) || !inactive((v + 2) % 3),
        }
    }

    /// The normal a hit at `alpha` of `sweep` on `feature` of `triangle`,
    /// touching `contact`, reports: `face_normal` (the rules' normal there)
    /// or the contact normal, `(centre − contact) / |centre − contact|`
    /// with the centre at `alpha` (the face normal when the two coincide).
    pub fn normal(
        &self,
        sweep: &Sweep,
        alpha: f64,
        triangle: u32,
        feature: Feature,
        contact: &nalgebra::Point3<f64>,
        face_normal: nalgebra::Vector3<f64>,
    ) -> nalgebra::Vector3<f64> {
        if !self.contact_normal_at(triangle, feature) {
            return face_normal;
        }
        let centre = sweep.p0 + (sweep.p1 - sweep.p0) * alpha;
        let towards = centre - contact;
        let length = towards.norm();
        if length > 0.0 && length.is_finite() {
            towards / length
        } else {
            face_normal
        }
    }

    /// `outcome` with the normal this rule reports.
    pub fn apply(&self, sweep: &Sweep, mut outcome: Outcome) -> Outcome {
        if let Some(hit) = outcome.hit.as_mut() {
            hit.normal = self.normal(
                sweep,
                hit.alpha,
                hit.triangle,
                hit.feature,
                &hit.contact,
                hit.normal,
            );
        }
        outcome
    }
}

/// By input triangle, the bits of its edges that are not active (see
/// [`NormalRule::ActiveEdges`]): flat and concave edges, and convex ones
/// whose faces meet at [`ACTIVE_EDGE_DEGREES`] or less.
fn inactive_edges(mesh: &Mesh, topology: &Topology) -> Vec<u8> {
    let cos_threshold = ACTIVE_EDGE_DEGREES.to_radians().cos();
    let count = mesh
        .triangles()
        .iter()
        .map(|t| t.index + 1)
        .max()
        .unwrap_or(0);
    let mut bits = vec![0u8; count as usize];
    for t in mesh.triangles() {
        for e in 0..3u8 {
            let Some(edge) = topology.triangle_edge(t.index, e) else {
                continue;
            };
            let active = match edge.class {
                EdgeClass::Boundary | EdgeClass::NonManifold => true,
                EdgeClass::Flat | EdgeClass::Concave => false,
                EdgeClass::Convex => {
                    let [a, b] = edge.triangles;
                    match (mesh.triangle_by_index(a), mesh.triangle_by_index(b)) {
                        (Some(a), Some(b)) => a.normal.dot(&b.normal) < cos_threshold,
                        _ => true,
                    }
                }
            };
            if !active {
                bits[t.index as usize] |= 1 << e;
            }
        }
    }
    bits
}
