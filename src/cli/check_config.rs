//! `check`'s settings for each trace: the `sweeptrace.toml` files found
//! beside and above it, then the command line (the library's
//! [`sweeptrace::regress::settings_for`] does the resolution).

use std::path::PathBuf;

use sweeptrace::regress::{self, Overrides, Settings};

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
        .map(|path| regress::ConfigFile::read(path, &path.display().to_string()))
        .transpose()?;
    traces
        .iter()
        .map(|trace| {
            if no_config {
                Ok(regress::resolve(&[], trace, command_line))
            } else if let Some(file) = &file {
                Ok(regress::resolve(
                    std::slice::from_ref(file),
                    trace,
                    command_line,
                ))
            } else {
                Ok(regress::settings_for(trace, command_line)?)
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
        regress::render_settings_json(&named)
    } else {
        regress::render_settings_text(&named)
    }
}
