//! A sweep's inputs, exactly: shortest round-trip decimals and hexadecimal
//! floating point, which read back to the same bits.

use serde::Serialize;

use crate::core::{Facing, Options, Sweep};
use crate::numbers::hex_float;

/// The inputs of one sweep, exactly: with these numbers the core makes the
/// same decision.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SweepInputs {
    /// Start of the ball's centre.
    pub p0: [f64; 3],
    /// End of the ball's centre.
    pub p1: [f64; 3],
    /// Radius `r`.
    pub radius: f64,
    /// Margin `ε` used.
    pub margin: f64,
    /// Facing rule used.
    pub facing: Facing,
}

/// [`SweepInputs`] as hexadecimal floating-point literals ([`hex_float`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HexInputs {
    /// Start of the ball's centre.
    pub p0: [String; 3],
    /// End of the ball's centre.
    pub p1: [String; 3],
    /// Radius `r`.
    pub radius: String,
    /// Margin `ε`.
    pub margin: String,
}

impl SweepInputs {
    /// The inputs of `sweep` under `options`.
    pub fn of(sweep: &Sweep, options: &Options) -> SweepInputs {
        SweepInputs {
            p0: sweep.p0.coords.into(),
            p1: sweep.p1.coords.into(),
            radius: sweep.radius,
            margin: options.margin,
            facing: options.facing,
        }
    }

    /// The sweep.
    pub fn sweep(&self) -> Sweep {
        Sweep::new(self.p0, self.p1, self.radius)
    }

    /// The options.
    pub fn options(&self) -> Options {
        Options {
            margin: self.margin,
            facing: self.facing,

            ..Options::default()
        }
    }

    /// `p0 (x, y, z), p1 (x, y, z), radius r, margin ε, facing f`, every
    /// number the shortest decimal that reads back to the same bits.
    pub fn text(&self) -> String {
        let v = |p: &[f64; 3]| format!("({}, {}, {})", p[0], p[1], p[2]);
        format!(
            "p0 {}, p1 {}, radius {}, margin {}, facing {}",
            v(&self.p0),
            v(&self.p1),
            self.radius,
            self.margin,
            self.facing
        )
    }

    /// The numbers as hexadecimal floating point.
    pub fn hex(&self) -> HexInputs {
        HexInputs {
            p0: self.p0.map(hex_float),
            p1: self.p1.map(hex_float),
            radius: hex_float(self.radius),
            margin: hex_float(self.margin),
        }
    }
}

impl HexInputs {
    /// `p0 (0x..., ...), p1 (...), radius 0x..., margin 0x...`.
    pub fn text(&self) -> String {
        let v = |p: &[String; 3]| format!("({}, {}, {})", p[0], p[1], p[2]);
        format!(
            "p0 {}, p1 {}, radius {}, margin {}",
            v(&self.p0),
            v(&self.p1),
            self.radius,
            self.margin
        )
    }
}
