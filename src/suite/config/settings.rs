//! The resolved settings of a trace, each with where it came from, and
//! their `--print-config` renderings.

use super::super::check::CheckOptions;
use crate::conventions::{PartialConventions, Setting, Source};
use crate::judge::{
    DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE, DEFAULT_NORMAL_TOLERANCE_DEGREES, FieldSet,
    Tolerances,
};
use crate::replay::ReplayOptions;

/// Values set by the command line (`None`: not given), the layer above
/// every file.
#[derive(Clone, Debug, Default, PartialEq)]
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
    pub engine: PartialConventions,
}

/// The settings a trace is checked with, each with its [`Source`].
#[derive(Clone, Debug, PartialEq)]
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
    /// The engine's conventions (the `[engine]` tables and flags), key by
    /// key, each with where it was declared (undeclared: the rules).
    pub engine: PartialConventions,
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
            engine: PartialConventions::default(),
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
        CheckOptions {
            tolerances: self.tolerances(),
            strict: self.strict.value,
            fail_on_tunnel: !self.allow_tunnels.value,
            replay: ReplayOptions {
                conventions: self.engine.conventions(),
                ..options.replay
            },
            ..options
        }
    }

    /// Each setting as `(key, value in TOML, its value as JSON, source)`,
    /// in the file's words (`tolerances.alpha`, `1e-5`, ...). The
    /// `[engine]` keys only when one is declared: a suite of an engine that
    /// follows the rules reads as it always did.
    pub fn entries(&self) -> Vec<(String, String, serde_json::Value, Source)> {
        let names: Vec<String> = self
            .fields
            .value
            .fields()
            .map(|f| format!("\"{}\"", f.as_str()))
            .collect();
        let mut entries = vec![
            (
                "tolerances.alpha".to_string(),
                number_text(self.alpha.value),
                self.alpha.value.into(),
                self.alpha.source.clone(),
            ),
            (
                "tolerances.normal_degrees".to_string(),
                number_text(self.normal_degrees.value),
                self.normal_degrees.value.into(),
                self.normal_degrees.source.clone(),
            ),
            (
                "tolerances.contact".to_string(),
                number_text(self.contact.value),
                self.contact.value.into(),
                self.contact.source.clone(),
            ),
            (
                "fields".to_string(),
                format!("[{}]", names.join(", ")),
                serde_json::json!(self.fields.value),
                self.fields.source.clone(),
            ),
            (
                "strict".to_string(),
                self.strict.value.to_string(),
                self.strict.value.into(),
                self.strict.source.clone(),
            ),
            (
                "allow_tunnels".to_string(),
                self.allow_tunnels.value.to_string(),
                self.allow_tunnels.value.into(),
                self.allow_tunnels.source.clone(),
            ),
        ];
        if self.engine.is_declared() {
            for (key, toml, json, source) in self.engine.entries() {
                entries.push((format!("engine.{key}"), toml, json, source));
            }
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
    /// The `[engine]` keys this part declares.
    pub(super) engine: PartialConventions,
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
        settings.engine.merge(&self.engine);
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
            engine: o.engine.clone(),
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
            .map(|(k, v, _, _)| k.len() + 3 + v.chars().count())
            .max()
            .unwrap_or(0);
        for (key, value, _, source) in entries {
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
            let settings: serde_json::Map<String, serde_json::Value> = s
                .entries()
                .into_iter()
                .map(|(key, _, value, source)| {
                    (key, serde_json::json!({ "value": value, "source": source }))
                })
                .collect();
            serde_json::json!({ "trace": trace, "settings": settings })
        })
        .collect();
    let mut text =
        serde_json::to_string_pretty(&serde_json::json!({ "traces": traces })).unwrap_or_default();
    text.push('\n');
    text
}
