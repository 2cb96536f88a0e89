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
//! contact by at most `δ` along `n`, so `|Δα| ≤ 3δ / |d · n|`.
//!
//! The contact point is bounded in two directions. **Along `n`** it moves
//! only with the feature and the radius, `3δ`: uncertainty in `α` slides a
//! contact within the surface, never off it, so a face contact off its
//! triangle's plane by more than that is an error, however slow the sweep.
//! **Across `n`** it moves with the feature (`2δ`, an edge's two ends) and
//! with the centre along the surface (`|Δα| · |d_t|`, `d_t` the part of `d`
//! across `n`, at most the path's length).
//!
//! **The normal.** A face normal (a face hit's, or the face normal the
//! rules report at an edge or a vertex) is the triangle's whatever `α` is:
//! it turns only with the triangle's vertices, by `2δ` over the triangle's
//! shortest edge. A contact normal (the centre minus the contact, at an
//! edge or a vertex under a contact-normal convention) turns with the moves
//! of the contact and the centre over `ρ`, where the centre's move along
//! the surface is the one the answer needs: `|Δα| · |d_t|` with the `Δα`
//! between the two answers (when `α` is compared), not the worst case of
//! the bound on `α`. Its length is not a matter of geometry: a normal is a
//! unit vector within the fixed normal tolerance ([`super::compare`]).
//!
//! **Grazing contacts.** On an edge or a vertex the first-order bound
//! breaks down near a double root of the quadratic: a ball that only
//! grazes the feature meets it with `d · n → 0`, so `3δ / |d · n|` grows
//! without bound, while the true move of `α` stays finite and grows as the
//! square root of the move of the inputs. There the bound is the exact
//! change of the root of `|d⊥|² (α − α*)² + m² = ρ²` (`d⊥` the part of `d`
//! across the edge, or all of `d` at a vertex, `m` the path's closest
//! approach to the feature): with `s = √(ρ² − m²) = ρ |d · n| / |d⊥|`, a
//! move `ε = 3δ` of the contact distance changes `s²` by at most
//! `2ρε + ε²`, so `s` moves by at most
//! `max(√(s² + 2ρε + ε²) − s, s − √(max(0, s² − 2ρε)))`, which is `ρε / s`
//! to first order and `√(2ρε)` at a tangent contact (`s = 0`); the moves
//! along the path shift `α*` by `2ε / 3 |d⊥|` more. A face has no double
//! root (the plane does not curve): its `α` is linear in the moves, and a
//! ball sliding along the plane is ill-conditioned there, as the bound
//! says. The backward error inverts these bounds (by bisection, since the
//! edge and vertex bound is not linear).
//!
//! A difference in the discrete fields (kind, triangle, feature, hit
//! or miss) passes only when a move of one input within the same budget
//! makes the core give the engine's answer (the perturbations of
//! [`super::agreement`], at `u₃₂ · S` instead of `f64`'s unit).
//!
//! None of this runs on a sweep that agrees within the fixed tolerances.

use serde::Serialize;

use nalgebra::Vector3;

use crate::core::{Feature, Sweep, SweepHit, SweptPath};
use crate::replay::{SceneState, SweepResult};
use crate::trace::OutcomeMsg;

use super::compare::{ContactAxis, Field, FieldDiff, Tolerances, angle_degrees};

/// The unit roundoff of `f32`, `u₃₂ = 2⁻²⁴`.
pub const F32_UNIT: f64 = 1.0 / 16_777_216.0;

/// `c`, single precision's backward-error budget in units of `u₃₂ · S`:
/// [`crate::conventions::F32_BUDGET`], where it is explained. A declared
/// `accuracy` replaces it ([`crate::conventions::EngineConventions::budget`]).
pub const F32_OPERATIONS: f64 = crate::conventions::F32_BUDGET;

/// How much each continuous field of the reference answer moves when the
/// inputs move by `units · δ`, `δ = u₃₂ · S` (see the module's
/// documentation): [`Sensitivity::bounds`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Sensitivity {
    /// `δ = u₃₂ · S`, in the scene's length unit.
    pub unit: f64,
    /// `|Δα|` per unit move to first order (infinite for a contact met
    /// tangentially; the bound itself is then finite, see
    /// [`Sensitivity::bounds`]).
    pub alpha: f64,
    /// The contact point's move per unit move to first order, a length.
    pub contact: f64,
    /// The normal's turn per unit move to first order, in degrees.
    pub normal_degrees: f64,
    /// What the bounds are computed from.
    #[serde(skip)]
    geometry: Geometry,
    /// `|Δα|` between the two answers judged, when `α` is compared
    /// ([`Sensitivity::observing`]): a contact normal turns by the centre's
    /// move that this `Δα` gives, not by the whole bound on `α`.
    #[serde(skip)]
    observed_alpha: Option<f64>,
}

/// The quantities of one hit that its bounds depend on.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Geometry {
    /// `|d · n|`, the speed of approach along the contact normal.
    closing: f64,
    /// For an edge or a vertex: `|d⊥|`, the speed across the feature (the
    /// part of `d` across the edge; all of `d` at a vertex). `None` on a
    /// face, where `α` is linear in the moves.
    across_feature: Option<f64>,
    /// `|d_t|`, the part of `d` across the contact normal.
    along_surface: f64,
    /// The path's length `|d|` (the contact cannot move further than it).
    length: f64,
    /// The ball's radius `ρ` (with the margin).
    rho: f64,
    /// The hit triangle's shortest edge.
    shortest_edge: f64,
    /// The contact normal `n` (the centre minus the contact, unit).
    normal: Vector3<f64>,
    /// Whether the reported normal is a face normal (the triangle's, or an
    /// average of simultaneous triangles'), which does not turn with `α`.
    face_normal: bool,
    /// Whether the hit is on a face (its contact lies in the plane).
    on_face: bool,
}

/// The bounds at one budget: how far each continuous field may move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// `|Δα|`.
    pub alpha: f64,
    /// The contact point's move across the contact normal, a length.
    pub contact: f64,
    /// The contact point's move along the contact normal (off the
    /// surface), a length.
    pub contact_along_normal: f64,
    /// The normal's turn, in degrees.
    pub normal_degrees: f64,
}

impl Sensitivity {
    /// The sensitivity of the core's answer to `result`, which must be a
    /// hit; `None` for a miss or an invalid sweep.
    pub fn of(result: &SweepResult) -> Option<Sensitivity> {
        Sensitivity::of_hit(&result.scene, &result.sweep, &result.outcome.hit?)
    }

    /// The sensitivity of the core's hit `hit` on `sweep` in `scene` (a
    /// perturbed sweep's, when the unperturbed one is a miss).
    pub(super) fn of_hit(scene: &SceneState, sweep: &Sweep, hit: &SweepHit) -> Option<Sensitivity> {
        let path = SweptPath::against(&scene.mesh, sweep, &scene.options).ok()?;
        let unit = F32_UNIT * path.scale;
        let d = path.d;
        let centre = path.p0 + d * hit.alpha;
        let towards = centre - hit.contact;
        let n = if towards.norm() > 0.0 {
            towards.normalize()
        } else {
            hit.normal
        };
        let triangle = scene.mesh.triangle_by_index(hit.triangle);
        let across_feature = match hit.feature {
            Feature::Face => None,
            Feature::Vertex(_) => Some(d.norm()),
            Feature::Edge(i) => {
                let frame = triangle.map(|t| t.edges[usize::from(i) % 3]);
                let along = frame.map_or(0.0, |f| {
                    (f.edge_from_world_rotation.transpose() * Vector3::x()).dot(&d)
                });
                Some((d.norm_squared() - along * along).max(0.0).sqrt())
            }
        };
        let shortest_edge = triangle.map_or(f64::INFINITY, |t| {
            t.edges
                .iter()
                .map(|e| e.length)
                .fold(f64::INFINITY, f64::min)
        });
        // The reported normal is a face normal when it is the triangle's
        // (either side), or when it is not the contact normal (an average of
        // simultaneous triangles' face normals).
        let face_normal = hit.feature == Feature::Face
            || triangle.is_some_and(|t| {
                (hit.normal - t.normal).norm() < 1e-9 || (hit.normal + t.normal).norm() < 1e-9
            })
            || (hit.normal - n).norm() > 1e-6;
        let geometry = Geometry {
            closing: d.dot(&n).abs(),
            across_feature,
            along_surface: (d - n * d.dot(&n)).norm(),
            length: path.length,
            rho: path.rho,
            shortest_edge,
            normal: n,
            face_normal,
            on_face: hit.feature == Feature::Face,
        };
        let first_order = Sensitivity::first_order(unit, &geometry);
        Some(Sensitivity {
            unit,
            alpha: first_order.alpha,
            contact: first_order.contact,
            normal_degrees: first_order.normal_degrees,
            geometry,
            observed_alpha: None,
        })
    }

    /// The same sensitivity, judging `expected` against `got`: the `Δα`
    /// between them (when `tol` compares `α` and both are finite) is the
    /// move of the centre a contact normal is allowed to follow.
    pub fn observing(mut self, expected: &OutcomeMsg, got: &OutcomeMsg, tol: &Tolerances) -> Self {
        let delta = (expected.alpha - got.alpha).abs();
        self.observed_alpha =
            (tol.fields.contains(Field::Alpha) && delta.is_finite()).then_some(delta);
        self
    }

    /// The first-order moves per unit move of the inputs.
    fn first_order(unit: f64, g: &Geometry) -> Bounds {
        let alpha = if g.closing > 0.0 {
            3.0 * unit / g.closing
        } else {
            f64::INFINITY
        };
        Sensitivity::following(unit, 1.0, alpha, g, None)
    }

    /// The contact's moves and the normal's turn at `units`, given the
    /// bound on `α` there; `observed`: the `Δα` the answers show.
    fn following(unit: f64, units: f64, alpha: f64, g: &Geometry, observed: Option<f64>) -> Bounds {
        let move_of = |alpha: f64| (alpha * g.along_surface).min(g.length + units * unit);
        let face_turn = 2.0 * units * unit / g.shortest_edge;
        let turn = if g.face_normal {
            face_turn
        } else {
            // The centre's move that the answer needs, at most the bound's.
            let needed = move_of(observed.map_or(alpha, |o| o.min(alpha)));
            face_turn + (3.0 * units * unit + needed) / g.rho
        };
        Bounds {
            alpha,
            contact: 2.0 * units * unit + move_of(alpha),
            contact_along_normal: 3.0 * units * unit,
            normal_degrees: turn.to_degrees(),
        }
    }

    /// How far each continuous field may move when the inputs move by
    /// `units · δ`: on a face, `units` times the first-order figures; on
    /// an edge or a vertex, the change of the quadratic's root, which
    /// stays finite at a tangent contact (the module's documentation).
    pub fn bounds(&self, units: f64) -> Bounds {
        let g = &self.geometry;
        let Some(speed) = g.across_feature.filter(|v| *v > 0.0) else {
            let alpha = units * self.alpha;
            return Sensitivity::following(self.unit, units, alpha, g, self.observed_alpha);
        };
        let eps = 3.0 * units * self.unit;
        let s = (g.rho * g.closing / speed).min(g.rho);
        let grown = ((s * s + 2.0 * g.rho * eps + eps * eps).sqrt() - s).max(0.0);
        let shrunk = s - (s * s - 2.0 * g.rho * eps).max(0.0).sqrt();
        let alpha = (grown.max(shrunk) + 2.0 * eps / 3.0) / speed;
        Sensitivity::following(self.unit, units, alpha, g, self.observed_alpha)
    }

    /// `tol` widened to the moves `c` units of the inputs give: `α`, the
    /// contact across the normal and the normal's direction; the contact
    /// along the normal by its own bound; the normal's length not at all.
    pub fn widen(&self, tol: &Tolerances, c: f64) -> Tolerances {
        let b = self.bounds(c);
        let g = &self.geometry;
        Tolerances {
            alpha: tol.alpha.max(b.alpha),
            contact: tol.contact.max(b.contact),
            contact_axis: Some(ContactAxis {
                axis: g.normal.into(),
                tolerance: tol.contact.max(b.contact_along_normal),
                plane: g.on_face,
            }),
            normal_degrees: tol.normal_degrees.max(b.normal_degrees),
            normal_length: Some(tol.normal_length()),
            ..*tol
        }
    }

    /// The smallest budget, in units, whose bound on one field (`of`)
    /// reaches `difference`: a bisection, the bounds growing with the
    /// budget. Infinite when no budget up to `2⁶⁰` units does.
    fn units_for(&self, difference: f64, of: impl Fn(&Bounds) -> f64) -> f64 {
        if difference <= 0.0 {
            return 0.0;
        }
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        while of(&self.bounds(hi)) < difference {
            if hi > 1e18 {
                return f64::INFINITY;
            }
            lo = hi;
            hi *= 2.0;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if of(&self.bounds(mid)) < difference {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// The backward error of the continuous differences `fields` between
    /// `expected` and `got`: the smallest move of the inputs, in units of
    /// `u₃₂ · S`, that explains every one of them (to first order on a
    /// face; through the quadratic's root on an edge or a vertex).
    pub fn backward_error(
        &self,
        fields: &[FieldDiff],
        expected: &OutcomeMsg,
        got: &OutcomeMsg,
    ) -> f64 {
        let points =
            |a: Option<Option<[f64; 3]>>, b: Option<Option<[f64; 3]>>| a.flatten().zip(b.flatten());
        fields
            .iter()
            .map(|f| match f.field {
                Field::Alpha => self.units_for((expected.alpha - got.alpha).abs(), |b| b.alpha),
                Field::Contact => match points(expected.contact, got.contact) {
                    Some((a, b)) => {
                        let moved = Vector3::from(a) - Vector3::from(b);
                        let along = moved.dot(&self.geometry.normal).abs();
                        let across = (moved.norm_squared() - along * along).max(0.0).sqrt();
                        self.units_for(along, |b| b.contact_along_normal)
                            .max(self.units_for(across, |b| b.contact))
                    }
                    None => f64::INFINITY,
                },
                Field::Normal => match points(expected.normal, got.normal) {
                    Some((a, b)) => angle_degrees(a, b).map_or(f64::INFINITY, |angle| {
                        self.units_for(angle, |b| b.normal_degrees)
                    }),
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
    use crate::conventions::Precision;

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

    fn sensitivity(closing: f64, across_feature: Option<f64>) -> Sensitivity {
        let geometry = Geometry {
            closing,
            across_feature,
            along_surface: 1.0,
            length: 1.0,
            rho: 0.5,
            shortest_edge: 1.0,
            normal: Vector3::z(),
            face_normal: across_feature.is_none(),
            on_face: across_feature.is_none(),
        };
        let unit = 1e-7;
        let first = Sensitivity::first_order(unit, &geometry);
        Sensitivity {
            unit,
            alpha: first.alpha,
            contact: first.contact,
            normal_degrees: first.normal_degrees,
            geometry,
            observed_alpha: None,
        }
    }

    #[test]
    fn a_tangent_contact_has_a_square_root_bound() {
        // A ball grazing a vertex: d · n = 0, the first order is infinite.
        let s = sensitivity(0.0, Some(1.0));
        assert!(s.alpha.is_infinite());
        let b = s.bounds(16.0).alpha;
        let eps: f64 = 3.0 * 16.0 * 1e-7;
        let root = (2.0 * 0.5 * eps + eps * eps).sqrt();
        assert!((b - (root + 2.0 * eps / 3.0)).abs() < 1e-12, "{b}");
        // It grows as the square root of the budget, not linearly.
        let ratio = s.bounds(64.0).alpha / b;
        assert!((ratio - 2.0).abs() < 0.05, "{ratio}");
    }

    #[test]
    fn away_from_tangency_the_bound_is_first_order() {
        // Head on: d · n = |d⊥| = 1, s = ρ.
        let s = sensitivity(1.0, Some(1.0));
        let b = s.bounds(16.0).alpha;
        let first = 16.0 * s.alpha;
        assert!(b >= first && b < 2.0 * first, "{b} against {first}");
        // A face is linear in the moves.
        let face = sensitivity(0.25, None);
        assert_eq!(face.bounds(16.0).alpha, 16.0 * face.alpha);
    }

    #[test]
    fn the_backward_error_inverts_the_bounds() {
        for s in [
            sensitivity(0.0, Some(1.0)),
            sensitivity(0.3, Some(0.8)),
            sensitivity(0.25, None),
        ] {
            for units in [0.5, 3.0, 16.0, 700.0] {
                let found = s.units_for(s.bounds(units).alpha, |b| b.alpha);
                assert!((found / units - 1.0).abs() < 1e-9, "{units}: {found}");
            }
            assert_eq!(s.units_for(0.0, |b| b.alpha), 0.0);
        }
    }
}
