//! The tie set of a decision: every hit within the tie window of the
//! earliest `α`, named as an outcome names it, in the rules' tie order
//! (face < edge < vertex, then triangle, then feature). `check` and `diff`
//! accept an expectation that names any member of it.

use serde::{Serialize, Serializer};

use super::error::SweepError;
use super::mesh::Mesh;
use super::options::Options;
use super::outcome::{Feature, Outcome};
use super::path::Sweep;
use super::record::{Kind, Observer, TestRecord};
use super::sweep_mesh::{Broadphase, sweep_mesh_with};

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

    /// Whether an expectation naming `kind` and, when known, `triangle`
    /// and `feature` names this hit (`None`: not named, so any value;
    /// `Some(None)`: null). A face has no feature: any feature an expected
    /// face names is accepted.
    pub fn matches(
        &self,
        kind: Kind,
        triangle: Option<Option<u32>>,
        feature: Option<Option<u8>>,
    ) -> bool {
        kind == self.kind()
            && triangle.is_none_or(|t| t == Some(self.triangle))
            && (self.feature == Feature::Face || feature.is_none_or(|f| f == self.feature.index()))
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

/// An observer that keeps the hits of an explained sweep, from which
/// [`CollectTies::tie_set`] gives the decision's tie set. Cheaper than
/// [`CollectRecords`](super::CollectRecords): only hits are kept.
#[derive(Clone, Debug, Default)]
pub struct CollectTies {
    /// Every hit, in the order the tests ran.
    pub hits: Vec<Tie>,
}

impl CollectTies {
    /// The hits tied with `outcome`, in the tie order (the primary first).
    pub fn tie_set(&self, outcome: &Outcome) -> Vec<Tie> {
        let mut ties: Vec<Tie> = self
            .hits
            .iter()
            .copied()
            .filter(|t| outcome.ties_with(t.alpha))
            .collect();
        ties.sort_by_key(|t| t.order());
        ties
    }

    fn keep(&mut self, record: TestRecord) {
        if let Some(t) = Tie::of(&record) {
            self.hits.push(t);
        }
    }
}

impl Observer for CollectTies {
    fn face(&mut self, r: &super::record::FaceRecord) {
        self.keep(TestRecord::Face(*r));
    }
    fn edge(&mut self, r: &super::record::EdgeRecord) {
        self.keep(TestRecord::Edge(*r));
    }
    fn vertex(&mut self, r: &super::record::VertexRecord) {
        self.keep(TestRecord::Vertex(*r));
    }
}

/// The outcome of `sweep` and its tie set (every hit tied with the primary,
/// in the tie order, the primary first; empty when nothing is hit).
pub fn sweep_ties(
    mesh: &Mesh,
    sweep: &Sweep,
    options: &Options,
) -> Result<(Outcome, Vec<Tie>), SweepError> {
    let mut ties = CollectTies::default();
    let outcome = sweep_mesh_with(mesh, sweep, options, Broadphase::Bvh, &mut ties)?;
    let set = ties.tie_set(&outcome);
    Ok((outcome, set))
}
