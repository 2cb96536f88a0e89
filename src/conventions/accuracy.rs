//! The `accuracy` convention: the backward-error budget an engine is held
//! to ([`Accuracy`]), and single precision's own ([`F32_BUDGET`]).

use std::fmt;

use serde::Serialize;

/// The backward-error budget an engine is held to, in units of `u₃₂ · S`
/// (`accuracy` in the `[engine]` table): single precision's own is
/// [`F32_BUDGET`]; a calibrated engine declares less (what it showed when
/// known good), an engine whose solver is coarser than its arithmetic more.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Accuracy(f64);

/// Single precision's backward-error budget `c`, in units of `u₃₂ · S`:
/// what a single-precision engine spends on one sweep, when no `accuracy`
/// is declared. Its inputs are rounded to
/// `f32` (1 unit each); a compressed mesh stores its vertices on a grid of
/// 2²¹ steps across its bounds (Jolt's `MeshShape`: 8 units); the cast
/// transforms the inputs into the shape's space and runs a few dozen
/// operations on them, each rounding by 1 unit of its own magnitude, of
/// which a handful add up along one direction. 16 covers those with room
/// to spare; a real error of the engine (a contact 0.2 % late on a sweep
/// that meets the surface squarely) is hundreds of units.
pub const F32_BUDGET: f64 = 16.0;

/// The largest accuracy that can be declared, `2²⁰` units: beyond it the
/// inputs would move by more than a 16th of the scene's scale, and nothing
/// would be judged.
pub const MAX_ACCURACY: f64 = 1_048_576.0;

impl Accuracy {
    /// A budget of `units`, which must be as [`Accuracy`]'s parser takes
    /// (clamped into `(0, 2²⁰]` otherwise).
    pub fn new(units: f64) -> Accuracy {
        Accuracy(if units > 0.0 {
            units.min(MAX_ACCURACY)
        } else {
            1.0
        })
    }

    /// The budget, in units of `u₃₂ · S`.
    pub fn units(self) -> f64 {
        self.0
    }

    /// In words, for reports: `2^12 u₃₂·S, coarser than single precision
    /// explains (16)`, or `4 u₃₂·S, calibrated below single precision's 16`.
    pub fn words(self) -> String {
        let size = crate::numbers::power_of_two_text(self.0);
        if self.0 > F32_BUDGET {
            format!(
                "{size} u₃₂·S, coarser than single precision explains ({}): the engine's \
                 solver tolerance",
                F32_BUDGET
            )
        } else if self.0 < F32_BUDGET {
            format!("{size} u₃₂·S, calibrated below single precision's {F32_BUDGET}")
        } else {
            format!("{size} u₃₂·S, single precision's own")
        }
    }
}

impl fmt::Display for Accuracy {
    /// The number as TOML writes it (`4096`, `0.5`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.fract() == 0.0 {
            write!(f, "{}", self.0 as u64)
        } else {
            write!(f, "{:?}", self.0)
        }
    }
}

impl std::str::FromStr for Accuracy {
    type Err = String;
    /// A finite number `> 0` and at most [`MAX_ACCURACY`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let a = crate::numbers::parse_f64(s).ok_or_else(|| format!("`{s}` is not a number"))?;
        if !(a.is_finite() && a > 0.0 && a <= MAX_ACCURACY) {
            return Err(format!(
                "`{s}` is not a budget: it takes a number of u32 units of the sweep's scale, \
                 greater than 0 and at most 2^20 (single precision's own is 16)"
            ));
        }
        Ok(Accuracy(a))
    }
}

impl Serialize for Accuracy {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_f64(self.0)
    }
}
