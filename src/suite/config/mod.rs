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
//! keeps where it came from ([`Source`](crate::conventions::Source)), for `check --print-config`.
//!
//! ```toml
//! # Settings of every trace under this folder.
//! fields = ["kind", "triangle", "feature", "alpha", "contact"]
//! strict = false
//! allow_tunnels = false
//! # Files a search of this folder leaves out (globs relative to it).
//! exclude = ["scratch/**", "*.partial.mcap"]
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

mod file;
mod glob;
mod settings;
#[cfg(test)]
mod tests;

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

pub use file::{ConfigError, ConfigFile};
use settings::Layer;
pub use settings::{Overrides, Settings, render_settings_json, render_settings_text};

/// The name of a suite configuration file.
pub const CONFIG_FILE_NAME: &str = "sweeptrace.toml";

/// The settings of `trace`: the defaults, then `files` (nearest first, as
/// [`find_config_files`] gives them; the farthest applies first), then the
/// command line. Pure. `trace` and the files' paths must be in the same
/// frame (both absolute, or both relative to one folder) for the
/// `[[traces]]` globs to match; [`ConfigFiles`] gives absolute paths.
pub fn resolve(files: &[ConfigFile], trace: &Path, command_line: &Overrides) -> Settings {
    resolve_in(files.iter(), trace, command_line)
}

/// [`resolve`] over files held elsewhere (nearest first).
fn resolve_in<'a>(
    files: impl DoubleEndedIterator<Item = &'a ConfigFile>,
    trace: &Path,
    command_line: &Overrides,
) -> Settings {
    let mut settings = Settings::default();
    for file in files.rev() {
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

/// The settings of `trace` from its configuration files
/// ([`ConfigFiles::of`]) and the command line; [`ConfigFiles`] reads each
/// file once for many traces.
pub fn settings_for(trace: &Path, command_line: &Overrides) -> Result<Settings, ConfigError> {
    ConfigFiles::new().settings_for(trace, command_line)
}

/// The `exclude` glob that leaves `trace` out of a search of a folder, and
/// the configuration file that has it (named relative to the working
/// directory when under it):
/// the nearest file's globs first, then the farther ones'. Globs are
/// relative to their file's folder.
pub fn excluded_by(trace: &Path) -> Result<Option<(String, String)>, ConfigError> {
    ConfigFiles::new().excluded_by(trace)
}

/// The configuration files of a run over many traces, each found, read
/// and parsed once: the traces of one folder share their files, and a file
/// above many folders is parsed once for all of them. A file that changes
/// during the run is not read again.
#[derive(Debug, Default)]
pub struct ConfigFiles {
    /// The files of each folder holding a trace (nearest first), by the
    /// folder's absolute, normalized path.
    by_folder: HashMap<PathBuf, Vec<Arc<ConfigFile>>>,
    /// Each file parsed, by its absolute, normalized path.
    parsed: HashMap<PathBuf, Arc<ConfigFile>>,
}

impl ConfigFiles {
    /// An empty cache.
    pub fn new() -> ConfigFiles {
        ConfigFiles::default()
    }

    /// The configuration files of `trace` ([`find_config_files`]), nearest
    /// first, each named relative to the working directory when under it.
    pub fn of(&mut self, trace: &Path) -> Result<Vec<Arc<ConfigFile>>, ConfigError> {
        let absolute = absolute(trace)?;
        let folder = absolute.parent().unwrap_or(Path::new("")).to_path_buf();
        if let Some(files) = self.by_folder.get(&folder) {
            return Ok(files.clone());
        }
        let cwd = std::env::current_dir().ok().map(|d| normalize(&d));
        let mut files = Vec::new();
        for path in find_config_files(&absolute)? {
            if let Some(file) = self.parsed.get(&path) {
                files.push(file.clone());
                continue;
            }
            let shown = cwd
                .as_ref()
                .and_then(|cwd| path.strip_prefix(cwd).ok())
                .unwrap_or(&path)
                .display()
                .to_string();
            let file = Arc::new(ConfigFile::read(&path, &shown)?);
            self.parsed.insert(path, file.clone());
            files.push(file);
        }
        self.by_folder.insert(folder, files.clone());
        Ok(files)
    }

    /// How many files were read and parsed so far.
    pub fn parsed(&self) -> usize {
        self.parsed.len()
    }

    /// The settings of `trace` from its configuration files
    /// ([`ConfigFiles::of`]) and the command line.
    pub fn settings_for(
        &mut self,
        trace: &Path,
        command_line: &Overrides,
    ) -> Result<Settings, ConfigError> {
        let files = self.of(trace)?;
        Ok(resolve_in(
            files.iter().map(|f| &**f),
            &absolute(trace)?,
            command_line,
        ))
    }

    /// The `exclude` glob that leaves `trace` out of a search of a folder,
    /// and the configuration file that has it ([`excluded_by`]).
    pub fn excluded_by(&mut self, trace: &Path) -> Result<Option<(String, String)>, ConfigError> {
        let absolute = absolute(trace)?;
        Ok(self.of(&absolute)?.iter().find_map(|file| {
            file.excludes(&absolute)
                .map(|pattern| (file.name().to_string(), pattern.to_string()))
        }))
    }
}

/// `path` made absolute (against the working directory) and normalized.
fn absolute(path: &Path) -> Result<PathBuf, ConfigError> {
    std::path::absolute(path)
        .map(|p| normalize(&p))
        .map_err(|e| ConfigError::Read {
            file: path.display().to_string(),
            cause: e.to_string(),
        })
}
