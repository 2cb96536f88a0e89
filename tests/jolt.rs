//! A real single-precision engine judged fairly and strictly: Jolt Physics
//! (`examples/engines/jolt/`, the npm package `jolt-physics` 1.1.0 in
//! Node) over the engine protocol, with the `[engine]` table `check
//! --infer-config` wrote for it (`examples/engines/jolt/sweeptrace.toml`).
//! The clean engine passes `check` on every sample trace and `conform`;
//! each deliberately broken variant fails, and its failure names what is
//! wrong. Needs `node` and the package (`npm ci --prefix
//! examples/engines/jolt`): skipped without them, a failure when
//! `SWEEPTRACE_REQUIRE_NODE=1` (CI).

use anyhow::ensure;
use libtest_mimic::{Completion, Trial};

use crate::support::run_bin;
use crate::{os, trial};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(clean_jolt_passes_check_under_its_inferred_config),
        trial!(broken_jolt_variants_fail_check_naming_the_difference),
        trial!(jolt_conforms_under_its_config_and_its_broken_variants_do_not),
        trial!(issue_42_jolt_variants_fail_exactly_the_rule_added_for_them),
        trial!(jolt_config_is_what_infer_config_prints),
        trial!(jolt_with_back_faces_is_judged_two_sided_under_sides_two),
        trial!(conforms_printed_reproduce_command_keeps_the_table),
        trial!(a_calibrated_accuracy_catches_a_bias_single_precision_excuses),
        trial!(every_seeded_bug_fails_conform_and_check),
        trial!(jolt_keeps_a_contact_normal_within_one_degree_at_an_inactive_edge),
        trial!(jolts_contacts_pass_and_its_ghosts_show_with_collide_with_all),
        trial!(jolt_passes_conforms_contact_rules_and_its_ghost_modes_fail_them),
    ]
}

/// The engine command, or the reason to skip.
fn jolt() -> anyhow::Result<Result<String, Completion>> {
    crate::support::node_engine("jolt", "jolt-physics")
}

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn config() -> String {
    root()
        .join("examples/engines/jolt/sweeptrace.toml")
        .display()
        .to_string()
}

fn traces() -> String {
    root().join("traces").display().to_string()
}

/// `check traces/ --engine JOLT --config its table --json`, with
/// `JOLT_VARIANT=variant`: exit code and the parsed report.
fn check(engine: &str, variant: &str) -> anyhow::Result<(i32, serde_json::Value)> {
    check_with(engine, variant, &[])
}

/// [`check`] with more arguments (a convention's flag).
fn check_with(
    engine: &str,
    variant: &str,
    more: &[&str],
) -> anyhow::Result<(i32, serde_json::Value)> {
    let traces = traces();
    let args = ["check", &traces, "--engine", engine];
    run_json(variant, &[&args[..], more].concat())
}

/// `conform --engine JOLT --config its table --json` and `more`, with
/// `JOLT_VARIANT=variant`: exit code and the parsed report.
fn conform_with(
    engine: &str,
    variant: &str,
    more: &[&str],
) -> anyhow::Result<(i32, serde_json::Value)> {
    run_json(
        variant,
        &[&["conform", "--engine", engine][..], more].concat(),
    )
}

/// sweeptrace with `args`, Jolt's table and `--json`, with
/// `JOLT_VARIANT=variant`: exit code and the parsed report.
fn run_json(variant: &str, args: &[&str]) -> anyhow::Result<(i32, serde_json::Value)> {
    // The variant reaches the engine through the environment sweeptrace
    // passes on.
    let out = crate::support::bin()
        .env("JOLT_VARIANT", variant)
        .args(args)
        .args(["--config", &config(), "--json"])
        .output()?;
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

fn clean_jolt_passes_check_under_its_inferred_config() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let (code, report) = check(&engine, "")?;
    let traces = traces_of(&report);
    ensure!(traces.len() == 5, "{report}");
    ensure!(code == 0, "the clean engine fails: {report}");
    let precision: u64 = traces
        .iter()
        .map(|t| t["precision_divergent"].as_u64().unwrap_or(0))
        .sum();
    let largest = traces
        .iter()
        .map(|t| t["max_backward_error"].as_f64().unwrap_or(0.0))
        .fold(0.0, f64::max);
    // Jolt rounds: most differences are within single precision, and
    // every one of them within the budget of 16 units.
    ensure!(
        precision > 500,
        "{precision} differences within single precision"
    );
    ensure!(
        largest > 0.0 && largest <= 16.0,
        "largest backward error {largest}"
    );
    ensure!(
        traces.iter().all(|t| t["conventions"]["precision"] == "f32"
            && t["conventions"]["normal"] == "active_edges"),
        "the reports name the conventions: {report}"
    );
    Ok(Completion::Completed)
}

fn broken_jolt_variants_fail_check_naming_the_difference() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    // Each variant and a word its first divergence must show.
    let variants = [
        ("late", "beyond the f32 backward-error bound"),
        ("no_vertex", "\"vertex\""),
        ("next_triangle", "\"triangle\""),
        ("back_faces", "back_facing"),
        ("centre_contact", "\"contact\""),
        ("flipped_edge_normal", "\"normal\""),
        // Issue 42: wrong answers that passed as "within single precision".
        ("tilted_face_normal", "angle 1°"),
        ("half_normal", "not a unit vector"),
        ("contact_off_plane", "off the triangle's plane"),
        ("skin", "beyond the f32 backward-error bound"),
    ];
    for (variant, shows) in variants {
        let (code, report) = check(&engine, variant)?;
        ensure!(code == 1, "{variant}: exit {code}");
        let shown: Vec<serde_json::Value> = traces_of(&report)
            .into_iter()
            .flat_map(|t| t["divergences"].as_array().cloned().unwrap_or_default())
            .collect();
        ensure!(!shown.is_empty(), "{variant}: no divergence in {report}");
        let text = serde_json::Value::from(shown).to_string();
        ensure!(
            text.contains(shows),
            "{variant}: no divergence shows {shows}: {text}"
        );
    }
    Ok(Completion::Completed)
}

fn jolt_conforms_under_its_config_and_its_broken_variants_do_not() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let conform = |variant: &str| conform_with(&engine, variant, &[]);
    let failing = |report: &serde_json::Value| -> Vec<String> {
        report["rules"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|r| r["failed"].as_u64().unwrap_or(0) > 0)
            .filter_map(|r| r["rule"].as_str().map(str::to_string))
            .collect()
    };
    let (code, report) = conform("")?;
    ensure!(code == 0, "clean Jolt fails rules {:?}", failing(&report));
    // Its rounding is counted as such, not as fragile decisions.
    ensure!(
        report["within_precision"].as_u64() > Some(0) && report["fragile"] == 0,
        "within_precision {}, fragile {}",
        report["within_precision"],
        report["fragile"]
    );
    let not_applicable: Vec<&str> = report["rules"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|r| r["not_applicable"].is_string())
        .filter_map(|r| r["rule"].as_str())
        .collect();
    ensure!(
        not_applicable.contains(&"margin.face-hit") && not_applicable.contains(&"start.inside"),
        "the rules its conventions replace are listed: {not_applicable:?}"
    );
    let (code, report) = conform("back_faces")?;
    let fails = failing(&report);
    ensure!(
        code == 1 && fails.iter().any(|r| r == "face.miss.back-facing"),
        "back_faces fails {fails:?}"
    );
    let (code, report) = conform("no_vertex")?;
    let fails = failing(&report);
    ensure!(
        code == 1 && fails.iter().any(|r| r == "vertex.hit"),
        "no_vertex fails {fails:?}"
    );
    Ok(Completion::Completed)
}

/// Issue 42: six mistakes `check` saw on the sample traces and `conform`
/// passed. Under Jolt's own table each variant now fails exactly the rule
/// added for it (exit 1, the rule named, its first failing case shown),
/// where clean Jolt passes them all (the test above).
fn issue_42_jolt_variants_fail_exactly_the_rule_added_for_them() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let variants = [
        ("glued", "start.moving-away", "kind: engine face, core none"),
        (
            "first_hit",
            "mesh.closest-hit",
            "triangle: engine 0, core 1",
        ),
        (
            "loose_bary",
            "face.near-edge",
            "kind: engine edge, core face",
        ),
        (
            "wide_active_edges",
            "normal.shallow-convex-edge",
            "normal: engine",
        ),
        ("ghost_flat", "normal.flat-edge", "normal: engine"),
        ("lost_leaf", "mesh.large", "kind: engine none, core face"),
    ];
    for (variant, rule, shows) in variants {
        let (code, report) = conform_with(&engine, variant, &[])?;
        ensure!(code == 1, "{variant}: exit {code}");
        ensure!(
            report["failing_rules"] == serde_json::json!([rule]),
            "{variant}: failing rules {}, want [{rule}]",
            report["failing_rules"]
        );
        let first = report["rules"]
            .as_array()
            .into_iter()
            .flatten()
            .find(|r| r["rule"] == rule)
            .map(|r| r["first_failure"].clone())
            .unwrap_or_default();
        let (code, text, _) = run_bin(os![
            "conform",
            "--engine",
            &format!("{engine} --variant {variant}"),
            "--config",
            &config(),
            "--case",
            first["case"].as_str().unwrap_or(rule)
        ])?;
        ensure!(
            code == 1 && text.contains(shows),
            "{variant}: its first failing case does not show `{shows}` (exit {code}):\n{text}"
        );
    }
    Ok(Completion::Completed)
}

fn jolt_config_is_what_infer_config_prints() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
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
    let committed: toml::Table = toml::from_str(&std::fs::read_to_string(
        root().join("examples/engines/jolt/sweeptrace.toml"),
    )?)?;
    ensure!(
        parsed["engine"] == committed["engine"],
        "the committed table is not what --infer-config prints now:\n{stdout}"
    );
    ensure!(
        stderr.contains("tried the rules"),
        "progress on stderr: {stderr}"
    );
    Ok(Completion::Completed)
}

/// Failing sweeps of a `check --json` report.
fn failing_sweeps(report: &serde_json::Value) -> u64 {
    traces_of(report)
        .iter()
        .map(|t| t["divergent"].as_u64().unwrap_or(0))
        .sum()
}

/// Jolt with `CollideWithBackFaces` (the `back_faces` variant) fails
/// under its one-sided table, and comes within a few dozen sweeps of
/// passing under the same table with `--sides two`: what remains is a ball
/// resting on the terrain's front (at ρ, within Jolt's collision
/// tolerance) and moving away, which Jolt reports as a hit at α = 0 once
/// no face is culled. `conform` passes, the back-facing rules and
/// `start.moving-away` n/a.
fn jolt_with_back_faces_is_judged_two_sided_under_sides_two() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let (code, one) = check(&engine, "back_faces")?;
    ensure!(code == 1, "one side: exit {code}");
    let (code, two) = check_with(&engine, "back_faces", &["--sides", "two"])?;
    let (under_one, under_two) = (failing_sweeps(&one), failing_sweeps(&two));
    // Measured: 1,169 under one side, 63 under two, all on the terrain;
    // the other four traces pass.
    ensure!(
        under_one > 1000 && under_two * 10 < under_one,
        "back_faces: {under_one} failing sweeps under one side, {under_two} under two (exit {code})"
    );
    ensure!(
        traces_of(&two)
            .iter()
            .all(|t| t["conventions"]["sides"] == "two"),
        "the reports name the convention: {two}"
    );
    for name in [
        "record_bowl_margin",
        "record_box_strict",
        "record_cube_corner_margin",
        "record_mini_golf",
    ] {
        ensure!(
            traces_of(&two)
                .iter()
                .any(|t| t["trace"].as_str().is_some_and(|p| p.contains(name))
                    && t["divergent"] == 0),
            "{name} passes under two sides: {two}"
        );
    }
    let (code, report) = conform_with(&engine, "back_faces", &["--sides", "two"])?;
    ensure!(code == 0, "conform --sides two: {report}");
    let replaced: Vec<&str> = report["rules"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|r| {
            r["not_applicable"]
                .as_str()
                .is_some_and(|n| n.contains("sides = two"))
        })
        .filter_map(|r| r["rule"].as_str())
        .collect();
    // With initial_overlap = "alpha0" as well, a ball within ρ leaving
    // the front moves toward the back: start.moving-away is replaced too.
    ensure!(
        replaced
            == [
                "face.miss.back-facing",
                "start.moving-away",
                "edge.miss.back-facing"
            ],
        "{replaced:?}"
    );
    Ok(Completion::Completed)
}

/// Issue 44: `conform --config JOLT.toml` printed `reproduce: sweeptrace
/// conform --engine '…' --case facing.strict/0` without the table, and run
/// as printed that case failed though it passed in the configured run. The
/// printed command carries the conventions as flags (and `--no-config`):
/// run as printed, from another directory, it passes as the run did.
fn conforms_printed_reproduce_command_keeps_the_table() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let out = crate::support::bin()
        .args(["conform", "--engine", &engine, "--config", &config()])
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    ensure!(
        out.status.code() == Some(0),
        "the configured run fails:\n{text}"
    );
    let line = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("reproduce: sweeptrace "))
        .ok_or_else(|| anyhow::anyhow!("no reproduce line:\n{text}"))?;
    ensure!(
        line.contains("--precision f32") && line.contains("--no-config"),
        "the table is not in {line}"
    );
    let bin = crate::support::bin().get_program().to_owned();
    let again = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("\"$0\" {line}"))
        .arg(&bin)
        .current_dir(std::env::temp_dir())
        .output()?;
    ensure!(
        again.status.code() == Some(0),
        "run as printed ({line}): exit {:?}\n{}",
        again.status.code(),
        String::from_utf8_lossy(&again.stdout)
    );
    Ok(Completion::Completed)
}

/// Issue 42's calibration: clean Jolt showed at most 1.8 units of backward
/// error, so its inferred table holds it to `accuracy = 4` instead of
/// single precision's 16. A small bias the 16 units excuse sweep by sweep
/// (α 0.2 % late, a 1e-3 penetration skin) then fails more sweeps, on the
/// terrain above all (measured: late 4 -> 16, skin 40 -> 109), while the
/// clean engine still passes (the first test).
fn a_calibrated_accuracy_catches_a_bias_single_precision_excuses() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let terrain_failing = |report: &serde_json::Value| -> u64 {
        traces_of(report)
            .iter()
            .filter(|t| t["trace"].as_str().is_some_and(|n| n.contains("terrain")))
            .map(|t| t["divergent"].as_u64().unwrap_or(0))
            .sum()
    };
    for variant in ["late", "skin"] {
        let (code, calibrated) = check(&engine, variant)?;
        ensure!(code == 1, "{variant}: exit {code}");
        ensure!(
            traces_of(&calibrated)
                .iter()
                .all(|t| t["conventions"]["accuracy"] == 4.0),
            "{variant}: the reports name the accuracy: {calibrated}"
        );
        let (_, single) = check_with(&engine, variant, &["--accuracy", "16"])?;
        let (at_4, at_16) = (terrain_failing(&calibrated), terrain_failing(&single));
        ensure!(
            at_4 > at_16 && at_4 >= 2 * at_16.max(1),
            "{variant}: the terrain fails {at_4} sweeps held to 4 units, {at_16} held to 16"
        );
    }
    Ok(Completion::Completed)
}

/// The mutation test of the verdict (issue 42; the table in
/// docs/ENGINES.md, "Seeded bugs"): every deliberate mistake of the Jolt
/// example fails `conform` under Jolt's own table, and every one the
/// samples can show fails `check` (`ghost_flat` cannot: no sample ball
/// lands on a flat internal edge; conform's `normal.flat-edge` does). The
/// ten variants the test above checks are not run again here.
fn every_seeded_bug_fails_conform_and_check() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(e) => e,
        Err(skip) => return Ok(skip),
    };
    let variants = [
        "late",
        "no_vertex",
        "next_triangle",
        "back_faces",
        "centre_contact",
        "flipped_edge_normal",
        "tilted_face_normal",
        "half_normal",
        "contact_off_plane",
        "skin",
        "glued",
        "first_hit",
        "loose_bary",
        "wide_active_edges",
        "ghost_flat",
        "lost_leaf",
    ];
    for variant in variants {
        let (code, report) = conform_with(&engine, variant, &[])?;
        ensure!(
            code == 1 && report["failed"].as_u64() > Some(0),
            "{variant}: conform exits {code}: {}",
            report["failing_rules"]
        );
    }
    for variant in [
        "glued",
        "first_hit",
        "loose_bary",
        "wide_active_edges",
        "lost_leaf",
    ] {
        let (code, report) = check(&engine, variant)?;
        let failing: u64 = traces_of(&report)
            .iter()
            .map(|t| t["divergent"].as_u64().unwrap_or(0))
            .sum();
        ensure!(
            code == 1 && failing > 0,
            "{variant}: check exits {code} with {failing} failing sweeps"
        );
    }
    Ok(Completion::Completed)
}

/// Jolt's `ActiveEdges::FixNormal` leaves a contact normal alone when it is
/// within 1° of the triangle's normal and the triangle has an active edge,
/// even at an inactive edge: clean Jolt failed 2 sweeps of a recorded
/// rolling terrain (4,746 sweeps) on that until the `active_edges` rule
/// modelled it. Here: triangle 0 in z = 0, triangle 1 folded down by 2°
/// across its edge 0 (inactive), triangle 2 folded down by 20° across its
/// edge 1 (active); balls fall onto the inactive edge from 0.3°–0.8° off
/// vertical (Jolt: the contact normal) and from 1.5° (the face normal).
fn jolt_keeps_a_contact_normal_within_one_degree_at_an_inactive_edge() -> anyhow::Result<Completion>
{
    use sweeptrace::trace::{SceneMsg, SweepMsg, TraceWriter};
    let engine = match jolt()? {
        Ok(engine) => engine,
        Err(skip) => return Ok(skip),
    };
    let (t2, t20) = (2f64.to_radians().tan(), 20f64.to_radians().tan());
    let out = 2.0 / 2f64.sqrt();
    let scene = SceneMsg {
        name: Some("ridge".into()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, -2.0, -2.0 * t2],
            [1.0 + out, 1.0 + out, -2.0 * t20],
        ],
        triangles: vec![[0, 1, 2], [1, 0, 3], [2, 1, 4]],
        margin: 0.0,
        facing: Default::default(),
    };
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("ridge.mcap");
    let mut w = TraceWriter::new(std::fs::File::create(&path)?)?;
    w.scene(0, &scene)?;
    for (frame, degrees) in [0.3f64, 0.5, 0.8, 1.5].into_iter().enumerate() {
        // Touching (0.6 + 0.1·frame, 0, 0) with the centre `degrees` off
        // +z toward -y, falling straight down from 0.5 above that.
        let (s, c) = degrees.to_radians().sin_cos();
        let x = 0.6 + 0.1 * frame as f64;
        let sweep = SweepMsg {
            frame: frame as u64,
            ball: 0,
            radius: 0.25,
            p0: [x, -0.25 * s, 0.25 * c + 0.5],
            p1: [x, -0.25 * s, 0.25 * c - 0.1],
        };
        w.sweep(1 + frame as u64, &sweep)?;
    }
    w.finish()?;
    let path = path.display().to_string();
    let (code, report) = run_json("clean", &["check", &path, "--engine", &engine])?;
    ensure!(
        code == 0,
        "clean Jolt fails the ridge (exit {code}): {}",
        serde_json::to_string_pretty(&report)?
    );
    Ok(Completion::Completed)
}

/// Contact queries answered by Jolt's own CollideShape (`--engine-contacts`):
/// on a welded terrain clean Jolt's contacts are the core's contact set
/// (under its table), and with `EActiveEdgeMode::CollideWithAll`
/// (`--ghosts`) its ghost contacts are listed. The mini-golf course's wall
/// segments repeat their vertices: welded (the example's default, as Jolt's
/// own `Indexify`) clean Jolt passes there too; with the trace's indices
/// (`--no-weld`) its contacts at two such seams are ghosts, and the report
/// says why (shared by position only).
fn jolts_contacts_pass_and_its_ghosts_show_with_collide_with_all() -> anyhow::Result<Completion> {
    let engine = match jolt()? {
        Ok(engine) => engine,
        Err(skip) => return Ok(skip),
    };
    let dir = tempfile::tempdir()?;
    let record = |scene: &str| -> anyhow::Result<String> {
        let path = dir.path().join(format!("{scene}.mcap"));
        let out = crate::support::bin()
            .args([
                "record",
                "--scene",
                scene,
                "--terrain-cells",
                "20",
                "--frames",
                "200",
            ])
            .args(["--contacts", "-o"])
            .arg(&path)
            .output()?;
        ensure!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        Ok(path.display().to_string())
    };
    let terrain = record("terrain")?;
    let with_ghosts = format!("{engine} --ghosts");
    let check = |trace: &str, engine: &str| {
        run_json(
            "clean",
            &["check", trace, "--engine", engine, "--engine-contacts"],
        )
    };
    let (code, report) = check(&terrain, &engine)?;
    let t = &traces_of(&report)[0];
    ensure!(
        code == 0 && t["contacts"]["compared"].as_u64() > Some(1000) && t["ghosts"] == 0,
        "clean Jolt's contacts on the terrain (exit {code}): {:#}",
        t["contacts"]
    );
    let (code, report) = check(&terrain, &with_ghosts)?;
    let t = &traces_of(&report)[0];
    ensure!(
        code == 1 && t["ghosts"].as_u64() > Some(3),
        "Jolt with CollideWithAll (exit {code}): {} ghosts",
        t["ghosts"]
    );
    let golf = record("mini_golf")?;
    let (code, report) = check(&golf, &engine)?;
    let t = &traces_of(&report)[0];
    ensure!(
        code == 0 && t["contacts"]["compared"].as_u64() > Some(1000) && t["ghosts"] == 0,
        "clean Jolt's contacts on the welded mini-golf course (exit {code}): {:#}",
        t["contacts"]
    );
    let (code, report) = check(&golf, &format!("{engine} --no-weld"))?;
    let t = &traces_of(&report)[0];
    let ghosts = t["ghost_contacts"].as_array().cloned().unwrap_or_default();
    ensure!(
        code == 1
            && t["contacts"]["divergent"] == 0
            && !ghosts.is_empty()
            && ghosts
                .iter()
                .all(|g| g["unwelded"] == true && g["answer"] == true),
        "clean Jolt on the unwelded mini-golf course (exit {code}): {:#}",
        t["ghost_contacts"]
    );
    Ok(Completion::Completed)
}

/// conform's contact rules over the protocol, under Jolt's table: clean
/// Jolt passes every one; with `EActiveEdgeMode::CollideWithAll` it fails
/// exactly the places that must not push (a flat seam, a shallow convex
/// edge, a valley), and with the trace's vertex indices unwelded only the
/// seam shared by position only.
fn jolt_passes_conforms_contact_rules_and_its_ghost_modes_fail_them() -> anyhow::Result<Completion>
{
    let engine = match jolt()? {
        Ok(engine) => engine,
        Err(skip) => return Ok(skip),
    };
    for (flag, want) in [
        ("", &[][..]),
        (
            " --ghosts",
            &[
                "contact.flat-seam",
                "contact.shallow-convex-edge",
                "contact.concave-corner",
            ][..],
        ),
        (" --no-weld", &["contact.flat-seam"][..]),
    ] {
        let command = format!("{engine}{flag}");
        let (code, report) = run_json(
            "clean",
            &["conform", "--engine", &command, "--case", "contact"],
        )?;
        ensure!(
            code == i32::from(!want.is_empty())
                && report["failing_rules"] == serde_json::json!(want)
                && report["cases"].as_u64() >= Some(16),
            "Jolt{flag}: exit {code}, failing rules {}",
            report["failing_rules"]
        );
    }
    Ok(Completion::Completed)
}
