//! `git bisect run sweeptrace check TRACE --engine ./engine.py` finds the
//! commit that broke an engine: a throwaway repository whose history
//! introduces a bug into a Python engine at a known commit, with one
//! commit whose engine cannot be started (exit 125: skipped).

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use libtest_mimic::Trial;

use crate::engine::{example_engine, worked_examples_trace};
use crate::{ensure, trial};

pub fn tests() -> Vec<Trial> {
    vec![trial!(
        git_bisect_run_finds_the_commit_that_broke_the_engine,
        timeout = Duration::from_secs(120)
    )]
}

/// Runs git in `repo` with `args`; its stdout, or an error with its output.
fn git(repo: &Path, args: &[&str]) -> anyhow::Result<String> {
    let out = Command::new("git")
        .current_dir(repo)
        .args([
            "-c",
            "commit.gpgsign=false",
            "-c",
            "core.hooksPath=/dev/null",
        ])
        .args(args)
        .env("GIT_CONFIG_NOSYSTEM", "1")
        .env_remove("GIT_DIR")
        .env_remove("GIT_WORK_TREE")
        .output()
        .map_err(|e| anyhow::anyhow!("running git: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() {
        anyhow::bail!(
            "git {}: {}\n{stdout}\n{}",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(stdout)
}

/// Writes `engine.py` (executable) and commits everything with `message`;
/// returns the commit's id.
fn commit(
    repo: &Path,
    engine: Option<&str>,
    executable: bool,
    message: &str,
) -> anyhow::Result<String> {
    let path = repo.join("engine.py");
    if let Some(source) = engine {
        std::fs::write(&path, source)?;
    }
    #[cfg(unix)]
    if path.exists() {
        use std::os::unix::fs::PermissionsExt;
        let mode = if executable { 0o755 } else { 0o644 };
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode))?;
    }
    std::fs::write(repo.join("CHANGES"), format!("{message}\n"))?;
    git(repo, &["add", "-A"])?;
    git(repo, &["commit", "-q", "-m", message])?;
    Ok(git(repo, &["rev-parse", "HEAD"])?.trim().to_string())
}

fn git_bisect_run_finds_the_commit_that_broke_the_engine() -> anyhow::Result<()> {
    if Command::new("git").arg("--version").output().is_err() {
        return Err(anyhow::anyhow!("git is not installed"));
    }
    let dir = tempfile::tempdir()?;
    let repo = dir.path().join("engine-repo");
    std::fs::create_dir(&repo)?;
    let trace = dir.path().join("examples.mcap");
    std::fs::write(&trace, worked_examples_trace())?;
    git(&repo, &["init", "-q"])?;
    git(&repo, &["config", "user.name", "Bisect Test"])?;
    git(&repo, &["config", "user.email", "bisect@example.invalid"])?;

    let good = std::fs::read_to_string(example_engine())?;
    let renamed = good
        .replace("def sweep(", "def sweep_one(")
        .replace("answer = sweep(", "answer = sweep_one(");
    let buggy = renamed.replace(
        "bugs = set(args.bug)",
        "bugs = set(args.bug) | {\"skip-vertex\"}  # vertices are rare: skip them",
    );
    ensure!(
        renamed != good && buggy != renamed,
        "the edits apply to the example engine"
    );
    let with_comment = |s: &str, n: u32| format!("{s}\n# tuning pass {n}\n");

    let first = commit(
        &repo,
        Some(&good),
        true,
        "engine: face, edge and vertex tests",
    )?;
    commit(&repo, Some(&renamed), true, "rename sweep to sweep_one")?;
    commit(&repo, Some(&with_comment(&renamed, 1)), true, "tuning 1")?;
    // The engine cannot be started here (not executable): exit 125, and
    // bisect skips the commit (git's first probe, the middle of the range).
    let unstartable = commit(
        &repo,
        Some(&with_comment(&renamed, 2)),
        false,
        "tuning 2 (lost the executable bit)",
    )?;
    commit(&repo, Some(&with_comment(&renamed, 3)), true, "tuning 3")?;
    let broke = commit(
        &repo,
        Some(&with_comment(&buggy, 3)),
        true,
        "skip the vertex test",
    )?;
    let last = commit(&repo, Some(&with_comment(&buggy, 4)), true, "tuning 4")?;

    git(&repo, &["bisect", "start", &last, &first])?;
    let sweeptrace = env!("CARGO_BIN_EXE_sweeptrace");
    let trace_arg = trace.display().to_string();
    let result = git(
        &repo,
        &[
            "bisect",
            "run",
            sweeptrace,
            "check",
            &trace_arg,
            "--engine",
            "./engine.py",
        ],
    );
    let log = git(&repo, &["bisect", "log"]).unwrap_or_default();
    git(&repo, &["bisect", "reset"])?;
    let out = result?;
    // The unstartable commit, on its own: exit 125.
    git(&repo, &["checkout", "-q", &unstartable])?;
    let status = Command::new(sweeptrace)
        .current_dir(&repo)
        .args(["check", &trace_arg, "--engine", "./engine.py"])
        .output()?
        .status;
    ensure!(
        status.code() == Some(125),
        "the unstartable commit: {status}, want exit 125"
    );
    ensure!(
        out.contains(&format!("{broke} is the first bad commit"))
            && log.contains(&format!("# skip: [{unstartable}]"))
            && log.matches("# skip: ").count() == 1,
        "bisect should name {broke} (\"skip the vertex test\") skipping only {unstartable}:\n{out}\n{log}"
    );
    Ok(())
}
