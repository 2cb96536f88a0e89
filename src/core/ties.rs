//! The tie set of a decision: every hit within the tie window of the
//! earliest `α`, named as an outcome names it, in the rules' tie order
//! (face < edge < vertex, then triangle, then feature). `check` and `diff`
//! accept an expectation that names any member of it.

use super::error::SweepError;
use super::mesh::Mesh;
use super::options::Options;
use super::outcome::{Outcome, Tie};
use super::path::Sweep;
use super::record::{Observer, TestRecord};
use super::sweep_mesh::{Broadphase, sweep_mesh_with};

/// An observer that keeps the hits of an explained sweep, from which
/// [`CollectTies::tie_set`] gives the decision's tie set. Cheaper than
/// [`CollectRecords`](super::record::CollectRecords): only hits are kept.
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
