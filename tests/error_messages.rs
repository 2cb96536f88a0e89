//! Error messages in one style: a representative set of failing commands,
//! each of whose messages names the file (and the channel, frame and field
//! where there is one) and says no part of itself twice
//! (`sweeptrace::fuzzing::repeated_segment`).

use std::path::Path;

use libtest_mimic::Trial;

use crate::{ensure, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(failing_commands_say_each_thing_once),
        trial!(inputs_are_shown_escaped_and_in_the_users_words),
    ]
}

/// One failing command: its arguments, the exit code, and what its message
/// must contain besides the file.
struct Case {
    what: &'static str,
    args: Vec<std::ffi::OsString>,
    exit: i32,
    file: String,
    must_say: Vec<&'static str>,
}

fn failing_commands_say_each_thing_once() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let at = |name: &str| dir.path().join(name);
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tunnel_floor.mcap");
    let bytes = std::fs::read(&sample)?;

    // A corrupt chunk, a truncated file, a bad field of a sweep.
    let mut corrupt = bytes.clone();
    let (start, len) = crate::trace_io::first_chunk(&corrupt).context("no chunk")?;
    corrupt[start + 9 + len - len / 3] ^= 0x5a;
    std::fs::write(at("corrupt.mcap"), &corrupt)?;
    std::fs::write(at("truncated.mcap"), &bytes[..bytes.len() * 2 / 3])?;
    let scene = br#"{"vertices":[[0,0,0],[4,0,0],[0,4,0]],"triangles":[[0,1,2]]}"#;
    let bad_sweep = br#"{"frame":7,"radius":-1,"p0":[1,1,1],"p1":[1,1,-1]}"#;
    let bad_type = br#"{"frame":8,"radius":0.5,"p0":[1,"x",1],"p1":[1,1,-1]}"#;
    std::fs::write(
        at("bad_field.mcap"),
        crate::trace_io::raw_trace(&[("/scene", 0, scene), ("/sweep", 1, bad_sweep)]),
    )?;
    std::fs::write(
        at("bad_type.mcap"),
        crate::trace_io::raw_trace(&[("/scene", 0, scene), ("/sweep", 1, bad_type)]),
    )?;
    std::fs::write(at("level.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 9\n")?;

    let path = |name: &str| at(name).display().to_string();
    let sample_name = sample.display().to_string();
    let os = |parts: &[&str]| {
        parts
            .iter()
            .map(std::ffi::OsString::from)
            .collect::<Vec<_>>()
    };
    let cases = vec![
        Case {
            what: "info on a missing file",
            args: os(&["info", &path("missing.mcap")]),
            exit: 2,
            file: path("missing.mcap"),
            must_say: vec!["No such file or directory"],
        },
        Case {
            what: "replay of a corrupt chunk",
            args: os(&[
                "replay",
                &path("corrupt.mcap"),
                "--outcomes",
                &path("out.jsonl"),
            ]),
            exit: 2,
            file: path("corrupt.mcap"),
            must_say: vec!["corrupt MCAP data", "chunk 0"],
        },
        Case {
            what: "info of a truncated file",
            args: os(&["info", &path("truncated.mcap")]),
            exit: 3,
            file: path("truncated.mcap"),
            must_say: vec!["truncated"],
        },
        Case {
            what: "replay of a sweep with a bad radius",
            args: os(&[
                "replay",
                &path("bad_field.mcap"),
                "--outcomes",
                &path("out.jsonl"),
            ]),
            exit: 2,
            file: path("bad_field.mcap"),
            must_say: vec!["channel `/sweep`", "frame 7", "field `radius`"],
        },
        Case {
            what: "bless of a sweep with a mistyped coordinate",
            args: os(&["bless", &path("bad_type.mcap"), "-o", &path("blessed.mcap")]),
            exit: 2,
            file: path("bad_type.mcap"),
            must_say: vec!["channel `/sweep`", "frame 8", "field `p0[1]`"],
        },
        Case {
            what: "replay --outcomes to a full device",
            args: os(&["replay", &sample_name, "--outcomes", "/dev/full"]),
            exit: 2,
            file: "/dev/full".to_string(),
            must_say: vec!["No space left on device"],
        },
        Case {
            what: "replay --rrd into a missing directory",
            args: os(&[
                "replay",
                &sample_name,
                "--rrd",
                &path("no/such/dir/out.rrd"),
            ]),
            exit: 2,
            file: path("no/such/dir/out.rrd"),
            must_say: vec!["No such file or directory"],
        },
        Case {
            what: "record into a missing directory",
            args: os(&[
                "record",
                "--scene",
                "cube",
                "--frames",
                "3",
                "-o",
                &path("no/t.mcap"),
            ]),
            exit: 2,
            file: path("no/t.mcap"),
            must_say: vec!["No such file or directory"],
        },
        Case {
            what: "record with an OBJ whose face names a missing vertex",
            args: os(&[
                "record",
                "--mesh",
                &path("level.obj"),
                "-o",
                &path("t.mcap"),
            ]),
            exit: 2,
            file: path("level.obj"),
            must_say: vec![],
        },
        Case {
            what: "diff with a missing file",
            args: os(&["diff", &sample_name, &path("missing.mcap")]),
            exit: 2,
            file: path("missing.mcap"),
            must_say: vec!["No such file or directory"],
        },
        Case {
            what: "check of a corrupt trace",
            args: os(&["check", &path("corrupt.mcap")]),
            exit: 2,
            file: path("corrupt.mcap"),
            must_say: vec!["corrupt MCAP data", "chunk 0"],
        },
    ];
    for case in cases {
        let args: Vec<&std::ffi::OsStr> = case.args.iter().map(|a| a.as_os_str()).collect();
        let (code, stdout, stderr) = crate::support::run_bin(&args)?;
        let what = case.what;
        ensure!(
            code == case.exit,
            "{what}: exit {code}, want {}: {stdout}{stderr}",
            case.exit
        );
        // The message: the `error:` line, or check's `ERROR` line.
        let message = stderr
            .lines()
            .chain(stdout.lines())
            .find(|l| {
                l.starts_with("error: ") || l.starts_with("ERROR ") || l.starts_with("incomplete: ")
            })
            .with_context(|| format!("{what}: no error line: {stdout}{stderr}"))?;
        ensure!(
            message.matches(case.file.as_str()).count() == 1,
            "{what}: the message does not name {} exactly once: {message}",
            case.file
        );
        for needle in case.must_say {
            ensure!(
                message.contains(needle),
                "{what}: the message does not say `{needle}`: {message}"
            );
        }
        if let Some(repeated) = sweeptrace::fuzzing::repeated_segment(message) {
            anyhow::bail!("{what}: the message repeats `{repeated}`: {message}");
        }
    }
    Ok(())
}

/// Text taken from an input and shown on a terminal (a settings file's
/// value or key, a scene's name, an answer) has its control characters
/// escaped; messages name no type of the program (`expected struct
/// RawEngine`); a number too large is said to be; an integer prints as
/// one (a triangle index `1000000`, not `1.0000e6`); `replay --json`
/// prints one JSON document with the error, as `check --json` does (issue
/// 43, item 12).
fn inputs_are_shown_escaped_and_in_the_users_words() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let repo = dir.path();
    std::fs::create_dir_all(repo.join(".git"))?;
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_cube_corner_margin.mcap"),
        repo.join("t.mcap"),
    )?;
    let run = |args: &[&str]| {
        crate::support::run_bin_in(
            repo,
            &args.iter().map(std::ffi::OsStr::new).collect::<Vec<_>>(),
        )
    };
    let raw = |text: &str| text.chars().any(|c| c.is_control() && c != '\n');
    // Settings files: a value and a key with an escape sequence, values
    // of the wrong type.
    for (file, must_say) in [
        (
            "[engine]\nfacing = \"\\u001b[2Jred\"\n",
            "`engine.facing` is `\\u{1b}[2Jred`",
        ),
        (
            "[engine]\n\"x\\u001b[2J\" = 1\n",
            "unknown key `x\\u{1b}[2J`",
        ),
        ("engine = 3\n", "expected the `[engine]` table"),
        ("tolerances = 3\n", "expected the `[tolerances]` table"),
        ("traces = [1]\n", "expected a `[[traces]]` table"),
    ] {
        std::fs::write(repo.join("sweeptrace.toml"), file)?;
        let (code, out, err) = run(&["check", "t.mcap"])?;
        ensure!(
            code == 2 && err.contains(must_say) && !raw(&err) && !err.contains("struct"),
            "{file:?}: exit {code}\n{out}{err}"
        );
    }
    std::fs::remove_file(repo.join("sweeptrace.toml"))?;
    // A scene's name, in `info` and `mesh`.
    let scene = br#"{"name":"evil\u001b[2J\u0007","vertices":[[0,0,0],[4,0,0],[0,4,0]],"triangles":[[0,1,2]]}"#;
    let sweep = br#"{"frame":0,"radius":0.5,"p0":[1,1,1],"p1":[1,1,-1]}"#;
    std::fs::write(
        repo.join("named.mcap"),
        crate::trace_io::raw_trace(&[("/scene", 0, scene), ("/sweep", 1, sweep)]),
    )?;
    for command in [["info", "named.mcap"], ["mesh", "named.mcap"]] {
        let (code, out, err) = run(&command)?;
        ensure!(
            code == 0 && out.contains("evil\\u{1b}[2J\\u{7}") && !raw(&out) && !raw(&err),
            "{command:?}: exit {code}\n{out}{err}"
        );
    }
    // A ball number too large, an answer with control characters.
    let (code, out, err) = run(&[
        "bless",
        "t.mcap",
        "--accept",
        "0:4294967296",
        "-o",
        "b.mcap",
    ])?;
    ensure!(
        code == 2 && err.contains("the ball `4294967296` is too large (at most 4294967295)"),
        "exit {code}\n{out}{err}"
    );
    let (code, out, err) = run(&["bless", "t.mcap", "--accept", "0:\u{1b}[2J", "-o", "b.mcap"])?;
    ensure!(
        code == 2 && err.contains("the ball `\\u{1b}[2J` is not a whole number") && !raw(&err),
        "exit {code}\n{out}{err}"
    );
    // An integer in a divergence's values.
    let index = serde_json::json!(1_000_000);
    ensure!(
        sweeptrace::judge::divergence::value_text(&index) == "1000000"
            && sweeptrace::judge::divergence::value_text_exact(&serde_json::json!(1e300))
                == "1e300",
        "{}",
        sweeptrace::judge::divergence::value_text(&index)
    );
    // `replay --json` that fails: one JSON document, with the error.
    let (code, out, err) = run(&["replay", "missing.mcap", "--outcomes", "o.jsonl", "--json"])?;
    let v: serde_json::Value =
        serde_json::from_str(&out).with_context(|| format!("not JSON: {out}{err}"))?;
    ensure!(
        code == 2
            && v["status"] == "error"
            && v["exit_code"] == 2
            && v["trace"] == "missing.mcap"
            && v["error"]
                .as_str()
                .is_some_and(|e| e.contains("missing.mcap: cannot open")),
        "exit {code}\n{out}{err}"
    );
    Ok(())
}
