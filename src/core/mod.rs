//! The collision core: a moving ball against a triangle mesh.
//!
//! The semantics are those of the project's `SEMANTICS.md`: per triangle a
//! face test, three edge tests in each edge's standard frame and three
//! vertex tests; the mesh sweep takes the earliest collision, decides
//! between the hits tied with it (within the tie window, see
//! [`TIE_WINDOW_ULPS`](options::TIE_WINDOW_ULPS)) by kind (face, edge, vertex), triangle and feature,
//! averages the front normals of the tied triangles, and flags a decision
//! that rounding could change ([`Fragility`]).
//!
//! Two entry points share one implementation: [`sweep_mesh`] (fast, no
//! allocation) and [`sweep_mesh_with`] (hands every test's record to an
//! [`Observer`](record::Observer)).
//!
//! [`first_crossing`](crossing::first_crossing) is a separate query: where a segment (a ball's centre
//! moving) passes through a triangle from its front to its back, the fact
//! behind a tunnel.
//!
//! [`Topology`](topology::Topology) is the mesh's adjacency: each edge's triangles and class,
//! and the defects (flipped windings, cracks, T-junctions, ...).

mod bvh;
mod contact;
#[cfg(test)]
mod contact_exact_tests;
pub mod crossing;
mod error;
pub mod explain;
mod feature;
mod fragility;
mod initial;
pub mod mesh;
pub mod options;
mod outcome;
mod path;
mod quadratic;
pub mod record;
#[cfg(test)]
mod sides_tests;
mod sweep_edge;
mod sweep_face;
mod sweep_mesh;
mod sweep_vertex;
mod ties;
pub mod topology;

pub(crate) use contact::triangle_contact;
pub use contact::{Contact, ContactQuery, contact_set};
pub use error::{MeshError, SweepError};
pub use feature::{Feature, Kind};
pub use fragility::{FragileReason, Fragility};
pub(crate) use initial::closest_point;
pub use initial::initial_contacts;
pub use mesh::Mesh;
pub use options::{Facing, InitialOverlap, Options, Sides};
pub use outcome::{Outcome, SweepHit, Tie};
pub use path::{Sweep, SweptPath};
pub(crate) use sweep_edge::sweep_edge;
pub use sweep_face::{barycentric, sweep_face};
pub use sweep_mesh::{Broadphase, sweep_mesh, sweep_mesh_with};
pub(crate) use sweep_vertex::sweep_vertex;
pub use ties::{CollectTies, sweep_ties};
