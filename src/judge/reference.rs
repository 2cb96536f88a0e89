//! The core's decision on one sweep as the judge sees it ([`Decision`]):
//! its outcome under the scene's conventions, the hits that can be members
//! of its tie set, and whether it accepts an answer (the primary, or
//! another member of the tie set with that member's own contact).

use nalgebra::Point3;

use crate::core::SweepHit;
use crate::core::record::{EdgeRecord, FaceRecord, Observer, TestRecord, VertexRecord};
use crate::core::{
    Broadphase, Feature, Outcome, Sweep, SweptPath, Tie, initial_contacts, sweep_mesh_with,
};
use crate::replay::SceneState;
use crate::trace::OutcomeMsg;

use super::compare::{FieldDiff, Tolerances, compare, differing};
use crate::conventions::TieRule;

/// Keeps the records of the tests that hit.
#[derive(Default)]
struct Hits(Vec<TestRecord>);

impl Observer for Hits {
    // Triangles whose every test ends back-facing hit nothing.
    const WANTS_RECORDS: bool = false;
    fn face(&mut self, r: &FaceRecord) {
        if r.alpha().is_some() {
            self.0.push(TestRecord::Face(*r));
        }
    }
    fn edge(&mut self, r: &EdgeRecord) {
        if r.alpha().is_some() {
            self.0.push(TestRecord::Edge(*r));
        }
    }
    fn vertex(&mut self, r: &VertexRecord) {
        if r.alpha().is_some() {
            self.0.push(TestRecord::Vertex(*r));
        }
    }
}

/// By backward error, how a tie member's own bound is found: the fixed
/// tolerances widened by that member's sensitivity at the budget (the
/// answers' `Δα` observed, as for the primary). A member is then held to
/// exactly what it would be held to as the primary: an edge member's
/// contact normal turns with the centre, a face's does not.
#[derive(Clone, Copy)]
pub(super) struct MemberBounds<'t> {
    pub fixed: &'t Tolerances,
    pub budget: f64,
    pub expected: &'t OutcomeMsg,
    pub got: &'t OutcomeMsg,
}

/// The core's decision on one sweep under the scene's options and
/// conventions: its outcome and the hits that can be members of its tie
/// set.
pub(super) struct Decision<'a> {
    scene: &'a SceneState,
    sweep: Sweep,
    outcome: Outcome,
    hits: Vec<TestRecord>,
    /// Under `initial_overlap = alpha0`, when the ball starts in contact:
    /// every initial contact, all tied at `α = 0`.
    initial: Vec<SweepHit>,
}

impl<'a> Decision<'a> {
    /// The sensitivity of the decision's hit (`None` for a miss): what a
    /// perturbed decision's answer is widened by when the unperturbed
    /// sweep has no hit to measure it on.
    pub(super) fn sensitivity(&self) -> Option<super::precision::Sensitivity> {
        super::precision::Sensitivity::of_hit(self.scene, &self.sweep, self.outcome.hit.as_ref()?)
    }

    pub(super) fn of(scene: &'a SceneState, sweep: &Sweep) -> Option<Decision<'a>> {
        let mut hits = Hits::default();
        let outcome = sweep_mesh_with(
            &scene.mesh,
            sweep,
            &scene.options,
            Broadphase::Bvh,
            &mut hits,
        )
        .ok()?;
        let initial = if !scene.options.initial_overlap.is_rules()
            && outcome.hit.is_some_and(|h| h.alpha == 0.0)
        {
            let path = SweptPath::against(&scene.mesh, sweep, &scene.options).ok()?;
            initial_contacts(&scene.mesh, &path, &scene.options)
                .into_iter()
                .map(|(h, _)| h)
                .collect()
        } else {
            Vec::new()
        };
        Some(Decision {
            scene,
            sweep: *sweep,
            outcome: scene.normals.apply(sweep, outcome),
            hits: hits.0,
            initial,
        })
    }

    /// The normal a tie member reports under [`TieRule::Any`]: its own
    /// (its triangle's face normal, or its contact normal where the
    /// scene's normal rule gives that). `back`: the member was hit on its
    /// triangle's back (`sides = two`), whose face normal is `-n`.
    fn member_normal(&self, tie: &Tie, contact: &Point3<f64>, back: bool) -> Option<[f64; 3]> {
        let front = self.scene.mesh.triangle_by_index(tie.triangle)?.normal;
        let face = if back { -front } else { front };
        let alpha = self.outcome.hit.map_or(tie.alpha, |h| h.alpha);
        let n =
            self.scene
                .normals
                .normal(&self.sweep, alpha, tie.triangle, tie.feature, contact, face);
        Some([n.x, n.y, n.z])
    }

    /// The tolerances `member` is judged with: its own bound under
    /// `bounds` when its values are its own (`ties = "any"`: its own
    /// normal), else `tol` (the primary's: under the rule order a member
    /// carries the primary's normal, which the primary's bound is for).
    fn member_tolerances(
        &self,
        member: &OutcomeMsg,
        tol: &Tolerances,
        bounds: Option<&MemberBounds>,
    ) -> Tolerances {
        let own_values = self.scene.conventions.ties == TieRule::Any;
        let own = bounds.filter(|_| own_values).and_then(|b| {
            let hit = SweepHit {
                alpha: member.alpha,
                triangle: member.triangle??,
                feature: Feature::from_parts(member.kind, member.feature?)?,
                normal: member
                    .normal
                    .flatten()
                    .map(Into::into)
                    .or(self.outcome.hit.map(|h| h.normal))?,
                contact: member.contact??.into(),
            };
            let s = super::precision::Sensitivity::of_hit(self.scene, &self.sweep, &hit)?;
            Some(
                s.observing(b.expected, b.got, b.fixed)
                    .widen(b.fixed, b.budget),
            )
        });
        own.unwrap_or(*tol)
    }

    /// Whether the decision accepts `answer`: it matches the primary, or
    /// another member of the tie set with that member's own contact (see
    /// [`Decision::disagreement`], which says why not; this one only
    /// compares, for the searches that ask many times).
    pub(super) fn accepts(
        &self,
        answer: &OutcomeMsg,
        tol: &Tolerances,
        bounds: Option<&MemberBounds>,
    ) -> bool {
        let primary = OutcomeMsg::from_outcome(answer.frame, answer.ball, &self.outcome);
        differing(answer, &primary, tol).is_empty()
            || self.members(primary).any(|(member, _)| {
                let tol = self.member_tolerances(&member, tol, bounds);
                differing(answer, &member, &tol).is_empty()
            })
    }

    /// `None` when the decision accepts `answer` ([`Decision::accepts`]).
    /// Otherwise the fields that differ: from the first member the answer
    /// names, or from the primary. `tol` judges the primary; a member is
    /// judged by its own bound under `bounds` (by backward error), else by
    /// `tol` too.
    pub(super) fn disagreement(
        &self,
        answer: &OutcomeMsg,
        tol: &Tolerances,
        bounds: Option<&MemberBounds>,
    ) -> Option<Vec<FieldDiff>> {
        if self.accepts(answer, tol, bounds) {
            return None;
        }
        let primary = OutcomeMsg::from_outcome(answer.frame, answer.ball, &self.outcome);
        let named = self
            .members(primary)
            .find(|(_, tie)| names_tie(answer, tie))
            .map(|(member, _)| {
                compare(
                    answer,
                    &member,
                    &self.member_tolerances(&member, tol, bounds),
                )
            });
        Some(named.unwrap_or_else(|| compare(answer, &primary, tol)))
    }

    /// The members of the tie set other than the primary, in order (the
    /// sweep's tied hits, then the initial contacts), each as the outcome
    /// it stands for: the primary's fields with the member's kind,
    /// triangle, feature and contact, and its own normal under
    /// [`TieRule::Any`].
    fn members(&self, primary: OutcomeMsg) -> impl Iterator<Item = (OutcomeMsg, Tie)> + '_ {
        let any = self.scene.conventions.ties == TieRule::Any;
        let hits = self.hits.iter().filter_map(move |r| {
            let tie = Tie::of(r).filter(|t| self.outcome.ties_with(t.alpha))?;
            let mut member = primary;
            member.kind = tie.kind();
            member.triangle = Some(Some(tie.triangle));
            member.feature = Some(tie.feature.index());
            member.contact = Some(r.contact().map(|c| [c.x, c.y, c.z]));
            if any && let Some(contact) = r.contact() {
                member.normal = Some(self.member_normal(&tie, &contact, r.back()));
            }
            Some((member, tie))
        });
        let initial = self.initial.iter().map(move |h| {
            let tie = Tie {
                triangle: h.triangle,
                feature: h.feature,
                alpha: 0.0,
            };
            let mut member = primary;
            member.kind = tie.kind();
            member.triangle = Some(Some(tie.triangle));
            member.feature = Some(tie.feature.index());
            member.contact = Some(Some([h.contact.x, h.contact.y, h.contact.z]));
            if any {
                // An initial contact's normal is its side's (`-n` on a back).
                let back = self
                    .scene
                    .mesh
                    .triangle_by_index(tie.triangle)
                    .is_some_and(|t| t.normal.dot(&h.normal) < 0.0);
                member.normal = Some(self.member_normal(&tie, &h.contact, back));
            }
            (member, tie)
        });
        hits.chain(initial)
    }
}

/// Whether `answer` names `tie`. The trace spells "not given" as an absent
/// field (`None`) and "given as null" as `Some(None)`: a tie is a hit, so a
/// null triangle never names it, nor a null feature an edge or a vertex.
fn names_tie(answer: &OutcomeMsg, tie: &Tie) -> bool {
    let triangle = match answer.triangle {
        None => None,
        Some(None) => return false,
        Some(Some(t)) => Some(t),
    };
    let feature = match answer.feature {
        None => None,
        Some(None) if tie.feature != Feature::Face => return false,
        Some(f) => f,
    };
    tie.matches(answer.kind, triangle, feature)
}
