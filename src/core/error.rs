//! Errors of the collision core.

use thiserror::Error;

/// A mesh that cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MeshError {
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate {coordinate:?}")]
    NonFiniteVertex {
        /// Index of the vertex.
        vertex: usize,
        /// Its coordinates.
        coordinate: [f64; 3],
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The offending vertex index.
        index: u64,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// No triangle is left to collide with.
    #[error("the mesh has no usable triangle ({triangles} given, {degenerate} degenerate)")]
    Empty {
        /// Triangles given.
        triangles: usize,
        /// Of which degenerate.
        degenerate: usize,
    },
    /// More vertices or triangles than indices can address.
    #[error("the mesh is too large: {what} exceeds {limit}")]
    TooLarge {
        /// What overflowed.
        what: &'static str,
        /// The limit.
        limit: usize,
    },
}

/// A sweep that cannot be tested.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SweepError {
    /// A coordinate or number is NaN or infinite.
    #[error("`{field}` is not finite ({})", crate::numbers::Shortest(*.value))]
    NonFinite {
        /// The field (`p0`, `p1`, `radius`, `margin`).
        field: &'static str,
        /// The value found.
        value: f64,
    },
    /// The radius is zero or negative.
    #[error("`radius` must be > 0, got {}", crate::numbers::Shortest(*.0))]
    NonPositiveRadius(f64),
    /// The margin is negative.
    #[error("`margin` must be ≥ 0, got {}", crate::numbers::Shortest(*.0))]
    NegativeMargin(f64),
    /// The margin is not smaller than the radius.
    #[error(
        "`margin` ({}) must be smaller than `radius` ({})",
        crate::numbers::Shortest(*.margin),
        crate::numbers::Shortest(*.radius)
    )]
    MarginNotBelowRadius {
        /// The margin.
        margin: f64,
        /// The radius.
        radius: f64,
    },
}
