//! What a new user trips on in the first hour (issue 23): a filter that
//! selects nothing, two traces of different scenes, an input that is not a
//! trace, and the words of the reports. Every run is of the real binary,
//! in a temporary directory, so a test also sees what it leaves behind.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use libtest_mimic::Trial;

use crate::trial;
use crate::{ensure, os};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(filter_selecting_nothing_is_an_error_naming_the_trace_contents),
        trial!(filter_selecting_part_says_how_much),
        trial!(non_trace_input_leaves_no_output),
        trial!(empty_file_is_not_a_truncated_trace),
        trial!(truncated_trace_still_writes_what_was_read),
        trial!(info_of_a_non_trace_prints_nothing_on_stdout),
        trial!(info_of_a_cut_chunked_trace_does_not_say_not_chunked),
        trial!(diff_of_different_scenes_is_refused),
        trial!(replay_summary_reads_right),
        trial!(sweep_lists_the_closest_tests_only),
    ]
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn golf() -> PathBuf {
    root().join("traces/record_mini_golf.mcap")
}

/// Runs the binary in `dir`: exit code, stdout, stderr.
fn run_in(dir: &Path, args: &[&OsStr]) -> anyhow::Result<(i32, String, String)> {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| anyhow::anyhow!("running sweeptrace: {e}"))?;
    Ok((
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

fn entries(dir: &Path) -> anyhow::Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    Ok(names)
}

/// The balls and frames of the mini-golf sample, as `info` reads them
/// (`sweeps: N (4 balls: 0, 1, 2, 3)`, `frames: A to B`).
fn golf_contents() -> anyhow::Result<(u32, u32, u64, u64)> {
    let (code, out, err) = crate::support::run_bin(os!["info", golf().as_os_str()])?;
    ensure!(code == 0, "info: {err}");
    let line = |key: &str| {
        out.lines()
            .find_map(|l| l.strip_prefix(key))
            .map(str::trim)
            .with_context(|| format!("no `{key}` in {out}"))
    };
    let balls = line("sweeps:")?;
    let list = balls
        .split_once(": ")
        .map(|(_, l)| l.trim_end_matches(')'))
        .unwrap_or("");
    let balls: Vec<u32> = list.split(", ").filter_map(|b| b.parse().ok()).collect();
    let (lo, hi) = line("frames:")?.split_once(" to ").context("frames line")?;
    Ok((
        *balls.iter().min().context("no ball")?,
        *balls.iter().max().context("no ball")?,
        lo.parse().map_err(|_| anyhow::anyhow!("frame"))?,
        hi.parse().map_err(|_| anyhow::anyhow!("frame"))?,
    ))
}

/// `--ball 99` or `--frames 5000..6000` on a trace of balls 0..=3 and
/// frames 0..=591 is an error (exit 2) naming what the trace has, in every
/// command that takes a frame or ball, and writes nothing.
fn filter_selecting_nothing_is_an_error_naming_the_trace_contents() -> anyhow::Result<()> {
    let (b_lo, b_hi, f_lo, f_hi) = golf_contents()?;
    let has = format!("balls {b_lo}..={b_hi}, frames {f_lo}..={f_hi}");
    let trace = golf();
    let t = trace.as_os_str();
    let beyond_ball = (b_hi + 90).to_string();
    let beyond_frames = format!("{}..{}", f_hi + 1000, f_hi + 2000);
    let beyond_frame = (f_hi + 1000).to_string();
    let b = beyond_ball.as_str();
    let cases: Vec<Vec<&OsStr>> = vec![
        os!["replay", t, "--ball", b].to_vec(),
        os!["replay", t, "--frames", &beyond_frames].to_vec(),
        os![
            "replay",
            t,
            "--ball",
            b,
            "--outcomes",
            "out.jsonl",
            "--foxglove",
            "f.foxglove.mcap"
        ]
        .to_vec(),
        os!["diff", t, t, "--ball", b].to_vec(),
        os!["diff", t, t, "--frames", &beyond_frames, "--json"].to_vec(),
        os!["repro", t, "--frame", &beyond_frame, "-o", "case.mcap"].to_vec(),
        os!["repro", t, "--frame", "1", "--ball", b, "-o", "case.mcap"].to_vec(),
        os!["sweep", "--trace", t, "--frame", &beyond_frame].to_vec(),
    ];
    for args in cases {
        let dir = tempfile::tempdir()?;
        let (code, out, err) = run_in(dir.path(), &args)?;
        ensure!(code == 2, "{args:?}: exit {code}\n{out}{err}");
        ensure!(err.contains(&has), "{args:?}: does not say `{has}`: {err}");
        ensure!(!err.contains("wrote"), "{args:?}: says it wrote: {err}");
        let left = entries(dir.path())?;
        ensure!(left.is_empty(), "{args:?}: left {left:?}");
    }
    Ok(())
}

/// A filter that keeps part of the trace says how much it kept.
fn filter_selecting_part_says_how_much() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = golf();
    let (code, _, err) = run_in(
        dir.path(),
        os![
            "replay",
            trace.as_os_str(),
            "--frames",
            "100..120",
            "--outcomes",
            "out.jsonl"
        ],
    )?;
    ensure!(code == 0, "exit {code}: {err}");
    let kept = std::fs::read_to_string(dir.path().join("out.jsonl"))?
        .lines()
        .count();
    let (code, all, _) = run_in(
        dir.path(),
        os!["replay", trace.as_os_str(), "--outcomes", "-"],
    )?;
    ensure!(code == 0, "exit {code}");
    let total = all.lines().count();
    let want = format!("the filter (frames 100..120) kept {kept} of {total} sweeps");
    ensure!(kept > 0 && kept < total, "kept {kept} of {total}");
    ensure!(err.contains(&want), "no `{want}` in: {err}");
    let (code, _, err) = run_in(
        dir.path(),
        os![
            "diff",
            trace.as_os_str(),
            trace.as_os_str(),
            "--frames",
            "100..120"
        ],
    )?;
    ensure!(code == 0 && err.contains(&want), "diff: exit {code}: {err}");
    Ok(())
}

/// `replay README.md` (not a trace) exits 2 and leaves no `.rrd` (nor any
/// other output, nor a temporary file), and says it wrote nothing; so do
/// the other commands that write files.
fn non_trace_input_leaves_no_output() -> anyhow::Result<()> {
    let readme = root().join("README.md");
    let r = readme.as_os_str();
    let cases: Vec<Vec<&OsStr>> = vec![
        os!["replay", r].to_vec(),
        os![
            "replay",
            r,
            "--rrd",
            "x.rrd",
            "--foxglove",
            "x.foxglove.mcap",
            "--outcomes",
            "x.jsonl"
        ]
        .to_vec(),
        os!["bless", r, "-o", "blessed.mcap"].to_vec(),
        os!["repro", r, "--frame", "0", "-o", "case.mcap"].to_vec(),
        os!["check", r, "--rrd-on-failure", "failures"].to_vec(),
        os!["record", "--mesh", r, "-o", "r.mcap"].to_vec(),
    ];
    for args in cases {
        let dir = tempfile::tempdir()?;
        let (code, out, err) = run_in(dir.path(), &args)?;
        ensure!(code == 2, "{args:?}: exit {code}\n{out}{err}");
        ensure!(!err.contains("wrote"), "{args:?}: says it wrote: {err}");
        let left = entries(dir.path())?;
        ensure!(left.is_empty(), "{args:?}: left {left:?}");
    }
    Ok(())
}

/// A 0-byte file is not a truncated trace: exit 2, `empty file`, in every
/// command that reads traces.
fn empty_file_is_not_a_truncated_trace() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    std::fs::write(dir.path().join("empty.mcap"), b"")?;
    for args in [
        os!["info", "empty.mcap"].to_vec(),
        os!["replay", "empty.mcap", "--outcomes", "-"].to_vec(),
        os!["check", "empty.mcap"].to_vec(),
    ] {
        let (code, out, err) = run_in(dir.path(), &args)?;
        ensure!(code == 2, "{args:?}: exit {code}: {out}{err}");
        ensure!(
            format!("{out}{err}").contains("empty file") && !err.contains("truncated"),
            "{args:?}: {out}{err}"
        );
    }
    ensure!(entries(dir.path())? == ["empty.mcap"], "left files");
    Ok(())
}

/// A trace cut off after some complete chunks: the documented exception,
/// exit 3, and the outputs hold what was read.
fn truncated_trace_still_writes_what_was_read() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let bytes = std::fs::read(golf())?;
    std::fs::write(dir.path().join("cut.mcap"), &bytes[..bytes.len() * 2 / 3])?;
    let (code, _, err) = run_in(
        dir.path(),
        os!["replay", "cut.mcap", "--outcomes", "cut.jsonl"],
    )?;
    ensure!(code == 3, "exit {code}: {err}");
    let lines = std::fs::read_to_string(dir.path().join("cut.jsonl"))?
        .lines()
        .count();
    ensure!(
        lines > 0 && err.contains("wrote the outcomes"),
        "{lines} lines: {err}"
    );
    Ok(())
}

/// `info` of a directory, of a file that is not MCAP, of an empty file:
/// the error only, nothing on stdout.
fn info_of_a_non_trace_prints_nothing_on_stdout() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    std::fs::write(dir.path().join("empty.mcap"), b"")?;
    let traces = root().join("traces");
    let readme = root().join("README.md");
    for input in [
        traces.as_os_str(),
        readme.as_os_str(),
        OsStr::new("empty.mcap"),
    ] {
        for json in [false, true] {
            let mut args = vec![OsStr::new("info"), input];
            if json {
                args.push(OsStr::new("--json"));
            }
            let (code, out, err) = run_in(dir.path(), &args)?;
            ensure!(code == 2, "{args:?}: exit {code}");
            ensure!(out.is_empty(), "{args:?}: stdout `{out}`");
            ensure!(err.starts_with("error: "), "{args:?}: stderr `{err}`");
        }
    }
    Ok(())
}

/// A chunked trace cut off inside its first chunk: whether it is chunked is
/// not known, so it is not said to be `not chunked`; the file's size is
/// its size, not the bytes read.
fn info_of_a_cut_chunked_trace_does_not_say_not_chunked() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let bytes = std::fs::read(golf())?;
    let cut = &bytes[..bytes.len() / 8];
    std::fs::write(dir.path().join("cut.mcap"), cut)?;
    let (code, out, err) = run_in(dir.path(), os!["info", "cut.mcap"])?;
    ensure!(code == 3, "exit {code}: {out}{err}");
    let file = out
        .lines()
        .find(|l| l.starts_with("file:"))
        .with_context(|| format!("no file line: {out}"))?;
    ensure!(!file.contains("not chunked"), "{file}");
    ensure!(file.contains(&format!("{} bytes", cut.len())), "{file}");
    let (_, whole, _) = crate::support::run_bin(os!["info", golf().as_os_str()])?;
    ensure!(
        whole.contains(&format!("file:        {} bytes, ", bytes.len())),
        "the whole sample: {whole}"
    );
    Ok(())
}

/// `diff` of two traces of different scenes says how they differ and
/// refuses (exit 2) unless --allow-different-scenes; an override of the
/// margin or facing rule is not a difference of scenes.
fn diff_of_different_scenes_is_refused() -> anyhow::Result<()> {
    let golf = golf();
    let bowl = root().join("traces/record_bowl_margin.mcap");
    let box_strict = root().join("traces/record_box_strict.mcap");
    let (code, out, err) =
        crate::support::run_bin(os!["diff", golf.as_os_str(), bowl.as_os_str()])?;
    ensure!(code == 2, "exit {code}: {out}{err}");
    ensure!(out.is_empty(), "a report was printed: {out}");
    for want in [
        "scene 0",
        "vertices and",
        "triangles in A",
        "margin 0 in A, 0.02 in B",
        "--allow-different-scenes",
    ] {
        ensure!(err.contains(want), "no `{want}` in: {err}");
    }
    let (code, out, err) =
        crate::support::run_bin(os!["diff", golf.as_os_str(), box_strict.as_os_str()])?;
    ensure!(
        code == 2 && err.contains("facing non_strict in A, strict in B"),
        "{code}: {out}{err}"
    );
    let (code, out, err) = crate::support::run_bin(os![
        "diff",
        golf.as_os_str(),
        bowl.as_os_str(),
        "--allow-different-scenes"
    ])?;
    ensure!(code == 1, "exit {code}: {err}");
    ensure!(
        out.contains("the scenes differ:") && err.contains("warning"),
        "{out}{err}"
    );
    let (code, _, err) = crate::support::run_bin(os![
        "diff",
        box_strict.as_os_str(),
        box_strict.as_os_str(),
        "--facing-b",
        "non_strict",
        "--margin-a",
        "0.01"
    ])?;
    ensure!(
        code == 0 || code == 1,
        "an override refused: exit {code}: {err}"
    );
    Ok(())
}

/// The replay summary: singular where one, the total time as well as the
/// time in the core.
fn replay_summary_reads_right() -> anyhow::Result<()> {
    let trace = golf();
    let (code, _, err) = crate::support::run_bin(os![
        "replay",
        trace.as_os_str(),
        "--frames",
        "120",
        "--ball",
        "0",
        "--outcomes",
        "-"
    ])?;
    ensure!(code == 0, "exit {code}: {err}");
    ensure!(
        err.contains("1 sweep replayed") && err.contains("over 1 scene:"),
        "{err}"
    );
    ensure!(
        err.contains("1 collision (") || err.contains("0 collisions ("),
        "{err}"
    );
    ensure!(!err.contains("(s)"), "{err}");
    ensure!(
        err.contains(" s in all, ") && err.contains(" s of it in the core"),
        "{err}"
    );
    Ok(())
}

/// `sweep` shows the few tests that came closest, ranked, and the count
/// of the rest; a back-facing face the ball never comes near is not among
/// them; --all shows every test.
fn sweep_lists_the_closest_tests_only() -> anyhow::Result<()> {
    let inside_box = os![
        "sweep",
        "--scene",
        "box",
        "--radius",
        "0.1",
        "--from",
        "0,0,0.5",
        "--to",
        "0.3,0.2,-0.9"
    ];
    let (code, out, err) = crate::support::run_bin(inside_box)?;
    ensure!(code == 0, "exit {code}: {err}");
    ensure!(
        !out.contains("back-facing"),
        "far back-facing faces listed:\n{out}"
    );
    let mut all = inside_box.to_vec();
    all.push(OsStr::new("--all"));
    let (_, every, _) = crate::support::run_bin(&all)?;
    ensure!(
        every.matches("back-facing").count() >= 20,
        "--all:\n{every}"
    );

    let (code, out, err) = crate::support::run_bin(os![
        "sweep",
        "--scene",
        "cube",
        "--radius",
        "0.5",
        "--from",
        "0,3,0.2",
        "--to",
        "0.9,-3,0.2"
    ])?;
    ensure!(code == 0, "exit {code}: {err}");
    let listed = crate::support::close_tests(&out);
    ensure!(!listed.is_empty() && listed.len() <= 5, "listed:\n{out}");
    ensure!(
        listed[0].ends_with("<- primary"),
        "the primary test is not first:\n{out}"
    );
    let hits = listed.iter().take_while(|l| l.contains(": hit")).count();
    ensure!(
        listed[hits..].iter().all(|l| !l.contains(": hit")),
        "hits after misses:\n{out}"
    );
    ensure!(
        out.contains("came close too, less so"),
        "no count of the rest:\n{out}"
    );
    Ok(())
}
