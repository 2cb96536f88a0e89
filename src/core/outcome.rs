//! What a sweep reports: a hit or no hit ([`Outcome`]), and the hits tied
//! with it ([`Tie`], [`in_tie_window`]: the one definition of "tied").

use nalgebra::{Point3, Vector3};
use serde::{Serialize, Serializer};

use super::feature::{Feature, Kind};
use super::fragility::Fragility;
use super::record::TestRecord;

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
    /// [`CollectRecords`](super::record::CollectRecords) or [`CollectTies`](super::CollectTies)): every
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

/// Whether a hit at `alpha` lies in the tie window `window` of the minimum
/// `min_alpha`: `alpha ≤ min_alpha + window`. The one definition of "tied"
/// (the combiner, [`Outcome::ties_with`] and every consumer use it).
#[inline]
pub fn in_tie_window(alpha: f64, min_alpha: f64, window: f64) -> bool {
    alpha <= min_alpha + window
}

/// One member of a decision's tie set: a hit, named as an outcome names it.
///
/// Serialised as `{kind, triangle, feature, alpha}` (the feature index,
/// `null` for a face).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tie {
    /// Input index of its triangle.
    pub triangle: u32,
    /// The feature it touches.
    pub feature: Feature,
    /// Its own `α`.
    pub alpha: f64,
}

impl Tie {
    /// The tie-set entry of a record, if it is a hit.
    pub fn of(record: &TestRecord) -> Option<Tie> {
        Some(Tie {
            triangle: record.triangle(),
            feature: record.feature(),
            alpha: record.alpha()?,
        })
    }

    /// Its kind.
    #[inline]
    pub fn kind(&self) -> Kind {
        self.feature.kind()
    }

    /// The tie order: face < edge < vertex, then triangle, then feature.
    pub fn order(&self) -> (Kind, u32, Option<u8>) {
        (self.feature.kind(), self.triangle, self.feature.index())
    }

    /// Whether an answer naming `kind` and, when given, `triangle` and
    /// `feature` (the edge or vertex index) names this hit. `None` names
    /// any triangle or feature. A face has no feature index: any index an
    /// answer gives with a face is accepted.
    pub fn matches(&self, kind: Kind, triangle: Option<u32>, feature: Option<u8>) -> bool {
        kind == self.kind()
            && triangle.is_none_or(|t| t == self.triangle)
            && (self.feature == Feature::Face
                || feature.is_none_or(|f| Some(f) == self.feature.index()))
    }
}

impl Serialize for Tie {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Flat {
            kind: Kind,
            triangle: u32,
            feature: Option<u8>,
            alpha: f64,
        }
        Flat {
            kind: self.kind(),
            triangle: self.triangle,
            feature: self.feature.index(),
            alpha: self.alpha,
        }
        .serialize(serializer)
    }
}
