//! What a hit touches: the [`Kind`] of a collision and the [`Feature`] of a
//! triangle (its face, an edge or a vertex, with the index). A leaf that
//! every test, record and outcome imports, as parry's `FeatureId` is.

use serde::Serialize;

/// The kind of a collision.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// Ties between kinds go in this order: face first.
    Face,
    /// An edge.
    Edge,
    /// A vertex.
    Vertex,
    /// Nothing touched.
    #[default]
    None,
}

impl Kind {
    /// Name used in outcomes.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Face => "face",
            Kind::Edge => "edge",
            Kind::Vertex => "vertex",
            Kind::None => "none",
        }
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The part of a triangle a test touches: its face, one of its edges or one
/// of its vertices, with the edge or vertex index (0..3) in the variant, the
/// way parry's `FeatureId` carries it.
///
/// Edge `i` runs from vertex `i` to vertex `(i + 1) % 3`. The order is the
/// tie order within one triangle: face < edge < vertex, then the index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Feature {
    /// The face (its interior).
    Face,
    /// Edge `i`.
    Edge(u8),
    /// Vertex `i`.
    Vertex(u8),
}

impl Feature {
    /// The kind of the feature, the word traces and reports use.
    #[inline]
    pub fn kind(self) -> Kind {
        match self {
            Feature::Face => Kind::Face,
            Feature::Edge(_) => Kind::Edge,
            Feature::Vertex(_) => Kind::Vertex,
        }
    }

    /// The edge or vertex index, as an outcome reports it; `None` for the
    /// face (a face has no feature index).
    #[inline]
    pub fn index(self) -> Option<u8> {
        match self {
            Feature::Face => None,
            Feature::Edge(i) | Feature::Vertex(i) => Some(i),
        }
    }

    /// The feature a trace's `kind` and `feature` fields name: `None` for
    /// [`Kind::None`], for an edge or a vertex without an index, or for an
    /// index past 2. A face ignores the index.
    pub fn from_parts(kind: Kind, index: Option<u8>) -> Option<Feature> {
        match (kind, index) {
            (Kind::Face, _) => Some(Feature::Face),
            (Kind::Edge, Some(i)) if i < 3 => Some(Feature::Edge(i)),
            (Kind::Vertex, Some(i)) if i < 3 => Some(Feature::Vertex(i)),
            _ => None,
        }
    }

    /// The key of the tie order within one triangle's tests: face < edge <
    /// vertex, then the index.
    #[inline]
    pub(crate) fn order_key(self) -> (Kind, u8) {
        (self.kind(), self.index().unwrap_or(0))
    }
}

impl std::fmt::Display for Feature {
    /// `face`, `edge 2`, `vertex 0`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Feature::Face => f.write_str("face"),
            Feature::Edge(i) => write!(f, "edge {i}"),
            Feature::Vertex(i) => write!(f, "vertex {i}"),
        }
    }
}
