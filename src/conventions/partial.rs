//! The conventions as the layers declare them: each key optional, with
//! where it was set ([`PartialConventions`]). The command line (clap reads
//! its flags straight into it), each settings file's `[engine]` table and
//! `--infer-config` produce one; merged layer over layer
//! ([`PartialConventions::merge`]), the keys left unset are the rules'
//! ([`PartialConventions::conventions`]).

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use super::{Accuracy, EngineConventions, FacingRule, MarginRule, NormalRule, Precision, TieRule};
use crate::core::{InitialOverlap, Sides};

/// Where a setting came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Source {
    /// The built-in default.
    Default,
    /// A line of a configuration file.
    File {
        /// The file, as written in the report (its name as given to `check`).
        file: String,
        /// The line of the key (1-based).
        line: usize,
    },
    /// The command line.
    CommandLine,
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Default => f.write_str("default"),
            Source::File { file, line } => write!(f, "{file}:{line}"),
            Source::CommandLine => f.write_str("command line"),
        }
    }
}

/// A value and where it came from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Setting<T> {
    /// The value.
    pub value: T,
    /// Where it came from.
    pub source: Source,
}

impl<T> Setting<T> {
    /// `value` as the built-in default.
    pub fn default_value(value: T) -> Setting<T> {
        Setting {
            value,
            source: Source::Default,
        }
    }
}

/// The keys of the `[engine]` table, in the table's order.
pub const KEYS: [&str; 8] = [
    "precision",
    "margin",
    "facing",
    "sides",
    "initial_overlap",
    "normal",
    "ties",
    "accuracy",
];

/// The `[engine]` table's keys as one layer declares them (`None`: not
/// declared there), each with its [`Source`]. The doc comment of each field
/// is its flag's `--help`.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct PartialConventions {
    /// The engine's arithmetic: `f64` (fixed tolerances) or `f32` (each
    /// difference judged by backward error: passes when the exact rules
    /// give it for inputs moved by at most 16 u32 units of the sweep's
    /// scale) [default: f64].
    #[cfg_attr(feature = "cli", arg(long, value_name = "f64|f32", value_parser = one_of::<Precision>(), help_heading = "Engine conventions"))]
    pub precision: Option<Setting<Precision>>,
    /// The margin ε (tests use the detection radius ρ = r - ε, 0 ≤ ε <
    /// r): `scene` (each scene's) or a number every scene uses
    /// [default: scene]. `--margin` is the same flag.
    #[cfg_attr(feature = "cli", arg(
        id = "engine_margin",
        long = "engine-margin",
        visible_alias = "margin",
        allow_negative_numbers = true,
        value_name = "scene|NUMBER",
        value_parser = given::<MarginRule>,
        help_heading = "Engine conventions"
    ))]
    pub margin: Option<Setting<MarginRule>>,
    /// The facing rule: `scene` (each scene's), `strict` (n·d < 0) or
    /// `non_strict` (n·d ≤ 0) for every scene [default: scene].
    /// `--facing` is the same flag.
    #[cfg_attr(feature = "cli", arg(
        id = "engine_facing",
        long = "engine-facing",
        visible_alias = "facing",
        value_name = "RULE",
        value_parser = one_of::<FacingRule>(),
        help_heading = "Engine conventions"
    ))]
    pub facing: Option<Setting<FacingRule>>,
    /// Which sides of a triangle collide: `one` (the rules: a contact
    /// from behind, `n · d > 0`, is no collision) or `two` (a hit from
    /// behind too, reported with the normal `-n`) [default: one].
    #[cfg_attr(feature = "cli", arg(long, value_name = "one|two", value_parser = one_of::<Sides>(), help_heading = "Engine conventions"))]
    pub sides: Option<Setting<Sides>>,
    /// A ball that starts within its radius of the mesh: `none` (the
    /// rules: no collision), `alpha0` (a hit at α = 0 with the nearest
    /// feature when it moves toward it) or `alpha0_always` (whatever the
    /// direction, as Rapier's stopAtPenetration) [default: none].
    #[cfg_attr(feature = "cli", arg(long, value_name = "none|alpha0|alpha0_always", value_parser = one_of::<InitialOverlap>(), help_heading = "Engine conventions"))]
    pub initial_overlap: Option<Setting<InitialOverlap>>,
    /// The normal of a hit: `face` (the rules: the triangle's),
    /// `contact` (centre minus contact, normalised, at edges and
    /// vertices) or `active_edges` (the contact normal at active edges
    /// only, as Jolt) [default: face].
    #[cfg_attr(feature = "cli", arg(long, value_name = "RULE", value_parser = one_of::<NormalRule>(), help_heading = "Engine conventions"))]
    pub normal: Option<Setting<NormalRule>>,
    /// A tie: `rule` (the decision's α and normal) or `any` (any member
    /// with its own contact and normal) [default: rule].
    #[cfg_attr(feature = "cli", arg(long, value_name = "rule|any", value_parser = one_of::<TieRule>(), help_heading = "Engine conventions"))]
    pub ties: Option<Setting<TieRule>>,
    /// The backward-error budget the engine is held to, in u32 units of
    /// the sweep's scale: less than 16 for an engine calibrated when known
    /// good (`--infer-config` proposes it), more for a solver coarser than
    /// its arithmetic. Judges by backward error at any precision
    /// [default: 16 under --precision f32].
    #[cfg_attr(feature = "cli", arg(long, value_name = "UNITS", value_parser = given::<Accuracy>, help_heading = "Engine conventions"))]
    pub accuracy: Option<Setting<Accuracy>>,
}

/// The parser of a flag whose values are a closed set: a typo is an error
/// listing them.
#[cfg(feature = "cli")]
fn one_of<T>() -> impl clap::builder::TypedValueParser<Value = Setting<T>>
where
    T: FromStr + strum::VariantNames + Clone + Send + Sync + 'static,
    T::Err: fmt::Display,
{
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::VARIANTS).try_map(|name: String| given::<T>(&name))
}

/// A flag's value, given on the command line.
#[cfg(feature = "cli")]
fn given<T: FromStr>(text: &str) -> Result<Setting<T>, String>
where
    T::Err: fmt::Display,
{
    text.parse::<T>()
        .map(|value| Setting {
            value,
            source: Source::CommandLine,
        })
        .map_err(|e| e.to_string())
}

/// `text` as a value of one of the closed sets, or the error naming them.
fn named<T: FromStr + strum::VariantNames>(key: &str, text: &str) -> Result<T, String> {
    text.parse::<T>().map_err(|_| {
        format!(
            "`engine.{key}` is `{text}`; it takes one of {}",
            T::VARIANTS
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

impl PartialConventions {
    /// Sets `key` (one of [`KEYS`]) to the value written `text`, set at
    /// `source`. The error says what the key takes, in the table's words
    /// (`` `engine.sides` is `three`; it takes one of "one", "two" ``), or
    /// that the key is unknown.
    pub fn set(&mut self, key: &str, text: &str, source: Source) -> Result<(), String> {
        fn at<T>(value: T, source: Source) -> Option<Setting<T>> {
            Some(Setting { value, source })
        }
        match key {
            "precision" => self.precision = at(named(key, text)?, source),
            "margin" => {
                let margin = text
                    .parse::<MarginRule>()
                    .map_err(|e| format!("`engine.margin` takes \"scene\" or a number ≥ 0: {e}"))?;
                self.margin = at(margin, source);
            }
            "facing" => self.facing = at(named(key, text)?, source),
            "sides" => self.sides = at(named(key, text)?, source),
            "initial_overlap" => self.initial_overlap = at(named(key, text)?, source),
            "normal" => self.normal = at(named(key, text)?, source),
            "ties" => self.ties = at(named(key, text)?, source),
            "accuracy" => {
                let accuracy = text
                    .parse::<Accuracy>()
                    .map_err(|e| format!("`engine.accuracy` is {e}"))?;
                self.accuracy = at(accuracy, source);
            }
            _ => {
                return Err(format!(
                    "unknown key `{key}`, expected one of {}",
                    KEYS.map(|k| format!("`{k}`")).join(", ")
                ));
            }
        }
        Ok(())
    }

    /// Every key `over` declares replaces this layer's.
    pub fn merge(&mut self, over: &PartialConventions) {
        fn set<T: Clone>(to: &mut Option<Setting<T>>, from: &Option<Setting<T>>) {
            if from.is_some() {
                to.clone_from(from);
            }
        }
        set(&mut self.precision, &over.precision);
        set(&mut self.margin, &over.margin);
        set(&mut self.facing, &over.facing);
        set(&mut self.sides, &over.sides);
        set(&mut self.initial_overlap, &over.initial_overlap);
        set(&mut self.normal, &over.normal);
        set(&mut self.ties, &over.ties);
        set(&mut self.accuracy, &over.accuracy);
    }

    /// The conventions: each declared key's value, the rules' elsewhere.
    pub fn conventions(&self) -> EngineConventions {
        fn or<T: Copy>(s: &Option<Setting<T>>, rules: T) -> T {
            s.as_ref().map_or(rules, |s| s.value)
        }
        let rules = EngineConventions::default();
        EngineConventions {
            precision: or(&self.precision, rules.precision),
            margin: or(&self.margin, rules.margin),
            facing: or(&self.facing, rules.facing),
            sides: or(&self.sides, rules.sides),
            initial_overlap: or(&self.initial_overlap, rules.initial_overlap),
            normal: or(&self.normal, rules.normal),
            ties: or(&self.ties, rules.ties),
            accuracy: self.accuracy.as_ref().map(|s| s.value),
        }
    }

    /// Where each key came from, in the table's order ([`Source::Default`]
    /// where no layer declares it).
    pub fn sources(&self) -> [Source; 8] {
        fn of<T>(s: &Option<Setting<T>>) -> Source {
            s.as_ref().map_or(Source::Default, |s| s.source.clone())
        }
        [
            of(&self.precision),
            of(&self.margin),
            of(&self.facing),
            of(&self.sides),
            of(&self.initial_overlap),
            of(&self.normal),
            of(&self.ties),
            of(&self.accuracy),
        ]
    }

    /// Whether any key is declared.
    pub fn is_declared(&self) -> bool {
        self.sources().iter().any(|s| *s != Source::Default)
    }

    /// Where the declared keys came from, once each in the order of the
    /// keys: a file's name, or `the command line`.
    pub fn declared_sources(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for source in self.sources() {
            let name = match source {
                Source::Default => continue,
                Source::File { file, .. } => file,
                Source::CommandLine => "the command line".to_string(),
            };
            if !out.contains(&name) {
                out.push(name);
            }
        }
        out
    }

    /// Each key as `(key, value as TOML writes it, its value as JSON,
    /// source)`, in the table's order, the rules' values where undeclared;
    /// `accuracy` only where answers are judged by backward error (its
    /// default single precision's budget).
    pub fn entries(&self) -> Vec<(&'static str, String, serde_json::Value, Source)> {
        let c = self.conventions();
        let quoted = |s: &dyn fmt::Display| format!("\"{s}\"");
        let texts = [
            (quoted(&c.precision), serde_json::json!(c.precision)),
            (c.margin_toml(), serde_json::json!(c.margin)),
            (quoted(&c.facing), serde_json::json!(c.facing)),
            (quoted(&c.sides), serde_json::json!(c.sides)),
            (
                quoted(&c.initial_overlap),
                serde_json::json!(c.initial_overlap),
            ),
            (quoted(&c.normal), serde_json::json!(c.normal)),
            (quoted(&c.ties), serde_json::json!(c.ties)),
            match c.budget() {
                Some(units) => (crate::numbers::shortest(units), serde_json::json!(units)),
                None => (String::new(), serde_json::Value::Null),
            },
        ];
        KEYS.into_iter()
            .zip(texts)
            .zip(self.sources())
            .filter(|((key, _), _)| *key != "accuracy" || c.budget().is_some())
            .map(|((key, (toml, json)), source)| (key, toml, json, source))
            .collect()
    }
}
