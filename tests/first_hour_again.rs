//! What still cost a new user time in the first hour (issue 34): a suite
//! folder holding the tool's own Foxglove output, files a suite wants left
//! out, `check` without `--frames`/`--ball`, `replay` without `--json`, and
//! the small items of that issue. Every run is of the real binary, in a
//! temporary directory, so a test also sees what it leaves behind.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use libtest_mimic::Trial;

use crate::support::run_bin_in;
use crate::trial;
use crate::{ensure, os};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(check_leaves_out_the_foxglove_files_replay_wrote),
        trial!(check_leaves_out_what_exclude_globs_match),
        trial!(bad_exclude_glob_is_an_error_with_file_and_line),
        trial!(check_takes_frames_and_ball_like_replay),
        trial!(replay_json_prints_the_summary_as_one_object),
    ]
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The smallest sample trace (661 sweeps, expectations from the core).
fn cube() -> PathBuf {
    root().join("traces/record_cube_corner_margin.mcap")
}

fn golf() -> PathBuf {
    root().join("traces/record_mini_golf.mcap")
}

/// A throwaway repository (`.git` at its root: the settings files above it
/// are not read) with the cube sample at `suite/cube.mcap`.
fn suite() -> anyhow::Result<(tempfile::TempDir, PathBuf)> {
    let dir = tempfile::tempdir()?;
    let repo = dir.path().join("repo");
    std::fs::create_dir_all(repo.join(".git"))?;
    std::fs::create_dir_all(repo.join("suite"))?;
    std::fs::copy(cube(), repo.join("suite/cube.mcap"))?;
    Ok((dir, repo))
}

fn run(dir: &Path, args: &[&OsStr]) -> anyhow::Result<(i32, String, String)> {
    run_bin_in(dir, args)
}

/// `replay X --foxglove suite/X.fg.mcap` then `check suite/`: the Foxglove
/// file is left out, said once on stderr (naming the file and the trace it
/// came from), and the suite passes; `--json` keeps stdout JSON. Named
/// alone, the Foxglove file is not a trace to check (exit 2, the same note).
fn check_leaves_out_the_foxglove_files_replay_wrote() -> anyhow::Result<()> {
    let (_dir, repo) = suite()?;
    let (code, out, err) = run(
        &repo,
        os![
            "replay",
            "suite/cube.mcap",
            "--foxglove",
            "suite/grid.fg.mcap"
        ],
    )?;
    ensure!(code == 0, "replay: exit {code}\n{out}{err}");
    // A Foxglove file under a name a trace could have is told by content.
    std::fs::copy(
        repo.join("suite/grid.fg.mcap"),
        repo.join("suite/other.mcap"),
    )?;
    for json in [false, true] {
        let mut args = os!["check", "suite"].to_vec();
        if json {
            args.push(OsStr::new("--json"));
        }
        let (code, out, err) = run(&repo, &args)?;
        ensure!(code == 0, "check (json {json}): exit {code}\n{out}{err}");
        ensure!(
            !out.contains("NO EXPECTATIONS") && !out.contains("fg.mcap"),
            "check (json {json}) reports the Foxglove file:\n{out}"
        );
        let notes: Vec<&str> = err.lines().filter(|l| l.contains("Foxglove")).collect();
        ensure!(
            notes.len() == 1
                && notes[0].contains("left out 2 Foxglove files")
                && notes[0].contains("suite/grid.fg.mcap (from cube.mcap)")
                && notes[0].contains("suite/other.mcap"),
            "check (json {json}) does not say once what it left out:\n{err}"
        );
        if json {
            let value: serde_json::Value =
                serde_json::from_str(&out).context("check --json: stdout is not JSON")?;
            ensure!(
                value.to_string().contains("cube.mcap"),
                "check --json: {value}"
            );
        } else {
            ensure!(out.starts_with("ok suite/cube.mcap"), "check: {out}");
        }
    }
    let (code, out, err) = run(&repo, os!["check", "suite/grid.fg.mcap"])?;
    ensure!(
        code == 2,
        "check of the Foxglove file alone: exit {code}\n{out}{err}"
    );
    ensure!(
        err.contains(
            "left out 1 Foxglove file that `sweeptrace replay --foxglove` wrote (not a trace)"
        ) && err.contains("no trace found"),
        "check of the Foxglove file alone: {err}"
    );
    Ok(())
}

/// `exclude` globs in `sweeptrace.toml`, relative to its folder, leave the
/// files a search of a folder finds out of the check (said once, with the
/// glob and the file); a file named on the command line is checked all
/// the same, and `--no-config` ignores them.
fn check_leaves_out_what_exclude_globs_match() -> anyhow::Result<()> {
    let (_dir, repo) = suite()?;
    std::fs::create_dir_all(repo.join("suite/scratch"))?;
    // Not a trace: checked, it is an error.
    std::fs::write(repo.join("suite/scratch/notes.mcap"), "not a trace\n")?;
    let (code, out, err) = run(&repo, os!["check", "suite"])?;
    ensure!(code == 2, "without exclude: exit {code}\n{out}{err}");
    std::fs::write(
        repo.join("suite/sweeptrace.toml"),
        "exclude = [\"scratch/**\", \"*.tmp.mcap\"]\n",
    )?;
    let (code, out, err) = run(&repo, os!["check", "suite"])?;
    ensure!(code == 0, "with exclude: exit {code}\n{out}{err}");
    ensure!(
        !out.contains("notes.mcap"),
        "checked the excluded file:\n{out}"
    );
    let notes: Vec<&str> = err.lines().filter(|l| l.contains("exclude")).collect();
    ensure!(
        notes.len() == 1
            && notes[0].contains("left out 1 file")
            && notes[0]
                .contains("suite/scratch/notes.mcap (`scratch/**` in suite/sweeptrace.toml)"),
        "does not say once what it left out and why:\n{err}"
    );
    // A glob of a file in a parent folder applies below it too.
    std::fs::remove_file(repo.join("suite/sweeptrace.toml"))?;
    std::fs::write(
        repo.join("sweeptrace.toml"),
        "exclude = [\"suite/scratch/*.mcap\"]\n",
    )?;
    let (code, out, err) = run(&repo, os!["check", "suite"])?;
    ensure!(code == 0, "exclude in the parent: exit {code}\n{out}{err}");
    for args in [
        os!["check", "suite", "suite/scratch/notes.mcap"].to_vec(),
        os!["check", "suite", "--no-config"].to_vec(),
    ] {
        let (code, out, err) = run(&repo, &args)?;
        ensure!(
            code == 2 && out.contains("ERROR suite/scratch/notes.mcap"),
            "{args:?}: the file is not checked: exit {code}\n{out}{err}"
        );
    }
    Ok(())
}

/// An `exclude` entry that is not a glob stops `check` with the file, line
/// and column, as a bad `match` does.
fn bad_exclude_glob_is_an_error_with_file_and_line() -> anyhow::Result<()> {
    let (_dir, repo) = suite()?;
    std::fs::write(
        repo.join("suite/sweeptrace.toml"),
        "strict = false\nexclude = [\"ok/*.mcap\", \"a[b\"]\n",
    )?;
    let (code, out, err) = run(&repo, os!["check", "suite"])?;
    ensure!(
        code == 2
            && err.contains("suite/sweeptrace.toml:2:25: `exclude`: `a[b` is not a glob")
            && out.is_empty(),
        "exit {code}\n{out}{err}"
    );
    Ok(())
}

/// The count of sweeps in `check`'s line (`ok T: 120 sweeps, ...`).
fn checked_sweeps(out: &str) -> anyhow::Result<u64> {
    let (_, rest) = out.split_once(": ").context("no `: ` in the check line")?;
    rest.split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .with_context(|| format!("no sweep count in {out}"))
}

/// `check --frames A..B --ball N` compares exactly the sweeps `replay`
/// replays with the same filter; a filter that keeps nothing is an error
/// (exit 2) naming the trace's balls and frames, as in `replay`.
fn check_takes_frames_and_ball_like_replay() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = golf();
    let t = trace.as_os_str();
    let (code, out, err) = run(dir.path(), os!["check", t])?;
    ensure!(code == 0, "check: exit {code}\n{out}{err}");
    let all = checked_sweeps(&out)?;
    let (code, out, err) = run(
        dir.path(),
        os!["check", t, "--frames", "100..200", "--ball", "1"],
    )?;
    ensure!(code == 0, "check with a filter: exit {code}\n{out}{err}");
    let some = checked_sweeps(&out)?;
    let (code, json, err) = run(
        dir.path(),
        os![
            "replay",
            t,
            "--frames",
            "100..200",
            "--ball",
            "1",
            "--outcomes",
            "o.jsonl",
            "--json"
        ],
    )?;
    ensure!(code == 0, "replay: exit {code}\n{json}{err}");
    let value: serde_json::Value = serde_json::from_str(&json)?;
    ensure!(
        value["sweeps"].as_u64() == Some(some) && some > 0 && some < all,
        "check compared {some} of {all} sweeps, replay replayed {}",
        value["sweeps"]
    );
    ensure!(
        out.contains(&format!("{some} compared")),
        "not every selected sweep compared: {out}"
    );
    let (code, out, err) = run(dir.path(), os!["check", t, "--ball", "99"])?;
    ensure!(
        code == 2 && out.contains("selects none of the trace's") && out.contains("balls 0..="),
        "--ball 99: exit {code}\n{out}{err}"
    );
    let (code, _, err) = run(dir.path(), os!["check", t, "--frames", "x"])?;
    ensure!(code == 2 && err.contains("--frames"), "--frames x: {err}");
    Ok(())
}

/// `replay --json` prints one JSON object on stdout: the counts the text
/// summary gives (sweeps equal to the outcome lines, outcomes by kind
/// summing to them), the files written, `incomplete` null; the text
/// summary is not printed. With `--outcomes -` it is refused (both want
/// stdout) and nothing is written.
fn replay_json_prints_the_summary_as_one_object() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = cube();
    let t = trace.as_os_str();
    let (code, out, err) = run(
        dir.path(),
        os!["replay", t, "--outcomes", "o.jsonl", "--json"],
    )?;
    ensure!(code == 0, "exit {code}\n{out}{err}");
    let v: serde_json::Value =
        serde_json::from_str(&out).with_context(|| format!("stdout is not JSON: {out}"))?;
    let lines = std::fs::read_to_string(dir.path().join("o.jsonl"))?
        .lines()
        .count() as u64;
    ensure!(
        v["sweeps"].as_u64() == Some(lines),
        "sweeps {} vs {lines} lines",
        v["sweeps"]
    );
    let by_kind: u64 = v["outcomes"]
        .as_object()
        .context("outcomes")?
        .values()
        .filter_map(serde_json::Value::as_u64)
        .sum();
    ensure!(
        by_kind == lines,
        "outcomes by kind sum to {by_kind}, not {lines}: {v}"
    );
    ensure!(
        v["expected"]["attached"].as_u64() == Some(lines)
            && v["incomplete"].is_null()
            && v["wrote"][0].as_str() == Some("wrote the outcomes to o.jsonl")
            && v["verdicts"].is_object()
            && v["fragile"]["count"].is_u64()
            && v["tunnels"]["count"].as_u64() == Some(0),
        "{v}"
    );
    ensure!(
        !err.contains("replayed (") && !err.contains("time:"),
        "the text summary is printed too:\n{err}"
    );
    let dir = tempfile::tempdir()?;
    let (code, out, err) = run(dir.path(), os!["replay", t, "--outcomes", "-", "--json"])?;
    ensure!(
        code == 2 && err.contains("--json and --outcomes - both write to stdout") && out.is_empty(),
        "exit {code}\n{out}{err}"
    );
    ensure!(
        std::fs::read_dir(dir.path())?.next().is_none(),
        "refused, yet wrote something"
    );
    Ok(())
}
