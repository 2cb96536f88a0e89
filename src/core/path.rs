//! A validated sweep: the ball's path and detection radius.

use nalgebra::{Point3, Vector3};

use super::error::SweepError;
use super::options::{BROADPHASE_MARGIN, FRAGILE_ULPS, Options, TIE_WINDOW_ULPS};

/// One sweep as given: the ball of radius `radius` moves from `p0` to `p1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// Start of the ball's center.
    pub p0: Point3<f64>,
    /// End of the ball's center.
    pub p1: Point3<f64>,
    /// Radius `r` of the ball.
    pub radius: f64,
}

impl Sweep {
    /// A sweep from `p0` to `p1` of a ball of radius `radius`.
    pub fn new(p0: [f64; 3], p1: [f64; 3], radius: f64) -> Sweep {
        Sweep {
            p0: Point3::from(p0),
            p1: Point3::from(p1),
            radius,
        }
    }
}

/// A sweep checked against the options, with the values every test uses.
#[derive(Clone, Copy, Debug)]
pub struct SweptPath {
    /// Start.
    pub p0: Point3<f64>,
    /// End.
    pub p1: Point3<f64>,
    /// `d = p1 - p0`.
    pub d: Vector3<f64>,
    /// `|d|`.
    pub length: f64,
    /// Detection radius `ρ = r - ε`.
    pub rho: f64,
    /// The magnitude `S` the tests' rounding is relative to:
    /// `max(|p0|∞, |p1|∞) + ρ`, raised to the mesh's bounds by
    /// [`SweptPath::with_mesh_scale`] (the mesh sweep does that).
    pub scale: f64,
}

impl SweptPath {
    /// Validates `sweep` under `options`: finite values, `r > 0`, `0 ≤ ε < r`.
    pub fn new(sweep: &Sweep, options: &Options) -> Result<SweptPath, SweepError> {
        for (field, p) in [("p0", &sweep.p0), ("p1", &sweep.p1)] {
            for &v in p.iter() {
                if !v.is_finite() {
                    return Err(SweepError::NonFinite { field, value: v });
                }
            }
        }
        if !sweep.radius.is_finite() {
            return Err(SweepError::NonFinite {
                field: "radius",
                value: sweep.radius,
            });
        }
        if !options.margin.is_finite() {
            return Err(SweepError::NonFinite {
                field: "margin",
                value: options.margin,
            });
        }
        if sweep.radius <= 0.0 {
            return Err(SweepError::NonPositiveRadius(sweep.radius));
        }
        if options.margin < 0.0 {
            return Err(SweepError::NegativeMargin(options.margin));
        }
        if options.margin >= sweep.radius {
            return Err(SweepError::MarginNotBelowRadius {
                margin: options.margin,
                radius: sweep.radius,
            });
        }
        let d = sweep.p1 - sweep.p0;
        let length = d.norm();
        if !length.is_finite() {
            return Err(SweepError::NonFinite {
                field: "p1 - p0",
                value: length,
            });
        }
        let rho = sweep.radius - options.margin;
        Ok(SweptPath {
            p0: sweep.p0,
            p1: sweep.p1,
            d,
            length,
            rho,
            scale: sweep.p0.coords.amax().max(sweep.p1.coords.amax()) + rho,
        })
    }

    /// The path of `sweep` against `mesh`, as the mesh sweep tests it:
    /// [`SweptPath::new`] with [`SweptPath::scale`] raised to cover the
    /// mesh's bounds ([`SweptPath::with_mesh_scale`]).
    pub fn against(
        mesh: &super::Mesh,
        sweep: &Sweep,
        options: &Options,
    ) -> Result<SweptPath, SweepError> {
        let (lo, hi) = mesh.bounds();
        Ok(SweptPath::new(sweep, options)?.with_mesh_scale(&lo, &hi))
    }

    /// The path with [`SweptPath::scale`] raised to cover a mesh whose
    /// axis-aligned bounds are `(lo, hi)`.
    pub fn with_mesh_scale(mut self, lo: &Point3<f64>, hi: &Point3<f64>) -> SweptPath {
        let coordinates = self.p0.coords.amax().max(self.p1.coords.amax());
        self.scale = coordinates.max(lo.coords.amax()).max(hi.coords.amax()) + self.rho;
        self
    }

    /// The broadphase's margin `BROADPHASE_MARGIN · S`, in length
    /// ([`BROADPHASE_MARGIN`]).
    #[inline]
    pub fn broadphase_margin(&self) -> f64 {
        BROADPHASE_MARGIN * self.scale
    }

    /// The rounding unit `u = f64::EPSILON · S`: the size of one rounding
    /// of the positions the tests compute.
    #[inline]
    pub fn rounding(&self) -> f64 {
        f64::EPSILON * self.scale
    }

    /// `u` as a fraction of the path, `u / |d|` (0 for a path of length 0,
    /// which hits nothing).
    #[inline]
    fn rounding_in_alpha(&self) -> f64 {
        if self.length > 0.0 {
            self.rounding() / self.length
        } else {
            0.0
        }
    }

    /// The tie window in `α`: `TIE_WINDOW_ULPS · u / |d|`, at most 1. Hits
    /// within it of the minimum `α` are tied (see [`TIE_WINDOW_ULPS`]).
    #[inline]
    pub fn tie_window(&self) -> f64 {
        (TIE_WINDOW_ULPS * self.rounding_in_alpha()).min(1.0)
    }

    /// The tie window as a length, `TIE_WINDOW_ULPS · u`: how far outside
    /// its feature a contact may lie and still count.
    #[inline]
    pub fn tie_distance(&self) -> f64 {
        TIE_WINDOW_ULPS * self.rounding()
    }

    /// The fragility band in `α`, `FRAGILE_ULPS · u / |d|` (see
    /// [`FRAGILE_ULPS`]).
    #[inline]
    pub fn fragile_window(&self) -> f64 {
        FRAGILE_ULPS * self.rounding_in_alpha()
    }

    /// The fragility band as a length, `FRAGILE_ULPS · u`.
    #[inline]
    pub fn fragile_distance(&self) -> f64 {
        FRAGILE_ULPS * self.rounding()
    }

    /// The ball's center at fraction `beta` of the path.
    #[inline]
    pub fn at(&self, beta: f64) -> Point3<f64> {
        self.p0 + self.d * beta
    }
}
