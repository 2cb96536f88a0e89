//! The resolved settings of a trace, each with where it came from, and
//! their `--print-config` renderings.

use std::fmt;

use serde::Serialize;

use super::super::check::CheckOptions;
use crate::conventions::NormalRule;
use crate::conventions::Precision;
use crate::conventions::TieRule;
use crate::conventions::{EngineConventions, FacingRule, MarginRule};
use crate::core::{InitialOverlap, Sides};
use crate::judge::{
    DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE, DEFAULT_NORMAL_TOLERANCE_DEGREES, FieldSet,
    Tolerances,
};

/// Where a resolved setting came from.
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
    pub(super) fn default_value(value: T) -> Setting<T> {
        Setting {
            value,
            source: Source::Default,
        }
    }
}

/// Values set by the command line (`None`: not given), the layer above
/// every file.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// `--tolerance`.
    pub alpha: Option<f64>,
    /// `--normal-tolerance`, in degrees.
    pub normal_degrees: Option<f64>,
    /// `--contact-tolerance`.
    pub contact: Option<f64>,
    /// `--fields`.
    pub fields: Option<FieldSet>,
    /// `--strict`.
    pub strict: Option<bool>,
    /// `--allow-tunnels`.
    pub allow_tunnels: Option<bool>,
    /// The engine conventions given on the command line (`--precision`,
    /// `--margin`, `--facing`, `--sides`, `--initial-overlap`, `--normal`, `--ties`).
    pub engine: EngineOverrides,
}

/// The `[engine]` keys given on the command line (`None`: not given).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EngineOverrides {
    /// `--precision`.
    pub precision: Option<Precision>,
    /// `--margin`.
    pub margin: Option<MarginRule>,
    /// `--facing`.
    pub facing: Option<FacingRule>,
    /// `--sides`.
    pub sides: Option<Sides>,
    /// `--initial-overlap`.
    pub initial_overlap: Option<InitialOverlap>,
    /// `--normal`.
    pub normal: Option<NormalRule>,
    /// `--ties`.
    pub ties: Option<TieRule>,
}

/// The settings a trace is checked with, each with its [`Source`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// Absolute tolerance on `α` (`tolerances.alpha`).
    pub alpha: Setting<f64>,
    /// Angular tolerance on the normal, in degrees (`tolerances.normal_degrees`).
    pub normal_degrees: Setting<f64>,
    /// Distance tolerance on the contact (`tolerances.contact`).
    pub contact: Setting<f64>,
    /// The fields compared (`fields`).
    pub fields: Setting<FieldSet>,
    /// Whether divergences rounding explains fail too (`strict`).
    pub strict: Setting<bool>,
    /// Whether tunnels are listed without failing (`allow_tunnels`).
    pub allow_tunnels: Setting<bool>,
    /// The engine's conventions (the `[engine]` table), key by key.
    pub engine: EngineSettings,
}

/// The `[engine]` table's keys, each with its [`Source`] (docs/ENGINES.md,
/// "Conventions").
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EngineSettings {
    /// `engine.precision`.
    pub precision: Setting<Precision>,
    /// `engine.margin`.
    pub margin: Setting<MarginRule>,
    /// `engine.facing`.
    pub facing: Setting<FacingRule>,
    /// `engine.sides`.
    pub sides: Setting<Sides>,
    /// `engine.initial_overlap`.
    pub initial_overlap: Setting<InitialOverlap>,
    /// `engine.normal`.
    pub normal: Setting<NormalRule>,
    /// `engine.ties`.
    pub ties: Setting<TieRule>,
}

impl Default for EngineSettings {
    fn default() -> Self {
        let rules = EngineConventions::default();
        EngineSettings {
            precision: Setting::default_value(rules.precision),
            margin: Setting::default_value(rules.margin),
            facing: Setting::default_value(rules.facing),
            sides: Setting::default_value(rules.sides),
            initial_overlap: Setting::default_value(rules.initial_overlap),
            normal: Setting::default_value(rules.normal),
            ties: Setting::default_value(rules.ties),
        }
    }
}

impl EngineSettings {
    /// Whether any key was set (by a file or the command line).
    pub fn is_declared(&self) -> bool {
        self.sources().iter().any(|s| **s != Source::Default)
    }

    /// Where each key came from, in the table's order.
    fn sources(&self) -> [&Source; 7] {
        [
            &self.precision.source,
            &self.margin.source,
            &self.facing.source,
            &self.sides.source,
            &self.initial_overlap.source,
            &self.normal.source,
            &self.ties.source,
        ]
    }

    /// Where the declared keys came from, once each in the order of the
    /// keys: a file's name, or `the command line`.
    pub fn declared_sources(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for source in self.sources() {
            let name = match source {
                Source::Default => continue,
                Source::File { file, .. } => file.clone(),
                Source::CommandLine => "the command line".to_string(),
            };
            if !out.contains(&name) {
                out.push(name);
            }
        }
        out
    }

    /// The conventions these settings declare.
    pub fn conventions(&self) -> EngineConventions {
        EngineConventions {
            precision: self.precision.value,
            margin: self.margin.value,
            facing: self.facing.value,
            sides: self.sides.value,
            initial_overlap: self.initial_overlap.value,
            normal: self.normal.value,
            ties: self.ties.value,
        }
    }
}

impl Default for Settings {
    /// The defaults, as `check` has them without a file or option.
    fn default() -> Self {
        Settings {
            alpha: Setting::default_value(DEFAULT_ALPHA_TOLERANCE),
            normal_degrees: Setting::default_value(DEFAULT_NORMAL_TOLERANCE_DEGREES),
            contact: Setting::default_value(DEFAULT_CONTACT_TOLERANCE),
            fields: Setting::default_value(FieldSet::ALL),
            strict: Setting::default_value(false),
            allow_tunnels: Setting::default_value(false),
            engine: EngineSettings::default(),
        }
    }
}

impl Settings {
    /// The comparison's tolerances.
    pub fn tolerances(&self) -> Tolerances {
        Tolerances {
            alpha: self.alpha.value,
            normal_degrees: self.normal_degrees.value,
            contact: self.contact.value,
            fields: self.fields.value,
            ..Tolerances::default()
        }
    }

    /// `options` with these settings' tolerances, `strict`, tunnel rule
    /// and engine conventions.
    pub fn check_options(&self, options: CheckOptions) -> CheckOptions {
        let conventions = self.engine.conventions();
        CheckOptions {
            tolerances: conventions.judge_with(self.tolerances()),
            strict: self.strict.value,
            fail_on_tunnel: !self.allow_tunnels.value,
            replay: conventions.replay_with(options.replay),
            ..options
        }
    }

    /// Each setting as `(key, value in TOML, source)`, in the file's words
    /// (`tolerances.alpha`, `1e-5`, ...).
    pub fn entries(&self) -> Vec<(&'static str, String, &Source)> {
        let fields = self
            .fields
            .value
            .fields()
            .map(|f| format!("\"{}\"", f.as_str()))
            .collect::<Vec<_>>()
            .join(", ");
        let mut entries = vec![
            (
                "tolerances.alpha",
                number_text(self.alpha.value),
                &self.alpha.source,
            ),
            (
                "tolerances.normal_degrees",
                number_text(self.normal_degrees.value),
                &self.normal_degrees.source,
            ),
            (
                "tolerances.contact",
                number_text(self.contact.value),
                &self.contact.source,
            ),
            ("fields", format!("[{fields}]"), &self.fields.source),
            ("strict", self.strict.value.to_string(), &self.strict.source),
            (
                "allow_tunnels",
                self.allow_tunnels.value.to_string(),
                &self.allow_tunnels.source,
            ),
        ];
        // The `[engine]` keys only when one is declared: a suite of an
        // engine that follows the rules reads as it always did.
        if self.engine.is_declared() {
            entries.extend([
                (
                    "engine.precision",
                    format!("\"{}\"", self.engine.precision.value),
                    &self.engine.precision.source,
                ),
                (
                    "engine.margin",
                    self.engine.conventions().margin_toml(),
                    &self.engine.margin.source,
                ),
                (
                    "engine.facing",
                    format!("\"{}\"", self.engine.facing.value),
                    &self.engine.facing.source,
                ),
                (
                    "engine.sides",
                    format!("\"{}\"", self.engine.sides.value),
                    &self.engine.sides.source,
                ),
                (
                    "engine.initial_overlap",
                    format!("\"{}\"", self.engine.initial_overlap.value),
                    &self.engine.initial_overlap.source,
                ),
                (
                    "engine.normal",
                    format!("\"{}\"", self.engine.normal.value),
                    &self.engine.normal.source,
                ),
                (
                    "engine.ties",
                    format!("\"{}\"", self.engine.ties.value),
                    &self.engine.ties.source,
                ),
            ]);
        }
        entries
    }
}

/// A number as TOML reads it back: Rust's shortest round-trip digits, in
/// exponent notation for small and large magnitudes (`1e-5`, `0.01`, `20.0`).
pub(super) fn number_text(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x:?}")
    }
}

/// What one part of a file (its top level, or a `[[traces]]` block) sets.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Layer {
    pub(super) alpha: Option<Setting<f64>>,
    pub(super) normal_degrees: Option<Setting<f64>>,
    pub(super) contact: Option<Setting<f64>>,
    pub(super) fields: Option<Setting<FieldSet>>,
    pub(super) strict: Option<Setting<bool>>,
    pub(super) allow_tunnels: Option<Setting<bool>>,
    pub(super) precision: Option<Setting<Precision>>,
    pub(super) margin: Option<Setting<MarginRule>>,
    pub(super) facing: Option<Setting<FacingRule>>,
    pub(super) sides: Option<Setting<Sides>>,
    pub(super) initial_overlap: Option<Setting<InitialOverlap>>,
    pub(super) normal: Option<Setting<NormalRule>>,
    pub(super) ties: Option<Setting<TieRule>>,
}

impl Layer {
    /// Sets in `settings` every key this layer holds.
    pub(super) fn apply(&self, settings: &mut Settings) {
        fn set<T: Clone>(to: &mut Setting<T>, from: &Option<Setting<T>>) {
            if let Some(s) = from {
                *to = s.clone();
            }
        }
        set(&mut settings.alpha, &self.alpha);
        set(&mut settings.normal_degrees, &self.normal_degrees);
        set(&mut settings.contact, &self.contact);
        set(&mut settings.fields, &self.fields);
        set(&mut settings.strict, &self.strict);
        set(&mut settings.allow_tunnels, &self.allow_tunnels);
        set(&mut settings.engine.precision, &self.precision);
        set(&mut settings.engine.margin, &self.margin);
        set(&mut settings.engine.facing, &self.facing);
        set(&mut settings.engine.sides, &self.sides);
        set(&mut settings.engine.initial_overlap, &self.initial_overlap);
        set(&mut settings.engine.normal, &self.normal);
        set(&mut settings.engine.ties, &self.ties);
    }

    pub(super) fn of_command_line(o: &Overrides) -> Layer {
        fn given<T>(v: Option<T>) -> Option<Setting<T>> {
            v.map(|value| Setting {
                value,
                source: Source::CommandLine,
            })
        }
        Layer {
            alpha: given(o.alpha),
            normal_degrees: given(o.normal_degrees),
            contact: given(o.contact),
            fields: given(o.fields),
            strict: given(o.strict),
            allow_tunnels: given(o.allow_tunnels),
            precision: given(o.engine.precision),
            margin: given(o.engine.margin),
            facing: given(o.engine.facing),
            sides: given(o.engine.sides),
            initial_overlap: given(o.engine.initial_overlap),
            normal: given(o.engine.normal),
            ties: given(o.engine.ties),
        }
    }
}

/// `check --print-config`: each trace's settings and where each came from,
/// one block per trace, aligned (`  tolerances.alpha = 1e-5  # examples/sweeptrace.toml:9`).
pub fn render_settings_text(traces: &[(String, Settings)]) -> String {
    let mut out = String::new();
    for (trace, settings) in traces {
        out.push_str(trace);
        out.push('\n');
        let entries = settings.entries();
        let width = entries
            .iter()
            .map(|(k, v, _)| k.len() + 3 + v.chars().count())
            .max()
            .unwrap_or(0);
        for (key, value, source) in entries {
            let line = format!("{key} = {value}");
            let pad = width - line.chars().count();
            out.push_str(&format!("  {line}{:pad$}  # {source}\n", ""));
        }
    }
    out
}

/// `check --print-config --json`: `{"traces": [{"trace", "settings": {KEY:
/// {"value", "source": {"kind": "default" | "file" (with "file", "line") |
/// "command_line"}}}}]}`, the keys as in the file (`tolerances.alpha`).
pub fn render_settings_json(traces: &[(String, Settings)]) -> String {
    let traces: Vec<serde_json::Value> = traces
        .iter()
        .map(|(trace, s)| {
            let entry = |value: serde_json::Value, source: &Source| {
                serde_json::json!({ "value": value, "source": source })
            };
            let mut settings = serde_json::json!({
                    "tolerances.alpha": entry(s.alpha.value.into(), &s.alpha.source),
                    "tolerances.normal_degrees":
                        entry(s.normal_degrees.value.into(), &s.normal_degrees.source),
                    "tolerances.contact": entry(s.contact.value.into(), &s.contact.source),
                    "fields": entry(serde_json::json!(s.fields.value), &s.fields.source),
                    "strict": entry(s.strict.value.into(), &s.strict.source),
                    "allow_tunnels": entry(s.allow_tunnels.value.into(), &s.allow_tunnels.source),
            });
            if s.engine.is_declared()
                && let Some(map) = settings.as_object_mut()
            {
                map.insert("engine.precision".to_string(), entry(serde_json::json!(s.engine.precision.value), &s.engine.precision.source));
                map.insert("engine.margin".to_string(), entry(serde_json::json!(s.engine.margin.value), &s.engine.margin.source));
                map.insert("engine.facing".to_string(), entry(serde_json::json!(s.engine.facing.value), &s.engine.facing.source));
                map.insert("engine.sides".to_string(), entry(serde_json::json!(s.engine.sides.value), &s.engine.sides.source));
                map.insert("engine.initial_overlap".to_string(), entry(serde_json::json!(s.engine.initial_overlap.value), &s.engine.initial_overlap.source));
                map.insert("engine.normal".to_string(), entry(serde_json::json!(s.engine.normal.value), &s.engine.normal.source));
                map.insert("engine.ties".to_string(), entry(serde_json::json!(s.engine.ties.value), &s.engine.ties.source));
            }
            serde_json::json!({ "trace": trace, "settings": settings })
        })
        .collect();
    let mut text =
        serde_json::to_string_pretty(&serde_json::json!({ "traces": traces })).unwrap_or_default();
    text.push('\n');
    text
}
