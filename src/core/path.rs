//! A validated sweep: the ball's path and detection radius.

use nalgebra::{Point3, Vector3};

use super::error::SweepError;
use super::options::Options;

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
pub struct Path {
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
}

impl Path {
    /// Validates `sweep` under `options`: finite values, `r > 0`, `0 ≤ ε < r`.
    pub fn new(sweep: &Sweep, options: &Options) -> Result<Path, SweepError> {
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
        Ok(Path {
            p0: sweep.p0,
            p1: sweep.p1,
            d,
            length,
            rho: sweep.radius - options.margin,
        })
    }

    /// The ball's center at fraction `beta` of the path.
    #[inline]
    pub fn at(&self, beta: f64) -> Point3<f64> {
        self.p0 + self.d * beta
    }
}
