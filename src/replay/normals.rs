//! Which normal the hits of a scene report under the engine's normal
//! convention ([`NormalRule`]): the face normal, the contact normal, or the
//! contact normal at active edges only, with the scene's active edges.

use nalgebra::Vector3;

use crate::core::topology::{EdgeClass, Topology};
use crate::core::{Feature, Mesh, Outcome, Sweep};

use crate::conventions::{ACTIVE_EDGE_DEGREES, ACTIVE_EDGE_KEEP_DEGREES, NormalRule};

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
    /// By input triangle: its front normal (empty unless the rule is
    /// [`NormalRule::ActiveEdges`]), for the contact normal kept within
    /// [`ACTIVE_EDGE_KEEP_DEGREES`] of it.
    fronts: Vec<Vector3<f64>>,
}

impl SceneNormals {
    /// The normals of `rule` over `mesh` and its `topology`.
    pub fn new(rule: NormalRule, mesh: &Mesh, topology: &Topology) -> SceneNormals {
        let (inactive, fronts) = if rule == NormalRule::ActiveEdges {
            (inactive_edges(mesh, topology), front_normals(mesh))
        } else {
            (Vec::new(), Vec::new())
        };
        SceneNormals {
            rule,
            inactive,
            fronts,
        }
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
        let contact_normal = || {
            let centre = sweep.p0 + (sweep.p1 - sweep.p0) * alpha;
            let towards = centre - contact;
            let length = towards.norm();
            (length > 0.0 && length.is_finite()).then(|| towards / length)
        };
        self.rule_normal(triangle, feature, contact_normal, face_normal)
    }

    /// The normal this rule reports on `feature` of `triangle`, given the
    /// contact normal there (`contact_normal`, asked only when the rule
    /// needs it; `None` when the centre is on the mesh) and the face normal
    /// (the rules' normal there).
    pub fn rule_normal(
        &self,
        triangle: u32,
        feature: Feature,
        contact_normal: impl FnOnce() -> Option<Vector3<f64>>,
        face_normal: Vector3<f64>,
    ) -> Vector3<f64> {
        self.rule_normal_of(Query::Sweep, triangle, feature, contact_normal, face_normal)
    }

    /// [`SceneNormals::rule_normal`] for a contact query: under
    /// [`NormalRule::ActiveEdges`] an inactive feature answers the face
    /// normal whatever the angle (Jolt's `CollideSphereVsTriangles`; the
    /// [`ACTIVE_EDGE_KEEP_DEGREES`] exception is its shape cast's).
    pub fn contact_rule_normal(
        &self,
        triangle: u32,
        feature: Feature,
        contact_normal: Vector3<f64>,
        face_normal: Vector3<f64>,
    ) -> Vector3<f64> {
        self.rule_normal_of(
            Query::Contact,
            triangle,
            feature,
            || Some(contact_normal),
            face_normal,
        )
    }

    fn rule_normal_of(
        &self,
        query: Query,
        triangle: u32,
        feature: Feature,
        contact_normal: impl FnOnce() -> Option<Vector3<f64>>,
        face_normal: Vector3<f64>,
    ) -> Vector3<f64> {
        if self.contact_normal_at(triangle, feature) {
            return contact_normal().unwrap_or(face_normal);
        }
        if query == Query::Sweep && self.keeps_near_contact_normal(triangle, feature) {
            // Jolt keeps a contact normal within 1° of the triangle's own
            // (on the side the hit faces).
            let Some(front) = self.fronts.get(triangle as usize) else {
                return face_normal;
            };
            let own = if front.dot(&face_normal) < 0.0 {
                -front
            } else {
                *front
            };
            let keep = ACTIVE_EDGE_KEEP_DEGREES.to_radians().cos();
            if let Some(n) = contact_normal().filter(|n| n.dot(&own) > keep) {
                return n;
            }
        }
        face_normal
    }

    /// Whether an inactive edge or vertex hit on `triangle` keeps a contact
    /// normal near the face's ([`ACTIVE_EDGE_KEEP_DEGREES`]): under
    /// [`NormalRule::ActiveEdges`], when the triangle has an active edge.
    fn keeps_near_contact_normal(&self, triangle: u32, feature: Feature) -> bool {
        self.rule == NormalRule::ActiveEdges
            && feature != Feature::Face
            && self
                .inactive
                .get(triangle as usize)
                .is_some_and(|bits| bits & 0b111 != 0b111)
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

/// Which query a normal is for (the active-edge rule differs in one case).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Query {
    Sweep,
    Contact,
}

/// By input triangle, its front normal (zero for a triangle left out).
fn front_normals(mesh: &Mesh) -> Vec<Vector3<f64>> {
    let mut fronts = vec![Vector3::zeros(); mesh.input_triangle_count()];
    for t in mesh.triangles() {
        fronts[t.index as usize] = t.normal;
    }
    fronts
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

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, Vector3};

    use super::SceneNormals;
    use crate::conventions::NormalRule;
    use crate::core::topology::Topology;
    use crate::core::{Feature, Mesh, Sweep};

    /// Triangle 0 in z = 0 with, across its edge 0 (y = 0), triangle 1
    /// folded down by 2° (an inactive convex edge) and, across its edge 1,
    /// triangle 2 folded down by 20° (active).
    fn ridge() -> (Vec<[f64; 3]>, Vec<[u64; 3]>) {
        let t2 = 2f64.to_radians().tan();
        let t20 = 20f64.to_radians().tan();
        let out = 2.0 / 2f64.sqrt();
        let vertices = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, -2.0, -2.0 * t2],
            [1.0 + out, 1.0 + out, -2.0 * t20],
        ];
        (vertices, vec![[0, 1, 2], [1, 0, 3], [2, 1, 4]])
    }

    fn normals(vertices: Vec<[f64; 3]>, triangles: &[[u64; 3]]) -> SceneNormals {
        let topology = Topology::new(&vertices, triangles).unwrap();
        let mesh = Mesh::new(vertices, triangles).unwrap();
        SceneNormals::new(NormalRule::ActiveEdges, &mesh, &topology)
    }

    /// The normal answered for a ball of radius 1 touching the point (1, 0, 0)
    /// of edge 0 of `triangle` from a direction `degrees` off +z toward -y.
    fn answer(normals: &SceneNormals, triangle: u32, degrees: f64) -> Vector3<f64> {
        let (s, c) = degrees.to_radians().sin_cos();
        let centre = [1.0, -s, c];
        let sweep = Sweep::new(centre, [1.0, -s, c - 1.0], 1.0);
        let contact = Point3::new(1.0, 0.0, 0.0);
        normals.normal(
            &sweep,
            0.0,
            triangle,
            Feature::Edge(0),
            &contact,
            Vector3::z(),
        )
    }

    #[test]
    fn an_inactive_edge_keeps_a_contact_normal_within_one_degree_when_its_triangle_has_an_active_edge()
     {
        let (vertices, triangles) = ridge();
        let normals = normals(vertices, &triangles);
        // Jolt's ActiveEdges::FixNormal: within 1° of the face, the contact
        // normal is left alone.
        let kept = answer(&normals, 0, 0.5);
        let (s, c) = 0.5f64.to_radians().sin_cos();
        assert!((kept - Vector3::new(0.0, -s, c)).norm() < 1e-12, "{kept}");
        // Beyond 1°, the face normal.
        assert_eq!(answer(&normals, 0, 1.5), Vector3::z());
    }

    #[test]
    fn a_triangle_with_no_active_edge_answers_its_face_normal_at_any_angle() {
        // A 3 × 3 grid of unit squares in z = 0: the middle square's two
        // triangles have only flat (inactive) edges.
        let mut vertices = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                vertices.push([x as f64, y as f64, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        for y in 0..3u64 {
            for x in 0..3u64 {
                let i = y * 4 + x;
                triangles.push([i, i + 1, i + 5]);
                triangles.push([i, i + 5, i + 4]);
            }
        }
        let normals = normals(vertices, &triangles);
        // Triangle 8 is [5, 6, 10]: its edge 0 runs from (1, 1) to (2, 1).
        let (s, c) = 0.5f64.to_radians().sin_cos();
        let sweep = Sweep::new([1.5, 1.0 - s, c], [1.5, 1.0 - s, c - 1.0], 1.0);
        let contact = Point3::new(1.5, 1.0, 0.0);
        let n = normals.normal(&sweep, 0.0, 8, Feature::Edge(0), &contact, Vector3::z());
        assert_eq!(n, Vector3::z());
    }
}
