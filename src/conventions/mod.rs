//! An engine's conventions: where it departs from the rules of
//! docs/SEMANTICS.md by design, declared in `sweeptrace.toml`'s `[engine]`
//! table (or by `check`'s flags) so that a check judges the engine by what
//! it means to compute.
//!
//! **A convention changes the reference answer, not the tolerance**: the
//! margin, the facing rule, the sides, the initial overlap and the normal
//! change what the core computes (the replay's options); the precision and
//! the tie rule change how an answer is judged against it. A suite without
//! the table is judged by the rules.
//!
//! This module is a leaf: it depends on the core's option values only, so
//! that the replay, the judge and the suite all carry the same type.

use std::fmt;

use serde::Serialize;

use crate::core::{Facing, InitialOverlap, Sides};

mod accuracy;
mod partial;

pub use accuracy::{Accuracy, F32_BUDGET, MAX_ACCURACY};
pub use partial::{KEYS, PartialConventions, Setting, Source};

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
    serde::Deserialize,
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

/// Which member of a tie an answer may name: an engine convention (`ties`
/// in `sweeptrace.toml`'s `[engine]` table).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    serde::Deserialize,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum TieRule {
    /// Any member of the tie set, with the decision's `α` and normal (the
    /// averaged normal under the rules) and the member's own contact:
    /// `check` accepts it as a tie, `conform` asks for the tie order's.
    #[default]
    Rule,
    /// Any member of the tie set with its own contact and its own normal
    /// (an engine that keeps the first hit it meets, as most do).
    Any,
}

impl TieRule {
    /// Whether this is the default, `rule`.
    pub fn is_rule(&self) -> bool {
        *self == TieRule::Rule
    }
}

/// Which normal a hit reports: an engine convention (docs/ENGINES.md,
/// "Conventions"). The rules report the triangle's front normal, averaged
/// over a tie; engines report the contact normal, the direction from the
/// contact to the ball's centre, which differs at an edge or a vertex.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    serde::Serialize,
    serde::Deserialize,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum NormalRule {
    /// The rules: the front normal of the triangle hit, averaged over the
    /// triangles tied with it.
    #[default]
    Face,
    /// The contact normal at every edge and vertex hit (a face hit keeps
    /// the face normal, which is its contact normal). On an internal flat
    /// or concave place that is a ghost contact, and `check` still reports
    /// it as one.
    Contact,
    /// The contact normal at an *active* edge or vertex, the face normal
    /// elsewhere, as Jolt's meshes do: an edge is active when it is a
    /// boundary or non-manifold edge, or a convex edge whose faces meet at
    /// more than [`ACTIVE_EDGE_DEGREES`]; a vertex hit is active when
    /// either edge of its triangle at the vertex is. An engine that
    /// removes ghost contacts this way answers the face normal on internal
    /// flat and concave places, except that on a triangle with an active
    /// edge a contact normal within 1° of the triangle's is kept, as
    /// Jolt's `ActiveEdges::FixNormal` does
    /// ([`ACTIVE_EDGE_KEEP_DEGREES`]).
    ActiveEdges,
}

/// The angle between two faces above which their shared convex edge is
/// active ([`NormalRule::ActiveEdges`]): Jolt's default
/// (`MeshShapeSettings::mActiveEdgeCosThresholdAngle` = cos 5°).
pub const ACTIVE_EDGE_DEGREES: f64 = 5.0;

/// Under [`NormalRule::ActiveEdges`], a contact normal within this angle of
/// the triangle's normal is kept at an inactive edge or vertex when the
/// triangle has an active edge (Jolt's `ActiveEdges::FixNormal`: the
/// contact normal is left alone when it is within 1° of the triangle's,
/// after the check that the triangle has any active edge). On a triangle
/// with no active edge the face normal is answered whatever the angle.
pub const ACTIVE_EDGE_KEEP_DEGREES: f64 = 1.0;

/// The margin an engine uses: the scene's (the rules) or always the same.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum MarginRule {
    /// The margin each scene declares.
    #[default]
    Scene,
    /// This margin for every scene (Jolt, Rapier: 0).
    Fixed(f64),
}

impl fmt::Display for MarginRule {
    /// `scene`, or the number as TOML writes it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MarginRule::Scene => f.write_str("scene"),
            MarginRule::Fixed(m) => write!(f, "{m:?}"),
        }
    }
}

impl std::str::FromStr for MarginRule {
    type Err = String;
    /// `scene`, or a finite number `≥ 0`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "scene" {
            return Ok(MarginRule::Scene);
        }
        let m = crate::numbers::parse_f64(s)
            .ok_or_else(|| format!("`{s}` is neither `scene` nor a number"))?;
        crate::numbers::check(m, crate::numbers::Rule::NonNegative)?;
        Ok(MarginRule::Fixed(m))
    }
}

impl Serialize for MarginRule {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            MarginRule::Scene => serializer.serialize_str("scene"),
            MarginRule::Fixed(m) => serializer.serialize_f64(*m),
        }
    }
}

/// The facing rule an engine uses: the scene's (the rules) or always one.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Serialize,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum FacingRule {
    /// The rule each scene declares.
    #[default]
    Scene,
    /// `n · d < 0` for every scene.
    Strict,
    /// `n · d ≤ 0` for every scene (Jolt: a face is a back face only when
    /// `n · d > 0`).
    NonStrict,
}

impl From<Facing> for FacingRule {
    /// The rule that imposes `facing` on every scene.
    fn from(facing: Facing) -> FacingRule {
        match facing {
            Facing::Strict => FacingRule::Strict,
            Facing::NonStrict => FacingRule::NonStrict,
        }
    }
}

impl FacingRule {
    /// The facing rule it imposes, if any.
    pub fn facing(self) -> Option<Facing> {
        match self {
            FacingRule::Scene => None,
            FacingRule::Strict => Some(Facing::Strict),
            FacingRule::NonStrict => Some(Facing::NonStrict),
        }
    }
}

/// What an engine does where it departs from the rules: every key of the
/// `[engine]` table. The default is the rules.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EngineConventions {
    /// The arithmetic it computes in.
    pub precision: Precision,
    /// Its margin.
    pub margin: MarginRule,
    /// Its facing rule.
    pub facing: FacingRule,
    /// Which sides of a triangle collide.
    pub sides: Sides,
    /// What a ball that starts within `ρ` gets.
    pub initial_overlap: InitialOverlap,
    /// The normal it reports.
    pub normal: NormalRule,
    /// Which member of a tie it may name.
    pub ties: TieRule,
    /// The backward-error budget it is held to, when declared (otherwise
    /// single precision's, [`F32_BUDGET`], under `precision = "f32"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<Accuracy>,
}

impl EngineConventions {
    /// The backward-error budget the judgement holds answers to, in units
    /// of `u₃₂ · S`: the declared accuracy, else [`F32_BUDGET`] under
    /// `precision = "f32"`; `None`: no backward error, the fixed
    /// tolerances (the rules at `f64`).
    pub fn budget(&self) -> Option<f64> {
        match (self.accuracy, self.precision) {
            (Some(a), _) => Some(a.units()),
            (None, Precision::F32) => Some(F32_BUDGET),
            (None, Precision::F64) => None,
        }
    }

    /// What the differences an answer is excused for are within, in words:
    /// `single precision`, or `the declared accuracy (2^12 u₃₂·S, coarser
    /// than single precision explains (16): the engine's solver tolerance)`.
    pub fn within_words(&self) -> String {
        match self.accuracy {
            None => "single precision".to_string(),
            Some(a) => format!("the declared accuracy ({})", a.words()),
        }
    }

    /// Whether these are the rules (no convention declared).
    pub fn is_rules(&self) -> bool {
        *self == EngineConventions::default()
    }

    /// The conventions that differ from the rules, as `key = value` pairs
    /// in the table's words.
    pub fn declared(&self) -> Vec<(&'static str, String)> {
        let rules = EngineConventions::default();
        let mut out = Vec::new();
        if self.precision != rules.precision {
            out.push(("precision", format!("\"{}\"", self.precision)));
        }
        if self.margin != rules.margin {
            out.push(("margin", self.margin_toml()));
        }
        if self.facing != rules.facing {
            out.push(("facing", format!("\"{}\"", self.facing)));
        }
        if self.sides != rules.sides {
            out.push(("sides", format!("\"{}\"", self.sides)));
        }
        if self.initial_overlap != rules.initial_overlap {
            out.push(("initial_overlap", format!("\"{}\"", self.initial_overlap)));
        }
        if self.normal != rules.normal {
            out.push(("normal", format!("\"{}\"", self.normal)));
        }
        if self.ties != rules.ties {
            out.push(("ties", format!("\"{}\"", self.ties)));
        }
        if let Some(a) = self.accuracy {
            out.push(("accuracy", a.to_string()));
        }
        out
    }

    /// The command-line flags that declare these conventions (`--precision
    /// f32 --engine-margin 0 --normal active_edges`), for the commands a
    /// report prints: run as printed, they judge under the same table.
    pub fn flags(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (key, value) in self.declared() {
            let flag = match key {
                "margin" => "engine-margin".to_string(),
                "facing" => "engine-facing".to_string(),
                other => other.replace('_', "-"),
            };
            out.push(format!("--{flag}"));
            out.push(value.trim_matches('"').to_string());
        }
        out
    }

    /// The margin as TOML writes it (`"scene"` or a number).
    pub fn margin_toml(&self) -> String {
        match self.margin {
            MarginRule::Scene => "\"scene\"".to_string(),
            MarginRule::Fixed(m) => format!("{m:?}"),
        }
    }

    /// In words, for reports: `precision f32, margin 0, normal
    /// active_edges`; `the rules` when none is declared.
    pub fn summary(&self) -> String {
        let declared = self.declared();
        if declared.is_empty() {
            return "the rules".to_string();
        }
        declared
            .iter()
            .map(|(k, v)| format!("{k} {}", v.trim_matches('"')))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Why the conformance rule `rule` (a name of `conform`'s rule list)
    /// does not apply to an engine with these conventions, if it does not:
    /// the convention that replaces it (`the engine declares margin = 0`).
    pub fn replaces(&self, rule: &str) -> Option<String> {
        let declares =
            |key: &str, value: String| Some(format!("the engine declares {key} = {value}"));
        let rule = rule.split('/').next().unwrap_or(rule);
        let group = rule.split('.').next().unwrap_or(rule);
        match (group, rule) {
            ("margin", _) if self.margin != MarginRule::Scene => {
                declares("margin", self.margin.to_string())
            }
            // A declared facing rule replaces the scene's other one.
            (_, "facing.strict") if self.facing == FacingRule::NonStrict => {
                declares("facing", self.facing.to_string())
            }
            (_, "facing.non-strict") if self.facing == FacingRule::Strict => {
                declares("facing", self.facing.to_string())
            }
            // Both sides collide: a contact from behind is a hit.
            (_, "face.miss.back-facing" | "edge.miss.back-facing" | "contact.back-facing")
                if self.sides == Sides::Two =>
            {
                declares("sides", self.sides.to_string())
            }
            (_, "start.inside") if self.initial_overlap != InitialOverlap::None => {
                declares("initial_overlap", self.initial_overlap.to_string())
            }
            // Two-sided, a ball within ρ that leaves the front moves toward
            // the back: an initial contact at α = 0, from behind.
            // A start within ρ is a hit whatever the direction.
            (_, "start.moving-away") if self.initial_overlap == InitialOverlap::Alpha0Always => {
                declares("initial_overlap", self.initial_overlap.to_string())
            }
            (_, "start.moving-away")
                if self.sides == Sides::Two && self.initial_overlap == InitialOverlap::Alpha0 =>
            {
                Some(format!(
                    "the engine declares sides = {} and initial_overlap = {}",
                    self.sides, self.initial_overlap
                ))
            }
            // Face normals and any member of a tie: each of the ridge's two
            // triangles may name its own face normal, which is what the rule
            // tells apart from the contact normal.
            (_, "normal.shallow-convex-edge")
                if self.normal == NormalRule::Face && self.ties != TieRule::Rule =>
            {
                Some(format!(
                    "the engine declares normal = {} and ties = {}",
                    self.normal, self.ties
                ))
            }
            ("tie", _) if self.ties != TieRule::Rule => declares("ties", self.ties.to_string()),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_the_rules_and_changes_nothing() {
        let c = EngineConventions::default();
        assert!(c.is_rules());
        assert!(c.declared().is_empty());
        assert_eq!(c.summary(), "the rules");
        let options = crate::replay::ReplayOptions::default().core_options(0.25, Facing::Strict);
        assert_eq!(
            (
                options.margin,
                options.facing,
                options.sides,
                options.initial_overlap
            ),
            (0.25, Facing::Strict, Sides::One, InitialOverlap::None)
        );
    }

    #[test]
    fn each_convention_lands_where_it_acts() {
        let c = EngineConventions {
            precision: Precision::F32,
            margin: MarginRule::Fixed(0.0),
            facing: FacingRule::NonStrict,
            sides: Sides::Two,
            initial_overlap: InitialOverlap::Alpha0,
            normal: NormalRule::ActiveEdges,
            ties: TieRule::Any,
            accuracy: Some(Accuracy::new(4096.0)),
        };
        let replay = crate::replay::ReplayOptions {
            conventions: c,
            ..Default::default()
        };
        let options = replay.core_options(0.25, Facing::Strict);
        assert_eq!(
            (
                options.margin,
                options.facing,
                options.sides,
                options.initial_overlap
            ),
            (0.0, Facing::NonStrict, Sides::Two, InitialOverlap::Alpha0)
        );
        assert_eq!(
            c.summary(),
            "precision f32, margin 0.0, facing non_strict, sides two, initial_overlap alpha0, \
             normal active_edges, ties any, accuracy 4096"
        );
        assert_eq!(c.budget(), Some(4096.0));
        assert_eq!(
            c.flags().join(" "),
            "--precision f32 --engine-margin 0.0 --engine-facing non_strict --sides two \
             --initial-overlap alpha0 --normal active_edges --ties any --accuracy 4096"
        );
        assert_eq!(
            c.replaces("margin.inside-band/0").as_deref(),
            Some("the engine declares margin = 0.0")
        );
        assert_eq!(c.replaces("edge.basic/0"), None);
        for rule in ["face.miss.back-facing/0", "edge.miss.back-facing"] {
            assert_eq!(
                c.replaces(rule).as_deref(),
                Some("the engine declares sides = two"),
                "{rule}"
            );
        }
        assert_eq!(
            c.replaces("start.moving-away/1").as_deref(),
            Some("the engine declares sides = two and initial_overlap = alpha0")
        );
        // Contact normals at active edges: the ridge's normal is judged.
        assert_eq!(c.replaces("normal.shallow-convex-edge/0"), None);
        assert_eq!(c.replaces("normal.flat-edge/0"), None);
        let face_any = EngineConventions {
            ties: TieRule::Any,
            ..EngineConventions::default()
        };
        assert_eq!(
            face_any.replaces("normal.shallow-convex-edge").as_deref(),
            Some("the engine declares normal = face and ties = any")
        );
        assert_eq!(face_any.replaces("normal.flat-edge"), None);
        let one_sided = EngineConventions {
            initial_overlap: InitialOverlap::Alpha0,
            ..EngineConventions::default()
        };
        assert_eq!(one_sided.replaces("start.moving-away"), None);
        let one = EngineConventions::default();
        assert_eq!(one.replaces("face.miss.back-facing/0"), None);
        assert_eq!(one.replaces("edge.miss.back-facing/0"), None);
    }

    #[test]
    fn the_budget_is_the_accuracy_else_single_precisions() {
        let rules = EngineConventions::default();
        assert_eq!(rules.budget(), None);
        let f32 = EngineConventions {
            precision: Precision::F32,
            ..rules
        };
        assert_eq!(f32.budget(), Some(F32_BUDGET));
        let calibrated = EngineConventions {
            accuracy: Some("4".parse().unwrap()),
            ..f32
        };
        assert_eq!(calibrated.budget(), Some(4.0));
        assert_eq!(calibrated.summary(), "precision f32, accuracy 4");
        // A declared accuracy judges by backward error at any precision.
        let coarse = EngineConventions {
            accuracy: Some("0.5".parse().unwrap()),
            ..rules
        };
        assert_eq!(coarse.budget(), Some(0.5));
        assert_eq!(coarse.declared(), vec![("accuracy", "0.5".to_string())]);
        for bad in ["0", "-4", "nan", "inf", "1e7", "some"] {
            assert!(bad.parse::<Accuracy>().is_err(), "{bad}");
        }
        assert_eq!(
            Accuracy::new(4096.0).words(),
            "2^12 u₃₂·S, coarser than single precision explains (16): the engine's solver \
             tolerance"
        );
        assert_eq!(
            Accuracy::new(4.0).words(),
            "4 u₃₂·S, calibrated below single precision's 16"
        );
    }

    #[test]
    fn margins_parse_as_scene_or_a_number() {
        assert_eq!("scene".parse::<MarginRule>(), Ok(MarginRule::Scene));
        assert_eq!("0".parse::<MarginRule>(), Ok(MarginRule::Fixed(0.0)));
        assert!("-1".parse::<MarginRule>().is_err());
        assert!("some".parse::<MarginRule>().is_err());
    }
}
