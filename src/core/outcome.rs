//! What a sweep reports: a hit or no hit ([`Outcome`]), and the feature a
//! hit touches ([`Feature`]).

use nalgebra::{Point3, Vector3};
use serde::{Serialize, Serializer};

use super::fragility::Fragility;
use super::record::{Kind, TestRecord};
use super::ties::{Tie, in_tie_window};

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

/// The primary collision of a sweep that hits something.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepHit {
    /// Fraction of the path travelled at first contact (the minimum `α`
    /// over every collision), in `[0, 1]`.
    pub alpha: f64,
    /// Input index of the primary triangle: chosen among the hits tied with
    /// `alpha` ([`Outcome::ties_with`]) by the order face < edge < vertex,
    /// then lower triangle, then lower feature.
    pub triangle: u32,
    /// The feature of the primary triangle the collision touches.
    pub feature: Feature,
    /// The reported normal: the primary triangle's front normal, or the
    /// normalised average of the front normals of every triangle with a hit
    /// tied with `alpha`.
    pub normal: Vector3<f64>,
    /// The point of the mesh the primary test touches (at its own `α`,
    /// which is tied with `alpha`).
    pub contact: Point3<f64>,
}

/// The result of one sweep: the primary collision, if any, and how far the
/// decision can be trusted.
///
/// Serialised as the flat record reports have always shown (`alpha` 1 and
/// `kind` `none` for a miss, `null` triangle, feature, normal and contact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// The primary collision; `None` when the ball travels its whole path.
    pub hit: Option<SweepHit>,
    /// The tie window of this sweep, in `α` (`SweptPath::tie_window`): a hit
    /// at `α ≤ alpha + tie_window` is tied with the primary. A miss has one
    /// too (the window its fragility flags were judged with).
    pub tie_window: f64,
    /// Why the decision may not survive a change of the inputs at the level
    /// of their rounding; empty when it is robust. A miss can be fragile
    /// (a test rejected by less than the band).
    pub fragile: Fragility,
}

impl Outcome {
    /// The outcome of a sweep that touches nothing, with a zero tie window
    /// and no fragility.
    pub const NONE: Outcome = Outcome {
        hit: None,
        tie_window: 0.0,
        fragile: Fragility::ROBUST,
    };

    /// Whether something was hit.
    #[inline]
    pub fn is_hit(&self) -> bool {
        self.hit.is_some()
    }

    /// Fraction of the path the ball travels: the hit's `α`, or 1 when
    /// nothing is hit (the ball reaches the end of its path).
    #[inline]
    pub fn travelled(&self) -> f64 {
        self.hit.map_or(1.0, |h| h.alpha)
    }

    /// The kind of the primary collision, as traces name it
    /// ([`Kind::None`] for a miss).
    #[inline]
    pub fn kind(&self) -> Kind {
        self.hit.map_or(Kind::None, |h| h.feature.kind())
    }

    /// Whether `record` is the test that reported this outcome's primary
    /// collision (a hit on the same triangle and feature).
    pub fn is_reported_by(&self, record: &TestRecord) -> bool {
        self.hit.is_some_and(|h| {
            record.alpha().is_some()
                && record.triangle() == h.triangle
                && record.feature() == h.feature
        })
    }

    /// Whether a hit at `alpha` is tied with this outcome's primary hit: it
    /// lies within the tie window of the minimum `α` ([`in_tie_window`]).
    /// Tied hits share the averaged normal, and any of them is an
    /// acceptable answer to the rules (the primary is the first of them in
    /// the tie order). Never true when nothing was hit.
    pub fn ties_with(&self, alpha: f64) -> bool {
        self.hit
            .is_some_and(|h| in_tie_window(alpha, h.alpha, self.tie_window))
    }

    /// The tie set among `records` (the records of this sweep, e.g. from
    /// [`CollectRecords`](super::CollectRecords) or [`CollectTies`](super::CollectTies)): every
    /// hit tied with this outcome, in the tie order (the primary first).
    pub fn tie_set(&self, records: &[TestRecord]) -> Vec<Tie> {
        let mut ties: Vec<Tie> = records
            .iter()
            .filter_map(Tie::of)
            .filter(|t| self.ties_with(t.alpha))
            .collect();
        ties.sort_by_key(|t| t.order());
        ties.dedup_by_key(|t| t.order());
        ties
    }
}

impl Serialize for Outcome {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Flat {
            alpha: f64,
            kind: Kind,
            triangle: Option<u32>,
            feature: Option<u8>,
            normal: Option<Vector3<f64>>,
            contact: Option<Point3<f64>>,
            tie_window: f64,
            fragile: Fragility,
        }
        Flat {
            alpha: self.travelled(),
            kind: self.kind(),
            triangle: self.hit.map(|h| h.triangle),
            feature: self.hit.and_then(|h| h.feature.index()),
            normal: self.hit.map(|h| h.normal),
            contact: self.hit.map(|h| h.contact),
            tie_window: self.tie_window,
            fragile: self.fragile,
        }
        .serialize(serializer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feature_parts_round_trip() {
        for f in [
            Feature::Face,
            Feature::Edge(0),
            Feature::Edge(2),
            Feature::Vertex(1),
        ] {
            assert_eq!(Feature::from_parts(f.kind(), f.index()), Some(f));
        }
        assert_eq!(
            Feature::from_parts(Kind::Face, Some(2)),
            Some(Feature::Face)
        );
        assert_eq!(Feature::from_parts(Kind::Edge, None), None);
        assert_eq!(Feature::from_parts(Kind::Vertex, Some(3)), None);
        assert_eq!(Feature::from_parts(Kind::None, None), None);
    }

    #[test]
    fn tie_order_within_a_triangle() {
        let mut features = [
            Feature::Vertex(0),
            Feature::Edge(2),
            Feature::Face,
            Feature::Edge(0),
        ];
        features.sort_by_key(|f| f.order_key());
        assert_eq!(
            features,
            [
                Feature::Face,
                Feature::Edge(0),
                Feature::Edge(2),
                Feature::Vertex(0)
            ]
        );
    }

    #[test]
    fn a_miss_serialises_as_the_flat_record() {
        let json = serde_json::to_value(Outcome::NONE).unwrap();
        assert_eq!(json["alpha"], 1.0);
        assert_eq!(json["kind"], "none");
        assert!(json["triangle"].is_null() && json["feature"].is_null());
        assert!(json["normal"].is_null() && json["contact"].is_null());
    }
}
