//! One `sweeptrace.toml`: parsed, validated, its values located by line
//! and column.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use super::glob::{Pattern, Patterns};
use super::normalize;
use super::settings::{Layer, Settings};
use crate::conventions::{Setting, Source};
use crate::error_text::escaped;
use crate::judge::{Field, FieldSet};
use crate::numbers::{self, Rule};

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

/// The largest settings file read (64 MiB; a large suite's file with
/// tens of thousands of `[[traces]]` blocks is a few MiB).
pub const MAX_CONFIG_BYTES: u64 = 64 * 1024 * 1024;

// ------------------------------------------------------------ the file

/// The file as written: every key optional, unknown keys refused.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table of settings")]
struct RawFile {
    fields: Option<Spanned<Vec<Spanned<String>>>>,
    strict: Option<Spanned<bool>>,
    allow_tunnels: Option<Spanned<bool>>,
    tolerances: Option<RawTolerances>,
    exclude: Option<Spanned<Vec<Spanned<String>>>>,
    engine: Option<RawEngine>,
    #[serde(default)]
    traces: Vec<RawBlock>,
}

/// `[engine]`: the engine's conventions (top level only: one engine per
/// file), read key by key into the conventions' partial type
/// ([`crate::conventions::PartialConventions::set`]).
struct RawEngine(BTreeMap<Spanned<String>, Spanned<toml::Value>>);

impl<'de> Deserialize<'de> for RawEngine {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Table;
        impl<'de> serde::de::Visitor<'de> for Table {
            type Value = RawEngine;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("the `[engine]` table")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut map: A,
            ) -> Result<RawEngine, A::Error> {
                let mut keys = BTreeMap::new();
                while let Some((key, value)) = map.next_entry()? {
                    keys.insert(key, value);
                }
                Ok(RawEngine(keys))
            }
        }
        d.deserialize_map(Table)
    }
}

/// A `[[traces]]` block: a glob and the keys of the top level.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a `[[traces]]` table")]
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
#[serde(deny_unknown_fields, expecting = "the `[tolerances]` table")]
struct RawTolerances {
    alpha: Option<Spanned<f64>>,
    normal_degrees: Option<Spanned<f64>>,
    contact: Option<Spanned<f64>>,
}

/// One parsed and validated `sweeptrace.toml`.
#[derive(Clone, Debug)]
pub struct ConfigFile {
    path: PathBuf,
    name: String,
    top: Layer,
    /// The `[[traces]]` blocks' globs, and each block's layer (in the
    /// file's order).
    patterns: Patterns,
    blocks: Vec<Layer>,
    /// `exclude`: the globs (as written, and compiled) of the files a
    /// search of a folder leaves out.
    exclude: Vec<(String, Pattern)>,
}

/// A file's text and where each of its lines starts, to turn byte
/// offsets into places (a binary search per place, not a count of the
/// lines before it: a file with many keys parses in linear time).
struct Places<'a> {
    text: &'a str,
    name: &'a str,
    /// The byte offset of each line's start, ascending (the first is 0).
    line_starts: Vec<usize>,
}

impl<'a> Places<'a> {
    fn new(text: &'a str, name: &'a str) -> Places<'a> {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Places {
            text,
            name,
            line_starts,
        }
    }

    /// 1-based line and column (in characters) of byte `offset`.
    fn at(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        // The last line that starts at or before `offset`.
        let line = self.line_starts.partition_point(|&start| start <= offset);
        let start = self.line_starts[line - 1];
        let column = self
            .text
            .get(start..offset)
            .map_or(0, |before| before.chars().count());
        (line, column + 1)
    }

    fn line<T>(&self, value: &Spanned<T>) -> usize {
        self.at(value.span().start).0
    }

    /// The error `message` at `value`'s place. The message quotes the
    /// file's text: its control characters are escaped.
    fn error<T>(&self, value: &Spanned<T>, message: String) -> ConfigError {
        ConfigError::Invalid {
            file: self.name.to_string(),
            at: Some(self.at(value.span().start)),
            message: escaped(&message).into_owned(),
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
            ..Layer::default()
        })
    }

    /// `[engine]`'s keys into `layer`, each value checked against its set
    /// ([`crate::conventions::PartialConventions::set`]).
    fn engine(&self, raw: &RawEngine, layer: &mut Layer) -> Result<(), ConfigError> {
        // In the order of the file, so that the first fault is reported.
        let mut keys: Vec<_> = raw.0.iter().collect();
        keys.sort_by_key(|(k, _)| k.span().start);
        for (key, value) in keys {
            let text = match value.get_ref() {
                toml::Value::String(s) => s.clone(),
                toml::Value::Integer(i) => i.to_string(),
                toml::Value::Float(f) => format!("{f:?}"),
                other => format!("a {}", other.type_str()),
            };
            let source = self.setting(value, ()).source;
            layer
                .engine
                .set(key.get_ref(), &text, source)
                .map_err(|message| {
                    // A bad value at the value; an unknown key at the key.
                    if crate::conventions::KEYS.contains(&key.get_ref().as_str()) {
                        self.error(value, message)
                    } else {
                        self.error(key, message)
                    }
                })?;
        }
        Ok(())
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
        let places = Places::new(text, name);
        let raw: RawFile = toml::from_str(text).map_err(|e| ConfigError::Invalid {
            file: name.to_string(),
            at: e.span().map(|s| places.at(s.start)),
            message: toml_message(e.message()),
        })?;
        let mut top = places.layer(
            &raw.fields,
            &raw.strict,
            &raw.allow_tunnels,
            &raw.tolerances,
        )?;
        if let Some(engine) = &raw.engine {
            places.engine(engine, &mut top)?;
        }
        let mut blocks = Vec::with_capacity(raw.traces.len());
        let glob = |key: &str, pattern: &Spanned<String>| {
            Pattern::new(pattern.get_ref()).map_err(|e| {
                places.error(
                    pattern,
                    format!(
                        "`{key}`: `{}` is not a glob: {}",
                        pattern.get_ref(),
                        e.kind()
                    ),
                )
            })
        };
        let mut exclude = Vec::new();
        for pattern in raw.exclude.as_ref().map_or(&[][..], |l| l.get_ref()) {
            exclude.push((pattern.get_ref().clone(), glob("exclude", pattern)?));
        }
        let mut patterns = Patterns::default();
        for block in &raw.traces {
            patterns.push(glob("match", &block.pattern)?);
            let layer = places.layer(
                &block.fields,
                &block.strict,
                &block.allow_tunnels,
                &block.tolerances,
            )?;
            blocks.push(layer);
        }
        Ok(ConfigFile {
            path: path.to_path_buf(),
            name: name.to_string(),
            top,
            patterns,
            blocks,
            exclude,
        })
    }

    /// Reads and parses the file at `path`, named `name` in messages.
    /// A file larger than [`MAX_CONFIG_BYTES`] is an error, not a read
    /// without end.
    pub fn read(path: &Path, name: &str) -> Result<ConfigFile, ConfigError> {
        use std::io::Read;
        let cannot_read = |cause: String| ConfigError::Read {
            file: name.to_string(),
            cause,
        };
        let file = std::fs::File::open(path).map_err(|e| cannot_read(e.to_string()))?;
        let mut text = String::new();
        file.take(MAX_CONFIG_BYTES + 1)
            .read_to_string(&mut text)
            .map_err(|e| cannot_read(e.to_string()))?;
        if text.len() as u64 > MAX_CONFIG_BYTES {
            return Err(cannot_read(format!(
                "larger than {} MiB: not a settings file",
                MAX_CONFIG_BYTES >> 20
            )));
        }
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

    /// The `exclude` glob of this file that matches `trace` (relative to
    /// the file's folder), if any: a search of a folder leaves the trace
    /// out.
    pub fn excludes(&self, trace: &Path) -> Option<&str> {
        let relative = self.relative(trace)?;
        self.exclude
            .iter()
            .find(|(_, m)| m.is_match(&relative))
            .map(|(pattern, _)| pattern.as_str())
    }

    /// `trace` relative to the file's folder (`None` when not below it).
    fn relative(&self, trace: &Path) -> Option<PathBuf> {
        let dir = normalize(self.path.parent().unwrap_or(Path::new("")));
        normalize(trace)
            .strip_prefix(&dir)
            .map(Path::to_path_buf)
            .ok()
    }

    /// Applies the file to `settings` for `trace`: its top level, then the
    /// `[[traces]]` blocks that match the trace, in order.
    pub(super) fn apply(&self, trace: &Path, settings: &mut Settings) {
        self.top.apply(settings);
        if self.patterns.is_empty() {
            return;
        }
        let Some(relative) = self.relative(trace) else {
            return;
        };
        for i in self.patterns.matching(&relative) {
            self.blocks[i].apply(settings);
        }
    }
}

/// toml's message in the file's vocabulary (TOML has keys, not fields),
/// on one line, the file's text it quotes with its control characters
/// escaped.
fn toml_message(message: &str) -> String {
    let message = message
        .trim()
        .replace("unknown field", "unknown key")
        .replace("missing field", "missing key")
        .replace('\n', "; ");
    escaped(&message).into_owned()
}

#[cfg(test)]
mod places_tests {
    use super::Places;

    /// The line index gives the places counting the lines before each
    /// offset gives (the former way, quadratic over a file's keys), on
    /// every character boundary of a text with blank lines, a last line
    /// without a newline and characters of several bytes.
    #[test]
    fn line_index_gives_the_places_counting_gives() {
        let text = "a = 1\n\n[[traces]]\nmatch = \"é/ü*.mcap\"\n  x = \"→\"\r\nlast";
        let places = Places::new(text, "t.toml");
        for offset in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
            let before = &text[..offset];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            assert_eq!(places.at(offset), (line, column), "offset {offset}");
        }
        assert_eq!(places.at(text.len() + 10), places.at(text.len()));
    }
}
