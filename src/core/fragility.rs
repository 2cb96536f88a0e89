//! Why a decision may not survive a change of its inputs at the level of
//! their rounding: a small `Copy` set of named reasons.

use serde::ser::SerializeSeq;
use serde::{Serialize, Serializer};

/// One reason a decision is fragile. The thresholds are in
/// [`options`](super::options::FRAGILE_ULPS) and in docs/SEMANTICS.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FragileReason {
    /// Another hit (another triangle, kind or feature) lies within the
    /// fragility band of the minimum `α`: the tie window, or just outside
    /// it, decided between them.
    Tie,
    /// An edge or vertex contact whose quadratic is nearly tangent
    /// (approach cosine `√disc / (2ρ|d|)` below `GRAZING_COSINE`), or a
    /// tangent that missed by less than the fragility band.
    NearTangent,
    /// A face contact approached at a shallow angle (`|n · d| / |d|` below
    /// `GRAZING_COSINE`), or a triangle whose facing value is that small
    /// and whose tests hit (or would hit if the facing rule turned).
    Grazing,
    /// The ball touches a feature at the start of the path: a hit, or a
    /// test rejected because the ball starts just inside (`h0 − ρ` or `C`
    /// near 0), within the fragility band of `α = 0`.
    StartTouching,
    /// A hit within the fragility band of `α = 1`, or a contact just beyond
    /// the end of the path.
    NearEnd,
    /// A contact within the fragility band of its feature's boundary (a
    /// barycentric weight, or `xc` near 0 or `L`), or a touch point or `xc`
    /// just outside it.
    NearBoundary,
    /// One rounding of the inputs moves `α` by more than
    /// `ALPHA_SENSITIVITY` (a path short compared with the coordinates'
    /// magnitude).
    ImpreciseAlpha,
}

impl FragileReason {
    /// Every reason, in declaration order.
    pub const ALL: [FragileReason; 7] = [
        FragileReason::Tie,
        FragileReason::NearTangent,
        FragileReason::Grazing,
        FragileReason::StartTouching,
        FragileReason::NearEnd,
        FragileReason::NearBoundary,
        FragileReason::ImpreciseAlpha,
    ];

    /// Snake-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            FragileReason::Tie => "tie",
            FragileReason::NearTangent => "near_tangent",
            FragileReason::Grazing => "grazing",
            FragileReason::StartTouching => "start_touching",
            FragileReason::NearEnd => "near_end",
            FragileReason::NearBoundary => "near_boundary",
            FragileReason::ImpreciseAlpha => "imprecise_alpha",
        }
    }

    #[inline]
    const fn bit(self) -> u8 {
        1 << self as u8
    }
}

impl std::fmt::Display for FragileReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The set of reasons a decision is fragile; empty when it is robust.
/// Serializes as a list of snake-case names.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Fragility(u8);

impl Fragility {
    /// No reason: a robust decision.
    pub const ROBUST: Fragility = Fragility(0);

    /// Whether no reason is set.
    #[inline]
    pub fn is_robust(self) -> bool {
        self.0 == 0
    }

    /// Whether `reason` is set.
    #[inline]
    pub fn contains(self, reason: FragileReason) -> bool {
        self.0 & reason.bit() != 0
    }

    /// Adds `reason`.
    #[inline]
    pub fn insert(&mut self, reason: FragileReason) {
        self.0 |= reason.bit();
    }

    /// The set with `reason` added.
    #[inline]
    pub fn with(mut self, reason: FragileReason) -> Fragility {
        self.insert(reason);
        self
    }

    /// The reasons set, in declaration order.
    pub fn iter(self) -> impl Iterator<Item = FragileReason> {
        FragileReason::ALL
            .into_iter()
            .filter(move |r| self.contains(*r))
    }

    /// Number of reasons set.
    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Same as [`Fragility::is_robust`].
    pub fn is_empty(self) -> bool {
        self.is_robust()
    }
}

impl FromIterator<FragileReason> for Fragility {
    fn from_iter<I: IntoIterator<Item = FragileReason>>(iter: I) -> Self {
        let mut f = Fragility::ROBUST;
        for r in iter {
            f.insert(r);
        }
        f
    }
}

/// `tie, near_boundary`, or `robust`.
impl std::fmt::Display for Fragility {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.is_robust() {
            return f.write_str("robust");
        }
        for (i, r) in self.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(r.as_str())?;
        }
        Ok(())
    }
}

impl Serialize for Fragility {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut seq = serializer.serialize_seq(Some(self.len()))?;
        for r in self.iter() {
            seq.serialize_element(r.as_str())?;
        }
        seq.end()
    }
}
