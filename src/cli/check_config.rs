//! `check`'s settings for each trace: the `sweeptrace.toml` files found
//! beside and above it, then the command line (the library's
//! [`sweeptrace::suite::config::settings_for`] does the resolution). `replay`
//! and `sweep --trace` read the same files for the `[engine]` table, so
//! that their answers are the ones `check` judges by.

use std::path::{Path, PathBuf};

use sweeptrace::suite;
use sweeptrace::suite::config::{Overrides, Settings};

/// Where a run's settings come from: the `sweeptrace.toml` files found
/// beside and above each trace (each read once per run), one named file
/// instead of them (`--config`: the files found are not read at all), or
/// none (`--no-config`).
#[derive(Debug)]
pub enum SettingsFiles {
    /// The files found beside and above each trace.
    Found(suite::config::ConfigFiles),
    /// `--config FILE`, read and parsed once (its path made absolute, so
    /// that its globs meet the traces' absolute paths).
    Named(Box<suite::config::ConfigFile>),
    /// `--no-config`.
    None,
}

impl SettingsFiles {
    /// The files of a run: `no_config`, else `config`, else the ones found
    /// per trace. A named file that cannot be read or is invalid is an
    /// error naming it (and its line).
    pub fn new(no_config: bool, config: Option<&Path>) -> anyhow::Result<SettingsFiles> {
        Ok(match (no_config, config) {
            (true, _) => SettingsFiles::None,
            (false, Some(path)) => {
                let absolute = absolute(path)?;
                SettingsFiles::Named(Box::new(suite::config::ConfigFile::read(
                    &absolute,
                    &path.display().to_string(),
                )?))
            }
            (false, None) => SettingsFiles::Found(suite::config::ConfigFiles::new()),
        })
    }

    /// The settings of `trace`: the files, then `command_line`.
    pub fn settings(&mut self, trace: &Path, command_line: &Overrides) -> anyhow::Result<Settings> {
        Ok(match self {
            SettingsFiles::None => suite::config::resolve(&[], trace, command_line),
            SettingsFiles::Named(file) => suite::config::resolve(
                std::slice::from_ref(&**file),
                &absolute(trace)?,
                command_line,
            ),
            SettingsFiles::Found(files) => files.settings_for(trace, command_line)?,
        })
    }

    /// The `exclude` glob that leaves `trace` out of a search of a folder,
    /// and the file that has it: the named file's own globs with
    /// `--config`, none with `--no-config`.
    pub fn excluded_by(&mut self, trace: &Path) -> anyhow::Result<Option<(String, String)>> {
        Ok(match self {
            SettingsFiles::None => None,
            SettingsFiles::Named(file) => file
                .excludes(&absolute(trace)?)
                .map(|pattern| (file.name().to_string(), pattern.to_string())),
            SettingsFiles::Found(files) => files.excluded_by(trace)?,
        })
    }
}

/// `path` made absolute against the working directory, normalized.
fn absolute(path: &Path) -> anyhow::Result<PathBuf> {
    let absolute = std::path::absolute(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot make the path absolute: {e}", path.display()))?;
    Ok(suite::config::normalize(&absolute))
}

/// Each trace's settings, in the order of `traces`, from `files` and the
/// command line. A configuration file that cannot be read or is invalid is
/// an error naming it (and its line).
pub fn settings(
    traces: &[PathBuf],
    command_line: &Overrides,
    files: &mut SettingsFiles,
) -> anyhow::Result<Vec<Settings>> {
    traces
        .iter()
        .map(|trace| files.settings(trace, command_line))
        .collect()
}

/// `--print-config`'s output: every trace's settings with their sources.
pub fn render(traces: &[PathBuf], settings: &[Settings], json: bool) -> String {
    let named: Vec<(String, Settings)> = traces
        .iter()
        .zip(settings)
        .map(|(t, s)| (t.display().to_string(), s.clone()))
        .collect();
    if json {
        suite::config::render_settings_json(&named)
    } else {
        suite::config::render_settings_text(&named)
    }
}

/// Where a single-trace command (`replay`, `sweep --trace`) takes its
/// settings from: the `sweeptrace.toml` files beside and above the trace,
/// one named file, or none.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ConfigArgs {
    /// Read the `[engine]` table from this `sweeptrace.toml` instead of the
    /// files found beside and above the trace.
    #[arg(long, value_name = "FILE", conflicts_with = "no_config")]
    pub config: Option<PathBuf>,
    /// Ignore the `sweeptrace.toml` files: the rules, plus the conventions
    /// given on the command line.
    #[arg(long)]
    pub no_config: bool,
}

/// The settings of one trace for a command that computes the reference
/// answer (`replay`, `sweep --trace`): the files as `check` finds them (or
/// `config`'s), then `conventions` from the command line.
pub fn for_trace(
    trace: &Path,
    conventions: &sweeptrace::conventions::PartialConventions,
    config: &ConfigArgs,
) -> anyhow::Result<Settings> {
    let overrides = Overrides {
        engine: conventions.clone(),
        ..Overrides::default()
    };
    let mut files = SettingsFiles::new(config.no_config, config.config.as_deref())?;
    files.settings(trace, &overrides)
}

/// The error of a margin given instead of the scenes' that is not smaller
/// than a ball's radius in `trace`: a fault of the setting, named where it
/// was set (`sweeptrace.toml:2: engine.margin = 0.3 ...`, `--engine-margin
/// 0.3`, `--margin 0.3`), once, not the trace's nor each sweep's.
pub fn margin_fault(
    settings: &Settings,
    trace: &str,
    fault: &sweeptrace::suite::report::MarginFault,
) -> String {
    use sweeptrace::conventions::{Setting, Source};
    use sweeptrace::numbers::Shortest;
    let margin = Shortest(fault.margin);
    let set = match &settings.engine.margin {
        Some(Setting {
            source: Source::File { file, line },
            ..
        }) => format!("{file}:{line}: engine.margin = {margin}"),
        _ => format!("--engine-margin {margin}"),
    };
    format!(
        "{set} must be smaller than the radius of every ball it applies to: {trace} has a ball of radius {} (frame {}, ball {}); stopped there",
        Shortest(fault.radius),
        fault.frame,
        fault.ball
    )
}

/// The line that says which conventions the answers were computed under,
/// and where they were declared; `None` under the rules.
pub fn conventions_line(settings: &Settings) -> Option<String> {
    if !settings.engine.is_declared() {
        return None;
    }
    let conventions = settings.engine.conventions();
    Some(format!(
        "reference answers under the engine's declared conventions: {} (from {})",
        conventions.summary(),
        settings.engine.declared_sources().join(", ")
    ))
}

/// A replay error in words (always an `Err`): a declared margin that does
/// not fit a ball named where it was declared, any other naming the trace.
pub fn replay_error(
    err: sweeptrace::replay::ReplayError,
    settings: &sweeptrace::suite::config::Settings,
    source_name: &str,
) -> anyhow::Result<()> {
    use super::NameFileOnce as _;
    match sweeptrace::suite::report::MarginFault::of(&err) {
        Some(fault) => anyhow::bail!(margin_fault(settings, source_name, &fault)),
        None => Err(err).name_file_once("replaying", source_name),
    }
}
