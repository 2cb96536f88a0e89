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
    /// `n · d < 0`: strictly toward the front (the condition as
    /// the FAQ of the CS121 project that SEMANTICS.md follows states it).
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

/// What a ball that starts within `ρ` of the mesh gets: an engine
/// convention (docs/ENGINES.md, "Conventions").
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
pub enum InitialOverlap {
    /// The rules: no collision from the tests that start within `ρ` (a
    /// later hit, if any, is the answer).
    #[default]
    None,
    /// A hit at `α = 0` with the nearest feature of a triangle the facing
    /// rule lets the path through, the contact at its nearest point (Jolt,
    /// PhysX without `eASSUME_NO_INITIAL_OVERLAP`, parry with
    /// `stop_at_penetration`).
    Alpha0,
    /// A hit at `α = 0` whenever the ball starts within `ρ` of a triangle,
    /// whatever the direction it moves in, toward the triangle, along it or
    /// away (Rapier's `stopAtPenetration`, parry's `stop_at_penetration`
    /// casts): the facing rule is not asked. One-sided, only a triangle
    /// whose front holds the centre (or whose plane does); two-sided, any,
    /// the normal facing the centre.
    Alpha0Always,
    /// A hit at `α = 0` when the ball starts within `ρ` of a triangle and
    /// its path goes deeper: the direction is judged at the contact point
    /// (`(p0 − q)·d < 0`, the centre closing in on the nearest point `q`),
    /// not by the triangle's facing rule, so a ball leaving an edge or a
    /// vertex it overlaps is no hit, and a ball that does not move is none
    /// (parry's and Rapier's casts with `stop_at_penetration` false). The
    /// side as under `alpha0_always`: the one that holds the centre.
    Alpha0Deeper,
}

impl InitialOverlap {
    /// Whether this is the rules' choice (the default).
    pub fn is_rules(&self) -> bool {
        *self == InitialOverlap::None
    }
}

/// Which sides of a triangle collide: an engine convention
/// (docs/ENGINES.md, "Conventions").
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
pub enum Sides {
    /// The rules: only the front. A path moving toward a triangle's back
    /// (`n · d > 0`) is rejected by the facing rule.
    #[default]
    One,
    /// Both sides, as engines with double-sided meshes (Jolt's
    /// `CollideWithBackFaces`, PhysX's double-sided meshes, Bullet): a
    /// triangle the path moves toward the back of (`n · d > 0`) is tested
    /// as its mirror, with the normal `-n`, so the facing rule sees
    /// `-n · d = -|n · d| < 0` and the hit reports `-n`. A path parallel to
    /// the plane (`n · d = 0`) keeps the front normal: `non_strict` lets it
    /// through, `strict` does not.
    Two,
}

impl Sides {
    /// Whether this is the rules' choice (the default).
    pub fn is_rules(&self) -> bool {
        *self == Sides::One
    }

    /// Whether a triangle whose facing value is `normal_dot_d = n · d` is
    /// tested from its back, as its mirror with the normal `-n`.
    #[inline]
    pub fn flips(self, normal_dot_d: f64) -> bool {
        self == Sides::Two && normal_dot_d > 0.0
    }

    /// The facing value the rule judges: `n · d`, or `-|n · d|` for a
    /// triangle tested from its back.
    #[inline]
    pub fn facing_value(self, normal_dot_d: f64) -> f64 {
        if self.flips(normal_dot_d) {
            -normal_dot_d
        } else {
            normal_dot_d
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
    /// What a ball that starts within `ρ` of the mesh gets (the rules: no
    /// collision from those tests).
    #[serde(default, skip_serializing_if = "InitialOverlap::is_rules")]
    pub initial_overlap: InitialOverlap,
    /// Which sides of a triangle collide (the rules: the front only).
    #[serde(default, skip_serializing_if = "Sides::is_rules")]
    pub sides: Sides,
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

/// The *rounding unit* of a sweep is `u = f64::EPSILON · S`, a length,
/// where `S = max(|p0|∞, |p1|∞, |mesh bounds|∞) + ρ` is the largest
/// magnitude the tests subtract or rotate: every position a test computes
/// (a point in an edge's frame, a touch point, a distance) carries an error
/// of a few `u`. In `α` (a fraction of the path) that is `u / |d|`, divided
/// by the cosine of the approach angle.
///
/// The **tie window** is `TIE_WINDOW_ULPS · u / |d|` (at most 1): hits
/// whose `α` lies within it of the minimum are *tied*. The primary hit is
/// chosen among them by the rules' order (face < edge < vertex, then lower
/// triangle, then lower feature), and the normals of their triangles are
/// averaged. The same `TIE_WINDOW_ULPS · u` is the tolerance by which a
/// contact may lie outside its feature (a face's touch point outside the
/// triangle, an edge's `xc` outside `[0, L]`) and still count: the exact
/// contact there is the neighbouring edge or vertex at the same `α` within
/// rounding, and the tie order would choose the face or the edge anyway.
///
/// 1024 ulps covers the rounding of the tests (a few ulps of `S` per
/// coordinate) for approach cosines down to about 0.01; below that a tie
/// may still be decided by rounding, and the decision is flagged
/// ([`FRAGILE_ULPS`], [`GRAZING_COSINE`]).
pub const TIE_WINDOW_ULPS: f64 = 1024.0;

/// A decision is *fragile* (flagged in [`Outcome::fragile`](super::Outcome))
/// when a change of the inputs at the level of their rounding could change
/// it. The band is `FRAGILE_ULPS · u` in length and `FRAGILE_ULPS · u / |d|`
/// in `α` (see [`TIE_WINDOW_ULPS`] for `u`), 64 times the tie window: a
/// one-ulp change of an input moves a contact by about `u / cos`, which
/// stays below the band for every approach cosine above
/// [`GRAZING_COSINE`]. Used for: another hit within the band of the
/// minimum `α` (`tie`), a contact within the band of its feature's boundary
/// (`near_boundary`), a contact within it of `α = 0` or `α = 1`
/// (`start_touching`, `near_end`), and for rejected tests that missed by
/// less than it (a tangent missing by less than the band, a touch point or
/// `xc` outside by less than it, a root just before 0 or beyond 1).
pub const FRAGILE_ULPS: f64 = 65536.0;

/// The broadphase's margin, relative to the scale `S`: a triangle's box is
/// grown by `ρ + BROADPHASE_MARGIN · S` before the path is tested against it
/// (and a triangle whose plane stays farther than that from the path is
/// skipped), far above the fragility band (`FRAGILE_ULPS · ε · S ≈
/// 1.5e-11 · S`), so that every hit and near miss that matters is visited.
/// The one definition: the mesh sweep, the crossing query and `repro`'s
/// choice of the triangles a minimal trace keeps use it
/// ([`SweptPath::broadphase_margin`](super::SweptPath::broadphase_margin)).
pub const BROADPHASE_MARGIN: f64 = 1e-9;

/// A contact whose approach cosine is below this is *grazing* (face:
/// `|n · d| / |d|`; edge or vertex: `√disc / (2ρ|d|)`, the cosine between
/// the path and the contact normal, which is the discriminant relative to
/// its largest value `4ρ²|d|²`): its `α` moves by `1 / cos` times the
/// rounding of its inputs. Also the facing value `|n · d| / |d|` below
/// which a triangle's facing rule could turn under rounding.
pub const GRAZING_COSINE: f64 = 1e-3;

/// A hit's `α` is *imprecise* when one rounding of the inputs moves it by
/// more than this: `f64::EPSILON · S / (|d| · cos) > ALPHA_SENSITIVITY`
/// (a path short compared with the coordinates' magnitude, or a shallow
/// approach). At that level a comparison of `α` with tolerance `1e-6` can
/// fail from rounding alone.
pub const ALPHA_SENSITIVITY: f64 = 1e-8;
