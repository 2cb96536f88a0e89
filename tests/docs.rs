//! The command blocks of README.md and docs/*.md, run as they are written,
//! so that what the docs show cannot drift from what the tool does.
//!
//! The format is `trycmd`'s Markdown format, matched with `snapbox`:
//!
//! - A ```` ```console ```` block holds commands (`$ ` lines, a trailing
//!   ` \` continues one) each followed by its output, stdout and stderr
//!   interleaved as a terminal shows them. A `? N` line right after the
//!   command gives its exit code (else 0). In the output, a line `...`
//!   stands for any number of lines and `[..]` for any text within a line:
//!   used only where the output really varies (a time, a temporary path) or
//!   where the prose says it shows a part.
//! - A ```` ```sh ```` block shows commands without their output: each one is
//!   run, and must exit 0, or with the code a trailing `# exits N: why`
//!   gives.
//!
//! Each document runs in a sandbox of its own, in order, block after block
//! (a file one block writes is there for the next): a temporary directory
//! with copies of `traces/` and `tests/fixtures/`, `examples/` and `docs/`
//! linked, `sweeptrace` (this build) on `PATH`, and the files the docs name
//! as the reader's own (`run.mcap`, `level.obj`, `./build/engine`, ...; see
//! [`sandbox`]). Commands that cannot run here (installs, builds, the
//! viewer, `git bisect` on the reader's history, the C compiler, which the
//! C API's tests run) are left out by [`NOT_RUN`], each with its reason.
//!
//! When a shown output is wrong, `SWEEPTRACE_BLESS=1` rewrites the block
//! with the real output (elisions must then be put back by hand where the
//! output varies).

use std::ffi::OsStr;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use libtest_mimic::{Completion, Trial};

use crate::trial;

pub fn tests() -> Vec<Trial> {
    let mut trials: Vec<Trial> = DOCS
        .iter()
        .map(|doc| {
            let doc = *doc;
            crate::trial(&format!("docs::commands_of::{doc}"), move || {
                run_document(doc)
            })
        })
        .collect();
    trials.push(trial!(every_document_with_commands_is_run));
    trials.push(trial!(no_output_is_shown_apart_from_its_command));
    trials.push(trial!(parser_reads_commands_codes_and_outputs));
    trials
}

/// The documents whose commands are run. A new document with commands
/// must be added (checked by `every_document_with_commands_is_run`).
const DOCS: &[&str] = &[
    "README.md",
    "docs/COMMANDS.md",
    "docs/ENGINES.md",
    "docs/ENGINE_PROTOCOL.md",
    "docs/REGRESSION.md",
    "docs/VIEWERS.md",
];

/// Commands of the docs that are not run, with the reason: a command is
/// left out when one of these strings occurs in it.
const NOT_RUN: &[(&str, &str)] = &[
    (
        "cargo install",
        "installs the binary (CI builds both builds)",
    ),
    ("cargo test", "the test command itself"),
    (
        "cargo build --release -p sweeptrace-capi",
        "the C API's tests build and run it (capi/tests)",
    ),
    (
        "cc ",
        "the C API's tests run the documented C commands (capi/tests)",
    ),
    ("pip install", "installs the viewer"),
    (
        "rerun ",
        "opens the viewer (CI runs `rerun rrd verify` on recordings)",
    ),
    ("--spawn", "opens a viewer"),
    ("--connect", "needs a running viewer"),
    (
        "--review",
        "interactive: tests/bless_select.rs drives it in a terminal",
    ),
    ("git bisect", "needs the reader's history"),
    (
        "--engine ./engine",
        "the C engine the block builds: the C API's tests run it (capi/tests)",
    ),
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// One command of a block: its text (continuations joined), the exit code
/// expected and, in a `console` block, the output shown.
#[derive(Debug, Clone, PartialEq)]
struct DocCommand {
    /// 1-based line of the command in the document.
    line: usize,
    text: String,
    code: i32,
    /// `None` in an `sh` block: not compared.
    output: Option<String>,
}

/// A block of commands: its language and where its body lies (0-based line
/// indices, body only), for rewriting.
#[derive(Debug, Clone, PartialEq)]
struct Block {
    lang: String,
    indent: usize,
    body: std::ops::Range<usize>,
    commands: Vec<DocCommand>,
}

/// The `console` and `sh` blocks of a Markdown text.
fn blocks(text: &str) -> anyhow::Result<Vec<Block>> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let trimmed = lines[i].trim_start();
        let indent = lines[i].len() - trimmed.len();
        let Some(lang) = trimmed.strip_prefix("```") else {
            i += 1;
            continue;
        };
        let lang = lang.trim().to_string();
        let start = i + 1;
        let mut end = start;
        while end < lines.len() && lines[end].trim_start() != "```" {
            end += 1;
        }
        anyhow::ensure!(end < lines.len(), "line {}: unclosed code block", i + 1);
        let body: Vec<&str> = lines[start..end]
            .iter()
            .map(|l| l.get(indent..).unwrap_or(l.trim_start()))
            .collect();
        let commands = match lang.as_str() {
            "console" => console_commands(&body, start)?,
            "sh" => sh_commands(&body, start),
            _ => Vec::new(),
        };
        if lang == "console" || lang == "sh" {
            out.push(Block {
                lang,
                indent,
                body: start..end,
                commands,
            });
        }
        i = end + 1;
    }
    Ok(out)
}

/// Joins a command's continuation lines (a trailing ` \`).
fn take_command<'a>(body: &[&'a str], mut k: usize, first: &'a str) -> (String, usize) {
    let mut text = first.to_string();
    while text.ends_with('\\') && k + 1 < body.len() {
        text.pop();
        k += 1;
        let next = body[k].strip_prefix("> ").unwrap_or(body[k]);
        text.push_str(next.trim_start());
        text = text.replace("  ", " ");
    }
    (text.trim().to_string(), k)
}

fn console_commands(body: &[&str], start: usize) -> anyhow::Result<Vec<DocCommand>> {
    let mut out: Vec<DocCommand> = Vec::new();
    let mut k = 0;
    while k < body.len() {
        let line = body[k];
        if let Some(first) = line.strip_prefix("$ ") {
            let cmd_line = start + k + 1;
            let (text, last) = take_command(body, k, first);
            let mut code = 0;
            k = last + 1;
            if let Some(status) = body.get(k).and_then(|l| l.strip_prefix("? ")) {
                code = status.trim().parse().map_err(|_| {
                    anyhow::anyhow!("line {}: `? {status}` is not an exit code", start + k + 1)
                })?;
                k += 1;
            }
            let mut output = String::new();
            while k < body.len() && !body[k].starts_with("$ ") {
                output.push_str(body[k]);
                output.push('\n');
                k += 1;
            }
            out.push(DocCommand {
                line: cmd_line,
                text,
                code,
                output: Some(output),
            });
        } else if line.trim().is_empty() && out.is_empty() {
            k += 1;
        } else {
            anyhow::bail!(
                "line {}: a console block starts with a `$ ` command",
                start + k + 1
            );
        }
    }
    Ok(out)
}

fn sh_commands(body: &[&str], start: usize) -> Vec<DocCommand> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < body.len() {
        let line = body[k].trim();
        if line.is_empty() || line.starts_with('#') {
            k += 1;
            continue;
        }
        let (text, last) = take_command(body, k, line);
        // `# exits N: why` after a command that ends other than with 0.
        let code = text
            .split_once("# exits ")
            .and_then(|(_, c)| c.split(|ch: char| !ch.is_ascii_digit()).next())
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        out.push(DocCommand {
            line: start + k + 1,
            text,
            code,
            output: None,
        });
        k = last + 1;
    }
    out
}

/// Why a command is not run, when it is not.
fn not_run(command: &str) -> Option<&'static str> {
    NOT_RUN
        .iter()
        .find(|(pattern, _)| command.contains(pattern))
        .map(|(_, why)| *why)
}

/// The sandbox of one document: see the module's documentation.
fn sandbox() -> anyhow::Result<tempfile::TempDir> {
    let dir = tempfile::Builder::new()
        .prefix("sweeptrace-docs-")
        .tempdir()?;
    let d = dir.path();
    copy_dir(&root().join("traces"), &d.join("traces"))?;
    copy_dir(&root().join("tests/fixtures"), &d.join("tests/fixtures"))?;
    std::os::unix::fs::symlink(root().join("examples"), d.join("examples"))?;
    std::os::unix::fs::symlink(root().join("docs"), d.join("docs"))?;
    // The reader's own files the docs name.
    std::fs::copy(
        root().join("traces/record_mini_golf.mcap"),
        d.join("run.mcap"),
    )?;
    for name in ["old.mcap", "new.mcap"] {
        std::fs::copy(root().join("traces/record_mini_golf.mcap"), d.join(name))?;
    }
    std::fs::copy(
        root().join("examples/rapier/rapier_mini_golf.mcap"),
        d.join("rapier.mcap"),
    )?;
    std::fs::copy(
        root().join("tests/fixtures/scanned/bunny_res4.obj"),
        d.join("level.obj"),
    )?;
    // The floor of docs/COMMANDS.md, "Why did my ball fall through?".
    std::fs::write(
        d.join("cw.obj"),
        "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nf 1 2 3\nf 1 4 3\n",
    )?;
    // The reader's engine: the example engine in Python.
    std::fs::create_dir_all(d.join("build"))?;
    let engine = d.join("build/engine");
    std::fs::write(
        &engine,
        "#!/bin/sh\nexec python3 examples/engines/sweep_engine.py \"$@\"\n",
    )?;
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&engine, std::fs::Permissions::from_mode(0o755))?;
    // A suite of the reader's: one of the sample traces.
    std::fs::create_dir_all(d.join("suite"))?;
    std::fs::copy(
        root().join("tests/fixtures/wrong_engine_config.mcap"),
        d.join("suite/wrong_engine_config.mcap"),
    )?;
    // Settings files with a mistake each (docs/REGRESSION.md).
    for (name, toml) in [
        (
            "typo",
            "[tolerances]\nalpha = 1e-6\nnormal_degrees = 0.5\nalfa = 1e-5\n",
        ),
        ("colours", "fields = [\"kind\", \"colour\"]\n"),
    ] {
        std::fs::create_dir_all(d.join(name))?;
        std::fs::copy(
            root().join("traces/record_box_strict.mcap"),
            d.join(name).join("box_strict.mcap"),
        )?;
        std::fs::write(d.join(name).join("sweeptrace.toml"), toml)?;
    }
    // The ball recorded over the flipped floor (docs/COMMANDS.md shows
    // the same command).
    let (code, out) = run_in(
        d,
        "sweeptrace record --mesh cw.obj -o cw.mcap --balls 1 --position 1,3,2 --radius 0.5",
    )?;
    anyhow::ensure!(code == 0, "recording cw.mcap: {out}");
    Ok(dir)
}

fn copy_dir(from: &Path, to: &Path) -> anyhow::Result<()> {
    for entry in walkdir::WalkDir::new(from) {
        let entry = entry?;
        let target = to.join(entry.path().strip_prefix(from)?);
        if entry.file_type().is_dir() {
            std::fs::create_dir_all(&target)?;
        } else {
            std::fs::copy(entry.path(), &target)?;
        }
    }
    Ok(())
}

/// Runs `command` in `dir` with `sh`, stderr into stdout: exit code and
/// output.
fn run_in(dir: &Path, command: &str) -> anyhow::Result<(i32, String)> {
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_sweeptrace"))
        .parent()
        .expect("the binary is in a directory");
    let path = std::env::join_paths(std::iter::once(bin_dir.to_path_buf()).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))?;
    // `cargo run -- ARGS` is the same binary.
    let command = command.replace("cargo run -- ", "sweeptrace ");
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!("exec 2>&1\n{command}"))
        .current_dir(dir)
        .env("PATH", path)
        .env("SUITE", "suite")
        .env("ENGINE", "python3 examples/engines/sweep_engine.py")
        .env("NO_COLOR", "1")
        .env_remove("SWEEPTRACE_BLESS")
        .output()?;
    Ok((
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    ))
}

/// Whether `output` is what `expected` shows (snapbox's `...` and `[..]`).
fn matches(expected: &str, output: &str) -> Result<(), String> {
    snapbox::Assert::new()
        .try_eq(
            Some(&"the real output"),
            snapbox::Data::text(output),
            snapbox::Data::text(expected),
        )
        .map_err(|e| e.to_string())
}

/// Why a command that needs Jolt (Node and `npm ci` in
/// examples/engines/jolt) cannot run here, if it cannot; an error when
/// `SWEEPTRACE_REQUIRE_NODE=1` requires it.
fn jolt_missing(command: &str) -> anyhow::Result<Option<&'static str>> {
    if !command.contains("examples/engines/jolt") {
        return Ok(None);
    }
    let node = Command::new("node").arg("--version").output().is_ok();
    let installed = root()
        .join("examples/engines/jolt/node_modules/jolt-physics")
        .is_dir();
    if node && installed {
        return Ok(None);
    }
    anyhow::ensure!(
        std::env::var_os("SWEEPTRACE_REQUIRE_NODE").is_none_or(|v| v != "1"),
        "`{command}` needs node and `npm ci --prefix examples/engines/jolt`, \
         and SWEEPTRACE_REQUIRE_NODE=1 requires it"
    );
    Ok(Some(
        "needs node and `npm ci --prefix examples/engines/jolt`",
    ))
}

fn needs_python(command: &str) -> bool {
    command.contains("python3") || command.contains("./build/engine") || command.contains("$ENGINE")
}

fn run_document(doc: &'static str) -> anyhow::Result<Completion> {
    let path = root().join(doc);
    let text = std::fs::read_to_string(&path)?;
    let blocks = blocks(&text).map_err(|e| anyhow::anyhow!("{doc}: {e}"))?;
    let python = Command::new("python3").arg("--version").output().is_ok();
    let dir = sandbox()?;
    let bless = std::env::var_os(crate::support::BLESS).is_some_and(|v| v == "1");
    let mut failures = String::new();
    let mut skipped: Vec<String> = Vec::new();
    let mut rewrites: Vec<(std::ops::Range<usize>, usize, String)> = Vec::new();
    for block in &blocks {
        let mut new_body = String::new();
        for cmd in &block.commands {
            let why = not_run(&cmd.text)
                .or(if !python && needs_python(&cmd.text) {
                    Some("python3 is not on PATH")
                } else {
                    None
                })
                .or(jolt_missing(&cmd.text)?);
            if let Some(why) = why {
                skipped.push(format!("{doc}:{}: {} ({why})", cmd.line, cmd.text));
                if let Some(shown) = &cmd.output {
                    write_command(&mut new_body, cmd, cmd.code, shown);
                }
                continue;
            }
            let (code, output) = run_in(dir.path(), &cmd.text)?;
            if code != cmd.code {
                let _ = writeln!(
                    failures,
                    "{doc}:{}: `{}` exited {code}, the doc says {}; its output:\n{output}",
                    cmd.line, cmd.text, cmd.code
                );
            }
            if let Some(shown) = &cmd.output {
                match matches(shown, &output) {
                    Ok(()) => write_command(&mut new_body, cmd, cmd.code, shown),
                    Err(diff) => {
                        let _ = writeln!(
                            failures,
                            "{doc}:{}: `{}` prints other than the doc shows:\n{diff}",
                            cmd.line, cmd.text
                        );
                        write_command(&mut new_body, cmd, code, &output);
                    }
                }
            }
        }
        if block.lang == "console" {
            rewrites.push((block.body.clone(), block.indent, new_body));
        }
    }
    if !failures.is_empty() {
        if bless {
            rewrite(&path, &text, &rewrites)?;
        }
        let left_out: String = skipped
            .iter()
            .map(|s| format!("  not run: {s}\n"))
            .collect();
        anyhow::bail!(
            "{failures}{left_out}(when the tool's output is right, `{}=1 cargo test --test integration \
             -- docs::` rewrites the shown outputs; put back the elisions where the output varies)",
            crate::support::BLESS
        );
    }
    // Commands left out for want of Python or Node: the run is partial, and
    // says so (REQUIRE_PYTHON / SWEEPTRACE_REQUIRE_NODE make it a failure).
    let partial: Vec<&String> = skipped
        .iter()
        .filter(|s| s.contains("python3 is not on PATH") || s.contains("needs node"))
        .collect();
    if partial.is_empty() {
        return Ok(Completion::Completed);
    }
    anyhow::ensure!(
        std::env::var_os(crate::support::REQUIRE_PYTHON).is_none_or(|v| v != "1"),
        "{} commands need python3, and {}=1 requires them: {partial:?}",
        partial.len(),
        crate::support::REQUIRE_PYTHON
    );
    Ok(Completion::ignored_with(format!(
        "partly skipped: {} commands not run ({})",
        partial.len(),
        partial
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("; ")
    )))
}

fn write_command(out: &mut String, cmd: &DocCommand, code: i32, output: &str) {
    let _ = writeln!(out, "$ {}", cmd.text);
    if code != 0 {
        let _ = writeln!(out, "? {code}");
    }
    out.push_str(output);
}

/// Replaces the bodies of the console blocks with `rewrites`.
fn rewrite(
    path: &Path,
    text: &str,
    rewrites: &[(std::ops::Range<usize>, usize, String)],
) -> anyhow::Result<()> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = String::new();
    let mut i = 0;
    for (range, indent, body) in rewrites {
        for l in &lines[i..range.start] {
            out.push_str(l);
            out.push('\n');
        }
        for l in body.lines() {
            if !l.is_empty() {
                out.push_str(&" ".repeat(*indent));
            }
            out.push_str(l);
            out.push('\n');
        }
        i = range.end;
    }
    for l in &lines[i..] {
        out.push_str(l);
        out.push('\n');
    }
    let tmp = path.with_extension("md.tmp");
    std::fs::write(&tmp, out)?;
    std::fs::rename(tmp, path)?;
    Ok(())
}

/// Every Markdown file of README.md and docs/ with a `console` block, or an
/// `sh` block running `sweeptrace`, is in [`DOCS`].
fn every_document_with_commands_is_run() -> anyhow::Result<()> {
    let mut files: Vec<PathBuf> = vec![root().join("README.md")];
    for entry in std::fs::read_dir(root().join("docs"))? {
        let p = entry?.path();
        if p.extension() == Some(OsStr::new("md")) {
            files.push(p);
        }
    }
    let mut missing = Vec::new();
    for f in files {
        let rel = f.strip_prefix(root())?.to_string_lossy().into_owned();
        if DOCS.contains(&rel.as_str()) || rel == "docs/perf-history.md" {
            continue;
        }
        let text = std::fs::read_to_string(&f)?;
        let runs = blocks(&text)?.iter().any(|b| {
            b.lang == "console" || b.commands.iter().any(|c| c.text.contains("sweeptrace "))
        });
        if runs {
            missing.push(rel);
        }
    }
    anyhow::ensure!(
        missing.is_empty(),
        "these documents show commands but are not in tests/docs.rs's DOCS: {missing:?}"
    );
    Ok(())
}

/// A ```` ```text ```` block right after a block of commands would be an
/// output shown apart from its command, which nothing checks: outputs go
/// in `console` blocks.
fn no_output_is_shown_apart_from_its_command() -> anyhow::Result<()> {
    let mut found = Vec::new();
    for doc in DOCS {
        let text = std::fs::read_to_string(root().join(doc))?;
        let lines: Vec<&str> = text.lines().collect();
        for b in blocks(&text)? {
            if b.lang != "sh" {
                continue;
            }
            // The next non-blank line after the closing fence.
            let next = lines[b.body.end + 1..]
                .iter()
                .position(|l| !l.trim().is_empty())
                .map(|k| b.body.end + 1 + k);
            if let Some(n) = next
                && lines[n].trim_start().starts_with("```text")
            {
                found.push(format!("{doc}:{}", n + 1));
            }
        }
    }
    anyhow::ensure!(
        found.is_empty(),
        "an output shown in a text block after its commands (make them one console block): {found:?}"
    );
    Ok(())
}

fn parser_reads_commands_codes_and_outputs() -> anyhow::Result<()> {
    let md = "intro\n\n```console\n$ sweeptrace check a.mcap \\\n    --json\n? 1\nFAIL a\n...\n$ sweeptrace info b.mcap\nok [..]\n```\n\n```sh\n# a comment\nsweeptrace mesh x.obj   # why\ncargo install --path .\n```\n\n```text\nnot a command\n```\n";
    let b = blocks(md)?;
    anyhow::ensure!(b.len() == 2, "{b:?}");
    let c = &b[0].commands;
    anyhow::ensure!(c.len() == 2, "{c:?}");
    anyhow::ensure!(
        c[0].text == "sweeptrace check a.mcap --json",
        "{:?}",
        c[0].text
    );
    anyhow::ensure!(
        c[0].code == 1 && c[0].output.as_deref() == Some("FAIL a\n...\n"),
        "{:?}",
        c[0]
    );
    anyhow::ensure!(
        c[1].code == 0 && c[1].output.as_deref() == Some("ok [..]\n"),
        "{:?}",
        c[1]
    );
    let s = &b[1].commands;
    anyhow::ensure!(s.len() == 2 && s[0].output.is_none(), "{s:?}");
    anyhow::ensure!(not_run(&s[1].text).is_some() && not_run(&s[0].text).is_none());
    // The matching: `...` for lines, `[..]` within a line; anything else exact.
    anyhow::ensure!(matches("a\n...\nz [..]\n", "a\nb\nc\nz 12 s\n").is_ok());
    anyhow::ensure!(matches("a\nz 12 s\n", "a\nz 13 s\n").is_err());
    Ok(())
}
