//! The rules the conformance cases exercise, in the order of
//! docs/SEMANTICS.md: each one's name (what `conform --case` and the
//! reports call it) and what it checks.

/// A rule and what it checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rule {
    /// Its name.
    pub name: &'static str,
    /// What it checks, in words (with the SEMANTICS.md step).
    pub description: &'static str,
}

/// Every rule, in the order of docs/SEMANTICS.md.
pub const RULES: &[Rule] = &[
    Rule {
        name: "face.hit",
        description: "the ball reaches the plane at ρ with its touch point inside the triangle: a face collision at β (face, step 5)",
    },
    Rule {
        name: "face.near-edge",
        description: "the touch point lies inside the triangle, within 0.4 % of its altitude from an edge: still a face collision, not an edge (face, step 5; a classification by barycentric weights needs a threshold below that)",
    },
    Rule {
        name: "face.miss.outside-triangle",
        description: "the touch point falls outside the triangle and no edge or vertex is within ρ: no collision (face, step 4)",
    },
    Rule {
        name: "face.miss.beyond-end",
        description: "the path ends before the ball reaches the plane at ρ: β > 1 (face, step 3)",
    },
    Rule {
        name: "face.miss.parallel",
        description: "the path runs parallel to the plane, farther than ρ: no collision (face, step 2)",
    },
    Rule {
        name: "face.miss.back-facing",
        description: "the ball comes from behind the triangle: the facing rule rejects every test",
    },
    Rule {
        name: "start.inside",
        description: "the ball starts within ρ of the plane (h0 < ρ) and moves through it: the face test ignores it (face, step 1)",
    },
    Rule {
        name: "start.touching",
        description: "the ball starts exactly ρ from the plane (h0 = ρ) moving toward it: a face collision at α = 0",
    },
    Rule {
        name: "start.moving-away",
        description: "the ball starts within ρ of the face or touching it and moves away (n·d > 0): no collision, also under initial_overlap = alpha0, which asks that the ball move toward the triangle (facing rule)",
    },
    Rule {
        name: "path.zero-length",
        description: "p0 = p1: nothing moves, nothing is hit (vertex: not moving; face and edge: parallel)",
    },
    Rule {
        name: "edge.hit",
        description: "the path comes within ρ of an edge, between its ends, facing it: an edge collision at s0 (edge, step 7; each of the three edges)",
    },
    Rule {
        name: "edge.miss.no-real-roots",
        description: "the path never comes within ρ of the edge's line: B² - 4AC < 0 (edge, step 2)",
    },
    Rule {
        name: "edge.miss.before-start",
        description: "the ball starts within ρ of the edge's line and moves away: s0 < 0 (edge, step 4)",
    },
    Rule {
        name: "edge.miss.beyond-end",
        description: "the path ends before the ball comes within ρ of the edge: s0 > 1 (edge, step 4)",
    },
    Rule {
        name: "edge.miss.beyond-v1",
        description: "the contact on the edge's line lies beyond v1 (xc > L): not an edge collision, the vertex test finds it (edge, step 5)",
    },
    Rule {
        name: "edge.miss.before-v0",
        description: "the contact on the edge's line lies before v0 (xc < 0): the vertex test finds it (edge, step 5)",
    },
    Rule {
        name: "edge.miss.parallel",
        description: "the path runs parallel to the edge (A = 0): no edge collision (edge, step 1)",
    },
    Rule {
        name: "edge.miss.back-facing",
        description: "the ball comes at the edge from behind the triangle: back-facing (edge, step 6)",
    },
    Rule {
        name: "vertex.hit",
        description: "the path comes within ρ of a vertex, facing it: a vertex collision at the smaller root",
    },
    Rule {
        name: "vertex.miss.no-real-roots",
        description: "the path never comes within ρ of the vertex: no collision",
    },
    Rule {
        name: "vertex.miss.before-start",
        description: "the ball starts within ρ of the vertex and moves away: s0 < 0",
    },
    Rule {
        name: "vertex.miss.beyond-end",
        description: "the path ends before the ball comes within ρ of the vertex: s0 > 1",
    },
    Rule {
        name: "end.exact-hit",
        description: "the ball touches exactly at the end of the path: a collision at α = 1 with its kind set (worked example 4)",
    },
    Rule {
        name: "tie.edge-end",
        description: "a contact exactly at an edge's end is found by the edge and the vertex test at the same α: the tie order makes it an edge collision",
    },
    Rule {
        name: "tie.shared-edge.planar",
        description: "a touch point on the edge shared by two coplanar triangles: both faces tie, the lower triangle is primary",
    },
    Rule {
        name: "tie.shared-edge.cube",
        description: "a cube edge hit by both of its triangles at the same α: the lower triangle is primary, the normal the average of both faces' normals (worked example 5)",
    },
    Rule {
        name: "tie.shared-vertex",
        description: "the apex of a pyramid hit head-on: the vertex of four triangles ties, the normal averages their four normals",
    },
    Rule {
        name: "tie.kind-order",
        description: "straight down onto a triangle's vertex: the face, both edges that end there and the vertex all touch at one α: the kind order face < edge < vertex makes it a face collision",
    },
    Rule {
        name: "tie.across-kinds",
        description: "the face of triangle 1 and an edge of triangle 0 touch at one α: the kind order comes before the triangle index, so the face of the higher triangle is primary",
    },
    Rule {
        name: "tie.feature-order",
        description: "a ball inside the plane's band (no face test) moving to a vertex along its bisector touches the triangle's two edges there at one α: the lower feature (edge 0) is primary",
    },
    Rule {
        name: "tie.cube-corner",
        description: "a ball coming diagonally at a cube's corner: a vertex collision shared by the corner's triangles, averaged normal",
    },
    Rule {
        name: "normal.shallow-convex-edge",
        description: "a ridge whose faces meet at 14.25° hit on its edge: under the rules both faces tie and their normals average; under normal = active_edges the edge is active (beyond 5°) and the normal is the contact normal, not a face's",
    },
    Rule {
        name: "normal.flat-edge",
        description: "a ball landing on the edge shared by two coplanar triangles: every normal rule reports the plane's normal there, whichever member of the tie is named (no ghost normal leaning toward the edge)",
    },
    Rule {
        name: "grazing.face-hit",
        description: "a path descending onto the face at a grazing angle (cosine below 1e-3): still a face collision at β",
    },
    Rule {
        name: "grazing.edge-tangent",
        description: "a path that passes exactly ρ from an edge's line (a double root): a tangent edge collision",
    },
    Rule {
        name: "margin.face-hit",
        description: "with margin ε the face test detects at ρ = r - ε: α moves accordingly",
    },
    Rule {
        name: "margin.edge-miss",
        description: "a path that passes within r but farther than ρ = r - ε from an edge: no collision",
    },
    Rule {
        name: "margin.vertex-hit",
        description: "with margin ε the vertex test detects at ρ = r - ε",
    },
    Rule {
        name: "facing.non-strict",
        description: "a path in the triangle's plane (n·d = 0) toward an edge: the non-strict rule n·d ≤ 0 lets it hit",
    },
    Rule {
        name: "facing.strict",
        description: "the strict rule n·d < 0: the same in-plane path hits nothing; an ordinary approach still hits",
    },
    Rule {
        name: "degenerate.skipped",
        description: "degenerate triangles (a repeated index, zero area) are left out of every test; the others keep their indices",
    },
    Rule {
        name: "mesh.closest-hit",
        description: "of two triangles on the path, the nearer is hit, though the farther comes first in the list: the primary is the smallest α, not the first triangle found",
    },
    Rule {
        name: "mesh.large",
        description: "a height field of 3,200 triangles hit at cells far apart in space and in index: each sweep finds its triangle (no part of the mesh is lost)",
    },
    Rule {
        name: "contact.face",
        description: "(--contacts) the centre above the face's interior, within ρ: one contact, the face, the centre's projection, separation |c − q| − ρ and the face normal (Contacts)",
    },
    Rule {
        name: "contact.edge",
        description: "(--contacts) the centre in an edge's region: the closest point on the edge (computed in its standard frame) and the normal the `normal` convention expects there (Contacts; each of the three edges)",
    },
    Rule {
        name: "contact.vertex",
        description: "(--contacts) the centre in a vertex's region: the vertex, and the normal the `normal` convention expects there (Contacts; each of the three vertices)",
    },
    Rule {
        name: "contact.flat-seam",
        description: "(--contacts) two coplanar triangles: beside their shared edge, the other triangle's closest point is on that edge, a place that must not push: its normal is the faces' (a leaning normal there is a ghost contact, a failure under any convention)",
    },
    Rule {
        name: "contact.shallow-convex-edge",
        description: "(--contacts) a convex edge whose faces meet at 3.58°: the normal the convention expects at the edge (the face normal under `active_edges`, whose threshold is 5°; the contact normal under `contact`)",
    },
    Rule {
        name: "contact.concave-corner",
        description: "(--contacts) a valley: reaching over its line, the other face's closest point is on that concave edge, a place that must not push: its normal is the face's (a leaning normal there is a ghost contact, a failure under any convention)",
    },
    Rule {
        name: "contact.speculative",
        description: "(--contacts) the contact distance s: a triangle within ρ + s is a contact, with a positive separation; one beyond it is not (Contacts)",
    },
    Rule {
        name: "contact.apart",
        description: "(--contacts) a ball apart from the mesh, with no contact distance: no contact (Contacts)",
    },
    Rule {
        name: "contact.back-facing",
        description: "(--contacts) the centre behind the triangle: one-sided, no contact (Contacts; under sides = \"two\" a contact, and the rule does not apply)",
    },
];
