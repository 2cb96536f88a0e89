//! Reproducing and diagnosing a divergence: bit-exact inputs in `check`'s
//! reports, `repro` (a minimal trace and a Rust test), `sweep --trace` and
//! `--mesh`, and the configuration `check` infers from failing
//! expectations.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use libtest_mimic::Trial;
use sweeptrace::core::{Facing, Kind, Mesh, Sweep, sweep_mesh};
use sweeptrace::judge::{Agreement, Tolerances, compare};
use sweeptrace::numbers::parse_f64;
use sweeptrace::replay::ReplayOptions;
use sweeptrace::suite::bless::bless_bytes;
use sweeptrace::suite::repro::{ReproCase, find_sweep};
use sweeptrace::suite::{CheckOptions, Status, check_file, check_reader, render_json, render_text};
use sweeptrace::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceReader, TraceWriter};

use crate::ensure;
use crate::os;
use crate::support::run_bin;
use crate::support::scene_t;
use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(divergence_inputs_read_back_bit_exactly),
        trial!(check_hex_binary),
        trial!(fixture_case_gives_the_same_verdict),
        trial!(sample_trace_cases_reproduce_and_their_tests_hold),
        trial!(binary_writes_case_and_test),
        trial!(repro_honours_the_declared_conventions),
        trial!(alpha0_always_accepts_a_start_within_rho_moving_away),
        trial!(rrd_on_failure_marks_divergences_under_the_declared_conventions),
        trial!(sweep_from_trace_and_obj),
        trial!(sweep_flag_errors),
        trial!(infer_wrong_engine_config_margin_0),
        trial!(infer_margin_and_facing_implied_by_a_parallel_hit),
        trial!(infer_strict_facing_by_replaying_both),
    ]
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture() -> PathBuf {
    root().join("tests/fixtures/wrong_engine_config.mcap")
}

/// The numbers of a `(a, b, c)` group following `label` in `text`.
fn numbers_after(text: &str, label: &str) -> anyhow::Result<Vec<f64>> {
    let start = text
        .find(label)
        .with_context(|| format!("no `{label}` in:\n{text}"))?
        + label.len();
    let rest = &text[start..];
    let open = rest.find('(').context("no (")?;
    let close = rest.find(')').context("no )")?;
    rest[open + 1..close]
        .split(',')
        .map(|t| parse_f64(t).with_context(|| format!("`{t}` does not parse")))
        .collect()
}

fn same_bits(what: &str, got: &[f64], want: &[f64]) -> anyhow::Result<()> {
    ensure!(
        got.len() == want.len()
            && got
                .iter()
                .zip(want)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
        "{what}: {got:?} does not read back as {want:?}"
    );
    Ok(())
}

fn divergence_inputs_read_back_bit_exactly() -> anyhow::Result<()> {
    let options = CheckOptions {
        hex: true,
        ..CheckOptions::default()
    };
    let report = check_file(&fixture(), &options);
    let d = report
        .divergences
        .details
        .first()
        .context("no divergence")?;
    // Frame 2 of the fixture: p0 (2, -0.45, 3), p1 (2, -0.45, -3), r 0.5, margin 0.1.
    same_bits("p0", &d.inputs.p0, &[2.0, -0.45, 3.0])?;
    same_bits("p1", &d.inputs.p1, &[2.0, -0.45, -3.0])?;
    same_bits(
        "radius, margin",
        &[d.inputs.radius, d.inputs.margin],
        &[0.5, 0.1],
    )?;
    ensure!(d.inputs.facing == Facing::NonStrict, "facing");
    let text = render_text(&report);
    ensure!(
        text.contains(
            "inputs: p0 (2, -0.45, 3), p1 (2, -0.45, -3), radius 0.5, margin 0.1, facing non_strict"
        ),
        "text:\n{text}"
    );
    for d in &report.divergences.details {
        let block = sweeptrace::judge::divergence::render_divergence(d, "");
        let inputs = &block[block.find("inputs: ").context("inputs line")?..];
        same_bits("decimal p0", &numbers_after(inputs, "p0 ")?, &d.inputs.p0)?;
        same_bits("decimal p1", &numbers_after(inputs, "p1 ")?, &d.inputs.p1)?;
        let hex = &block[block.find("inputs (hex): ").context("hex line")?..];
        same_bits("hex p0", &numbers_after(hex, "p0 ")?, &d.inputs.p0)?;
        same_bits("hex p1", &numbers_after(hex, "p1 ")?, &d.inputs.p1)?;
        // The pasted inputs make the same decision.
        let scene = SceneMsg {
            name: None,
            ..scene_t(0.1)
        };
        let mesh = Mesh::new(scene.vertices.clone(), &scene.triangles)?;
        let again = sweep_mesh(
            &mesh,
            &Sweep::new(
                numbers_after(hex, "p0 ")?
                    .try_into()
                    .map_err(|_| anyhow::anyhow!("3"))?,
                numbers_after(hex, "p1 ")?
                    .try_into()
                    .map_err(|_| anyhow::anyhow!("3"))?,
                d.inputs.radius,
            ),
            &d.inputs.options(),
        )?;
        ensure!(
            again.travelled().to_bits() == d.got.alpha.to_bits() && again.kind() == d.got.kind,
            "pasted inputs decide {again:?}, the report says {:?}",
            d.got
        );
    }
    let json: serde_json::Value = serde_json::from_str(&render_json(&[report], 1))?;
    let inputs = &json["traces"][0]["divergences"][0]["inputs"];
    let p0: Vec<f64> = serde_json::from_value(inputs["p0"].clone())?;
    same_bits("json p0", &p0, &[2.0, -0.45, 3.0])?;
    ensure!(
        json["traces"][0]["divergences"][0]["inputs_hex"]["margin"] == "0x1.999999999999ap-4",
        "json hex: {inputs}"
    );
    Ok(())
}

fn check_hex_binary() -> anyhow::Result<()> {
    let f = fixture();
    let (code, out, err) = run_bin(os!["check", f.as_os_str(), "--hex"])?;
    ensure!(code == 1, "exit {code}\n{out}\n{err}");
    ensure!(
        out.contains("inputs (hex): p0 (0x1p+1, -0x1.ccccccccccccdp-2, 0x1.8p+1)"),
        "stdout:\n{out}"
    );
    let (_, out, _) = run_bin(os!["check", f.as_os_str()])?;
    ensure!(
        out.contains("inputs: p0 (2, -0.45, 3)") && !out.contains("inputs (hex)"),
        "without --hex:\n{out}"
    );
    Ok(())
}

fn case_of(path: &Path, frame: u64, ball: u32) -> anyhow::Result<ReproCase> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    let found = find_sweep(
        TraceReader::new(bytes.as_slice(), &name),
        &name,
        frame,
        ball,
    )?;
    ReproCase::build(
        &name,
        &found,
        &Tolerances::default(),
        &sweeptrace::conventions::EngineConventions::default(),
    )
    .map_err(anyhow::Error::from)
}

fn case_bytes(case: &ReproCase) -> anyhow::Result<Vec<u8>> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    case.write(&mut w)?;
    Ok(w.finish()?.into_inner())
}

/// The float literals of generated code, comments left out, in order.
fn float_literals(code: &str) -> Vec<String> {
    code.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .flat_map(|l| {
            l.split(|c: char| " ,()[];&{}".contains(c))
                .filter(|t| {
                    let digits = t.strip_prefix('-').unwrap_or(t);
                    digits.starts_with(|c: char| c.is_ascii_digit())
                        && (digits.contains('.') || digits.contains('e'))
                })
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The integer triples of the `&[...]` triangle list of generated code.
fn triangle_literals(code: &str) -> anyhow::Result<Vec<[u64; 3]>> {
    code.lines()
        .filter(|l| l.trim_start().starts_with('[') && l.contains("// triangle "))
        .map(|l| {
            let inner = l
                .trim()
                .strip_prefix('[')
                .and_then(|r| r.split(']').next())
                .with_context(|| format!("triangle line `{l}`"))?;
            let v: Vec<u64> = inner
                .split(',')
                .map(|t| {
                    t.trim()
                        .parse::<u64>()
                        .map_err(|e| anyhow::anyhow!("`{t}`: {e}"))
                })
                .collect::<Result<_, _>>()?;
            v.try_into()
                .map_err(|_| anyhow::anyhow!("three indices in `{l}`"))
        })
        .collect()
}

/// The generated test's numbers read back to the case's bits, and the
/// test's calls, run here on the numbers read back, decide as its
/// assertion says (it holds exactly when the expectation agrees).
fn check_generated_test(case: &ReproCase) -> anyhow::Result<()> {
    let tol = Tolerances::default();
    let code = case.rust_test(&tol);
    let literals = float_literals(&code);
    let want = case.test_numbers(&tol);
    ensure!(
        literals.len() == want.len(),
        "{} literals, {} numbers:\n{code}",
        literals.len(),
        want.len()
    );
    let parsed: Vec<f64> = literals
        .iter()
        .map(|t| t.parse::<f64>().map_err(|e| anyhow::anyhow!("`{t}`: {e}")))
        .collect::<Result<_, _>>()?;
    same_bits("generated literals", &parsed, &want)?;
    let nv = case.vertices.len();
    let vertices: Vec<[f64; 3]> = parsed[..3 * nv]
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let at = 3 * nv;
    let p0 = [parsed[at], parsed[at + 1], parsed[at + 2]];
    let p1 = [parsed[at + 3], parsed[at + 4], parsed[at + 5]];
    let (radius, margin) = (parsed[at + 6], parsed[at + 7]);
    let triangles = triangle_literals(&code)?;
    ensure!(
        triangles == case.triangles,
        "triangles of the code:\n{code}"
    );
    let mesh = Mesh::new(vertices, &triangles)?;
    let options = sweeptrace::Options {
        margin,
        facing: case.inputs.facing,
        ..sweeptrace::Options::default()
    };
    let outcome = sweep_mesh(&mesh, &Sweep::new(p0, p1, radius), &options)?;
    ensure!(
        outcome.travelled().to_bits() == case.reduced_outcome.travelled().to_bits()
            && outcome.kind() == case.reduced_outcome.kind()
            && outcome.hit.map(|h| h.triangle) == case.reduced_outcome.hit.map(|h| h.triangle),
        "the code's numbers decide {outcome:?}, the case {:?}",
        case.reduced_outcome
    );
    let asserted = case.asserted();
    let got = OutcomeMsg::from_outcome(case.frame, case.ball, &outcome);
    let holds = if case.asserts_tie() {
        let (_, ties) = sweeptrace::core::sweep_ties(&mesh, &Sweep::new(p0, p1, radius), &options)?;
        let mut rest = compare(&asserted, &got, &tol);
        rest.retain(|f| {
            !matches!(
                f.field,
                sweeptrace::judge::Field::Kind
                    | sweeptrace::judge::Field::Triangle
                    | sweeptrace::judge::Field::Feature
            )
        });
        ties.iter().any(|t| {
            t.matches(
                asserted.kind,
                asserted.triangle.flatten(),
                asserted.feature.flatten(),
            )
        }) && rest.is_empty()
    } else {
        compare(&asserted, &got, &tol).is_empty()
    };
    let agrees = match &case.agreement {
        None => true,
        Some(a) => matches!(a, Agreement::Match | Agreement::Tie),
    };
    ensure!(
        holds == agrees,
        "the test's assertion holds: {holds}, the check agrees: {agrees}\n{code}"
    );
    Ok(())
}

fn fixture_case_gives_the_same_verdict() -> anyhow::Result<()> {
    let full = check_file(&fixture(), &CheckOptions::default());
    for frame in [2u64, 3] {
        let case = case_of(&fixture(), frame, 0)?;
        ensure!(case.reproduces(), "frame {frame}: {}", case.summary());
        let bytes = case_bytes(&case)?;
        let report = check_reader(bytes.as_slice(), "case", &CheckOptions::default());
        ensure!(
            report.status() == Status::Fail && report.divergent == 1,
            "frame {frame}: the case must fail as the trace does:\n{}",
            render_text(&report)
        );
        let want = full
            .divergences
            .details
            .iter()
            .find(|d| d.frame == frame)
            .context("frame in the full report")?;
        let got = &report.divergences.details[0];
        ensure!(
            got.fields
                .iter()
                .map(|f| f.field)
                .eq(want.fields.iter().map(|f| f.field))
                && got.got == want.got
                && got.inputs == want.inputs,
            "frame {frame}: same divergence: {got:?}\nvs {want:?}"
        );
        check_generated_test(&case)?;
    }
    Ok(())
}

/// For every sample trace, a few sweeps of each kind (and fragile ones):
/// the reduced case makes the same decision and checks `ok` on its own.
fn sample_trace_cases_reproduce_and_their_tests_hold() -> anyhow::Result<()> {
    let mut cases = 0;
    for name in [
        "record_mini_golf.mcap",
        "record_terrain.mcap",
        "record_cube_corner_margin.mcap",
        "record_box_strict.mcap",
        "record_bowl_margin.mcap",
    ] {
        let path = root().join("traces").join(name);
        let bytes = std::fs::read(&path)?;
        let mut picked: Vec<(u64, u32)> = Vec::new();
        let mut seen: std::collections::BTreeMap<String, usize> = Default::default();
        for event in sweeptrace::replay_events(
            TraceReader::new(bytes.as_slice(), name),
            ReplayOptions::default(),
        ) {
            if let Ok(sweeptrace::replay::ReplayEvent::Sweep(r)) = event {
                let key = format!("{}{}", r.outcome.kind(), r.outcome.fragile.is_robust());
                let n = seen.entry(key).or_default();
                if *n < 2 {
                    *n += 1;
                    picked.push((r.frame, r.ball));
                }
            }
        }
        for (frame, ball) in picked {
            let case = case_of(&path, frame, ball)?;
            ensure!(
                case.reproduces(),
                "{name} {frame}/{ball}: {}",
                case.summary()
            );
            ensure!(
                case.original_triangles.len() < case.original_triangle_count
                    || case.original_triangle_count <= 12,
                "{name} {frame}/{ball}: the case should be smaller than the scene"
            );
            let report = check_reader(
                case_bytes(&case)?.as_slice(),
                "case",
                &CheckOptions::default(),
            );
            ensure!(
                report.status() == Status::Ok,
                "{name} {frame}/{ball}:\n{}",
                render_text(&report)
            );
            check_generated_test(&case)?;
            cases += 1;
        }
    }
    ensure!(cases >= 20, "only {cases} cases");
    Ok(())
}

/// Issue 44: `repro` wrote its case under the rules even when a table
/// declared conventions. An engine that declares `initial_overlap =
/// "alpha0"` answers a hit at α = 0 for a ball that starts within ρ of the
/// triangle: under that convention (in the trace's `sweeptrace.toml`) the
/// case matches, its Rust test builds the core's options with it, and the
/// `check` command it prints passes the written case, which fails under
/// the rules.
fn repro_honours_the_declared_conventions() -> anyhow::Result<()> {
    use sweeptrace::core::{InitialOverlap, Options};
    let dir = tempfile::tempdir()?;
    let scene = scene_t(0.0);
    let mesh = Mesh::new(scene.vertices.clone(), &scene.triangles)?;
    // Starts 0.25 above the triangle's plane with ρ = 0.5, moving down.
    let sweep = SweepMsg {
        frame: 0,
        ball: 0,
        radius: 0.5,
        p0: [0.5, 0.5, 0.25],
        p1: [0.5, 0.5, -1.0],
    };
    let alpha0 = Options {
        initial_overlap: InitialOverlap::Alpha0,
        ..Options::default()
    };
    let core = sweep_mesh(
        &mesh,
        &Sweep::new(sweep.p0, sweep.p1, sweep.radius),
        &alpha0,
    )?;
    ensure!(core.is_hit() && core.travelled() == 0.0, "{core:?}");
    let trace = dir.path().join("overlap.mcap");
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &scene)?;
    w.sweep(1, &sweep)?;
    w.expected(1, &OutcomeMsg::from_outcome(0, 0, &core))?;
    std::fs::write(&trace, w.finish()?.into_inner())?;
    std::fs::write(
        dir.path().join("sweeptrace.toml"),
        "[engine]\ninitial_overlap = \"alpha0\"\n",
    )?;
    let out = dir.path().join("case.mcap");
    let (code, stdout, stderr) = run_bin(os![
        "repro",
        trace.as_os_str(),
        "--frame",
        "0",
        "-o",
        out.as_os_str()
    ])?;
    ensure!(code == 0, "exit {code}\n{stdout}\n{stderr}");
    ensure!(
        stderr.contains("against the expectation: match")
            && stderr.contains("initial_overlap alpha0"),
        "judged under the table:\n{stderr}"
    );
    ensure!(
        stdout.contains("initial_overlap: InitialOverlap::Alpha0")
            && stdout
                .contains("use sweeptrace::{Facing, InitialOverlap, Kind, Mesh, Options, Sweep};"),
        "the test builds the options with the convention:\n{stdout}"
    );
    // The printed command judges the case as repro did; the rules fail it.
    let command = stderr
        .lines()
        .find_map(|l| l.split_once("check it under the same conventions: sweeptrace "))
        .map(|(_, c)| c.to_string())
        .with_context(|| format!("no check command in:\n{stderr}"))?;
    let args: Vec<std::ffi::OsString> = command.split(' ').map(Into::into).collect();
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let (code, stdout, stderr) = run_bin(&args)?;
    ensure!(code == 0, "{command}: exit {code}\n{stdout}{stderr}");
    let (code, stdout, _) = run_bin(os!["check", out.as_os_str(), "--no-config"])?;
    ensure!(code == 1, "under the rules: exit {code}\n{stdout}");
    Ok(())
}

/// Issue 47: Rapier's `stopAtPenetration` answers a hit at α = 0 for a
/// ball that starts within ρ of the floor and moves away from it. No table
/// could declare that (`alpha0` asks for an approach); `initial_overlap =
/// "alpha0_always"` does, and only that answer passes under it.
fn alpha0_always_accepts_a_start_within_rho_moving_away() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let scene = scene_t(0.0);
    // 0.25 above the triangle with ρ = 0.5, moving up and away.
    let sweep = SweepMsg {
        frame: 0,
        ball: 0,
        radius: 0.5,
        p0: [0.5, 0.5, 0.25],
        p1: [0.5, 0.5, 1.5],
    };
    let hit = OutcomeMsg::hit(0, 0, 0.0, Kind::Face)
        .triangle(0)
        .normal([0.0, 0.0, 1.0])
        .contact([0.5, 0.5, 0.0]);
    let trace = dir.path().join("leaving.mcap");
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &scene)?;
    w.sweep(1, &sweep)?;
    w.expected(1, &hit)?;
    std::fs::write(&trace, w.finish()?.into_inner())?;
    let t = trace.as_os_str();
    for (value, want) in [("none", 1), ("alpha0", 1), ("alpha0_always", 0)] {
        let (code, out, err) = run_bin(os!["check", t, "--no-config", "--initial-overlap", value])?;
        ensure!(
            code == want,
            "--initial-overlap {value}: exit {code}\n{out}{err}"
        );
    }
    // The seeded bug it must still catch: the same answer for a ball that
    // starts beyond ρ (0.75 above the plane) is no start in contact.
    let beyond = dir.path().join("beyond.mcap");
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &scene)?;
    w.sweep(
        1,
        &SweepMsg {
            p0: [0.5, 0.5, 0.75],
            ..sweep
        },
    )?;
    w.expected(1, &hit)?;
    std::fs::write(&beyond, w.finish()?.into_inner())?;
    let b = beyond.as_os_str();
    let (code, out, err) = run_bin(os![
        "check",
        b,
        "--no-config",
        "--initial-overlap",
        "alpha0_always"
    ])?;
    ensure!(
        code == 1,
        "a start beyond ρ passes: exit {code}\n{out}{err}"
    );
    Ok(())
}

/// Issue 44: `check --rrd-on-failure` records the frames around a failure
/// judged as the check judged them. Frame 0 starts within ρ and its
/// expectation is the hit at α = 0 that `initial_overlap = "alpha0"` (the
/// trace's table) gives; frame 1's expectation is wrong under any table.
/// The recording marks only frame 1 as divergent; with `--no-config` (the
/// rules) it marks both.
fn rrd_on_failure_marks_divergences_under_the_declared_conventions() -> anyhow::Result<()> {
    use sweeptrace::core::{InitialOverlap, Options};
    let dir = tempfile::tempdir()?;
    let scene = scene_t(0.0);
    let mesh = Mesh::new(scene.vertices.clone(), &scene.triangles)?;
    let start_within = SweepMsg {
        frame: 0,
        ball: 0,
        radius: 0.5,
        p0: [0.5, 0.5, 0.25],
        p1: [0.5, 0.5, -1.0],
    };
    let square = SweepMsg {
        frame: 1,
        p0: [1.0, 1.0, 3.0],
        p1: [1.0, 1.0, -3.0],
        ..start_within
    };
    let alpha0 = Options {
        initial_overlap: InitialOverlap::Alpha0,
        ..Options::default()
    };
    let sweep = |s: &SweepMsg| Sweep::new(s.p0, s.p1, s.radius);
    let first = sweep_mesh(&mesh, &sweep(&start_within), &alpha0)?;
    let trace = dir.path().join("marks.mcap");
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, &scene)?;
    w.sweep(1, &start_within)?;
    w.expected(1, &OutcomeMsg::from_outcome(0, 0, &first))?;
    w.sweep(2, &square)?;
    w.expected(2, &OutcomeMsg::miss(1, 0))?;
    std::fs::write(&trace, w.finish()?.into_inner())?;
    std::fs::write(
        dir.path().join("sweeptrace.toml"),
        "[engine]\ninitial_overlap = \"alpha0\"\n",
    )?;
    let marked = |extra: &[&str]| -> anyhow::Result<Vec<i64>> {
        let out = dir.path().join(format!("rrd{}", extra.len()));
        let mut args = os![
            "check",
            trace.as_os_str(),
            "--rrd-on-failure",
            out.as_os_str()
        ]
        .to_vec();
        args.extend(extra.iter().map(std::ffi::OsStr::new));
        let (code, stdout, stderr) = run_bin(&args)?;
        ensure!(code == 1, "{args:?}: exit {code}\n{stdout}{stderr}");
        let decoded = crate::replay::decode_rrd(&out.join("marks.rrd"))?;
        Ok(decoded
            .texts
            .iter()
            .filter(|((entity, _), _)| entity.trim_start_matches('/') == "divergences")
            .flat_map(|(_, by_frame)| by_frame.keys().copied())
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect())
    };
    let under_table = marked(&[])?;
    ensure!(under_table == [1], "under the table: {under_table:?}");
    let under_rules = marked(&["--no-config"])?;
    ensure!(under_rules == [0, 1], "under the rules: {under_rules:?}");
    Ok(())
}

fn binary_writes_case_and_test() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let out = dir.path().join("case.mcap");
    let f = fixture();
    let (code, stdout, stderr) = run_bin(os![
        "repro",
        f.as_os_str(),
        "--frame",
        "2",
        "-o",
        out.as_os_str()
    ])?;
    ensure!(code == 0, "exit {code}\n{stdout}\n{stderr}");
    ensure!(
        stdout.contains("#[test]")
            && stdout.contains("fn repro_wrong_engine_config_frame_2_ball_0()"),
        "stdout:\n{stdout}"
    );
    ensure!(
        stdout.contains("assert_eq!(outcome.kind(), Kind::Edge);"),
        "asserts the expectation:\n{stdout}"
    );
    ensure!(
        stderr.contains("the reduced case makes the same decision"),
        "stderr:\n{stderr}"
    );
    let (code, stdout, _) = run_bin(os!["check", out.as_os_str()])?;
    ensure!(
        code == 1 && stdout.contains("frame 2, ball 0: kind"),
        "check of the case: exit {code}\n{stdout}"
    );
    let (code, stdout, _) = run_bin(os!["info", out.as_os_str()])?;
    ensure!(
        code == 0 && stdout.contains("sweeptrace.repro") && stdout.contains("original_triangles"),
        "info of the case:\n{stdout}"
    );
    let (code, _, stderr) = run_bin(os![
        "repro",
        f.as_os_str(),
        "--frame",
        "99",
        "-o",
        out.as_os_str()
    ])?;
    ensure!(
        code == 2 && stderr.contains("no sweep of frame 99, ball 0"),
        "missing frame: exit {code}\n{stderr}"
    );
    Ok(())
}

fn sweep_from_trace_and_obj() -> anyhow::Result<()> {
    let f = fixture();
    let (code, out, err) = run_bin(os!["sweep", "--trace", f.as_os_str(), "--frame", "3"])?;
    ensure!(code == 0, "exit {code}\n{out}\n{err}");
    ensure!(
        out.contains("frame 3, ball 0")
            && out.contains("margin 0.1 (ρ = 0.4)")
            && out.contains("outcome: face collision at alpha = 0.43333")
            && out.contains("expected (the trace's /expected): face at alpha = 0.41667"),
        "sweep --trace:\n{out}"
    );
    // The trace's margin can be overridden: with 0 the expectation is met.
    let (_, out, _) = run_bin(os![
        "sweep",
        "--trace",
        f.as_os_str(),
        "--frame",
        "3",
        "--margin",
        "0"
    ])?;
    ensure!(
        out.contains("outcome: face collision at alpha = 0.41667"),
        "--margin 0:\n{out}"
    );
    let (_, out, _) = run_bin(os![
        "sweep",
        "--trace",
        f.as_os_str(),
        "--frame",
        "3",
        "--json"
    ])?;
    let json: serde_json::Value =
        serde_json::from_str(&out).map_err(|e| anyhow::anyhow!("{e}: {out}"))?;
    ensure!(
        json["expected"]["kind"] == "face" && json["margin"] == 0.1,
        "json: {json}"
    );

    let dir = tempfile::tempdir()?;
    let obj = dir.path().join("ramp.obj");
    std::fs::write(&obj, "v 0 0 0\nv 4 0 0\nv 0 4 0\nf 1 2 3\n")?;
    let (code, out, err) = run_bin(os![
        "sweep",
        "--mesh",
        obj.as_os_str(),
        "--radius",
        "0.5",
        "--from",
        "2,-0.3,3",
        "--to",
        "2,-0.3,-3"
    ])?;
    ensure!(code == 0, "exit {code}\n{out}\n{err}");
    ensure!(
        out.contains("scene ramp (1 triangle)")
            && out.contains("edge collision at alpha = 0.43333"),
        "sweep --mesh:\n{out}"
    );
    // Hex floats are read exactly.
    let (code, out, _) = run_bin(os![
        "sweep",
        "--scene",
        "triangle",
        "--from",
        "0x1p+0,0x1p+0,0x1.8p+1",
        "--to",
        "1,1,-3"
    ])?;
    ensure!(
        code == 0 && out.contains("face collision at alpha = 0.41667"),
        "hex input:\n{out}"
    );
    Ok(())
}

fn sweep_flag_errors() -> anyhow::Result<()> {
    let f = fixture();
    let cases: &[(&[&std::ffi::OsStr], &str)] = &[
        (os!["sweep", "--trace", f.as_os_str()], "--frame"),
        (
            os!["sweep", "--frame", "3", "--from", "0,0,1", "--to", "0,0,-1"],
            "--trace",
        ),
        (
            os![
                "sweep",
                "--trace",
                f.as_os_str(),
                "--frame",
                "3",
                "--from",
                "0,0,1"
            ],
            "cannot be used with",
        ),
        (
            os![
                "sweep", "--scene", "cube", "--mesh", "x.obj", "--from", "0,0,1", "--to", "0,0,-1"
            ],
            "cannot be used with",
        ),
        (os!["sweep", "--scene", "cube"], "--from"),
        (
            os![
                "sweep",
                "--mesh",
                "does-not-exist.obj",
                "--from",
                "0,0,1",
                "--to",
                "0,0,-1"
            ],
            "does-not-exist.obj",
        ),
        (
            os!["sweep", "--trace", f.as_os_str(), "--frame", "42"],
            "no sweep of frame 42, ball 0",
        ),
    ];
    for (args, says) in cases {
        let (code, out, err) = run_bin(args)?;
        ensure!(
            code == 2 && err.contains(says),
            "{args:?}: exit {code}, expected an error mentioning `{says}`\n{out}\n{err}"
        );
    }
    Ok(())
}

fn infer_wrong_engine_config_margin_0() -> anyhow::Result<()> {
    let report = check_file(&fixture(), &CheckOptions::default());
    let inferred = report.inferred.as_ref().context("nothing inferred")?;
    ensure!(inferred.margin == Some(0.0), "margin: {inferred:?}");
    ensure!(
        inferred.matches == 5 && inferred.compared == 5 && inferred.face_hits == 1,
        "{inferred:?}"
    );
    let text = render_text(&report);
    ensure!(
        text.contains("inferred engine configuration: margin 0 (from 1 expected face hit")
            && text.contains("expectations match with margin 0 and facing non_strict: 5 of 5"),
        "text:\n{text}"
    );
    let json: serde_json::Value = serde_json::from_str(&render_json(&[report], 1))?;
    ensure!(
        json["traces"][0]["inferred"]["margin"] == 0.0
            && json["traces"][0]["inferred"]["matches"] == 5,
        "json: {json}"
    );
    // A passing trace infers nothing.
    let ok = check_file(
        &root().join("traces/record_cube_corner_margin.mcap"),
        &CheckOptions::default(),
    );
    ensure!(ok.status() == Status::Ok && ok.inferred.is_none(), "{ok:?}");
    Ok(())
}

/// A trace of `scene` and `sweeps` whose expectations are the core's with
/// `margin` and `facing` (an engine configured otherwise than the scene).
pub(crate) fn recorded_by(
    scene: &SceneMsg,
    sweeps: &[SweepMsg],
    margin: f64,
    facing: Facing,
) -> anyhow::Result<Vec<u8>> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    w.scene(0, scene)?;
    for s in sweeps {
        w.sweep(1 + s.frame, s)?;
    }
    let plain = w.finish()?.into_inner();
    let options = ReplayOptions {
        conventions: sweeptrace::conventions::EngineConventions {
            margin: sweeptrace::conventions::MarginRule::Fixed(margin),
            facing: facing.into(),
            ..Default::default()
        },
        ..ReplayOptions::default()
    };
    bless_bytes(&plain, "<memory>", Cursor::new(Vec::new()), options)
        .map(|(_, c)| c.into_inner())
        .map_err(anyhow::Error::from)
}

/// A floor of two triangles (z = 0, front +z) and drops onto it, plus one
/// path parallel to it that crosses the edge y = 0 at height 0.3.
pub(crate) fn floor_and_sweeps(margin: f64, facing: Facing) -> (SceneMsg, Vec<SweepMsg>) {
    let scene = SceneMsg {
        name: Some("floor".into()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [8.0, 0.0, 0.0],
            [8.0, 8.0, 0.0],
            [0.0, 8.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        margin,
        facing,
    };
    let mut sweeps = Vec::new();
    let mut frame = 0;
    for (x, y) in [(1.0, 3.0), (2.5, 6.0), (5.0, 2.0), (6.0, 7.5), (3.3, 1.7)] {
        sweeps.push(SweepMsg {
            frame,
            ball: 0,
            radius: 0.5,
            p0: [x, y, 2.0 + 0.1 * frame as f64],
            p1: [x + 0.25, y, -1.0],
        });
        frame += 1;
    }
    // Parallel to the floor, toward it from y < 0: an edge hit on edge 0
    // of triangle 0 with n·d = 0, allowed only by the non_strict rule.
    sweeps.push(SweepMsg {
        frame,
        ball: 0,
        radius: 0.5,
        p0: [4.0, -1.0, 0.3],
        p1: [4.0, 1.0, 0.3],
    });
    (scene, sweeps)
}

fn infer_margin_and_facing_implied_by_a_parallel_hit() -> anyhow::Result<()> {
    // The engine: margin 0.05, non_strict; the scene declares margin 0, strict.
    let (scene, sweeps) = floor_and_sweeps(0.0, Facing::Strict);
    let bytes = recorded_by(&scene, &sweeps, 0.05, Facing::NonStrict)?;
    let report = check_reader(bytes.as_slice(), "floor", &CheckOptions::default());
    ensure!(report.status() == Status::Fail, "{}", render_text(&report));
    let inferred = report.inferred.as_ref().context("nothing inferred")?;
    let text = render_text(&report);
    ensure!(
        inferred.margin == Some(0.05) && inferred.face_hits == 5,
        "margin 0.05 from 5 face hits:\n{text}"
    );
    let spread = inferred.margin_spread.context("spread")?;
    ensure!(
        (spread.min - 0.05).abs() < 1e-12 && (spread.max - 0.05).abs() < 1e-12,
        "{spread:?}"
    );
    ensure!(
        inferred.facing == Facing::NonStrict
            && inferred.facing_implied
            && inferred.parallel_hits == 1
            && inferred.parallel_frame == Some(5),
        "facing implied by the parallel hit:\n{text}"
    );
    ensure!(
        text.contains("facing non_strict (an expected hit with n·d = 0, frame 5)")
            && text.contains("expectations match with margin 0.05 and facing non_strict: 6 of 6"),
        "text:\n{text}"
    );
    Ok(())
}

fn infer_strict_facing_by_replaying_both() -> anyhow::Result<()> {
    // The engine: margin 0, strict; the scene declares non_strict. The
    // parallel path then finds nothing: no hit implies a rule, replaying
    // both finds strict.
    let (scene, sweeps) = floor_and_sweeps(0.0, Facing::NonStrict);
    let bytes = recorded_by(&scene, &sweeps, 0.0, Facing::Strict)?;
    let report = check_reader(bytes.as_slice(), "floor", &CheckOptions::default());
    let text = render_text(&report);
    // The two rules differ only on a path parallel to the plane: a
    // fragile (grazing) divergence, not a failure; still inferred.
    ensure!(report.fragile.count == 1, "{text}");
    let inferred = report.inferred.as_ref().context("nothing inferred")?;
    ensure!(
        inferred.facing == Facing::Strict
            && !inferred.facing_implied
            && inferred.matches == 6
            && inferred.other_facing_matches == Some(5)
            && inferred.margin == Some(0.0),
        "strict by replay:\n{text}"
    );
    ensure!(
        text.contains("expectations match with margin 0 and facing strict: 6 of 6"),
        "text:\n{text}"
    );
    let _ = Kind::Face;
    Ok(())
}
