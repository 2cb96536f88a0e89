//! The resolved settings of a trace, each with where it came from, and
//! their `--print-config` renderings.

use std::fmt;

use serde::Serialize;

use super::super::check::CheckOptions;
use super::super::compare::{
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
        }
    }

    /// `options` with these settings' tolerances, `strict` and tunnel rule.
    pub fn check_options(&self, options: CheckOptions) -> CheckOptions {
        CheckOptions {
            tolerances: self.tolerances(),
            strict: self.strict.value,
            fail_on_tunnel: !self.allow_tunnels.value,
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
        vec![
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
        ]
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
            serde_json::json!({
                "trace": trace,
                "settings": {
                    "tolerances.alpha": entry(s.alpha.value.into(), &s.alpha.source),
                    "tolerances.normal_degrees":
                        entry(s.normal_degrees.value.into(), &s.normal_degrees.source),
                    "tolerances.contact": entry(s.contact.value.into(), &s.contact.source),
                    "fields": entry(serde_json::json!(s.fields.value), &s.fields.source),
                    "strict": entry(s.strict.value.into(), &s.strict.source),
                    "allow_tunnels": entry(s.allow_tunnels.value.into(), &s.allow_tunnels.source),
                },
            })
        })
        .collect();
    let mut text =
        serde_json::to_string_pretty(&serde_json::json!({ "traces": traces })).unwrap_or_default();
    text.push('\n');
    text
}
