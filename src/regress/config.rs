//! `check`'s suite configuration: `sweeptrace.toml` files beside the
//! traces, so that a folder of traces carries the settings it passes with.
//!
//! A trace's settings are found the way rustfmt and ruff find theirs: the
//! file `sweeptrace.toml` in the trace's folder and in each of its parents,
//! up to the repository root (the first folder holding `.git`; the
//! filesystem root when there is none) ([`find_config_files`]). Each file
//! is a [`ConfigFile`]; [`resolve`] (pure) layers them, key by key, from the
//! lowest precedence to the highest:
//!
//! 1. the defaults;
//! 2. each file, the farthest first: its top-level keys, then each of its
//!    `[[traces]]` blocks whose `match` glob matches the trace (in the
//!    file's order: the last matching block wins);
//! 3. the command line ([`Overrides`]).
//!
//! So a nearer file overrides a farther one for every key it sets, even a
//! key the farther file sets in a `[[traces]]` block. Each resolved value
//! keeps where it came from ([`Source`]), for `check --print-config`.
//!
//! ```toml
//! # Settings of every trace under this folder.
//! fields = ["kind", "triangle", "feature", "alpha", "contact"]
//! strict = false
//! allow_tunnels = false
//!
//! [tolerances]
//! alpha = 1e-5
//! normal_degrees = 0.01
//! contact = 1e-5
//!
//! # Settings of the traces the glob matches (relative to this file's folder).
//! [[traces]]
//! match = "rapier/*.mcap"
//! fields = ["kind", "alpha"]
//! tolerances = { alpha = 1e-4 }
//! ```
//!
//! Unknown keys and bad values are errors naming the file, line and column
//! ([`ConfigError`]).

use std::fmt;
use std::path::{Component, Path, PathBuf};

use serde::{Deserialize, Serialize};
use toml::Spanned;

use super::check::CheckOptions;
use super::compare::{
    DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE, DEFAULT_NORMAL_TOLERANCE_DEGREES, Field,
    FieldSet, Tolerances,
};
use crate::numbers::{self, Rule};

/// The name of a suite configuration file.
pub const CONFIG_FILE_NAME: &str = "sweeptrace.toml";

/// Where a resolved setting came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Source {
    /// The built-in default.
    Default,
    /// A line of a configuration file.
    File {
        /// The file, as [`ConfigFile::name`] gives it.
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
    fn default_value(value: T) -> Setting<T> {
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
fn number_text(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x:?}")
    }
}

/// Why a configuration file cannot be used. The message names the file,
/// and the line and column when the fault has one
/// (`examples/sweeptrace.toml:3:1: unknown key ...`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file says something wrong.
    #[error("{file}{}: {message}", .at.map(|(line, column)| format!(":{line}:{column}")).unwrap_or_default())]
    Invalid {
        /// The file.
        file: String,
        /// Line and column (1-based), when the fault has a place.
        at: Option<(usize, usize)>,
        /// What is wrong.
        message: String,
    },
    /// The file, or a folder on the way to it, cannot be read.
    #[error("{file}: cannot read: {cause}")]
    Read {
        /// The file or folder.
        file: String,
        /// The I/O error, in words.
        cause: String,
    },
}

// ------------------------------------------------------------ the file

/// The file as written: every key optional, unknown keys refused.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    fields: Option<Spanned<Vec<Spanned<String>>>>,
    strict: Option<Spanned<bool>>,
    allow_tunnels: Option<Spanned<bool>>,
    tolerances: Option<RawTolerances>,
    #[serde(default)]
    traces: Vec<RawBlock>,
}

/// A `[[traces]]` block: a glob and the keys of the top level.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBlock {
    #[serde(rename = "match")]
    pattern: Spanned<String>,
    fields: Option<Spanned<Vec<Spanned<String>>>>,
    strict: Option<Spanned<bool>>,
    allow_tunnels: Option<Spanned<bool>>,
    tolerances: Option<RawTolerances>,
}

/// `[tolerances]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTolerances {
    alpha: Option<Spanned<f64>>,
    normal_degrees: Option<Spanned<f64>>,
    contact: Option<Spanned<f64>>,
}

/// What one part of a file (its top level, or a `[[traces]]` block) sets.
#[derive(Clone, Debug, Default, PartialEq)]
struct Layer {
    alpha: Option<Setting<f64>>,
    normal_degrees: Option<Setting<f64>>,
    contact: Option<Setting<f64>>,
    fields: Option<Setting<FieldSet>>,
    strict: Option<Setting<bool>>,
    allow_tunnels: Option<Setting<bool>>,
}

impl Layer {
    /// Sets in `settings` every key this layer holds.
    fn apply(&self, settings: &mut Settings) {
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

    fn of_command_line(o: &Overrides) -> Layer {
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

/// A `[[traces]]` block, its glob compiled.
#[derive(Clone, Debug)]
struct TracesBlock {
    matcher: globset::GlobMatcher,
    layer: Layer,
}

/// One parsed and validated `sweeptrace.toml`.
#[derive(Clone, Debug)]
pub struct ConfigFile {
    path: PathBuf,
    name: String,
    top: Layer,
    blocks: Vec<TracesBlock>,
}

/// Reads a file's text, line by line, to turn byte offsets into places.
struct Places<'a> {
    text: &'a str,
    name: &'a str,
}

impl Places<'_> {
    /// 1-based line and column (in characters) of byte `offset`.
    fn at(&self, offset: usize) -> (usize, usize) {
        let before = &self.text[..offset.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, column)
    }

    fn line<T>(&self, value: &Spanned<T>) -> usize {
        self.at(value.span().start).0
    }

    fn error<T>(&self, value: &Spanned<T>, message: String) -> ConfigError {
        ConfigError::Invalid {
            file: self.name.to_string(),
            at: Some(self.at(value.span().start)),
            message,
        }
    }

    fn setting<T, U>(&self, value: &Spanned<T>, converted: U) -> Setting<U> {
        Setting {
            value: converted,
            source: Source::File {
                file: self.name.to_string(),
                line: self.line(value),
            },
        }
    }

    /// The layer of a top level or a block, its values validated.
    fn layer(
        &self,
        fields: &Option<Spanned<Vec<Spanned<String>>>>,
        strict: &Option<Spanned<bool>>,
        allow_tunnels: &Option<Spanned<bool>>,
        tolerances: &Option<RawTolerances>,
    ) -> Result<Layer, ConfigError> {
        let tolerance = |key: &str, v: &Option<Spanned<f64>>| {
            v.as_ref()
                .map(|v| {
                    numbers::check(*v.get_ref(), Rule::NonNegative)
                        .map_err(|e| self.error(v, format!("`tolerances.{key}` {e}")))?;
                    Ok::<_, ConfigError>(self.setting(v, *v.get_ref()))
                })
                .transpose()
        };
        let (alpha, normal_degrees, contact) = match tolerances {
            Some(t) => (
                tolerance("alpha", &t.alpha)?,
                tolerance("normal_degrees", &t.normal_degrees)?,
                tolerance("contact", &t.contact)?,
            ),
            None => (None, None, None),
        };
        let fields = fields
            .as_ref()
            .map(|list| self.field_set(list).map(|set| self.setting(list, set)))
            .transpose()?;
        Ok(Layer {
            alpha,
            normal_degrees,
            contact,
            fields,
            strict: strict.as_ref().map(|v| self.setting(v, *v.get_ref())),
            allow_tunnels: allow_tunnels
                .as_ref()
                .map(|v| self.setting(v, *v.get_ref())),
        })
    }

    fn field_set(&self, list: &Spanned<Vec<Spanned<String>>>) -> Result<FieldSet, ConfigError> {
        let valid = || {
            <Field as strum::IntoEnumIterator>::iter()
                .map(Field::as_str)
                .collect::<Vec<_>>()
                .join(", ")
        };
        if list.get_ref().is_empty() {
            return Err(self.error(
                list,
                format!(
                    "`fields` is empty: list the fields to compare, among {}",
                    valid()
                ),
            ));
        }
        let mut fields = Vec::new();
        for name in list.get_ref() {
            let field = name.get_ref().parse::<Field>().map_err(|_| {
                self.error(
                    name,
                    format!(
                        "unknown field `{}` in `fields`; the fields are {}",
                        name.get_ref(),
                        valid()
                    ),
                )
            })?;
            fields.push(field);
        }
        Ok(FieldSet::of(&fields))
    }
}

impl ConfigFile {
    /// Parses and validates the text of the file at `path`; errors and
    /// [`Source`]s name it as `path` shows. The `[[traces]]` globs are
    /// relative to `path`'s folder.
    pub fn parse(text: &str, path: &Path) -> Result<ConfigFile, ConfigError> {
        ConfigFile::parse_named(text, path, &path.display().to_string())
    }

    /// [`ConfigFile::parse`], with errors and sources naming the file
    /// `name` (a shorter form of `path`, such as one relative to the
    /// working directory).
    pub fn parse_named(text: &str, path: &Path, name: &str) -> Result<ConfigFile, ConfigError> {
        let places = Places { text, name };
        let raw: RawFile = toml::from_str(text).map_err(|e| ConfigError::Invalid {
            file: name.to_string(),
            at: e.span().map(|s| places.at(s.start)),
            message: toml_message(e.message()),
        })?;
        let top = places.layer(
            &raw.fields,
            &raw.strict,
            &raw.allow_tunnels,
            &raw.tolerances,
        )?;
        let mut blocks = Vec::with_capacity(raw.traces.len());
        for block in &raw.traces {
            let pattern = &block.pattern;
            let matcher = globset::GlobBuilder::new(pattern.get_ref())
                .literal_separator(true)
                .build()
                .map_err(|e| {
                    places.error(
                        pattern,
                        format!(
                            "`match`: `{}` is not a glob: {}",
                            pattern.get_ref(),
                            e.kind()
                        ),
                    )
                })?
                .compile_matcher();
            let layer = places.layer(
                &block.fields,
                &block.strict,
                &block.allow_tunnels,
                &block.tolerances,
            )?;
            blocks.push(TracesBlock { matcher, layer });
        }
        Ok(ConfigFile {
            path: path.to_path_buf(),
            name: name.to_string(),
            top,
            blocks,
        })
    }

    /// Reads and parses the file at `path`, named `name` in messages.
    pub fn read(path: &Path, name: &str) -> Result<ConfigFile, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Read {
            file: name.to_string(),
            cause: e.to_string(),
        })?;
        ConfigFile::parse_named(&text, path, name)
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's name in messages and sources.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Applies the file to `settings` for `trace`: its top level, then the
    /// `[[traces]]` blocks that match the trace, in order.
    fn apply(&self, trace: &Path, settings: &mut Settings) {
        self.top.apply(settings);
        if self.blocks.is_empty() {
            return;
        }
        let dir = normalize(self.path.parent().unwrap_or(Path::new("")));
        let Ok(relative) = normalize(trace).strip_prefix(&dir).map(Path::to_path_buf) else {
            return;
        };
        for block in &self.blocks {
            if block.matcher.is_match(&relative) {
                block.layer.apply(settings);
            }
        }
    }
}

/// toml's message in the file's vocabulary: TOML has keys, not fields.
fn toml_message(message: &str) -> String {
    message
        .trim()
        .replace("unknown field", "unknown key")
        .replace("missing field", "missing key")
        .replace('\n', "; ")
}

/// The settings of `trace`: the defaults, then `files` (nearest first, as
/// [`find_config_files`] gives them; the farthest applies first), then the
/// command line. Pure. `trace` and the files' paths must be in the same
/// frame (both absolute, or both relative to one folder) for the
/// `[[traces]]` globs to match; [`load_config_files`] gives absolute paths.
pub fn resolve(files: &[ConfigFile], trace: &Path, command_line: &Overrides) -> Settings {
    let mut settings = Settings::default();
    for file in files.iter().rev() {
        file.apply(trace, &mut settings);
    }
    Layer::of_command_line(command_line).apply(&mut settings);
    settings
}

/// `path` with `.` removed and `..` taken against the component before it,
/// without touching the file system (a `..` at the start stays).
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if matches!(out.components().next_back(), Some(Component::Normal(_))) {
                    out.pop();
                } else if !out.has_root() {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}

/// The `sweeptrace.toml` files that apply to `trace`, nearest first: in the
/// trace's folder and each parent, up to the first folder holding `.git`
/// (the repository root, included) or the filesystem root. Absolute,
/// normalized paths.
pub fn find_config_files(trace: &Path) -> Result<Vec<PathBuf>, ConfigError> {
    let absolute = std::path::absolute(trace).map_err(|e| ConfigError::Read {
        file: trace.display().to_string(),
        cause: e.to_string(),
    })?;
    let absolute = normalize(&absolute);
    let mut found = Vec::new();
    for dir in absolute.ancestors().skip(1) {
        let candidate = dir.join(CONFIG_FILE_NAME);
        if candidate.is_file() {
            found.push(candidate);
        }
        if dir.join(".git").exists() {
            break;
        }
    }
    Ok(found)
}

/// The configuration files of `trace` ([`find_config_files`]), read and
/// parsed, each named relative to the working directory when under it.
pub fn load_config_files(trace: &Path) -> Result<Vec<ConfigFile>, ConfigError> {
    let cwd = std::env::current_dir().ok().map(|d| normalize(&d));
    find_config_files(trace)?
        .into_iter()
        .map(|path| {
            let shown = cwd
                .as_ref()
                .and_then(|cwd| path.strip_prefix(cwd).ok())
                .unwrap_or(&path)
                .display()
                .to_string();
            ConfigFile::read(&path, &shown)
        })
        .collect()
}

/// The settings of `trace` from its configuration files
/// ([`load_config_files`]) and the command line.
pub fn settings_for(trace: &Path, command_line: &Overrides) -> Result<Settings, ConfigError> {
    let files = load_config_files(trace)?;
    let absolute = std::path::absolute(trace).map_err(|e| ConfigError::Read {
        file: trace.display().to_string(),
        cause: e.to_string(),
    })?;
    Ok(resolve(&files, &absolute, command_line))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, path: &str) -> ConfigFile {
        match ConfigFile::parse(text, Path::new(path)) {
            Ok(f) => f,
            Err(e) => panic!("{e}"),
        }
    }

    fn error(text: &str) -> String {
        match ConfigFile::parse(text, Path::new("suite/sweeptrace.toml")) {
            Ok(_) => panic!("parsed: {text}"),
            Err(e) => e.to_string(),
        }
    }

    fn file(path: &str, line: usize) -> Source {
        Source::File {
            file: path.to_string(),
            line,
        }
    }

    #[test]
    fn no_file_gives_the_defaults() {
        let s = resolve(&[], Path::new("t.mcap"), &Overrides::default());
        assert_eq!(s, Settings::default());
        assert_eq!(s.tolerances(), Tolerances::default());
        let options = s.check_options(CheckOptions::default());
        assert_eq!(options, CheckOptions::default());
    }

    #[test]
    fn top_level_keys_with_their_lines() {
        let f = parse(
            "fields = [\"kind\", \"alpha\"]\nstrict = true\n\n[tolerances]\nalpha = 1e-4\ncontact = 2\n",
            "a/sweeptrace.toml",
        );
        let s = resolve(&[f], Path::new("a/t.mcap"), &Overrides::default());
        assert_eq!(s.fields.value, FieldSet::of(&[Field::Kind, Field::Alpha]));
        assert_eq!(s.fields.source, file("a/sweeptrace.toml", 1));
        assert_eq!(
            (s.strict.value, s.strict.source.clone()),
            (true, file("a/sweeptrace.toml", 2))
        );
        assert_eq!(s.alpha.value, 1e-4);
        assert_eq!(s.alpha.source, file("a/sweeptrace.toml", 5));
        // An integer is a number too.
        assert_eq!(s.contact.value, 2.0);
        assert_eq!(s.contact.source, file("a/sweeptrace.toml", 6));
        assert_eq!(
            s.normal_degrees,
            Setting::default_value(DEFAULT_NORMAL_TOLERANCE_DEGREES)
        );
        assert_eq!(s.allow_tunnels.source, Source::Default);
        assert!(s.check_options(CheckOptions::default()).fail_on_tunnel);
        assert!(s.check_options(CheckOptions::default()).strict);
    }

    #[test]
    fn nearer_files_override_farther_ones_key_by_key() {
        let far = parse(
            "strict = true\n[tolerances]\nalpha = 1e-3\ncontact = 1e-3\n",
            "root/sweeptrace.toml",
        );
        let near = parse("[tolerances]\nalpha = 1e-4\n", "root/sub/sweeptrace.toml");
        let s = resolve(
            &[near, far],
            Path::new("root/sub/t.mcap"),
            &Overrides::default(),
        );
        assert_eq!(s.alpha.value, 1e-4);
        assert_eq!(s.alpha.source, file("root/sub/sweeptrace.toml", 2));
        assert_eq!(s.contact.value, 1e-3);
        assert_eq!(s.contact.source, file("root/sweeptrace.toml", 4));
        assert_eq!(s.strict.source, file("root/sweeptrace.toml", 1));
    }

    #[test]
    fn a_nearer_file_overrides_a_farther_files_traces_block() {
        let far = parse(
            "[[traces]]\nmatch = \"sub/*.mcap\"\ntolerances = { alpha = 1e-3 }\n",
            "root/sweeptrace.toml",
        );
        let near = parse("[tolerances]\nalpha = 1e-4\n", "root/sub/sweeptrace.toml");
        let s = resolve(
            &[near.clone(), far.clone()],
            Path::new("root/sub/t.mcap"),
            &Overrides::default(),
        );
        assert_eq!(s.alpha.source, file("root/sub/sweeptrace.toml", 2));
        let s = resolve(&[far], Path::new("root/sub/t.mcap"), &Overrides::default());
        assert_eq!(
            (s.alpha.value, s.alpha.source),
            (1e-3, file("root/sweeptrace.toml", 3))
        );
    }

    #[test]
    fn traces_blocks_match_relative_to_the_file_and_the_last_one_wins() {
        let f = parse(
            "[tolerances]\nalpha = 1e-5\n\
             [[traces]]\nmatch = \"rapier/*.mcap\"\nfields = [\"kind\"]\ntolerances = { alpha = 1e-4 }\n\
             [[traces]]\nmatch = \"**/golf*.mcap\"\n[traces.tolerances]\nalpha = 1e-3\n",
            "ex/sweeptrace.toml",
        );
        let none = Overrides::default();
        let s = resolve(std::slice::from_ref(&f), Path::new("ex/other.mcap"), &none);
        assert_eq!(
            (s.alpha.value, s.alpha.source),
            (1e-5, file("ex/sweeptrace.toml", 2))
        );
        assert_eq!(s.fields.source, Source::Default);
        let s = resolve(
            std::slice::from_ref(&f),
            Path::new("ex/rapier/a.mcap"),
            &none,
        );
        assert_eq!(
            (s.alpha.value, s.alpha.source),
            (1e-4, file("ex/sweeptrace.toml", 6))
        );
        assert_eq!(s.fields.source, file("ex/sweeptrace.toml", 5));
        // Both blocks match: the last one wins, key by key.
        let s = resolve(
            std::slice::from_ref(&f),
            Path::new("ex/rapier/golf_1.mcap"),
            &none,
        );
        assert_eq!(
            (s.alpha.value, s.alpha.source),
            (1e-3, file("ex/sweeptrace.toml", 10))
        );
        assert_eq!(s.fields.source, file("ex/sweeptrace.toml", 5));
        // `*` does not cross a folder; the path is normalized first.
        let s = resolve(
            std::slice::from_ref(&f),
            Path::new("ex/rapier/deeper/a.mcap"),
            &none,
        );
        assert_eq!(s.alpha.value, 1e-5);
        let s = resolve(
            std::slice::from_ref(&f),
            Path::new("ex/x/../rapier/./a.mcap"),
            &none,
        );
        assert_eq!(s.alpha.value, 1e-4);
        // A trace outside the file's folder gets its top level only.
        let s = resolve(std::slice::from_ref(&f), Path::new("rapier/a.mcap"), &none);
        assert_eq!(s.alpha.value, 1e-5);
    }

    #[test]
    fn the_command_line_overrides_every_file() {
        let f = parse(
            "strict = true\nallow_tunnels = true\nfields = [\"kind\"]\n[tolerances]\nalpha = 1e-4\n",
            "s/sweeptrace.toml",
        );
        let cli = Overrides {
            alpha: Some(0.5),
            strict: Some(false),
            fields: Some(FieldSet::ALL),
            ..Overrides::default()
        };
        let s = resolve(&[f], Path::new("s/t.mcap"), &cli);
        assert_eq!((s.alpha.value, s.alpha.source), (0.5, Source::CommandLine));
        assert_eq!(
            (s.strict.value, s.strict.source),
            (false, Source::CommandLine)
        );
        assert_eq!(s.fields.value, FieldSet::ALL);
        assert_eq!(s.allow_tunnels.source, file("s/sweeptrace.toml", 2));
    }

    #[test]
    fn unknown_keys_name_file_line_and_column() {
        assert!(
            error("strict = true\nalfa = 1\n")
                .starts_with("suite/sweeptrace.toml:2:1: unknown key `alfa`, expected one of"),
            "{}",
            error("strict = true\nalfa = 1\n")
        );
        let e = error("[tolerances]\n  normal = 1\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:2:3: unknown key `normal`"),
            "{e}"
        );
        assert!(e.contains("normal_degrees"), "{e}");
        let e = error("[[traces]]\nmatch = \"*.mcap\"\nstrikt = true\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:3:1: unknown key `strikt`"),
            "{e}"
        );
        let e = error("[[traces]]\nstrict = true\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:1:1: missing key `match`"),
            "{e}"
        );
    }

    #[test]
    fn bad_values_name_file_line_and_what_is_allowed() {
        let e = error("\n[tolerances]\nalpha = -1e-5\n");
        assert_eq!(
            e,
            "suite/sweeptrace.toml:3:9: `tolerances.alpha` must be a finite number ≥ 0, got -0.00001"
        );
        let e = error("[tolerances]\ncontact = nan\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:2:11: `tolerances.contact` must be"),
            "{e}"
        );
        let e = error("fields = [\"kind\", \"colour\"]\n");
        assert_eq!(
            e,
            "suite/sweeptrace.toml:1:19: unknown field `colour` in `fields`; \
             the fields are kind, triangle, feature, alpha, normal, contact"
        );
        let e = error("fields = []\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:1:10: `fields` is empty"),
            "{e}"
        );
        let e = error("strict = \"yes\"\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:1:10: invalid type"),
            "{e}"
        );
        let e = error("[[traces]]\nmatch = \"a/[b\"\n");
        assert!(
            e.starts_with("suite/sweeptrace.toml:2:9: `match`: `a/[b` is not a glob"),
            "{e}"
        );
        let e = error("strict = \n");
        assert!(e.starts_with("suite/sweeptrace.toml:1:"), "{e}");
    }

    #[test]
    fn print_config_names_every_source() {
        let f = parse("[tolerances]\nalpha = 1e-5\n", "ex/sweeptrace.toml");
        let cli = Overrides {
            strict: Some(true),
            ..Overrides::default()
        };
        let s = resolve(&[f], Path::new("ex/t.mcap"), &cli);
        let text = render_settings_text(&[("ex/t.mcap".to_string(), s.clone())]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 7, "{text}");
        assert_eq!(lines[0], "ex/t.mcap");
        let expect = [
            ("tolerances.alpha = 1e-5", "# ex/sweeptrace.toml:2"),
            ("tolerances.normal_degrees = 0.01", "# default"),
            ("tolerances.contact = 1e-6", "# default"),
            (
                "fields = [\"kind\", \"triangle\", \"feature\", \"alpha\", \"normal\", \"contact\"]",
                "# default",
            ),
            ("strict = true", "# command line"),
            ("allow_tunnels = false", "# default"),
        ];
        for (line, (setting, source)) in lines[1..].iter().zip(expect) {
            assert!(line.starts_with(&format!("  {setting} ")), "{text}");
            assert!(line.ends_with(source), "{text}");
        }
        // The sources start in one column.
        let columns: Vec<usize> = lines[1..].iter().filter_map(|l| l.find("  # ")).collect();
        assert!(
            columns.len() == 6 && columns.iter().all(|&c| c == columns[0]),
            "{text}"
        );
        let json: serde_json::Value =
            serde_json::from_str(&render_settings_json(&[("ex/t.mcap".to_string(), s)])).unwrap();
        let settings = &json["traces"][0]["settings"];
        assert_eq!(settings["tolerances.alpha"]["value"], 1e-5);
        assert_eq!(
            settings["tolerances.alpha"]["source"],
            serde_json::json!({"kind": "file", "file": "ex/sweeptrace.toml", "line": 2})
        );
        assert_eq!(settings["strict"]["source"]["kind"], "command_line");
        assert_eq!(settings["fields"]["source"]["kind"], "default");
    }

    #[test]
    fn numbers_read_back() {
        for x in [1e-6, 1e-5, 0.01, 20.0, 0.5, 1.25e-7, 0.0] {
            let text = number_text(x);
            let back: f64 = text.parse().unwrap();
            assert_eq!(back, x, "{text}");
        }
        assert_eq!(number_text(1e-5), "1e-5");
        assert_eq!(number_text(0.01), "0.01");
        assert_eq!(number_text(20.0), "20.0");
    }

    #[test]
    fn normalize_is_lexical() {
        assert_eq!(normalize(Path::new("a/./b/../c")), PathBuf::from("a/c"));
        assert_eq!(normalize(Path::new("../a")), PathBuf::from("../a"));
        assert_eq!(normalize(Path::new("/../a")), PathBuf::from("/a"));
    }
}
