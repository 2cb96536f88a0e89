//! `check`'s settings for each trace: the `sweeptrace.toml` files found
//! beside and above it, then the command line (the library's
//! [`sweeptrace::regress::settings_for`] does the resolution).

use std::path::PathBuf;

use sweeptrace::regress::{self, Overrides, Settings};

/// Each trace's settings, in the order of `traces`; with `no_config`, the
/// defaults and the command line only. A configuration file that cannot be
/// read or is invalid is an error naming it (and its line).
pub fn settings(
    traces: &[PathBuf],
    command_line: &Overrides,
    no_config: bool,
) -> anyhow::Result<Vec<Settings>> {
    traces
        .iter()
        .map(|trace| {
            if no_config {
                Ok(regress::resolve(&[], trace, command_line))
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
