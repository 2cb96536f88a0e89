//! Options of a sweep and the numerical thresholds of the core.
//!
//! Every threshold that replaces an exact `= 0` comparison of the
//! semantics is defined here, relative to the input's scale, so the
//! explanation of a test can name it.

use serde::{Deserialize, Serialize};

/// Which direction of travel lets a triangle report a collision.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Facing {
    /// `n · d ≤ 0`: moving toward the front, or parallel to the plane.
    #[default]
    NonStrict,
    /// `n · d < 0`: strictly toward the front (the course FAQ's wording).
    Strict,
}

impl Facing {
    /// Whether a path with direction `normal_dot_d = n · d` passes the rule.
    #[inline]
    pub fn allows(self, normal_dot_d: f64) -> bool {
        match self {
            Facing::NonStrict => normal_dot_d <= 0.0,
            Facing::Strict => normal_dot_d < 0.0,
        }
    }

    /// The name used in traces and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Facing::NonStrict => "non_strict",
            Facing::Strict => "strict",
        }
    }
}

impl std::fmt::Display for Facing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Facing {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "non_strict" | "non-strict" => Ok(Facing::NonStrict),
            "strict" => Ok(Facing::Strict),
            other => Err(format!(
                "unknown facing rule `{other}` (expected `non_strict` or `strict`)"
            )),
        }
    }
}

/// Options of the collision core.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Options {
    /// The margin `ε`: every test uses the detection radius `ρ = r - ε`.
    /// Must satisfy `0 ≤ ε < r`.
    pub margin: f64,
    /// The facing rule.
    pub facing: Facing,
}

/// A path is *parallel* to a plane or an edge when the component of `d`
/// that matters is at most this fraction of `|d|`:
/// face test `|n · d| ≤ PARALLEL_TOLERANCE · |d|`,
/// edge test `A ≤ (PARALLEL_TOLERANCE · |d|)²`.
/// A zero-length path is parallel to everything.
pub const PARALLEL_TOLERANCE: f64 = 1e-12;

/// A triangle is degenerate when `|(b - a) × (c - a)|` is at most this
/// fraction of the square of its longest edge (its smallest angle is then
/// below about 1e-12 radians), or when two of its indices are equal.
pub const DEGENERATE_TOLERANCE: f64 = 1e-12;

/// Triangles whose collision `α` lies within this absolute tolerance of the
/// minimum collide *simultaneously*: their front normals are averaged into
/// the reported normal. `α` is a fraction of the path, so the tolerance is
/// already relative to the path's length.
pub const SIMULTANEOUS_TOLERANCE: f64 = 1e-9;
