//! `check`'s settings file, `sweeptrace.toml`, through the binary: a folder
//! of traces passes or fails by its settings with no options, nearer files
//! override farther ones, the command line overrides both, `--print-config`
//! names where each setting came from, and bad files are errors naming
//! their line.

use std::path::{Path, PathBuf};

use libtest_mimic::Trial;

use crate::ensure;
use crate::os;
use crate::support::run_bin_in;
use crate::trial;
use anyhow::Context as _;
use sweeptrace::conventions::Source;
use sweeptrace::judge::{Field, FieldSet, Tolerances};
use sweeptrace::suite::config::{ConfigFile, Overrides, resolve};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(settings_file_makes_a_trace_pass_with_no_options),
        trial!(nearest_file_first_up_to_the_repository_root),
        trial!(command_line_overrides_the_file),
        trial!(print_config_names_the_source_of_each_setting),
        trial!(bad_key_is_an_error_with_file_and_line),
        trial!(bad_values_are_errors_with_file_and_line),
        trial!(repository_traces_and_examples_pass_with_no_options),
        trial!(regression_md_example_is_a_valid_file),
        trial!(named_config_replaces_discovery_and_its_exclude_applies),
        trial!(declared_margin_too_large_is_the_settings_fault_said_once),
        trial!(dangling_symlink_is_left_out_with_a_note),
        trial!(settings_files_are_parsed_once_per_run),
    ]
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A throwaway repository (`.git` at its root) holding the Rapier sample at
/// `suite/rapier.mcap`: it fails with the default settings (its normals
/// and α differ from the core's by design) and passes with
/// `fields = ["kind", "alpha"]` and an α tolerance of 1e-5.
fn repository() -> anyhow::Result<(tempfile::TempDir, PathBuf)> {
    let dir = tempfile::tempdir()?;
    let repo = dir.path().join("repo");
    let suite = repo.join("suite");
    std::fs::create_dir_all(repo.join(".git"))?;
    std::fs::create_dir_all(&suite)?;
    std::fs::copy(
        root().join("examples/rapier/rapier_mini_golf.mcap"),
        suite.join("rapier.mcap"),
    )?;
    Ok((dir, repo))
}

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

const PASSING: &str = "fields = [\"kind\", \"alpha\"]\n\n[tolerances]\nalpha = 1e-5\n";

fn settings_file_makes_a_trace_pass_with_no_options() -> anyhow::Result<()> {
    let (_dir, repo) = repository()?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(code == 1, "no settings file: exit {code}: {out}{err}");
    write(&repo.join("suite/sweeptrace.toml"), PASSING)?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(
        code == 0 && out.contains("fields compared: kind,alpha"),
        "with the settings file: exit {code}: {out}{err}"
    );
    // A file argument: its folder's file applies too.
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite/rapier.mcap"])?;
    ensure!(code == 0, "a file argument: exit {code}: {out}{err}");
    // --no-config ignores it.
    let (code, out, err) = run_bin_in(&repo, os!["check", "--no-config", "suite"])?;
    ensure!(code == 1, "--no-config: exit {code}: {out}{err}");
    // A [[traces]] block applies to the traces its glob matches only.
    write(
        &repo.join("sweeptrace.toml"),
        "[[traces]]\nmatch = \"suite/*.mcap\"\nfields = [\"kind\", \"alpha\"]\n\
         tolerances = { alpha = 1e-5 }\n\n[[traces]]\nmatch = \"other/*.mcap\"\nstrict = true\n",
    )?;
    std::fs::remove_file(repo.join("suite/sweeptrace.toml"))?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(
        code == 0,
        "a matching [[traces]] block: exit {code}: {out}{err}"
    );
    write(
        &repo.join("sweeptrace.toml"),
        "[[traces]]\nmatch = \"elsewhere/*.mcap\"\nfields = [\"kind\", \"alpha\"]\n\
         tolerances = { alpha = 1e-5 }\n",
    )?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(code == 1, "no matching block: exit {code}: {out}{err}");
    Ok(())
}

fn nearest_file_first_up_to_the_repository_root() -> anyhow::Result<()> {
    let (dir, repo) = repository()?;
    // Above the repository root: never read (it would be an error).
    write(&dir.path().join("sweeptrace.toml"), "not = [valid\n")?;
    write(&repo.join("sweeptrace.toml"), PASSING)?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(code == 0, "the root's file: exit {code}: {out}{err}");
    // The nearer file's α tolerance wins; the fields still come from the
    // farther one.
    write(
        &repo.join("suite/sweeptrace.toml"),
        "# tighter\n[tolerances]\nalpha = 1e-6\n",
    )?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(
        code == 1 && out.contains("fields compared: kind,alpha") && out.contains("alpha: expected"),
        "the nearer file: exit {code}: {out}{err}"
    );
    let (code, out, err) = run_bin_in(&repo, os!["check", "--print-config", "suite"])?;
    ensure!(code == 0, "--print-config: exit {code}: {out}{err}");
    ensure!(
        setting_line(&out, "tolerances.alpha")?.ends_with("# suite/sweeptrace.toml:3")
            && setting_line(&out, "fields")?.ends_with("# sweeptrace.toml:1"),
        "{out}"
    );
    // Files under the working directory are named relative to it, the
    // others by their full path.
    let (code, out, err) = run_bin_in(&repo.join("suite"), os!["check", "--print-config", "."])?;
    let alpha = setting_line(&out, "tolerances.alpha")?;
    let fields = setting_line(&out, "fields")?;
    ensure!(
        code == 0
            && alpha.ends_with("# sweeptrace.toml:3")
            && fields.contains("# /")
            && fields.ends_with("repo/sweeptrace.toml:1"),
        "from the suite's folder: exit {code}: {out}{err}"
    );
    Ok(())
}

/// The line of `--print-config`'s text output that gives `key`.
fn setting_line<'a>(out: &'a str, key: &str) -> anyhow::Result<&'a str> {
    out.lines()
        .find(|l| l.trim_start().starts_with(&format!("{key} = ")))
        .with_context(|| format!("no `{key}` in:\n{out}"))
}

fn command_line_overrides_the_file() -> anyhow::Result<()> {
    let (_dir, repo) = repository()?;
    write(
        &repo.join("suite/sweeptrace.toml"),
        &format!("{PASSING}strict = true\n"),
    )?;
    // `strict` after a table is the table's key: an unknown tolerance.
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(
        code == 2 && err.contains("suite/sweeptrace.toml:5:1: unknown key `strict`"),
        "exit {code}: {out}{err}"
    );
    write(
        &repo.join("suite/sweeptrace.toml"),
        &format!("strict = true\n{PASSING}"),
    )?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(code == 0, "the file: exit {code}: {out}{err}");
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite", "--tolerance", "1e-6"])?;
    ensure!(
        code == 1 && out.contains("alpha: expected"),
        "--tolerance over the file: exit {code}: {out}{err}"
    );
    let (code, out, err) = run_bin_in(
        &repo,
        os!["check", "suite", "--fields", "kind,alpha,normal"],
    )?;
    ensure!(
        code == 1 && out.contains("normal: expected"),
        "--fields over the file: exit {code}: {out}{err}"
    );
    let (code, out, err) = run_bin_in(
        &repo,
        os![
            "check",
            "--strict=false",
            "--allow-tunnels",
            "--print-config",
            "suite"
        ],
    )?;
    ensure!(
        code == 0
            && setting_line(&out, "strict")?.contains("strict = false")
            && setting_line(&out, "strict")?.ends_with("# command line")
            && setting_line(&out, "allow_tunnels")?.contains("= true")
            && setting_line(&out, "allow_tunnels")?.ends_with("# command line"),
        "--strict=false: exit {code}: {out}{err}"
    );
    // A bare flag takes no value: the path after it is a path.
    let (code, out, err) = run_bin_in(&repo, os!["check", "--strict", "suite"])?;
    ensure!(code == 0, "--strict: exit {code}: {out}{err}");
    Ok(())
}

fn print_config_names_the_source_of_each_setting() -> anyhow::Result<()> {
    let (_dir, repo) = repository()?;
    write(&repo.join("suite/sweeptrace.toml"), PASSING)?;
    let (code, out, err) = run_bin_in(
        &repo,
        os![
            "check",
            "suite",
            "--print-config",
            "--contact-tolerance",
            "0.5"
        ],
    )?;
    ensure!(code == 0, "exit {code}: {out}{err}");
    // No check ran: no report line.
    ensure!(!out.contains("ok ") && !out.contains("FAIL"), "{out}");
    ensure!(out.lines().next() == Some("suite/rapier.mcap"), "{out}");
    for (key, value, source) in [
        ("tolerances.alpha", "1e-5", "suite/sweeptrace.toml:4"),
        ("tolerances.normal_degrees", "0.01", "default"),
        ("tolerances.contact", "0.5", "command line"),
        ("fields", "[\"kind\", \"alpha\"]", "suite/sweeptrace.toml:1"),
        ("strict", "false", "default"),
        ("allow_tunnels", "false", "default"),
    ] {
        let line = setting_line(&out, key)?;
        ensure!(
            line.contains(&format!("{key} = {value} ")) && line.ends_with(&format!("# {source}")),
            "{key}: {line}\n{out}"
        );
    }
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite", "--print-config", "--json"])?;
    ensure!(code == 0, "--json: exit {code}: {out}{err}");
    let json: serde_json::Value =
        serde_json::from_str(&out).map_err(|e| anyhow::anyhow!("{e}: {out}"))?;
    let trace = &json["traces"][0];
    ensure!(trace["trace"] == "suite/rapier.mcap", "{json}");
    ensure!(
        trace["settings"]["fields"]["value"] == serde_json::json!(["kind", "alpha"])
            && trace["settings"]["fields"]["source"]
                == serde_json::json!({"kind": "file", "file": "suite/sweeptrace.toml", "line": 1})
            && trace["settings"]["tolerances.alpha"]["value"] == 1e-5
            && trace["settings"]["strict"]["source"]["kind"] == "default",
        "{json}"
    );
    Ok(())
}

fn bad_key_is_an_error_with_file_and_line() -> anyhow::Result<()> {
    let (_dir, repo) = repository()?;
    write(
        &repo.join("suite/sweeptrace.toml"),
        "fields = [\"kind\"]\n\n[tolerances]\nalfa = 1e-5\n",
    )?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(
        code == 2
            && out.is_empty()
            && err.contains("suite/sweeptrace.toml:4:1: unknown key `alfa`")
            && err.contains("`normal_degrees`"),
        "exit {code}: {out}{err}"
    );
    // --print-config reads the files too; --no-config does not.
    let (code, _, err) = run_bin_in(&repo, os!["check", "--print-config", "suite"])?;
    ensure!(
        code == 2 && err.contains("unknown key `alfa`"),
        "exit {code}: {err}"
    );
    let (code, out, err) = run_bin_in(&repo, os!["check", "--no-config", "suite"])?;
    ensure!(code == 1, "--no-config: exit {code}: {out}{err}");
    Ok(())
}

fn bad_values_are_errors_with_file_and_line() -> anyhow::Result<()> {
    let (_dir, repo) = repository()?;
    for (text, message) in [
        (
            "[tolerances]\nalpha = -1e-5\n",
            "suite/sweeptrace.toml:2:9: `tolerances.alpha` must be a finite number ≥ 0, got -0.00001",
        ),
        (
            "fields = [\"kind\", \"colour\"]\n",
            "suite/sweeptrace.toml:1:19: unknown field `colour` in `fields`; \
             the fields are kind, triangle, feature, alpha, normal, contact",
        ),
        (
            "[[traces]]\nmatch = \"*.mcap\"\nallow_tunnels = \"yes\"\n",
            "suite/sweeptrace.toml:3:17: invalid type: string \"yes\", expected a boolean",
        ),
        (
            "[[traces]]\nmatch = \"{a,b\"\n",
            "suite/sweeptrace.toml:2:9: `match`: `{a,b` is not a glob",
        ),
    ] {
        write(&repo.join("suite/sweeptrace.toml"), text)?;
        let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
        ensure!(
            code == 2 && err.contains(message),
            "{text:?}: exit {code}: {out}{err}"
        );
        // Said once.
        ensure!(err.lines().count() == 1, "{err}");
    }
    Ok(())
}

/// The repository's own traces and examples pass with no options: the
/// Rapier sample by `examples/sweeptrace.toml`.
fn repository_traces_and_examples_pass_with_no_options() -> anyhow::Result<()> {
    let (code, out, err) = run_bin_in(root(), os!["check", "traces/", "examples/"])?;
    ensure!(code == 0, "exit {code}: {out}{err}");
    ensure!(
        out.contains("ok examples/rapier/rapier_mini_golf.mcap")
            && !out.contains("fields compared")
            && out.contains("judged under the engine's declared conventions: normal contact"),
        "{out}"
    );
    let (code, out, err) = run_bin_in(root(), os!["check", "--print-config", "examples/rapier/"])?;
    ensure!(
        code == 0
            && setting_line(&out, "tolerances.alpha")?.ends_with("# examples/sweeptrace.toml:19"),
        "exit {code}: {out}{err}"
    );
    Ok(())
}

/// The full example of docs/REGRESSION.md parses, and means what the text
/// around it says.
fn regression_md_example_is_a_valid_file() -> anyhow::Result<()> {
    let doc = std::fs::read_to_string(root().join("docs/REGRESSION.md"))?;
    let start = doc
        .find("```toml\n# traces/sweeptrace.toml")
        .context("no example in docs/REGRESSION.md")?
        + "```toml\n".len();
    let end = start + doc[start..].find("```").context("unterminated example")?;
    let file = ConfigFile::parse(&doc[start..end], Path::new("traces/sweeptrace.toml"))?;
    let files = std::slice::from_ref(&file);
    let none = Overrides::default();
    // Its top level spells out the defaults.
    let plain = resolve(files, Path::new("traces/a.mcap"), &none);
    ensure!(plain.tolerances() == Tolerances::default(), "{plain:?}");
    ensure!(
        !plain.strict.value && !plain.allow_tunnels.value,
        "{plain:?}"
    );
    let rapier = resolve(files, Path::new("traces/rapier/a.mcap"), &none);
    ensure!(
        rapier.alpha.value == 1e-5
            && rapier.contact.value == 1e-5
            && !rapier.fields.value.contains(Field::Normal)
            && rapier.fields.value != FieldSet::ALL,
        "{rapier:?}"
    );
    let legacy = resolve(files, Path::new("traces/old/deeper/legacy_1.mcap"), &none);
    ensure!(
        legacy.strict.value && matches!(legacy.strict.source, Source::File { .. }),
        "{legacy:?}"
    );
    Ok(())
}

/// A copy of the cube sample (balls of radius 0.25) at `suite/cube.mcap` of
/// a throwaway repository.
fn cube_suite() -> anyhow::Result<(tempfile::TempDir, PathBuf)> {
    let dir = tempfile::tempdir()?;
    let repo = dir.path().join("repo");
    std::fs::create_dir_all(repo.join(".git"))?;
    std::fs::create_dir_all(repo.join("suite/scratch"))?;
    std::fs::copy(
        root().join("traces/record_cube_corner_margin.mcap"),
        repo.join("suite/cube.mcap"),
    )?;
    Ok((dir, repo))
}

/// `check DIR --config FILE` takes its settings from FILE only: the files
/// found beside and above the traces are not read at all (a broken one
/// does not stop the run), and FILE's own `exclude` leaves files out, as
/// `--help` says (issue 43, item 7).
fn named_config_replaces_discovery_and_its_exclude_applies() -> anyhow::Result<()> {
    let (_dir, repo) = cube_suite()?;
    // Not a trace: checked, it is an error.
    write(&repo.join("suite/scratch/notes.mcap"), "not a trace\n")?;
    // A broken file where discovery would find it.
    write(&repo.join("suite/sweeptrace.toml"), "exclude = [\n")?;
    write(&repo.join("suite/ci.toml"), "exclude = [\"scratch/**\"]\n")?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite", "--config", "suite/ci.toml"])?;
    ensure!(
        code == 0 && out.contains("ok suite/cube.mcap") && !out.contains("notes.mcap"),
        "exit {code}\n{out}{err}"
    );
    ensure!(
        err.contains("left out 1 file")
            && err.contains("suite/scratch/notes.mcap (`scratch/**` in suite/ci.toml)")
            && !err.contains("suite/sweeptrace.toml"),
        "{err}"
    );
    // --print-config names the named file, never the discovered one.
    let (code, out, err) = run_bin_in(
        &repo,
        os![
            "check",
            "suite",
            "--config",
            "suite/ci.toml",
            "--print-config"
        ],
    )?;
    ensure!(
        code == 0 && !out.contains("suite/sweeptrace.toml") && !out.contains("notes.mcap"),
        "exit {code}\n{out}{err}"
    );
    // Without --config the broken file is read, and stops the run.
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    ensure!(
        code == 2 && err.contains("suite/sweeptrace.toml:"),
        "exit {code}\n{out}{err}"
    );
    Ok(())
}

/// An `[engine]` margin that is not smaller than the balls' radius (0.3
/// for balls of 0.25) is the settings file's fault: one error naming the
/// file, line and key, the run stops with exit 2, and no sweep is blamed
/// (before: an error per sweep of the trace and 122 "expectations without
/// a sweep"). Numbers print in their shortest form (`1e308`, not 309
/// digits). `replay` and `bless` say the same (issue 43, item 8).
fn declared_margin_too_large_is_the_settings_fault_said_once() -> anyhow::Result<()> {
    let (_dir, repo) = cube_suite()?;
    std::fs::copy(
        root().join("traces/record_cube_corner_margin.mcap"),
        repo.join("suite/cube2.mcap"),
    )?;
    write(
        &repo.join("suite/sweeptrace.toml"),
        "# the engine's margin\n[engine]\nmargin = 0.3\n",
    )?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite"])?;
    let all = format!("{out}{err}");
    let said = "suite/sweeptrace.toml:3: engine.margin = 0.3 must be smaller than the radius of every ball it applies to: suite/cube.mcap has a ball of radius 0.25 (frame 0, ball 0)";
    ensure!(
        code == 2 && all.matches(said).count() == 1,
        "exit {code}\n{all}"
    );
    ensure!(
        !all.contains("cube2.mcap")
            && !all.contains("expectations without a sweep")
            && all.matches("must be smaller").count() == 1,
        "the run did not stop at the first fault, or blamed sweeps:\n{all}"
    );
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite/cube.mcap", "--json"])?;
    let v: serde_json::Value =
        serde_json::from_str(&out).with_context(|| format!("not JSON: {out}{err}"))?;
    ensure!(
        code == 2
            && v["exit_code"] == 2
            && v["traces"][0]["errors"].as_array().map(Vec::len) == Some(1)
            && v["traces"][0]["errors"][0]
                .as_str()
                .is_some_and(|e| e.starts_with("suite/sweeptrace.toml:3: engine.margin = 0.3")),
        "exit {code}\n{out}{err}"
    );
    for command in [
        os!["replay", "suite/cube.mcap", "--outcomes", "o.jsonl"].to_vec(),
        os!["bless", "suite/cube.mcap", "-o", "b.mcap"].to_vec(),
        os![
            "sweep",
            "--trace",
            "suite/cube.mcap",
            "--frame",
            "0",
            "--ball",
            "0"
        ]
        .to_vec(),
    ] {
        let (code, out, err) = run_bin_in(&repo, &command)?;
        ensure!(
            code == 2
                && err
                    .matches("suite/sweeptrace.toml:3: engine.margin = 0.3 must be smaller")
                    .count()
                    == 1
                && !repo.join("o.jsonl").exists()
                && !repo.join("b.mcap").exists(),
            "{command:?}: exit {code}\n{out}{err}"
        );
    }
    // From the command line: the flag is named.
    let (code, out, err) = run_bin_in(
        &repo,
        os![
            "check",
            "suite/cube.mcap",
            "--no-config",
            "--engine-margin",
            "0.25"
        ],
    )?;
    ensure!(
        code == 2 && err.contains("--engine-margin 0.25 must be smaller than the radius"),
        "exit {code}\n{out}{err}"
    );
    // A huge margin prints as written.
    write(
        &repo.join("suite/sweeptrace.toml"),
        "[engine]\nmargin = 1e308\n",
    )?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "suite/cube.mcap"])?;
    ensure!(
        code == 2
            && err.contains("engine.margin = 1e308 must be smaller")
            && !err.contains("00000000"),
        "exit {code}\n{out}{err}"
    );
    let (code, out, err) = run_bin_in(
        &repo,
        os![
            "check",
            "suite/cube.mcap",
            "--engine",
            "true",
            "--engine-timeout",
            "1e300"
        ],
    )?;
    ensure!(
        code == 2 && err.contains("got 1e300") && !err.contains("00000000"),
        "exit {code}\n{out}{err}"
    );
    Ok(())
}

/// A symbolic link whose target does not exist, in a folder `check`
/// searches, is left out with a note, as a file that is not a trace; the
/// rest is checked (before: "cannot list the directory", exit 2) (issue
/// 43, item 9).
fn dangling_symlink_is_left_out_with_a_note() -> anyhow::Result<()> {
    let (_dir, repo) = cube_suite()?;
    std::os::unix::fs::symlink("gone.mcap", repo.join("suite/link.mcap"))?;
    std::os::unix::fs::symlink("nowhere", repo.join("suite/scratch/dir"))?;
    let (code, out, err) = run_bin_in(&repo, os!["check", "."])?;
    ensure!(
        code == 0 && out.contains("ok ./suite/cube.mcap"),
        "exit {code}\n{out}{err}"
    );
    ensure!(
        err.contains(
            "note: left out 2 symbolic links whose target does not exist: ./suite/link.mcap, ./suite/scratch/dir"
        ),
        "{err}"
    );
    Ok(())
}

/// One run reads each settings file once, however many traces and folders
/// share it ([`sweeptrace::suite::config::ConfigFiles`]); the places of its keys
/// are the same as from counting lines (issue 43, item 6; the timing is
/// the `settings` benchmark's).
fn settings_files_are_parsed_once_per_run() -> anyhow::Result<()> {
    let (_dir, repo) = cube_suite()?;
    std::fs::create_dir_all(repo.join("suite/a/b"))?;
    let blocks: String = (0..50)
        .map(|i| {
            format!(
                "\n[[traces]]\nmatch = \"suite/a/t{i}.mcap\"\ntolerances = {{ alpha = 1e-{} }}\n",
                i % 9 + 1
            )
        })
        .collect();
    write(
        &repo.join("sweeptrace.toml"),
        &format!("strict = true\n{blocks}"),
    )?;
    write(
        &repo.join("suite/a/sweeptrace.toml"),
        "allow_tunnels = true\n",
    )?;
    let mut files = sweeptrace::suite::config::ConfigFiles::new();
    let mut sources = Vec::new();
    for trace in [
        "suite/cube.mcap",
        "suite/a/t7.mcap",
        "suite/a/t8.mcap",
        "suite/a/b/t.mcap",
    ] {
        let settings = files.settings_for(&repo.join(trace), &Overrides::default())?;
        sources.push(settings.alpha.source.to_string());
    }
    ensure!(files.parsed() == 2, "{} files parsed", files.parsed());
    ensure!(
        sources[0] == "default"
            && sources[1].ends_with("repo/sweeptrace.toml:33")
            && sources[2].ends_with("repo/sweeptrace.toml:37"),
        "{sources:?}"
    );
    Ok(())
}
