//! The CLI built without the Rerun viewer (`cargo build
//! --no-default-features --features cli`): every command that needs no
//! recording gives the same outputs as this build's binary, the help is the
//! same, and each option that writes a Rerun recording is refused with
//! exit 2, the command that installs the viewer build, and no file written.
//!
//! This binary itself has the viewer (the tests need it), so the lean
//! binary is built by the caller and named by `SWEEPTRACE_LEAN_BIN`; `.ci/run`
//! builds it into the same target directory (only the crates whose features
//! differ are built again) and sets `SWEEPTRACE_REQUIRE_LEAN=1`, which makes
//! a missing binary a failure instead of a skip.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use libtest_mimic::{Completion, Trial};

use crate::support::run_program_in as run;
use crate::trial;
use crate::{ensure, os};

/// The path of the binary built without the viewer.
const LEAN_BIN: &str = "SWEEPTRACE_LEAN_BIN";
/// Set to `1` (CI does) to fail, instead of skip, when [`LEAN_BIN`] is not set.
const REQUIRE_LEAN: &str = "SWEEPTRACE_REQUIRE_LEAN";

/// What the lean build's `--version` says after the version number.
const LEAN_VERSION_MARK: &str = "(without the Rerun viewer)";
/// The command its errors give for the build with the viewer.
const VIEWER_BUILD: &str = "cargo install --locked --path .";

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(lean_binary_is_the_build_without_the_viewer),
        trial!(lean_help_is_the_same),
        trial!(lean_reports_are_the_same),
        trial!(lean_replay_outputs_are_the_same),
        trial!(lean_record_and_repro_write_the_same_files),
        trial!(lean_refuses_recordings_naming_the_viewer_build),
    ]
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The lean binary, or the completion of a skipped test.
fn lean_bin() -> anyhow::Result<Result<PathBuf, Completion>> {
    match std::env::var_os(LEAN_BIN) {
        Some(path) => {
            let path = PathBuf::from(path);
            ensure!(
                path.is_file(),
                "{LEAN_BIN}={}: no such file (build it with \
                 `cargo build --no-default-features --features cli` and copy \
                 target/debug/sweeptrace elsewhere first: a build with the default \
                 features replaces it)",
                path.display()
            );
            // The help's usage lines name the program as it was called.
            ensure!(
                path.file_name() == Some(OsStr::new("sweeptrace")),
                "{LEAN_BIN}={}: the copy must be named `sweeptrace`, as the help names \
                 the program as it was called",
                path.display()
            );
            Ok(Ok(path))
        }
        None if std::env::var_os(REQUIRE_LEAN).is_some_and(|v| v == "1") => anyhow::bail!(
            "{LEAN_BIN} is not set, and {REQUIRE_LEAN}=1 requires these tests \
             (the binary of `cargo build --no-default-features --features cli`)"
        ),
        None => Ok(Err(Completion::ignored_with(format!(
            "skipped: {LEAN_BIN} is not set (the binary of `cargo build \
             --no-default-features --features cli`); {REQUIRE_LEAN}=1 makes this a failure"
        )))),
    }
}

fn full_bin() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_sweeptrace"))
}

/// Runs both binaries with `args` in the repository root; fails unless the
/// exit codes and stdout are the same; returns them.
fn same_in_both(lean: &Path, args: &[&OsStr]) -> anyhow::Result<(i32, String)> {
    let (code, out, err) = run(full_bin(), root(), args)?;
    let (lean_code, lean_out, lean_err) = run(lean, root(), args)?;
    ensure!(
        (code, &out) == (lean_code, &lean_out),
        "{args:?}: the viewer build exits {code}, the lean build {lean_code}\n\
         viewer build stdout:\n{out}\nstderr:\n{err}\nlean build stdout:\n{lean_out}\nstderr:\n{lean_err}"
    );
    Ok((code, out))
}

fn lean_binary_is_the_build_without_the_viewer() -> anyhow::Result<Completion> {
    let lean = match lean_bin()? {
        Ok(p) => p,
        Err(skip) => return Ok(skip),
    };
    let (code, out, err) = run(&lean, root(), os!["--version"])?;
    ensure!(code == 0, "--version: exit {code}: {err}");
    ensure!(
        out.contains(LEAN_VERSION_MARK),
        "{LEAN_BIN} is not the build without the viewer: --version says {out:?}"
    );
    let (_, full, _) = run(full_bin(), root(), os!["--version"])?;
    ensure!(
        !full.contains(LEAN_VERSION_MARK)
            && full.trim() == out.replace(LEAN_VERSION_MARK, "").trim(),
        "the viewer build's --version {full:?} against the lean build's {out:?}"
    );
    Ok(Completion::Completed)
}

/// The same options in both builds: the viewer-only ones are refused at
/// run time, not missing from the help.
fn lean_help_is_the_same() -> anyhow::Result<Completion> {
    let lean = match lean_bin()? {
        Ok(p) => p,
        Err(skip) => return Ok(skip),
    };
    for sub in [
        "--help", "sweep", "info", "mesh", "replay", "check", "conform", "bless", "diff", "repro",
        "record",
    ] {
        let args: Vec<&OsStr> = if sub == "--help" {
            vec![OsStr::new(sub)]
        } else {
            vec![OsStr::new(sub), OsStr::new("--help")]
        };
        let (code, out) = same_in_both(&lean, &args)?;
        ensure!(code == 0 && !out.is_empty(), "{sub} --help: exit {code}");
    }
    Ok(Completion::Completed)
}

/// The commands that only read and report: `check` of every sample trace
/// (text, then JSON without its times), `info`, `mesh`, `sweep`, `diff`.
fn lean_reports_are_the_same() -> anyhow::Result<Completion> {
    let lean = match lean_bin()? {
        Ok(p) => p,
        Err(skip) => return Ok(skip),
    };
    let golf = "traces/record_mini_golf.mcap";
    let (code, out) = same_in_both(&lean, os!["check", "traces/"])?;
    ensure!(code == 0, "check traces/: exit {code}\n{out}");
    ensure!(
        out.contains("5 traces: 5 ok"),
        "check traces/ should pass every sample trace:\n{out}"
    );
    let (code, _) = same_in_both(
        &lean,
        os!["check", "tests/fixtures/wrong_engine_config.mcap"],
    )?;
    ensure!(code == 1, "check of a failing trace: exit {code}, not 1");
    let reports: [&[&OsStr]; 5] = [
        os!["info", golf],
        os!["mesh", golf],
        os![
            "sweep", "--scene", "cube", "--from", "0,0,3", "--to", "0,0,0", "--radius", "0.5"
        ],
        os!["diff", golf, golf],
        os![
            "check",
            "traces/record_terrain.mcap",
            "--json",
            "--print-config"
        ],
    ];
    for args in reports {
        same_in_both(&lean, args)?;
    }
    Ok(Completion::Completed)
}

/// `replay --outcomes`, `--foxglove` and `--json` write the same bytes
/// (the JSON summary without its times).
fn lean_replay_outputs_are_the_same() -> anyhow::Result<Completion> {
    let lean = match lean_bin()? {
        Ok(p) => p,
        Err(skip) => return Ok(skip),
    };
    let trace = root().join("traces/record_cube_corner_margin.mcap");
    let mut written = Vec::new();
    let mut summaries = Vec::new();
    for program in [full_bin(), lean.as_path()] {
        let dir = tempfile::tempdir()?;
        let (code, out, err) = run(
            program,
            dir.path(),
            &[
                OsStr::new("replay"),
                trace.as_os_str(),
                OsStr::new("--outcomes"),
                OsStr::new("run.jsonl"),
                OsStr::new("--foxglove"),
                OsStr::new("run.fg.mcap"),
                OsStr::new("--json"),
            ],
        )?;
        ensure!(
            code == 0,
            "{}: replay: exit {code}: {err}",
            program.display()
        );
        let mut json: serde_json::Value = serde_json::from_str(&out)?;
        json.as_object_mut()
            .map(|o| o.remove("seconds"))
            .ok_or_else(|| anyhow::anyhow!("the --json summary is not an object: {out}"))?;
        summaries.push(json);
        written.push((
            std::fs::read(dir.path().join("run.jsonl"))?,
            std::fs::read(dir.path().join("run.fg.mcap"))?,
        ));
    }
    ensure!(
        summaries[0] == summaries[1],
        "the --json summaries differ:\n{:#}\n{:#}",
        summaries[0],
        summaries[1]
    );
    ensure!(
        !written[0].0.is_empty() && written[0].0 == written[1].0,
        "the outcome files differ"
    );
    ensure!(written[0].1 == written[1].1, "the Foxglove files differ");
    Ok(Completion::Completed)
}

/// `record` and `repro` write the same trace bytes in both builds.
fn lean_record_and_repro_write_the_same_files() -> anyhow::Result<Completion> {
    let lean = match lean_bin()? {
        Ok(p) => p,
        Err(skip) => return Ok(skip),
    };
    let golf = root().join("traces/record_mini_golf.mcap");
    let mut files = Vec::new();
    for program in [full_bin(), lean.as_path()] {
        let dir = tempfile::tempdir()?;
        let (code, _, err) = run(
            program,
            dir.path(),
            os!["record", "--scene", "box", "-o", "box.mcap"],
        )?;
        ensure!(
            code == 0,
            "{}: record: exit {code}: {err}",
            program.display()
        );
        let (code, _, err) = run(
            program,
            dir.path(),
            &[
                OsStr::new("repro"),
                golf.as_os_str(),
                OsStr::new("--frame"),
                OsStr::new("10"),
                OsStr::new("--ball"),
                OsStr::new("0"),
                OsStr::new("-o"),
                OsStr::new("one.mcap"),
            ],
        )?;
        ensure!(
            code == 0,
            "{}: repro: exit {code}: {err}",
            program.display()
        );
        files.push((
            std::fs::read(dir.path().join("box.mcap"))?,
            std::fs::read(dir.path().join("one.mcap"))?,
        ));
    }
    ensure!(files[0].0 == files[1].0, "record wrote different traces");
    ensure!(files[0].1 == files[1].1, "repro wrote different traces");
    Ok(Completion::Completed)
}

/// Every way of asking for a Rerun recording: exit 2, the option named,
/// the command that installs the viewer build, what works without it, and
/// nothing written.
fn lean_refuses_recordings_naming_the_viewer_build() -> anyhow::Result<Completion> {
    let lean = match lean_bin()? {
        Ok(p) => p,
        Err(skip) => return Ok(skip),
    };
    let golf = root().join("traces/record_mini_golf.mcap");
    let failing = root().join("tests/fixtures/wrong_engine_config.mcap");
    let golf = golf.as_os_str();
    // (option, subcommand, the options after the trace, what the error offers instead)
    let cases: [(&str, &str, &[&OsStr], &str); 6] = [
        ("--rrd", "replay", os!["--rrd", "golf.rrd"], "--outcomes"),
        (
            "--rrd",
            "replay",
            os!["--rrd", "golf.rrd", "--outcomes", "out.jsonl"],
            "--foxglove",
        ),
        ("--spawn", "replay", os!["--spawn"], "--outcomes"),
        ("--connect", "replay", os!["--connect"], "--outcomes"),
        (
            "a replay without --outcomes or --foxglove",
            "replay",
            os![],
            "--foxglove",
        ),
        (
            "--rrd-on-failure",
            "check",
            os!["--rrd-on-failure", "failures"],
            "--json",
        ),
    ];
    for (option, sub, options, instead) in cases {
        let trace = if sub == "check" {
            failing.as_os_str()
        } else {
            golf
        };
        let args = [&[OsStr::new(sub), trace][..], options].concat();
        let dir = tempfile::tempdir()?;
        let (code, out, err) = run(&lean, dir.path(), &args)?;
        ensure!(
            code == 2,
            "{args:?}: exit {code}, not 2\nstdout:\n{out}\nstderr:\n{err}"
        );
        ensure!(
            err.starts_with(&format!("error: {option}"))
                && err.contains("built without")
                && err.contains(VIEWER_BUILD)
                && err.contains(instead),
            "{args:?}: the error should name {option}, say the build has no viewer, \
             give `{VIEWER_BUILD}` and name {instead}:\n{err}"
        );
        ensure!(out.is_empty(), "{args:?}: stdout should be empty:\n{out}");
        let left: Vec<_> = std::fs::read_dir(dir.path())?
            .filter_map(Result::ok)
            .map(|e| e.file_name())
            .collect();
        ensure!(left.is_empty(), "{args:?}: left files behind: {left:?}");
        // docs/COMMANDS.md shows the first of these messages as it is
        // (tests/docs.rs runs the default build, which has the viewer).
        if option == "--rrd" && options.len() == 2 {
            let doc = std::fs::read_to_string(root().join("docs/COMMANDS.md"))?;
            ensure!(
                doc.contains(&format!("```text\n{err}```")),
                "docs/COMMANDS.md should show the lean build's error for \
                 `replay TRACE --rrd golf.rrd` as it is:\n{err}"
            );
        }
    }
    Ok(Completion::Completed)
}
