//! `bless` as snapshot testing: an engine's answers pinned as a trace's
//! expectations (`--engine`), and blessing only what one means to bless
//! (`--frames`/`--ball`, `--accept`, `--review` at a terminal or from a
//! script). Every run is of the real binary, on the smallest sample trace
//! pinned from the Python engine with a deliberate bug (`ignore-margin`:
//! 13 sweeps differ from the core, several in one frame). Then `replay`,
//! `bless` and `check` under one `[engine]` table give one answer.

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Stdio;

use libtest_mimic::Trial;
use sweeptrace::trace::{EventBody, OutcomeMsg, TraceReader};

use crate::support::run_bin;
use crate::trial;
use crate::{ensure, os};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(engine_snapshot_pins_the_engine_and_check_says_what_changed),
        trial!(engine_that_cannot_start_writes_nothing_and_exits_125),
        trial!(bless_frames_and_ball_bless_only_those_sweeps),
        trial!(bless_accept_blesses_exactly_the_listed_sweeps),
        trial!(bless_review_from_a_script_accepts_rejects_and_lists_the_skipped),
        trial!(bless_review_at_a_terminal),
        trial!(replay_bless_and_check_agree_under_a_declared_table),
        trial!(bless_selection_of_nothing_is_an_error_and_writes_nothing),
        trial!(
            bless_review_refuses_an_endless_answer_line,
            timeout = std::time::Duration::from_secs(120)
        ),
    ]
}

const ENGINE: &str = "python3 examples/engines/sweep_engine.py";
const BUGGY: &str = "python3 examples/engines/sweep_engine.py --bug ignore-margin";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn cube() -> PathBuf {
    root().join("traces/record_cube_corner_margin.mcap")
}

/// Runs the binary in the repository's root (the engine commands are
/// relative to it).
fn run(args: &[&OsStr]) -> anyhow::Result<(i32, String, String)> {
    let out = crate::support::bin()
        .args(args)
        .current_dir(root())
        .output()?;
    Ok((
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

/// The cube sample with the buggy engine's answers as its expectations.
fn snapshot(dir: &Path) -> anyhow::Result<PathBuf> {
    let out = dir.join("snapshot.mcap");
    let (code, _, err) = run(os![
        "bless",
        cube().as_os_str(),
        "--engine",
        BUGGY,
        "--engine-name",
        "buggy-engine",
        "--engine-version",
        "2.0",
        "-o",
        out.as_os_str()
    ])?;
    ensure!(code == 0, "bless --engine: exit {code}: {err}");
    Ok(out)
}

/// A trace's expectations by `(frame, ball)`.
fn expectations(path: &Path) -> anyhow::Result<BTreeMap<(u64, u32), OutcomeMsg>> {
    let bytes = std::fs::read(path)?;
    let mut out = BTreeMap::new();
    for event in TraceReader::new(bytes.as_slice(), &path.display().to_string()) {
        if let EventBody::Expected(o) = event?.body {
            out.insert((o.frame, o.ball), o);
        }
    }
    Ok(out)
}

/// The sweeps `check` finds divergent from the core, in order.
fn divergent(path: &Path) -> anyhow::Result<Vec<(u64, u32)>> {
    let (code, stdout, err) = run_bin(os![
        "check",
        path.as_os_str(),
        "--json",
        "--max-details",
        "1000"
    ])?;
    ensure!(code <= 1, "check: exit {code}: {err}");
    let report: serde_json::Value = serde_json::from_str(&stdout)?;
    let trace = report
        .get("traces")
        .and_then(|t| t.get(0))
        .unwrap_or(&report);
    Ok(trace["divergences"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|d| {
            (
                d["frame"].as_u64().unwrap_or(u64::MAX),
                d["ball"].as_u64().unwrap_or(u64::MAX) as u32,
            )
        })
        .collect())
}

/// Which expectations differ between two traces.
fn changed(a: &Path, b: &Path) -> anyhow::Result<Vec<(u64, u32)>> {
    let (a, b) = (expectations(a)?, expectations(b)?);
    ensure!(
        a.len() == b.len(),
        "{} expectations against {}",
        a.len(),
        b.len()
    );
    Ok(a.iter()
        .filter(|(k, v)| b.get(k) != Some(v))
        .map(|(k, _)| *k)
        .collect())
}

fn engine_snapshot_pins_the_engine_and_check_says_what_changed() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let snap = snapshot(dir.path())?;
    // The provenance names the engine, its version and its command.
    let (code, info, _) = run(os!["info", snap.as_os_str()])?;
    ensure!(code == 0, "info: exit {code}");
    ensure!(
        info.contains("expected by: buggy-engine 2.0") && info.contains(BUGGY),
        "{info}"
    );
    // The same engine agrees with its snapshot...
    let (code, out, err) = run(os![
        "check",
        snap.as_os_str(),
        "--engine",
        BUGGY,
        "--against",
        "expected"
    ])?;
    ensure!(code == 0, "the pinned engine: exit {code}: {out}{err}");
    // ...the engine with its bug fixed does not, and check says where.
    let (code, out, _) = run(os![
        "check",
        snap.as_os_str(),
        "--engine",
        ENGINE,
        "--against",
        "expected"
    ])?;
    ensure!(
        code == 1 && out.contains("13 of 661 compared sweeps diverge"),
        "the fixed engine: exit {code}: {out}"
    );
    ensure!(
        divergent(&snap)?.len() == 13,
        "the snapshot against the core"
    );
    Ok(())
}

fn engine_that_cannot_start_writes_nothing_and_exits_125() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("never.mcap");
    let (code, _, err) = run(os![
        "bless",
        cube().as_os_str(),
        "--engine",
        "./no-such-engine",
        "-o",
        out.as_os_str()
    ])?;
    ensure!(code == 125, "exit {code}: {err}");
    ensure!(
        err.contains("no-such-engine") && err.contains("nothing written"),
        "{err}"
    );
    ensure!(
        std::fs::read_dir(dir.path())?.next().is_none(),
        "something was written"
    );
    // The same with --review, which checks through the engine first.
    let (code, _, err) = run(os![
        "bless",
        cube().as_os_str(),
        "--review",
        "--engine",
        "./no-such-engine",
        "-o",
        out.as_os_str()
    ])?;
    ensure!(
        code == 125 && err.contains("nothing written"),
        "--review: exit {code}: {err}"
    );
    ensure!(!out.exists(), "something was written");
    Ok(())
}

fn bless_frames_and_ball_bless_only_those_sweeps() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let snap = snapshot(dir.path())?;
    let before = divergent(&snap)?;
    // Frame 30 has several divergent balls.
    let in_30: Vec<_> = before.iter().filter(|(f, _)| *f == 30).copied().collect();
    ensure!(in_30.len() >= 3, "{before:?}");
    let frames = dir.path().join("frames.mcap");
    let (code, _, err) = run_bin(os![
        "bless",
        snap.as_os_str(),
        "--frames",
        "30",
        "-o",
        frames.as_os_str()
    ])?;
    ensure!(code == 0, "bless --frames: exit {code}: {err}");
    ensure!(err.contains("kept"), "{err}");
    let after = divergent(&frames)?;
    let expected: Vec<_> = before.iter().filter(|(f, _)| *f != 30).copied().collect();
    ensure!(
        after == expected,
        "{after:?} after --frames 30, from {before:?}"
    );
    // Only sweeps of frame 30 changed, and only the divergent ones among
    // them (the others got the same answer again).
    let moved = changed(&snap, &frames)?;
    ensure!(moved == in_30, "{moved:?} changed, {in_30:?} expected");
    // One ball of that frame.
    let (_, ball) = in_30[1];
    let one = dir.path().join("ball.mcap");
    let (code, _, err) = run_bin(os![
        "bless",
        snap.as_os_str(),
        "--frames",
        "30",
        "--ball",
        &ball.to_string(),
        "-o",
        one.as_os_str()
    ])?;
    ensure!(code == 0, "bless --ball: exit {code}: {err}");
    ensure!(
        changed(&snap, &one)? == vec![(30, ball)],
        "{:?}",
        changed(&snap, &one)?
    );
    // The source says the bless was partial, and whose the rest are.
    let (_, info, _) = run(os!["info", one.as_os_str()])?;
    ensure!(
        info.contains(
            "blessed = 1 of 661 sweeps; the other 660 keep their expectations from buggy-engine"
        ),
        "{info}"
    );
    Ok(())
}

fn bless_accept_blesses_exactly_the_listed_sweeps() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let snap = snapshot(dir.path())?;
    let before = divergent(&snap)?;
    let chosen = [before[0], before[before.len() - 1]];
    let list = chosen
        .iter()
        .map(|(f, b)| format!("{f}:{b}"))
        .collect::<Vec<_>>()
        .join(",");
    let out = dir.path().join("accepted.mcap");
    let (code, _, err) = run_bin(os![
        "bless",
        snap.as_os_str(),
        "--accept",
        &list,
        "-o",
        out.as_os_str()
    ])?;
    ensure!(code == 0, "bless --accept {list}: exit {code}: {err}");
    ensure!(
        changed(&snap, &out)? == chosen.to_vec(),
        "{:?}",
        changed(&snap, &out)?
    );
    ensure!(
        divergent(&out)?.len() == before.len() - 2,
        "divergences left"
    );
    // A malformed list is refused before anything runs.
    for bad in ["12", "12:x", "a:0", ","] {
        let (code, _, err) = run_bin(os![
            "bless",
            snap.as_os_str(),
            "--accept",
            bad,
            "-o",
            out.as_os_str()
        ])?;
        ensure!(
            code == 2 && (err.contains("FRAME:BALL") || err.contains("whole number")),
            "--accept {bad}: exit {code}: {err}"
        );
    }
    Ok(())
}

fn bless_review_from_a_script_accepts_rejects_and_lists_the_skipped() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let snap = snapshot(dir.path())?;
    let before = divergent(&snap)?;
    let out = dir.path().join("reviewed.mcap");
    // Reject the first, accept the second, an unknown answer then skip
    // the third, quit at the fourth.
    let mut child = crate::support::bin()
        .args(["bless", "--review", "-o"])
        .arg(&out)
        .arg(&snap)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    child
        .stdin
        .take()
        .ok_or_else(|| anyhow::anyhow!("no stdin"))?
        .write_all(b"r\na\nmaybe\ns\nq\n")?;
    let output = child.wait_with_output()?;
    let err = String::from_utf8_lossy(&output.stderr);
    ensure!(output.status.code() == Some(0), "exit: {err}");
    // Each change is shown with check's explanation.
    ensure!(
        err.contains(&format!("[1/{}]", before.len()))
            && err.contains("the core found")
            && err.contains("`maybe` is not an answer"),
        "{err}"
    );
    let skipped = before[2..]
        .iter()
        .map(|(f, b)| format!("{f}:{b}"))
        .collect::<Vec<_>>()
        .join(",");
    ensure!(
        err.contains("1 accepted, 1 rejected")
            && err.contains(&format!("to accept later: --accept {skipped}")),
        "{err}"
    );
    ensure!(
        changed(&snap, &out)? == vec![before[1]],
        "{:?}",
        changed(&snap, &out)?
    );
    // Nothing accepted: nothing written.
    let none = dir.path().join("none.mcap");
    let mut child = crate::support::bin()
        .args(["bless", "--review", "-o"])
        .arg(&none)
        .arg(&snap)
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    drop(child.stdin.take());
    let output = child.wait_with_output()?;
    let err = String::from_utf8_lossy(&output.stderr);
    ensure!(
        output.status.code() == Some(0) && err.contains("nothing accepted") && !none.exists(),
        "{err}"
    );
    Ok(())
}

/// The review at a real terminal: the binary runs on a pseudo-terminal
/// (Python's `pty`), which types an answer at each prompt.
fn bless_review_at_a_terminal() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let snap = snapshot(dir.path())?;
    let before = divergent(&snap)?;
    let out = dir.path().join("tty.mcap");
    let script = r#"
import os, pty, sys
binary, snap, out = sys.argv[1:4]
pid, fd = pty.fork()
if pid == 0:
    os.execv(binary, [binary, "bless", snap, "--review", "-o", out])
answers = [b"a\n", b"A\n"]
seen = b""
while True:
    try:
        chunk = os.read(fd, 4096)
    except OSError:
        break
    if not chunk:
        break
    seen += chunk
    if seen.endswith(b"(quit)? ") and answers:
        os.write(fd, answers.pop(0))
        seen += b"<typed>"
_, status = os.waitpid(pid, 0)
sys.stdout.write(seen.decode("utf-8", "replace"))
sys.exit(os.waitstatus_to_exitcode(status))
"#;
    let output = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg(&snap)
        .arg(&out)
        .output()?;
    let screen = String::from_utf8_lossy(&output.stdout);
    ensure!(
        output.status.code() == Some(0),
        "exit {:?}: {screen}{}",
        output.status.code(),
        String::from_utf8_lossy(&output.stderr)
    );
    // Accept one, then the rest: every divergence is blessed.
    ensure!(
        screen.contains(&format!("{} accepted, 0 rejected, 0 skipped", before.len())),
        "{screen}"
    );
    ensure!(divergent(&out)?.is_empty(), "divergences left after review");
    Ok(())
}

/// `replay`'s outcome lines, `bless` and `check` read the same `[engine]`
/// table beside the trace, so they agree: the blessed expectations are the
/// outcome lines, `check` passes under the table and fails without it
/// (`--no-config`), and `replay --json` names the conventions.
fn replay_bless_and_check_agree_under_a_declared_table() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let suite = dir.path().join("suite");
    std::fs::create_dir_all(dir.path().join(".git"))?;
    std::fs::create_dir_all(&suite)?;
    let trace = suite.join("cube.mcap");
    std::fs::copy(cube(), &trace)?;
    std::fs::write(
        suite.join("sweeptrace.toml"),
        "[engine]\nmargin = 0\ninitial_overlap = \"alpha0\"\nnormal = \"contact\"\n",
    )?;
    let lines = dir.path().join("outcomes.jsonl");
    let (code, stdout, err) = run_bin(os![
        "replay",
        trace.as_os_str(),
        "--outcomes",
        lines.as_os_str(),
        "--json"
    ])?;
    ensure!(code == 0, "replay: exit {code}: {err}");
    ensure!(
        err.contains("reference answers under the engine's declared conventions: margin 0.0, initial_overlap alpha0, normal contact"),
        "{err}"
    );
    let summary: serde_json::Value = serde_json::from_str(&stdout)?;
    ensure!(
        summary["conventions"]["initial_overlap"] == "alpha0"
            && summary["conventions"]["normal"] == "contact",
        "{stdout}"
    );
    let blessed = suite.join("blessed.mcap");
    let (code, _, err) = run_bin(os!["bless", trace.as_os_str(), "-o", blessed.as_os_str()])?;
    ensure!(code == 0, "bless: exit {code}: {err}");
    let expected = expectations(&blessed)?;
    let mut hits_at_zero = 0;
    for line in std::fs::read_to_string(&lines)?.lines() {
        // The outcome fields of the line (it has more: fragile, tunnel...).
        let mut value: serde_json::Value = serde_json::from_str(line)?;
        if let Some(map) = value.as_object_mut() {
            map.retain(|k, _| {
                [
                    "frame", "ball", "alpha", "kind", "triangle", "feature", "normal", "contact",
                ]
                .contains(&k.as_str())
            });
        }
        let o: OutcomeMsg = serde_json::from_value(value)?;
        let e = expected
            .get(&(o.frame, o.ball))
            .ok_or_else(|| anyhow::anyhow!("no expectation for {}:{}", o.frame, o.ball))?;
        ensure!(
            (e.alpha, e.kind, e.triangle, e.feature, e.normal, e.contact)
                == (o.alpha, o.kind, o.triangle, o.feature, o.normal, o.contact),
            "frame {}, ball {}: replay {o:?}, bless {e:?}",
            o.frame,
            o.ball
        );
        hits_at_zero += u32::from(o.alpha == 0.0 && o.kind != sweeptrace::Kind::None);
    }
    ensure!(hits_at_zero > 20, "only {hits_at_zero} hits at α = 0");
    // `sweep --trace` gives the same answer for a sweep that starts in
    // contact and one whose normal is the contact normal at an edge.
    let picks: Vec<&OutcomeMsg> = [
        expected
            .values()
            .find(|o| o.alpha == 0.0 && o.kind != sweeptrace::Kind::None),
        expected.values().find(|o| o.kind == sweeptrace::Kind::Edge),
    ]
    .into_iter()
    .flatten()
    .collect();
    ensure!(picks.len() == 2, "no edge hit in the cube under the table");
    for e in picks {
        let (code, stdout, err) = run_bin(os![
            "sweep",
            "--trace",
            trace.as_os_str(),
            "--frame",
            &e.frame.to_string(),
            "--ball",
            &e.ball.to_string(),
            "--json"
        ])?;
        ensure!(code == 0, "sweep: exit {code}: {err}");
        ensure!(err.contains("declared conventions"), "{err}");
        let v: serde_json::Value = serde_json::from_str(&stdout)?;
        let o = &v["outcome"];
        let normal: Option<[f64; 3]> = serde_json::from_value(o["normal"].clone())?;
        ensure!(
            o["alpha"].as_f64() == Some(e.alpha)
                && o["triangle"].as_u64() == e.triangle.flatten().map(u64::from)
                && normal == e.normal.flatten(),
            "frame {}, ball {}: sweep {o}, bless {e:?}",
            e.frame,
            e.ball
        );
    }
    let (code, out, _) = run_bin(os!["check", blessed.as_os_str()])?;
    ensure!(code == 0, "check under the table: exit {code}: {out}");
    let (code, out, _) = run_bin(os!["check", blessed.as_os_str(), "--no-config"])?;
    ensure!(code == 1, "check by the rules: exit {code}: {out}");
    // ...and the report sees the convention it was not told of, counts it
    // and says how to declare it.
    ensure!(
        out.contains(&format!(
            "{hits_at_zero} hits at α = 0 where the ball starts within its radius (initial_overlap = \"alpha0\")"
        )) && out.contains("declare them in an [engine] table"),
        "{out}"
    );
    let (_, json, _) = run_bin(os!["check", blessed.as_os_str(), "--no-config", "--json"])?;
    let report: serde_json::Value = serde_json::from_str(&json)?;
    let trace = report
        .get("traces")
        .and_then(|t| t.get(0))
        .unwrap_or(&report);
    ensure!(
        trace["conventions_seen"]["initial_overlap"].as_u64() == Some(u64::from(hits_at_zero)),
        "{}",
        trace["conventions_seen"]
    );
    Ok(())
}

/// A selection that selects no sweep (frames past the end, a ball the
/// trace lacks, a pair it lacks) is an error naming what the trace holds,
/// exit 2, and writes nothing: no output, and in place the trace as it was
/// (before: exit 0, "0 sweeps blessed", the trace rewritten) (issue 43,
/// item 10).
fn bless_selection_of_nothing_is_an_error_and_writes_nothing() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("cube.mcap");
    std::fs::copy(cube(), &trace)?;
    let before = std::fs::read(&trace)?;
    let out = dir.path().join("out.mcap");
    for (selection, filter) in [
        (os!["--frames", "99999.."], "(frames 99999..)"),
        (os!["--ball", "999"], "(ball 999)"),
        (os!["--accept", "99999:0"], "(sweeps 99999:0)"),
    ] {
        for target in [
            os!["-o", out.as_os_str()].to_vec(),
            os!["--in-place"].to_vec(),
        ] {
            let mut args = os!["bless", trace.as_os_str()].to_vec();
            args.extend_from_slice(selection);
            args.extend_from_slice(&target);
            let (code, out_text, err) = run(&args)?;
            ensure!(
                code == 2
                    && err.contains(&format!("the filter {filter} selects none of the trace's"))
                    && err.contains("; nothing written")
                    && !err.contains("wrote "),
                "{args:?}: exit {code}\n{out_text}{err}"
            );
            ensure!(!out.exists(), "{args:?} wrote {}", out.display());
            ensure!(
                std::fs::read(&trace)? == before,
                "{args:?} rewrote the trace"
            );
        }
    }
    Ok(())
}

/// `--review` reads an answer line up to a bound: a line without end
/// (`< /dev/zero`, or a long line without a newline) is an error, exit 2,
/// nothing written (before: the line was read without bound, gigabytes a
/// second) (issue 43, item 11).
fn bless_review_refuses_an_endless_answer_line() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = root().join("tests/fixtures/wrong_engine_config.mcap");
    let out = dir.path().join("reviewed.mcap");
    // A long line, then the end of input.
    let mut child = crate::support::bin()
        .args(["bless", "--review", "-o"])
        .arg(&out)
        .arg(&trace)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    let mut stdin = child
        .stdin
        .take()
        .ok_or_else(|| anyhow::anyhow!("no stdin"))?;
    // The binary may stop reading (and close the pipe) before all of it.
    let _ = stdin.write_all(&[b'x'; 8192]);
    drop(stdin);
    let output = child.wait_with_output()?;
    let err = String::from_utf8_lossy(&output.stderr);
    ensure!(
        output.status.code() == Some(2)
            && err.contains("an answer line longer than 1024 bytes")
            && !out.exists(),
        "a long line: {:?}\n{err}",
        output.status
    );
    // /dev/zero: the same, at once (under a 3 GB limit of address space,
    // so that a regression fails instead of taking the machine's memory).
    let child = std::process::Command::new("sh")
        .args([
            "-c",
            "ulimit -v 3000000 && exec \"$0\" bless --review -o \"$1\" \"$2\"",
        ])
        .arg(env!("CARGO_BIN_EXE_sweeptrace"))
        .arg(&out)
        .arg(&trace)
        .stdin(std::fs::File::open("/dev/zero")?)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    let output = child.wait_with_output()?;
    let err = String::from_utf8_lossy(&output.stderr);
    ensure!(
        output.status.code() == Some(2)
            && err.contains("an answer line longer than 1024 bytes")
            && !out.exists(),
        "/dev/zero: {:?}\n{err}",
        output.status
    );
    Ok(())
}
