//! Precision as part of the judgement: an engine that computes in single
//! precision is judged by **backward error**. Its answer passes when it is
//! what the exact rules give for inputs moved by at most `c · u₃₂ · S`,
//! where `u₃₂ = 2⁻²⁴` is the unit roundoff of `f32`, `S` the sweep's scale
//! (the largest coordinate magnitude the tests subtract, as the core's own
//! rounding unit uses it) and `c` = [`F32_OPERATIONS`].
//!
//! For the continuous fields the bound is first order: each field's
//! sensitivity to a move `δ` of the inputs ([`Sensitivity`]). A ball
//! meeting a feature along the contact normal `n` closes in at `|d · n|`
//! per unit of `α`; the centre, the feature and the radius each move the
//! contact by at most `δ` along `n`, so `|Δα| ≤ 3δ / |d · n|`. The contact
//! point moves with the feature (`δ`, twice for an edge's two ends) and
//! with the centre along the surface (`|Δα| · |d_t|`, `d_t` the part of `d`
//! across `n`); the normal turns by the moves of the contact and the
//! centre over `ρ`, and a face normal by `2δ` over the triangle's shortest
//! edge. A difference in the discrete fields (kind, triangle, feature, hit
//! or miss) passes only when a move of one input within the same budget
//! makes the core give the engine's answer (the perturbations of
//! [`super::judge`], at `u₃₂ · S` instead of `f64`'s unit).
//!
//! None of this runs on a sweep that agrees within the fixed tolerances.

use serde::{Deserialize, Serialize};

use crate::core::SweptPath;
use crate::replay::SweepResult;
use crate::trace::OutcomeMsg;

use super::compare::{Field, FieldDiff, Tolerances, angle_degrees};

/// The arithmetic an engine computes in: an engine convention
/// (`precision` in `sweeptrace.toml`'s `[engine]` table).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Precision {
    /// Double precision: the fixed tolerances, as always.
    #[default]
    F64,
    /// Single precision: differences judged by backward error.
    F32,
}

impl Precision {
    /// Whether this is the default, `f64`.
    pub fn is_f64(&self) -> bool {
        *self == Precision::F64
    }
}

/// The unit roundoff of `f32`, `u₃₂ = 2⁻²⁴`.
pub const F32_UNIT: f64 = 1.0 / 16_777_216.0;

/// `c`, the backward-error budget in units of `u₃₂ · S`: what a
/// single-precision engine spends on one sweep. Its inputs are rounded to
/// `f32` (1 unit each); a compressed mesh stores its vertices on a grid of
/// 2²¹ steps across its bounds (Jolt's `MeshShape`: 8 units); the cast
/// transforms the inputs into the shape's space and runs a few dozen
/// operations on them, each rounding by 1 unit of its own magnitude, of
/// which a handful add up along one direction. 16 covers those with room
/// to spare; a real error of the engine (a contact 0.2 % late on a sweep
/// that meets the surface squarely) is hundreds of units.
pub const F32_OPERATIONS: f64 = 16.0;

/// How much each continuous field of the reference answer moves per unit
/// move of the inputs, `δ = u₃₂ · S` (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Sensitivity {
    /// `δ = u₃₂ · S`, in the scene's length unit.
    pub unit: f64,
    /// `|Δα|` per unit move (infinite for a contact met tangentially).
    pub alpha: f64,
    /// The contact point's move per unit move, a length.
    pub contact: f64,
    /// The normal's turn per unit move, in degrees.
    pub normal_degrees: f64,
}

impl Sensitivity {
    /// The sensitivity of the core's answer to `result`, which must be a
    /// hit; `None` for a miss or an invalid sweep.
    pub fn of(result: &SweepResult) -> Option<Sensitivity> {
        let hit = result.outcome.hit?;
        let scene = &result.scene;
        let (lo, hi) = scene.mesh.bounds();
        let path = SweptPath::new(&result.sweep, &scene.options)
            .ok()?
            .with_mesh_scale(&lo, &hi);
        let unit = F32_UNIT * path.scale;
        let d = path.d;
        let centre = path.p0 + d * hit.alpha;
        let towards = centre - hit.contact;
        let n = if towards.norm() > 0.0 {
            towards.normalize()
        } else {
            hit.normal
        };
        let closing = d.dot(&n).abs();
        let alpha = if closing > 0.0 {
            3.0 * unit / closing
        } else {
            f64::INFINITY
        };
        let across = (d - n * d.dot(&n)).norm();
        let moved = 2.0 * unit + (alpha * across).min(path.length + unit);
        let shortest_edge = scene
            .mesh
            .triangle_by_index(hit.triangle)
            .map_or(f64::INFINITY, |t| {
                t.edges
                    .iter()
                    .map(|e| e.length)
                    .fold(f64::INFINITY, f64::min)
            });
        let turn = 2.0 * unit / shortest_edge + (unit + moved) / path.rho;
        Some(Sensitivity {
            unit,
            alpha,
            contact: moved,
            normal_degrees: turn.to_degrees(),
        })
    }

    /// `tol` widened to the moves `c` units of the inputs give.
    pub fn widen(&self, tol: &Tolerances, c: f64) -> Tolerances {
        Tolerances {
            alpha: tol.alpha.max(c * self.alpha),
            contact: tol.contact.max(c * self.contact),
            normal_degrees: tol.normal_degrees.max(c * self.normal_degrees),
            ..*tol
        }
    }

    /// The backward error of the continuous differences `fields` between
    /// `expected` and `got`: the smallest move of the inputs, in units of
    /// `u₃₂ · S`, that explains every one of them to first order.
    pub fn backward_error(
        &self,
        fields: &[FieldDiff],
        expected: &OutcomeMsg,
        got: &OutcomeMsg,
    ) -> f64 {
        let ratio = |difference: f64, per_unit: f64| {
            if difference <= 0.0 {
                0.0
            } else if per_unit > 0.0 {
                difference / per_unit
            } else {
                f64::INFINITY
            }
        };
        let points =
            |a: Option<Option<[f64; 3]>>, b: Option<Option<[f64; 3]>>| a.flatten().zip(b.flatten());
        fields
            .iter()
            .map(|f| match f.field {
                Field::Alpha => ratio((expected.alpha - got.alpha).abs(), self.alpha),
                Field::Contact => match points(expected.contact, got.contact) {
                    Some((a, b)) => ratio(
                        (nalgebra::Vector3::from(a) - nalgebra::Vector3::from(b)).norm(),
                        self.contact,
                    ),
                    None => f64::INFINITY,
                },
                Field::Normal => match points(expected.normal, got.normal) {
                    Some((a, b)) => angle_degrees(a, b)
                        .map_or(f64::INFINITY, |angle| ratio(angle, self.normal_degrees)),
                    None => f64::INFINITY,
                },
                Field::Kind | Field::Triangle | Field::Feature => f64::INFINITY,
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unit_is_two_to_the_minus_24() {
        assert_eq!(F32_UNIT, f64::from(f32::EPSILON) / 2.0);
    }

    #[test]
    fn precision_names_round_trip() {
        for p in [Precision::F64, Precision::F32] {
            assert_eq!(p.to_string().parse::<Precision>(), Ok(p));
        }
        assert!("f16".parse::<Precision>().is_err());
    }
}
