//! Known mistakes of collision code, by the α they give: when an
//! expectation's α is what one of them gives on the test that should have
//! produced it, `check` names the mistake in words instead of "the same test
//! with other numbers".
//!
//! One table, [`KNOWN_MISTAKES`]: each entry has a name, a sentence, and
//! the α the mistake gives from a test's record and `ρ` (`None` where it
//! does not apply). To add one, add an entry.

use crate::core::record::{EdgeRecord, FaceRecord, TestRecord, Verdict, VertexRecord};

/// A mistake collision code makes, recognised by the α it gives.
#[derive(Clone, Copy, Debug)]
pub struct Mistake {
    /// A short name (`radius_ignored`), for JSON.
    pub name: &'static str,
    /// What the mistake is, in words.
    pub words: &'static str,
    /// The α the mistake gives for the test of `record`, with the sweep's
    /// `rho` (ρ = r - ε); `None` where it does not apply.
    alpha: fn(record: &TestRecord, rho: f64) -> Option<f64>,
}

/// The mistakes `check` recognises, in the order it tries them.
pub const KNOWN_MISTAKES: &[Mistake] = &[
    Mistake {
        name: "radius_ignored",
        words: "ρ = 0, the radius ignored: α = h0/|n·d|, where the ball's centre reaches the \
                face's plane, instead of (h0 - ρ)/|n·d| where its surface does",
        alpha: |record, _| face(record).and_then(|f| forward(f.h0, -f.normal_dot_d)),
    },
    Mistake {
        name: "later_root",
        words: "the later root s1 instead of s0: the time the ball leaves the surface, not the \
                time it first touches it",
        alpha: |record, rho| match record {
            TestRecord::Face(f) => forward(f.h0 + rho, -f.normal_dot_d),
            TestRecord::Edge(EdgeRecord { roots, .. })
            | TestRecord::Vertex(VertexRecord { roots, .. }) => {
                roots.map(|(_, s1)| s1).filter(|s| (0.0..=1.0).contains(s))
            }
        },
    },
    // Under `sides = "two"` this is the declared convention, not a
    // mistake: the core then tests such a triangle from its back (its
    // records have `n · d < 0` and hit), so the entry never applies.
    Mistake {
        name: "two_sided",
        words: "the two-sided rule: a back-facing contact (n·d > 0, the ball moving out of the \
                surface's back) accepted as a hit",
        alpha: |record, rho| match record {
            TestRecord::Face(f) if f.normal_dot_d > 0.0 => forward(-f.h0 - rho, f.normal_dot_d),
            TestRecord::Edge(EdgeRecord { roots, verdict, .. })
            | TestRecord::Vertex(VertexRecord { roots, verdict, .. })
                if *verdict == Verdict::BackFacing =>
            {
                roots.map(|(s0, _)| s0).filter(|s| (0.0..=1.0).contains(s))
            }
            _ => None,
        },
    },
    Mistake {
        name: "alpha_from_p1",
        words: "α measured from p1 instead of p0: 1 - α",
        alpha: |record, _| record.alpha().map(|a| 1.0 - a),
    },
];

/// The face record of `record`, if it is one.
fn face(record: &TestRecord) -> Option<&FaceRecord> {
    match record {
        TestRecord::Face(f) => Some(f),
        _ => None,
    }
}

/// `distance / speed` when it is a time on the path (in `[0, 1]`).
fn forward(distance: f64, speed: f64) -> Option<f64> {
    (speed > 0.0)
        .then(|| distance / speed)
        .filter(|s| (0.0..=1.0).contains(s))
}

/// The first known mistake that gives `expected_alpha` on the test of
/// `record` (to a few rounding errors: the same computation done in
/// another order), with the α it gives. A test whose own α is the
/// expected one is no mistake.
pub fn known_mistake(
    record: &TestRecord,
    rho: f64,
    expected_alpha: f64,
) -> Option<&'static Mistake> {
    let close = |a: f64| (a - expected_alpha).abs() <= 1e-9 * expected_alpha.abs().max(1.0);
    if record.alpha().is_some_and(close) {
        return None;
    }
    KNOWN_MISTAKES
        .iter()
        .find(|m| (m.alpha)(record, rho).is_some_and(close))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::record::CollectRecords;
    use crate::core::{Broadphase, Mesh, Options, Sides, Sweep, sweep_mesh_with};

    /// The face record of worked example 1 from behind, and the α of the
    /// sweep, under `sides`.
    fn from_behind(sides: Sides) -> (TestRecord, f64) {
        let mesh = Mesh::new(
            vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
            &[[0, 1, 2]],
        )
        .expect("valid mesh");
        let options = Options {
            sides,
            ..Options::default()
        };
        let sweep = Sweep::new([1.0, 1.0, -3.0], [1.0, 1.0, 3.0], 0.5);
        let mut records = CollectRecords::default();
        let outcome = sweep_mesh_with(
            &mesh,
            &sweep,
            &options,
            Broadphase::Exhaustive,
            &mut records,
        )
        .expect("valid sweep");
        let face = records
            .records
            .into_iter()
            .find(|r| matches!(r, TestRecord::Face(_)))
            .expect("a face record");
        (face, outcome.hit.map_or(1.0, |h| h.alpha))
    }

    #[test]
    fn a_hit_from_behind_is_the_two_sided_mistake_only_under_one_side() {
        let two_sided_alpha = 2.5 / 6.0;
        let (record, alpha) = from_behind(Sides::One);
        assert_eq!(alpha, 1.0);
        assert_eq!(
            known_mistake(&record, 0.5, two_sided_alpha).map(|m| m.name),
            Some("two_sided")
        );
        let (record, alpha) = from_behind(Sides::Two);
        assert_eq!(alpha, two_sided_alpha);
        assert!(record.back());
        assert!(known_mistake(&record, 0.5, two_sided_alpha).is_none());
        assert!(
            KNOWN_MISTAKES
                .iter()
                .find(|m| m.name == "two_sided")
                .is_some_and(|m| (m.alpha)(&record, 0.5).is_none())
        );
    }
}
