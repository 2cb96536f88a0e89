//! The collision core: a moving ball against a triangle mesh.
//!
//! The semantics are those of the project's `SEMANTICS.md`: per triangle a
//! face test, three edge tests in each edge's standard frame and three
//! vertex tests; the mesh sweep takes the earliest collision, breaks exact
//! ties by kind (face, edge, vertex), triangle and feature, and averages the
//! front normals of triangles that collide simultaneously.
//!
//! Two entry points share one implementation: [`sweep_mesh`] (fast, no
//! allocation) and [`sweep_mesh_with`] (hands every test's record to an
//! [`Observer`]).

mod bvh;
mod error;
pub mod explain;
mod mesh;
mod options;
mod path;
pub mod quadratic;
mod record;
mod sweep_edge;
mod sweep_face;
mod sweep_mesh;
mod sweep_vertex;

pub use error::{MeshError, SweepError};
pub use mesh::{DegenerateReason, DegenerateTriangle, Mesh, StandardFrame, Triangle};
pub use options::{
    DEGENERATE_TOLERANCE, Facing, Options, PARALLEL_TOLERANCE, SIMULTANEOUS_TOLERANCE,
};
pub use path::{Path, Sweep};
pub use record::{
    CollectRecords, EdgeRecord, FaceRecord, Kind, NoObserver, Observer, TestRecord, Verdict,
    VertexRecord,
};
pub use sweep_edge::sweep_edge;
pub use sweep_face::{barycentric, sweep_face};
pub use sweep_mesh::{Broadphase, Outcome, sweep_mesh, sweep_mesh_with};
pub use sweep_vertex::sweep_vertex;
