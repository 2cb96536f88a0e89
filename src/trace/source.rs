//! Who computed a trace's `/expected` outcomes: the optional metadata record
//! `sweeptrace.expected_source` (docs/TRACE_FORMAT.md, *Expected source*).
//!
//! The record's entries are `engine` (required, not empty), `version`
//! (optional) and one `setting.<name>` per setting of the engine that
//! bears on its answers (`setting.fix_internal_edges = "false"`). Any other
//! key, an empty engine name, a control character, a string above its
//! length limit, too many settings or a second record are errors: the
//! writer refuses them ([`super::TraceWriter::expected_source`]) and the
//! reader reports them ([`super::TraceError::ExpectedSource`]).

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

/// Name of the metadata record.
pub const EXPECTED_SOURCE_METADATA: &str = "sweeptrace.expected_source";
/// Key of the engine's name.
pub const ENGINE_KEY: &str = "engine";
/// Key of the engine's version.
pub const VERSION_KEY: &str = "version";
/// Prefix of the keys of the settings.
pub const SETTING_PREFIX: &str = "setting.";
/// Longest engine name or version, in bytes of UTF-8.
pub const MAX_NAME_BYTES: usize = 128;
/// Longest setting name (without the prefix), in bytes of UTF-8.
pub const MAX_SETTING_NAME_BYTES: usize = 128;
/// Longest setting value, in bytes of UTF-8.
pub const MAX_SETTING_VALUE_BYTES: usize = 1024;
/// Most settings in one record.
pub const MAX_SETTINGS: usize = 64;

/// Who computed the expectations: an engine, its version and the settings
/// that bear on its answers.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct ExpectedSource {
    /// The engine's name (`rapier3d-f64`, `sweeptrace`, `my-game`); not empty.
    pub engine: String,
    /// Its version (`0.36.1`); empty when not known.
    pub version: String,
    /// Its settings, by name (`fix_internal_edges` → `false`).
    pub settings: BTreeMap<String, String>,
}

/// `sweeptrace` itself, at this crate's version, with the margin and facing
/// rule it decided with (`record`, `bless`).
pub fn sweeptrace_source(margin: &str, facing: &str) -> ExpectedSource {
    ExpectedSource::new("sweeptrace", env!("CARGO_PKG_VERSION"))
        .setting("margin", margin)
        .setting("facing", facing)
}

impl ExpectedSource {
    /// An engine and its version, without settings.
    pub fn new(engine: impl Into<String>, version: impl Into<String>) -> Self {
        ExpectedSource {
            engine: engine.into(),
            version: version.into(),
            settings: BTreeMap::new(),
        }
    }

    /// With one more setting (a setting of the same name is replaced).
    pub fn setting(mut self, name: impl Into<String>, value: impl ToString) -> Self {
        self.settings.insert(name.into(), value.to_string());
        self
    }

    /// Checks the rules of the format; the problem in words.
    pub fn validate(&self) -> Result<(), String> {
        if self.engine.is_empty() {
            return Err(format!("`{ENGINE_KEY}` is empty; name the engine"));
        }
        text_rule(ENGINE_KEY, &self.engine, MAX_NAME_BYTES)?;
        text_rule(VERSION_KEY, &self.version, MAX_NAME_BYTES)?;
        if self.settings.len() > MAX_SETTINGS {
            return Err(format!(
                "{} settings, above the limit of {MAX_SETTINGS}",
                self.settings.len()
            ));
        }
        for (name, value) in &self.settings {
            if name.is_empty() {
                return Err(format!(
                    "a setting has an empty name (key `{SETTING_PREFIX}`)"
                ));
            }
            let key = format!("{SETTING_PREFIX}{name}");
            text_rule(&key, name, MAX_SETTING_NAME_BYTES)?;
            text_rule(&key, value, MAX_SETTING_VALUE_BYTES)?;
        }
        Ok(())
    }

    /// The record's entries (`version` left out when empty).
    pub fn to_metadata(&self) -> BTreeMap<String, String> {
        let mut out = BTreeMap::from([(ENGINE_KEY.to_string(), self.engine.clone())]);
        if !self.version.is_empty() {
            out.insert(VERSION_KEY.to_string(), self.version.clone());
        }
        for (name, value) in &self.settings {
            out.insert(format!("{SETTING_PREFIX}{name}"), value.clone());
        }
        out
    }

    /// The source a record's entries give, validated; the problem in words.
    pub fn from_metadata(entries: &BTreeMap<String, String>) -> Result<Self, String> {
        let mut source = ExpectedSource::default();
        let mut engine = None;
        for (key, value) in entries {
            if key == ENGINE_KEY {
                engine = Some(value.clone());
            } else if key == VERSION_KEY {
                source.version = value.clone();
            } else if let Some(name) = key.strip_prefix(SETTING_PREFIX) {
                source.settings.insert(name.to_string(), value.clone());
            } else {
                return Err(format!(
                    "unknown key `{}` (the keys are `{ENGINE_KEY}`, `{VERSION_KEY}` and \
                     `{SETTING_PREFIX}<name>`)",
                    key.escape_debug()
                ));
            }
        }
        source.engine = engine.ok_or_else(|| format!("no `{ENGINE_KEY}` key"))?;
        source.validate()?;
        Ok(source)
    }
}

fn text_rule(key: &str, value: &str, limit: usize) -> Result<(), String> {
    if value.len() > limit {
        return Err(format!(
            "`{}` is {} bytes, above the limit of {limit}",
            key.escape_debug(),
            value.len()
        ));
    }
    if value.chars().any(char::is_control) {
        return Err(format!(
            "`{}` holds a control character: {:?}",
            key.escape_debug(),
            value
        ));
    }
    Ok(())
}

/// `rapier3d-f64 0.36.1 (fix_internal_edges = false)`: the engine, its
/// version when known and the settings in name order.
impl fmt::Display for ExpectedSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.engine)?;
        if !self.version.is_empty() {
            write!(f, " {}", self.version)?;
        }
        if !self.settings.is_empty() {
            let pairs: Vec<String> = self
                .settings
                .iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect();
            write!(f, " ({})", pairs.join(", "))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_text() {
        let s = ExpectedSource::new("rapier3d-f64", "0.36.1").setting("fix_internal_edges", false);
        assert_eq!(
            s.to_string(),
            "rapier3d-f64 0.36.1 (fix_internal_edges = false)"
        );
        assert_eq!(ExpectedSource::from_metadata(&s.to_metadata()), Ok(s));
        let bare = ExpectedSource::new("my-engine", "");
        assert_eq!(bare.to_string(), "my-engine");
        assert_eq!(bare.to_metadata().len(), 1);
        assert_eq!(ExpectedSource::from_metadata(&bare.to_metadata()), Ok(bare));
    }

    #[test]
    fn malformed_records_are_refused() {
        let entries = |pairs: &[(&str, &str)]| -> BTreeMap<String, String> {
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        };
        let problem = |pairs: &[(&str, &str)]| {
            ExpectedSource::from_metadata(&entries(pairs)).expect_err("refused")
        };
        assert!(problem(&[("version", "1")]).contains("no `engine` key"));
        assert!(problem(&[("engine", "")]).contains("`engine` is empty"));
        assert!(problem(&[("engine", "e"), ("engin", "x")]).contains("unknown key `engin`"));
        assert!(problem(&[("engine", "e"), ("setting.", "x")]).contains("empty name"));
        assert!(problem(&[("engine", "a\nb")]).contains("control character"));
        let long = "x".repeat(MAX_NAME_BYTES + 1);
        assert!(problem(&[("engine", &long)]).contains("above the limit of 128"));
        let many: BTreeMap<String, String> = (0..=MAX_SETTINGS)
            .map(|i| (format!("setting.s{i}"), "1".to_string()))
            .chain([("engine".to_string(), "e".to_string())])
            .collect();
        assert!(
            ExpectedSource::from_metadata(&many)
                .expect_err("refused")
                .contains("65 settings")
        );
    }
}
