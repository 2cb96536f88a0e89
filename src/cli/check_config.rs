//! `check`'s settings for each trace: the `sweeptrace.toml` files found
//! beside and above it, then the command line (the library's
//! [`sweeptrace::suite::settings_for`] does the resolution). `replay`
//! and `sweep --trace` read the same files for the `[engine]` table, so
//! that their answers are the ones `check` judges by.

use std::path::{Path, PathBuf};

use sweeptrace::suite::{self, Overrides, Settings};

/// Each trace's settings, in the order of `traces`; with `no_config`, the
/// defaults and the command line only; with `config`, that file instead of
/// the ones found beside and above each trace. A configuration file that
/// cannot be read or is invalid is an error naming it (and its line).
pub fn settings(
    traces: &[PathBuf],
    command_line: &Overrides,
    no_config: bool,
    config: Option<&std::path::Path>,
) -> anyhow::Result<Vec<Settings>> {
    let file = config
        .map(|path| suite::ConfigFile::read(path, &path.display().to_string()))
        .transpose()?;
    traces
        .iter()
        .map(|trace| {
            if no_config {
                Ok(suite::resolve(&[], trace, command_line))
            } else if let Some(file) = &file {
                Ok(suite::resolve(
                    std::slice::from_ref(file),
                    trace,
                    command_line,
                ))
            } else {
                Ok(suite::settings_for(trace, command_line)?)
            }
        })
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
        suite::render_settings_json(&named)
    } else {
        suite::render_settings_text(&named)
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
    let mut all = settings(
        &[trace.to_path_buf()],
        &overrides,
        config.no_config,
        config.config.as_deref(),
    )?;
    Ok(all.pop().unwrap_or_default())
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
