//! A second real single-precision engine: Rapier
//! (`examples/engines/rapier-js/`, the npm package
//! `@dimforge/rapier3d-compat` 0.21.0 in Node) over the engine protocol,
//! with the `[engine]` table `check --infer-config` wrote for it
//! (`examples/engines/rapier-js/sweeptrace.toml`).
//!
//! Under its inferred table (a declared accuracy of 2^17 units for its
//! solver's tolerance, `initial_overlap = "alpha0_always"` for its
//! `stopAtPenetration` starts, `normal = "contact"`, `sides = "two"`), 10 sample sweeps
//! still fail, each a genuine limitation; these tests hold the adapter and
//! the judgement to that: every sweep answered, the triangle of each hit
//! recovered, the misses `conform` asks for answered as misses, the
//! `stopAtPenetration` switch working, limitations named, and faults
//! reported. Needs `node` and the package
//! (`npm ci --prefix examples/engines/rapier-js`): skipped without them, a
//! failure when `SWEEPTRACE_REQUIRE_NODE=1` (CI).

use anyhow::ensure;
use libtest_mimic::{Completion, Trial};

use crate::support::run_bin;
use crate::{os, trial};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(rapier_answers_every_sample_sweep_within_its_measured_failures),
        trial!(rapier_stop_at_penetration_switch_changes_the_starts_only),
        trial!(rapier_passes_the_miss_rules_of_conform_under_its_table),
        trial!(rapier_without_stop_at_penetration_fails_only_named_limitations_and_conforms),
        trial!(rapiers_contacts_match_and_its_seam_ghosts_are_listed),
        trial!(rapier_fails_conforms_must_not_push_contact_rules_with_ghosts),
        trial!(rapier_config_is_what_infer_config_prints),
        trial!(rapier_engine_faults_are_errors),
        trial!(a_tie_member_is_reported_by_what_differs_from_it),
        trial!(rapiers_limitations_are_named_when_they_fail),
    ]
}

/// The engine command, or the reason to skip.
fn rapier() -> anyhow::Result<Result<String, Completion>> {
    crate::support::node_engine("rapier-js", "@dimforge/rapier3d-compat")
}

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn config() -> String {
    root()
        .join("examples/engines/rapier-js/sweeptrace.toml")
        .display()
        .to_string()
}

fn traces() -> String {
    root().join("traces").display().to_string()
}

/// sweeptrace with `args` and `--json`, with `env` set: exit code and the
/// parsed report.
fn run_json(args: &[&str], env: &[(&str, &str)]) -> anyhow::Result<(i32, serde_json::Value)> {
    let mut command = crate::support::bin();
    command.args(args).arg("--json");
    for (key, value) in env {
        command.env(key, value);
    }
    let out = command.output()?;
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).map_err(|e| {
        anyhow::anyhow!(
            "{} --json: {e}: {}",
            args.first().unwrap_or(&""),
            String::from_utf8_lossy(&out.stderr)
        )
    })?;
    Ok((out.status.code().unwrap_or(-1), report))
}

fn traces_of(report: &serde_json::Value) -> Vec<serde_json::Value> {
    report["traces"].as_array().cloned().unwrap_or_default()
}

/// The divergences of a check's report that no known limitation names.
fn unnamed_divergences(report: &serde_json::Value) -> Vec<String> {
    traces_of(report)
        .iter()
        .flat_map(|t| t["divergences"].as_array().cloned().unwrap_or_default())
        .filter(|d| d["limitation"].as_str().is_none_or(str::is_empty))
        .map(|d| format!("frame {}, ball {}", d["frame"], d["ball"]))
        .collect()
}

/// `check` of the sample traces with `engine` under `config`, every
/// divergence detailed: the JSON report (exit 0 or 1 asked).
fn check_samples(engine: &str, config: &str) -> anyhow::Result<serde_json::Value> {
    let traces = traces();
    let args = [
        "check",
        &traces,
        "--engine",
        engine,
        "--config",
        config,
        "--max-details",
        "100000",
    ];
    let (code, report) = run_json(&args, &[])?;
    ensure!(code == 0 || code == 1, "exit {code}: {report}");
    Ok(report)
}

fn sum(report: &serde_json::Value, key: &str) -> u64 {
    traces_of(report)
        .iter()
        .map(|t| t[key].as_u64().unwrap_or(0))
        .sum()
}

/// Under its table, measured (examples/engines/rapier-js/README.md): 10 of
/// 6,427 sweeps fail (its genuine limitations: seam bumps, grazing false
/// hits, a hit past the path's end, ...), the rest of its differences
/// within its declared accuracy (2^17 units: its solver's tolerance). An
/// adapter that lost the triangle, the contact or the normal (or Rapier's
/// hits) would fail on most of the 1,800 hits.
fn rapier_answers_every_sample_sweep_within_its_measured_failures() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let report = check_samples(&engine, &config())?;
    let all = traces_of(&report);
    ensure!(all.len() == 5, "{report}");
    ensure!(
        all.iter()
            .all(|t| t["compared"] == t["sweeps"]
                && t["errors"].as_array().is_none_or(Vec::is_empty)),
        "every sweep answered and compared: {report}"
    );
    let (failing, within) = (
        sum(&report, "divergent"),
        sum(&report, "precision_divergent"),
    );
    ensure!(
        failing <= 12,
        "{failing} failing sweeps (measured 9 of 6,427)"
    );
    // Each one is Rapier's own, named in words (issue 47's done-when).
    let unnamed = unnamed_divergences(&report);
    ensure!(
        unnamed.is_empty(),
        "failing sweeps that no known limitation names: {unnamed:?}"
    );
    ensure!(
        within >= 1000,
        "{within} differences within the declared accuracy (measured 1,676)"
    );
    let other_triangle = all
        .iter()
        .flat_map(|t| t["divergences"].as_array().cloned().unwrap_or_default())
        .filter(|d| {
            d["expected"]["alpha"].as_f64().is_some_and(|a| a > 0.0)
                && d["got"]["kind"] != "none"
                && d["fields"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .any(|f| f["field"] == "triangle")
        })
        .count();
    ensure!(
        other_triangle <= 40,
        "{other_triangle} hits at α > 0 name another triangle than the core's (measured 18)"
    );
    ensure!(
        all.iter().all(|t| t["conventions"]["precision"] == "f32"
            && t["conventions"]["initial_overlap"] == "alpha0_always"
            && t["conventions"]["normal"] == "contact"
            && t["conventions"]["sides"] == "two"
            && t["conventions"]["accuracy"] == 131072.0),
        "the reports name the conventions: {report}"
    );
    Ok(Completion::Completed)
}

/// `--no-stop-at-penetration` and `RAPIER_STOP_AT_PENETRATION=false` are
/// one switch: under the rules (every hit fails, so the failing count is
/// the count of hits) the default hits 414 bowl sweeps and the switched
/// engine 323, the starts that leave the bowl no longer hits.
fn rapier_stop_at_penetration_switch_changes_the_starts_only() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let bowl = root()
        .join("traces/record_bowl_margin.mcap")
        .display()
        .to_string();
    let hits = |engine: &str, env: &[(&str, &str)]| -> anyhow::Result<u64> {
        let (code, report) = run_json(&["check", &bowl, "--engine", engine, "--no-config"], env)?;
        ensure!(code == 1, "exit {code}: {report}");
        Ok(sum(&report, "divergent"))
    };
    let default = hits(&engine, &[])?;
    let flag = hits(&format!("{engine} --no-stop-at-penetration"), &[])?;
    let env = hits(&engine, &[("RAPIER_STOP_AT_PENETRATION", "false")])?;
    ensure!(
        flag == env,
        "the flag ({flag}) and the environment ({env}) differ"
    );
    ensure!(
        flag + 50 < default && flag > 200,
        "stopAtPenetration false: {flag} hits, true: {default} (measured 323 and 414)"
    );
    Ok(Completion::Completed)
}

/// `conform` under the table: no fault of the engine, the 15 rules its
/// conventions replace listed n/a, and every rule that asks for a miss
/// passes (measured: 11 pass, 32 within the declared accuracy, only
/// `path.zero-length` fails: Rapier answers no hit for a ball that starts
/// overlapping and does not move, where `alpha0_always` asks for one).
fn rapier_passes_the_miss_rules_of_conform_under_its_table() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let config = config();
    let (code, report) = run_json(&["conform", "--engine", &engine, "--config", &config], &[])?;
    ensure!(code == 0 || code == 1, "exit {code}: {report}");
    let rules = report["rules"].as_array().cloned().unwrap_or_default();
    let rule = |name: &str| rules.iter().find(|r| r["rule"] == name).cloned();
    for name in [
        "face.miss.outside-triangle",
        "face.miss.beyond-end",
        "face.miss.parallel",
        "edge.miss.no-real-roots",
        "edge.miss.beyond-end",
        "vertex.miss.no-real-roots",
        "vertex.miss.beyond-end",
    ] {
        let r = rule(name).ok_or_else(|| anyhow::anyhow!("no rule {name}: {report}"))?;
        ensure!(
            r["failed"] == 0 && r["passed"].as_u64() > Some(0),
            "{name} fails: {r}"
        );
    }
    let not_applicable = rules
        .iter()
        .filter(|r| r["not_applicable"].is_string())
        .count();
    ensure!(
        not_applicable == 15
            && rule("start.inside").is_some_and(|r| r["not_applicable"].is_string())
            && rule("margin.face-hit").is_some_and(|r| r["not_applicable"].is_string()),
        "the rules its conventions replace: {not_applicable} n/a in {report}"
    );
    Ok(Completion::Completed)
}

fn rapier_config_is_what_infer_config_prints() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let (code, stdout, stderr) = run_bin(os![
        "check",
        &traces(),
        "--engine",
        &engine,
        "--infer-config"
    ])?;
    ensure!(code == 0, "{stderr}");
    let parsed: toml::Table = toml::from_str(&stdout)?;
    let committed: toml::Table = toml::from_str(&std::fs::read_to_string(config())?)?;
    ensure!(
        parsed["engine"] == committed["engine"],
        "the committed table is not what --infer-config prints now:\n{stdout}"
    );
    Ok(Completion::Completed)
}

/// The engine's faults reach sweeptrace as faults (exit 2), with the
/// engine's own message: a sweep before any scene, and a bad value of
/// `RAPIER_STOP_AT_PENETRATION`.
fn rapier_engine_faults_are_errors() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let script = root().join("examples/engines/rapier-js/engine.js");
    let mut child = std::process::Command::new("node")
        .arg(&script)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()?;
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().expect("piped");
        stdin.write_all(
            b"{\"type\":\"sweep\",\"frame\":3,\"ball\":1,\"radius\":0.5,\"p0\":[0,0,1],\"p1\":[0,0,-1]}\n",
        )?;
    }
    let out = child.wait_with_output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    ensure!(
        out.status.code() == Some(2)
            && stderr.contains("the sweep of frame 3, ball 1 arrived before any scene"),
        "a sweep before any scene: {:?}, {stderr}",
        out.status.code()
    );
    let box_trace = root()
        .join("traces/record_box_strict.mcap")
        .display()
        .to_string();
    let out = crate::support::bin()
        .args(["check", &box_trace, "--engine", &engine, "--no-config"])
        .env("RAPIER_STOP_AT_PENETRATION", "maybe")
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    ensure!(
        out.status.code() == Some(2) && text.contains("RAPIER_STOP_AT_PENETRATION=maybe"),
        "a bad RAPIER_STOP_AT_PENETRATION: exit {:?}\n{text}",
        out.status.code()
    );
    Ok(Completion::Completed)
}

/// Issue 47's report faults, on Rapier's answer to bowl frame 0, ball 1 (a
/// ball starting within ρ of a face and of a concave edge; Rapier names
/// the edge with its contact normal): the report compares it with the
/// initial contact it names (only the normal differs, a ghost), lists the
/// core's initial contacts under "the core found", and explains the edge's
/// test by the declared `initial_overlap`, not by the rules.
fn a_tie_member_is_reported_by_what_differs_from_it() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let (_, text) = one_sweep_held_to_16(&engine, "record_bowl_margin.mcap", "0", "1")?;
    ensure!(
        text.contains("frame 0, ball 1: normal differs"),
        "the tie member's difference: {text}"
    );
    ensure!(
        !text.contains("kind: engine edge, core face"),
        "not a kind mismatch against the primary: {text}"
    );
    ensure!(
        text.contains("primary: initial contact: face 286")
            && text.contains("also at α = 0: initial contact: edge 255.1"),
        "the core's initial contacts: {text}"
    );
    ensure!(
        text.contains("under initial_overlap = alpha0_always an initial contact at α = 0, tied"),
        "the engine's test explained by the convention: {text}"
    );
    Ok(Completion::Completed)
}

/// Issue 47: held to single precision's 16 units, Rapier's false hit while
/// leaving at a grazing angle (mini golf frame 77, ball 1), its hit past
/// the path's end (bowl frame 218, ball 2) and a seam bump (bowl frame 95,
/// ball 1, which fails under its own table too) fail, each named in words.
fn rapiers_limitations_are_named_when_they_fail() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    for (trace, frame, ball, named) in [
        (
            "record_mini_golf.mcap",
            "77",
            "1",
            "named: a false hit while leaving at a grazing angle",
        ),
        (
            "record_bowl_margin.mcap",
            "218",
            "2",
            "named: a hit past the path's end",
        ),
        (
            "record_bowl_margin.mcap",
            "95",
            "1",
            "named: a seam bump (an early hit at an internal flat or concave place)",
        ),
    ] {
        let (code, text) = one_sweep_held_to_16(&engine, trace, frame, ball)?;
        ensure!(code == 1 && text.contains(named), "exit {code}: {text}");
    }
    Ok(Completion::Completed)
}

/// `check` of one sweep of a sample trace (`frame`, `ball`) against Rapier
/// under its table but held to single precision's 16 units: exit code and
/// text.
fn one_sweep_held_to_16(
    engine: &str,
    trace: &str,
    frame: &str,
    ball: &str,
) -> anyhow::Result<(i32, String)> {
    let trace = root().join("traces").join(trace).display().to_string();
    let config = config();
    let args = [
        "check",
        &trace,
        "--frames",
        frame,
        "--ball",
        ball,
        "--engine",
        engine,
        "--config",
        &config,
        "--accuracy",
        "16",
    ];
    let args: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
    let (code, text, _) = run_bin(&args)?;
    Ok((code, text))
}

/// Issue 47: the same engine with `stopAtPenetration` false, under the
/// table `--infer-config` wrote for it
/// (examples/engines/rapier-js/no-stop-at-penetration.toml: the other
/// initial overlap, `alpha0_deeper`): measured 8 of 6,427 sweeps fail, each
/// named (seam bumps, grazing false hits), and `conform` passes every rule
/// its conventions do not replace.
fn rapier_without_stop_at_penetration_fails_only_named_limitations_and_conforms()
-> anyhow::Result<Completion> {
    let default = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let engine = format!("{default} --no-stop-at-penetration");
    let config = root()
        .join("examples/engines/rapier-js/no-stop-at-penetration.toml")
        .display()
        .to_string();
    let report = check_samples(&engine, &config)?;
    let failing = sum(&report, "divergent");
    ensure!(
        failing <= 12,
        "{failing} failing sweeps (measured 8 of 6,427)"
    );
    let unnamed = unnamed_divergences(&report);
    ensure!(
        unnamed.is_empty(),
        "failing sweeps that no known limitation names: {unnamed:?}"
    );
    ensure!(
        traces_of(&report)
            .iter()
            .all(|t| t["conventions"]["initial_overlap"] == "alpha0_deeper"),
        "judged under alpha0_deeper: {report}"
    );
    // The value tells the two engines apart: the default engine (a hit at
    // α = 0 whatever the direction) judged under this table fails its
    // starts that leave the contact (measured 71 against 8).
    let other = sum(&check_samples(&default, &config)?, "divergent");
    ensure!(
        other > failing + 50,
        "stopAtPenetration true under alpha0_deeper: {other} failing, false: {failing}"
    );
    let (code, conform) = run_json(&["conform", "--engine", &engine, "--config", &config], &[])?;
    ensure!(
        code == 0 && conform["failed"] == 0,
        "conform under the table: exit {code}: {conform}"
    );
    Ok(Completion::Completed)
}

/// Issue 45: Rapier answers contact queries (each triangle's own
/// `Triangle.contactShape`, no internal-edge fix, as a default trimesh's
/// manifolds). On a recorded mini-golf contact trace under its table every
/// query matches the core's contact set (measured: 2,238 of 2,238 with
/// 200 frames), and its contact normals at the course's flat seams are
/// listed as ghost contacts, the engine's own (measured: 201 with the
/// sweeps').
fn rapiers_contacts_match_and_its_seam_ghosts_are_listed() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("golf.mcap");
    let out = crate::support::bin()
        .args([
            "record",
            "--scene",
            "mini_golf",
            "--frames",
            "150",
            "--contacts",
            "-o",
        ])
        .arg(&trace)
        .output()?;
    ensure!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (trace, config) = (trace.display().to_string(), config());
    let (code, report) = run_json(
        &[
            "check",
            &trace,
            "--engine",
            &engine,
            "--config",
            &config,
            "--engine-contacts",
        ],
        &[],
    )?;
    let t = &traces_of(&report)[0];
    let contacts = &t["contacts"];
    ensure!(
        code == 1
            && contacts["queries"].as_u64() > Some(500)
            && contacts["compared"] == contacts["queries"]
            && contacts["divergent"] == 0,
        "Rapier's contacts under its table (exit {code}): {contacts:#}"
    );
    // Its failing sweeps there are its limitations, each named (among
    // them a start 1e-10 beyond the radius, the radius in f32, answered as
    // a hit at α = 0 with a normal 7° off: a normal at a touching start).
    let unnamed = unnamed_divergences(&report);
    ensure!(
        unnamed.is_empty(),
        "failing sweeps that no known limitation names: {unnamed:?}"
    );
    let ghosts = t["ghost_contacts"].as_array().cloned().unwrap_or_default();
    let engines = ghosts.iter().filter(|g| g["answer"] == true).count();
    ensure!(
        engines >= 5,
        "{engines} ghost contacts of Rapier's own normals at the seams: {:#}",
        t["ghost_contacts"]
    );
    Ok(Completion::Completed)
}

/// conform's contact rules under Rapier's table: its pairwise triangle
/// contacts (a default trimesh, no internal-edge fix) are right everywhere
/// but at the flat seam and in the valley, where each triangle's own
/// contact normal leans: ghost contacts, the failures of exactly those two
/// rules. (The rules with a contact distance of 0 also hold the example to
/// reading a query whose `distance` is left out.)
fn rapier_fails_conforms_must_not_push_contact_rules_with_ghosts() -> anyhow::Result<Completion> {
    let engine = match rapier()? {
        Ok(engine) => engine,
        Err(skip) => return Ok(skip),
    };
    let config = config();
    let (code, report) = run_json(
        &[
            "conform", "--engine", &engine, "--case", "contact", "--config", &config,
        ],
        &[],
    )?;
    let ghosts: Vec<f64> = report["rules"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|r| r["first_failure"]["contacts"]["ghosts"][0]["angle_degrees"].as_f64())
        .collect();
    ensure!(
        code == 1
            && report["failing_rules"]
                == serde_json::json!(["contact.flat-seam", "contact.concave-corner"])
            && ghosts.len() == 2
            && report["passed"].as_u64() >= Some(12),
        "Rapier's contact rules (exit {code}): failing {}, ghosts {ghosts:?}, passed {}",
        report["failing_rules"],
        report["passed"]
    );
    Ok(Completion::Completed)
}
