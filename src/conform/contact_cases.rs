//! The conformance suite's contact queries (`conform --contacts`): what a
//! ball touches where it is (docs/SEMANTICS.md, "Contacts"), one rule per
//! place a contact generator can get wrong, the places that must not push
//! among them (a flat seam, a shallow convex edge, a concave corner), where
//! a leaning normal is the bump players call a ghost collision. Every
//! centre lies well inside its feature's region, so each case has one
//! right contact set; the test suite holds each case's `set` to the core's.

use crate::core::{Facing, Feature, Kind};
use crate::trace::{ContactMsg, SceneMsg};

use super::cases::{Case, CaseQuery, quad, scene, triangle_t};

/// A diamond of two triangles sharing the edge from (0, -2, 0) to
/// (0, 2, 0) (edge 2 of each), their outer corners at x = ±2 raised by
/// `rise`: triangle 0 on the +x side, triangle 1 on the -x side, both
/// facing up. Negative `rise` is a ridge (a convex edge), positive a
/// valley (a concave one).
fn diamond(name: &str, rise: f64) -> SceneMsg {
    scene(
        name,
        vec![
            [0.0, -2.0, 0.0],
            [2.0, 0.0, rise],
            [0.0, 2.0, 0.0],
            [-2.0, 0.0, rise],
        ],
        vec![[0, 1, 2], [2, 3, 0]],
        0.0,
        Facing::NonStrict,
    )
}

/// The square of `quad` with each triangle's own copies of the diagonal's
/// two vertices: a seam shared by position only (the weld makes it one
/// edge; an engine that finds neighbours by index sees two boundaries).
fn unwelded_quad() -> SceneMsg {
    let mut square = quad();
    square.name = Some("unwelded_quad".to_string());
    square.vertices = square
        .triangles
        .iter()
        .flatten()
        .map(|&v| square.vertices[v as usize])
        .collect();
    square.triangles = vec![[0, 1, 2], [3, 4, 5]];
    square
}

/// A ridge whose faces fall away at a slope of 1/32: their normals meet at
/// 2·atan(1/32) ≈ 3.58°, a convex edge below Jolt's 5° threshold (inactive).
fn gentle_ridge() -> SceneMsg {
    diamond("gentle_ridge", -0.0625)
}

/// A valley whose faces rise at a slope of 1/8: a concave edge.
fn valley() -> SceneMsg {
    diamond("valley", 0.25)
}

/// The contact cases, numbered as frames from `first`.
pub(super) fn contact_cases(first: u64) -> Vec<Case> {
    let t = || triangle_t(0.0, Facing::NonStrict);
    use Feature::{Edge, Face, Vertex};
    type Spec = (
        &'static str,
        &'static str,
        SceneMsg,
        f64,
        [f64; 3],
        f64,
        Vec<(u32, Feature)>,
    );
    let specs: Vec<Spec> = vec![
        (
            "contact.face",
            "resting on the middle of triangle T (separation 0)",
            t(),
            0.5,
            [1.0, 1.0, 0.5],
            0.0,
            vec![(0, Face)],
        ),
        (
            "contact.face",
            "sunk a quarter of its radius into the face",
            t(),
            0.5,
            [1.5, 0.75, 0.375],
            0.0,
            vec![(0, Face)],
        ),
        (
            "contact.edge",
            "beyond edge 0, touching it at (2, 0, 0)",
            t(),
            0.5,
            [2.0, -0.25, 0.25],
            0.0,
            vec![(0, Edge(0))],
        ),
        (
            "contact.edge",
            "beyond edge 1 (the hypotenuse), touching it at (2, 2, 0)",
            t(),
            0.5,
            [2.25, 2.25, 0.25],
            0.0,
            vec![(0, Edge(1))],
        ),
        (
            "contact.edge",
            "beyond edge 2, touching it at (0, 2, 0)",
            t(),
            0.5,
            [-0.25, 2.0, 0.25],
            0.0,
            vec![(0, Edge(2))],
        ),
        (
            "contact.vertex",
            "beyond vertex 0",
            t(),
            0.5,
            [-0.25, -0.25, 0.25],
            0.0,
            vec![(0, Vertex(0))],
        ),
        (
            "contact.vertex",
            "beyond vertex 1",
            t(),
            0.5,
            [4.25, -0.25, 0.25],
            0.0,
            vec![(0, Vertex(1))],
        ),
        (
            "contact.vertex",
            "beyond vertex 2",
            t(),
            0.5,
            [-0.25, 4.25, 0.25],
            0.0,
            vec![(0, Vertex(2))],
        ),
        (
            "contact.flat-seam",
            "sunk into triangle 0 of a flat square, beside the diagonal it shares with triangle 1, whose closest point is on that seam",
            quad(),
            0.5,
            [1.125, 0.875, 0.375],
            0.0,
            vec![(0, Face), (1, Edge(0))],
        ),
        (
            "contact.flat-seam",
            "the same, the diagonal shared by position only: each triangle has its own copies of its two vertices",
            unwelded_quad(),
            0.5,
            [1.125, 0.875, 0.375],
            0.0,
            vec![(0, Face), (1, Edge(0))],
        ),
        (
            "contact.shallow-convex-edge",
            "on triangle 0 of a ridge whose faces meet at 3.58°, beside the ridge, which is triangle 1's closest point",
            gentle_ridge(),
            0.5,
            [0.125, 0.0, 0.375],
            0.0,
            vec![(0, Face), (1, Edge(2))],
        ),
        (
            "contact.concave-corner",
            "in a valley, on triangle 1's face, reaching over the valley's line to triangle 0",
            valley(),
            0.75,
            [-0.5, 0.0, 0.5],
            0.0,
            vec![(1, Face), (0, Edge(2))],
        ),
        (
            "contact.speculative",
            "an eighth above the face, within a contact distance of a quarter",
            t(),
            0.5,
            [1.0, 1.0, 0.625],
            0.25,
            vec![(0, Face)],
        ),
        (
            "contact.speculative",
            "0.207 from edge 0, within a contact distance of a quarter",
            t(),
            0.5,
            [2.0, -0.5, 0.5],
            0.25,
            vec![(0, Edge(0))],
        ),
        (
            "contact.speculative",
            "three eighths above the face, beyond a contact distance of a quarter",
            t(),
            0.5,
            [1.0, 1.0, 0.875],
            0.25,
            vec![],
        ),
        (
            "contact.apart",
            "an eighth above the face, with no contact distance",
            t(),
            0.5,
            [1.0, 1.0, 0.625],
            0.0,
            vec![],
        ),
        (
            "contact.back-facing",
            "sunk into the face from behind",
            t(),
            0.5,
            [1.0, 1.0, -0.25],
            0.0,
            vec![],
        ),
    ];
    let mut out: Vec<Case> = Vec::with_capacity(specs.len());
    for (i, (rule, what, scene, radius, centre, distance, set)) in specs.into_iter().enumerate() {
        let index = out.iter().filter(|c| c.rule == rule).count();
        let kind = set.first().map_or(Kind::None, |(_, f)| f.kind());
        out.push(Case {
            rule,
            index,
            what,
            scene,
            query: CaseQuery::Contact {
                query: ContactMsg {
                    frame: first + i as u64,
                    ball: 0,
                    radius,
                    centre,
                    distance,
                },
                set,
            },
            kind,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::{ContactQuery, Mesh, Sides, contact_set};

    #[test]
    fn each_contact_case_has_the_set_it_says() {
        let cases = contact_cases(100);
        assert!(cases.len() >= 16);
        for (i, case) in cases.iter().enumerate() {
            let CaseQuery::Contact { query, set } = &case.query else {
                panic!("{}: not a contact case", case.id());
            };
            assert_eq!(query.frame, 100 + i as u64);
            let mesh = Mesh::new(case.scene.vertices.clone(), &case.scene.triangles).expect("mesh");
            let q = ContactQuery {
                centre: query.centre.into(),
                radius: query.radius,
                distance: query.distance,
            };
            let got: Vec<(u32, Feature)> = contact_set(&mesh, &q, Sides::One)
                .iter()
                .map(|c| (c.triangle, c.feature))
                .collect();
            assert_eq!(&got, set, "{} ({})", case.id(), case.what);
        }
    }

    #[test]
    fn the_ridge_is_shallow_and_the_valley_concave() {
        let normals = |s: SceneMsg| {
            let mesh = Mesh::new(s.vertices, &s.triangles).expect("mesh");
            [0, 1].map(|t| mesh.triangle_by_index(t).expect("triangle").normal)
        };
        let [a, b] = normals(gentle_ridge());
        let degrees = a.dot(&b).acos().to_degrees();
        assert!(degrees > 3.0 && degrees < 5.0, "{degrees}°");
        // Concave: each face's normal leans toward the other's side.
        let [right, left] = normals(valley());
        assert!(right.x < 0.0 && left.x > 0.0 && right.z > 0.0 && left.z > 0.0);
    }
}
