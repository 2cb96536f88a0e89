//! The help of every subcommand: plain text (no rustdoc link syntax), every
//! example runs as written from the repository root, and every option with
//! a fixed set of values lists them on a typo.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use libtest_mimic::Trial;

use crate::support::run_bin;
use crate::trial;
use crate::{ensure, os};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(help_has_no_rustdoc_syntax),
        trial!(help_examples_run_as_written),
        trial!(enum_options_list_their_values_on_a_typo),
    ]
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The subcommands, from the top-level help's `Commands:` list.
fn subcommands() -> anyhow::Result<Vec<String>> {
    let (code, out, err) = run_bin(os!["--help"])?;
    ensure!(code == 0, "--help: exit {code}: {err}");
    let list: Vec<String> = out
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect();
    ensure!(list.len() >= 9, "subcommands found: {list:?}\n{out}");
    Ok(list)
}

fn help_of(sub: &str) -> anyhow::Result<String> {
    let (code, out, err) = run_bin(os![sub, "--help"])?;
    ensure!(code == 0, "{sub} --help: exit {code}: {err}");
    Ok(out)
}

/// Rustdoc's link syntax (``[`Type`]``, `[text](target)`, `crate::` paths)
/// means nothing in a terminal.
fn help_has_no_rustdoc_syntax() -> anyhow::Result<()> {
    let mut helps = vec![("(top level)".to_string(), run_bin(os!["--help"])?.1)];
    for sub in subcommands()? {
        helps.push((sub.clone(), help_of(&sub)?));
    }
    let mut found = Vec::new();
    for (sub, text) in &helps {
        for line in text.lines() {
            if line.contains("[`")
                || line.contains("`]")
                || line.contains("crate::")
                || line.contains("](")
            {
                found.push(format!("{sub}: {}", line.trim()));
            }
        }
    }
    ensure!(
        found.is_empty(),
        "rustdoc syntax in the help:\n{}",
        found.join("\n")
    );
    Ok(())
}

/// The example command lines of a help text: the indented lines starting
/// with `sweeptrace ` under `Example:` / `Examples:`.
fn examples(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.trim_start().starts_with("Example"))
        .skip(1)
        .take_while(|l| l.starts_with("  ") || l.trim().is_empty())
        .map(str::trim)
        .filter(|l| l.starts_with("sweeptrace "))
        .map(str::to_string)
        .collect()
}

/// Copies `from` (a file or a directory) to `to`.
fn copy_tree(from: &Path, to: &Path) -> anyhow::Result<()> {
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent)?;
    }
    if from.is_dir() {
        std::fs::create_dir_all(to)?;
        for entry in std::fs::read_dir(from)? {
            let entry = entry?;
            copy_tree(&entry.path(), &to.join(entry.file_name()))?;
        }
        Ok(())
    } else {
        std::fs::copy(from, to)
            .map(|_| ())
            .map_err(|e| anyhow::anyhow!("{}: {e}", from.display()))
    }
}

/// Every example of every subcommand's help, run by `sh` in order in a
/// temporary copy of the repository files they name (so their outputs go
/// there), with this build's `sweeptrace` first on PATH: each must end
/// with 0 or 1 (1: differences found, a legitimate result of `check`,
/// `diff`, `conform`), never an error, and leave the repository as it was.
fn help_examples_run_as_written() -> anyhow::Result<()> {
    let mut lines = Vec::new();
    for sub in subcommands()? {
        let found = examples(&help_of(&sub)?);
        ensure!(!found.is_empty(), "`{sub} --help` has no example");
        lines.extend(found);
    }
    let dir = tempfile::tempdir()?;
    // The repository paths the examples name (a word, or the value of
    // `--opt=` or inside quotes), copied to the same place.
    let mut copied = BTreeSet::new();
    for line in &lines {
        for word in line.split(|c: char| c.is_whitespace() || c == '\'' || c == '"' || c == '=') {
            let word = word.trim_end_matches('/');
            if word.is_empty() || word.starts_with('-') || word == "." {
                continue;
            }
            let path = root().join(word);
            if path.exists() && copied.insert(PathBuf::from(word)) {
                copy_tree(&path, &dir.path().join(word))?;
            }
        }
    }
    let before = top_level_entries(root())?;
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .parent()
        .context("the binary has no directory")?
        .to_path_buf();
    let path = std::env::join_paths(std::iter::once(bin_dir).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))?;
    let mut failures = Vec::new();
    for line in &lines {
        let out = std::process::Command::new("sh")
            .arg("-c")
            .arg(line)
            .current_dir(dir.path())
            .env("PATH", &path)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .output()
            .map_err(|e| anyhow::anyhow!("running sh: {e}"))?;
        let code = out.status.code();
        if !matches!(code, Some(0 | 1)) {
            failures.push(format!(
                "`{line}`: exit {code:?}\n{}",
                String::from_utf8_lossy(&out.stderr)
            ));
        }
    }
    let after = top_level_entries(root())?;
    ensure!(
        before == after,
        "the examples changed the repository's top level: {:?}",
        after.symmetric_difference(&before).collect::<Vec<_>>()
    );
    ensure!(
        failures.is_empty(),
        "{} of {} examples fail:\n{}",
        failures.len(),
        lines.len(),
        failures.join("\n")
    );
    Ok(())
}

fn top_level_entries(dir: &Path) -> anyhow::Result<BTreeSet<String>> {
    Ok(std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect())
}

/// A typo in an option with a fixed set of values names the valid ones.
fn enum_options_list_their_values_on_a_typo() -> anyhow::Result<()> {
    let trace = root().join("traces/record_mini_golf.mcap");
    let trace = trace.as_os_str();
    let cases: [(&[&std::ffi::OsStr], &[&str]); 7] = [
        (
            os!["check", trace, "--fields", "kind,alhpa"],
            &["kind", "triangle", "feature", "alpha", "normal", "contact"],
        ),
        (
            os!["diff", trace, trace, "--fields", "normals"],
            &["alpha", "normal", "contact"],
        ),
        (
            os!["replay", trace, "--detail", "primry"],
            &["primary", "candidates", "all"],
        ),
        (
            os!["replay", trace, "--facing", "strikt"],
            &["non_strict", "strict"],
        ),
        (
            os!["record", "--scene", "minigolf"],
            &["mini_golf", "bowl", "box", "terrain", "cube", "triangle"],
        ),
        (
            os![
                "sweep", "--scene", "cubes", "--from", "0,0,1", "--to", "0,0,-1"
            ],
            &["cube", "triangle"],
        ),
        (
            os!["check", trace, "--engine", "x", "--against", "cor"],
            &["core", "expected"],
        ),
    ];
    for (args, values) in cases {
        let (code, out, err) = run_bin(args)?;
        ensure!(code == 2, "{args:?}: exit {code}: {out}{err}");
        for v in values {
            ensure!(err.contains(v), "{args:?}: `{v}` not listed in: {err}");
        }
    }
    Ok(())
}
