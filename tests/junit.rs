//! `check --junit` and `conform --junit`: the reports parsed back (an XML
//! 1.0 parser, in process), validated against the JUnit schema of
//! tests/fixtures/junit/junit.xsd and read back with Python's junitparser
//! (scripts/validate_junit.py; skipped without the packages unless
//! SWEEPTRACE_REQUIRE_PYTHON=1); GitHub Actions annotations; the report
//! written atomically.

use std::path::{Path, PathBuf};

use libtest_mimic::{Completion, Trial};
use roxmltree::{Document, Node};
use serde_json::Value;

use sweeptrace::core::Facing;
use sweeptrace::suite::{CheckOptions, check_file, render_text};

use crate::engine::example_engine_command;
use crate::support::run_bin;
use crate::{ensure, os, trial};
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(check_junit_of_passing_traces_has_one_suite_per_trace),
        trial!(check_junit_failure_and_error_carry_the_first_problem),
        trial!(check_junit_detail_sweeps_adds_divergences_and_tunnels),
        trial!(check_junit_fragile_divergences_are_skipped_unless_strict),
        trial!(conform_junit_fails_exactly_the_failing_rules),
        trial!(check_engine_junit_names_the_engine),
        trial!(github_annotations_only_in_github_actions),
        trial!(junit_not_writable_fails_before_checking_and_leaves_nothing),
        trial!(junit_reports_validate_against_the_schema_and_read_back),
    ]
}

const SCHEMA: &str = "tests/fixtures/junit/junit.xsd";
const WRONG_CONFIG: &str = "tests/fixtures/wrong_engine_config.mcap";
const TUNNEL: &str = "tests/fixtures/tunnel_floor.mcap";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn at(relative: &str) -> PathBuf {
    root().join(relative)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("test paths are UTF-8")
}

fn tempdir() -> anyhow::Result<tempfile::TempDir> {
    tempfile::tempdir().map_err(anyhow::Error::from)
}

fn read(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("reading {}: {e}", path.display()))
}

/// The document, parsed by a strict XML 1.0 parser.
fn parse(xml: &str) -> anyhow::Result<Document<'_>> {
    Document::parse(xml).map_err(|e| anyhow::anyhow!("not well-formed XML: {e}\n{xml}"))
}

fn attr<'a>(node: Node<'a, '_>, name: &str) -> anyhow::Result<&'a str> {
    node.attribute(name)
        .with_context(|| format!("<{}> without {name}", node.tag_name().name()))
}

fn count(node: Node, name: &str) -> anyhow::Result<u64> {
    attr(node, name)?
        .parse()
        .map_err(|e| anyhow::anyhow!("{name}: {e}"))
}

/// tests, failures, errors, skipped of a suite or the root.
fn counts(node: Node) -> anyhow::Result<[u64; 4]> {
    Ok([
        count(node, "tests")?,
        count(node, "failures")?,
        count(node, "errors")?,
        count(node, "skipped")?,
    ])
}

fn children<'a, 'i>(node: Node<'a, 'i>, tag: &str) -> Vec<Node<'a, 'i>> {
    node.children()
        .filter(|c| c.is_element() && c.has_tag_name(tag))
        .collect()
}

/// The case's `failure`, `error` or `skipped` element, if any.
fn outcome<'a, 'i>(case: Node<'a, 'i>) -> Option<Node<'a, 'i>> {
    case.children()
        .find(|c| c.is_element() && ["failure", "error", "skipped"].contains(&c.tag_name().name()))
}

fn result_of<'a>(case: Node<'a, '_>) -> &'a str {
    outcome(case).map_or("passed", |o| o.tag_name().name())
}

/// Checks that every suite's and the root's counts are those of the cases
/// they hold.
fn counts_add_up(doc: &Document) -> anyhow::Result<()> {
    let top = doc.root_element();
    ensure!(top.has_tag_name("testsuites"), "root: {:?}", top.tag_name());
    let mut total = [0u64; 4];
    for suite in children(top, "testsuite") {
        let mut held = [0u64; 4];
        for case in children(suite, "testcase") {
            held[0] += 1;
            match result_of(case) {
                "failure" => held[1] += 1,
                "error" => held[2] += 1,
                "skipped" => held[3] += 1,
                _ => {}
            }
        }
        ensure!(
            counts(suite)? == held,
            "suite {:?}: declares {:?}, holds {held:?}",
            suite.attribute("name"),
            counts(suite)?
        );
        for i in 0..4 {
            total[i] += held[i];
        }
    }
    ensure!(
        counts(top)? == total,
        "root declares {:?}, suites hold {total:?}",
        counts(top)?
    );
    Ok(())
}

fn property<'a>(suite: Node<'a, '_>, name: &str) -> Option<&'a str> {
    children(suite, "properties")
        .first()
        .into_iter()
        .flat_map(|p| children(*p, "property"))
        .find(|p| p.attribute("name") == Some(name))
        .and_then(|p| p.attribute("value"))
}

fn suite_named<'a, 'i>(doc: &'a Document<'i>, name: &str) -> anyhow::Result<Node<'a, 'i>> {
    children(doc.root_element(), "testsuite")
        .into_iter()
        .find(|s| s.attribute("name") == Some(name))
        .with_context(|| format!("no testsuite {name}"))
}

/// Only `keep` is left in `dir`: no temporary file of the report.
fn only_files(dir: &Path, keep: &[&str]) -> anyhow::Result<()> {
    let mut names: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut want: Vec<String> = keep.iter().map(|s| s.to_string()).collect();
    want.sort();
    ensure!(names == want, "{}: {names:?}, want {want:?}", dir.display());
    Ok(())
}

fn check_junit_of_passing_traces_has_one_suite_per_trace() -> anyhow::Result<()> {
    let dir = tempdir()?;
    let report = dir.path().join("r.xml");
    let (code, stdout, stderr) = run_bin(os!["check", s(&at("traces")), "--junit", s(&report)])?;
    ensure!(code == 0, "exit {code}\n{stdout}{stderr}");
    let traces = sweeptrace::suite::discovery::find_traces(&[at("traces")])?;
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;
    let top = doc.root_element();
    ensure!(
        counts(top)? == [traces.len() as u64, 0, 0, 0],
        "{:?} for {} traces",
        counts(top)?,
        traces.len()
    );
    let suites = children(top, "testsuite");
    ensure!(suites.len() == traces.len(), "{} suites", suites.len());
    for (suite, trace) in suites.iter().zip(&traces) {
        let name = trace.display().to_string();
        ensure!(
            attr(*suite, "name")? == name,
            "suite {:?}",
            suite.attribute("name")
        );
        ensure!(
            property(*suite, "tolerance.alpha") == Some("0.000001")
                && property(*suite, "tolerance.normal_degrees") == Some("0.01")
                && property(*suite, "fields") == Some("kind,triangle,feature,alpha,normal,contact")
                && property(*suite, "engine").is_none(),
            "properties of {name}"
        );
        let cases = children(*suite, "testcase");
        ensure!(cases.len() == 1, "{name}: {} cases", cases.len());
        let case = cases[0];
        ensure!(
            attr(case, "name")? == name && attr(case, "file")? == name,
            "case of {name}"
        );
        let time: f64 = attr(case, "time")?
            .parse()
            .map_err(|e| anyhow::anyhow!("time: {e}"))?;
        ensure!(time >= 0.0, "time {time}");
        ensure!(result_of(case) == "passed", "{name}: {}", result_of(case));
        let out = children(case, "system-out");
        ensure!(
            out.len() == 1
                && out[0]
                    .text()
                    .is_some_and(|t| t.starts_with(&format!("ok {name}: "))),
            "{name}: system-out {:?}",
            out.first().and_then(|o| o.text())
        );
    }
    let stamp = attr(top, "timestamp")?;
    ensure!(
        stamp.len() == 20 && stamp.ends_with('Z') && stamp.as_bytes()[10] == b'T',
        "timestamp {stamp}"
    );
    only_files(dir.path(), &["r.xml"])
}

fn check_junit_failure_and_error_carry_the_first_problem() -> anyhow::Result<()> {
    let dir = tempdir()?;
    let not_a_trace = dir.path().join("not_a_trace.mcap");
    std::fs::write(&not_a_trace, "plain text, not MCAP\n")?;
    let report = dir.path().join("f.xml");
    let wrong = at(WRONG_CONFIG);
    let (code, stdout, stderr) = run_bin(os![
        "check",
        s(&wrong),
        s(&not_a_trace),
        "--junit",
        s(&report)
    ])?;
    ensure!(code == 2, "exit {code}\n{stdout}{stderr}");
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;
    ensure!(counts(doc.root_element())? == [2, 1, 1, 0], "{xml}");

    let suite = suite_named(&doc, s(&wrong))?;
    let case = children(suite, "testcase")[0];
    let failure = outcome(case).context("no failure")?;
    ensure!(failure.has_tag_name("failure"), "{xml}");
    let message = attr(failure, "message")?;
    ensure!(
        message.starts_with(
            "2 of 5 compared sweeps diverge; first divergence: frame 2, ball 0: \
             kind expected edge, got none; triangle expected 0, got null"
        ) && !message.contains('\n'),
        "message: {message}"
    );
    ensure!(attr(failure, "type")? == "divergence", "type");
    // The body is what check prints for the trace, exactly.
    let printed = render_text(&check_file(&wrong, &CheckOptions::default()));
    ensure!(
        failure.text() == Some(printed.as_str()) && stdout.contains(&printed),
        "body:\n{:?}\nprinted:\n{printed}",
        failure.text()
    );

    let suite = suite_named(&doc, s(&not_a_trace))?;
    let case = children(suite, "testcase")[0];
    let error = outcome(case).context("no error")?;
    ensure!(error.has_tag_name("error"), "{xml}");
    let message = attr(error, "message")?;
    ensure!(
        message.contains("not an MCAP trace")
            && !message.contains('\n')
            && !message.starts_with(s(&not_a_trace)),
        "error message: {message}"
    );
    ensure!(
        error.text().is_some_and(|t| t.starts_with("ERROR ")),
        "error body {:?}",
        error.text()
    );
    only_files(dir.path(), &["f.xml", "not_a_trace.mcap"])
}

fn check_junit_detail_sweeps_adds_divergences_and_tunnels() -> anyhow::Result<()> {
    let dir = tempdir()?;
    let report = dir.path().join("d.xml");
    let (wrong, tunnel) = (at(WRONG_CONFIG), at(TUNNEL));
    let (code, stdout, stderr) = run_bin(os![
        "check",
        s(&wrong),
        s(&tunnel),
        "--junit",
        s(&report),
        "--junit-detail",
        "sweeps"
    ])?;
    ensure!(code == 1, "exit {code}\n{stdout}{stderr}");
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;

    let suite = suite_named(&doc, s(&wrong))?;
    let cases = children(suite, "testcase");
    let names: Vec<&str> = cases.iter().filter_map(|c| c.attribute("name")).collect();
    let want = [
        s(&wrong).to_string(),
        format!("{}: frame 2, ball 0", s(&wrong)),
        format!("{}: frame 3, ball 0", s(&wrong)),
    ];
    ensure!(names == want, "cases {names:?}");
    ensure!(
        cases.iter().all(|c| result_of(*c) == "failure"),
        "every case fails: {xml}"
    );
    let sweep = outcome(cases[2]).context("no failure")?;
    ensure!(
        attr(cases[2], "classname")? == "check.sweep"
            && attr(sweep, "message")?
                == "frame 3, ball 0: alpha expected 0.41667, got 0.43333 (|Δα| = 0.01667 > 1.0000e-6)",
        "sweep case: {:?}",
        sweep.attribute("message")
    );
    ensure!(
        sweep.text().is_some_and(
            |t| t.starts_with("frame 3, ball 0: alpha differ") && t.contains("the core found:")
        ),
        "sweep body {:?}",
        sweep.text()
    );

    let suite = suite_named(&doc, s(&tunnel))?;
    let cases = children(suite, "testcase");
    ensure!(
        cases.len() == 2,
        "tunnel suite: {} cases\n{xml}",
        cases.len()
    );
    let trace_failure = outcome(cases[0]).context("no failure")?;
    ensure!(
        attr(trace_failure, "type")? == "tunnel"
            && attr(trace_failure, "message")?
                .contains("first tunnel: frame 4, ball 0: through triangle 0 during its sweep"),
        "trace failure: {:?}",
        trace_failure.attribute("message")
    );
    ensure!(
        attr(cases[1], "classname")? == "check.tunnel"
            && attr(outcome(cases[1]).context("no failure")?, "message")?
                == "tunnel: frame 4, ball 0: through triangle 0 during its sweep at (1, -2, 0)",
        "tunnel case"
    );

    // The sweeps kept in detail, no more.
    let (code, _, stderr) = run_bin(os![
        "check",
        s(&wrong),
        "--max-details",
        "1",
        "--junit",
        s(&report),
        "--junit-detail",
        "sweeps"
    ])?;
    ensure!(code == 1, "exit {code}: {stderr}");
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    ensure!(counts(doc.root_element())? == [2, 2, 0, 0], "{xml}");
    only_files(dir.path(), &["d.xml"])
}

fn check_junit_fragile_divergences_are_skipped_unless_strict() -> anyhow::Result<()> {
    // Recorded with the strict facing rule, the scene declares non_strict:
    // they differ only on a path parallel to the floor, a divergence
    // rounding explains (tests/repro.rs, infer_strict_facing_by_replaying_both).
    let (scene, sweeps) = crate::repro::floor_and_sweeps(0.0, Facing::NonStrict);
    let bytes = crate::repro::recorded_by(&scene, &sweeps, 0.0, Facing::Strict)?;
    let dir = tempdir()?;
    let trace = dir.path().join("fragile.mcap");
    std::fs::write(&trace, bytes)?;
    let report = dir.path().join("s.xml");

    let (code, stdout, stderr) = run_bin(os!["check", s(&trace), "--junit", s(&report)])?;
    ensure!(code == 0, "exit {code}\n{stdout}{stderr}");
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;
    ensure!(counts(doc.root_element())? == [2, 0, 0, 1], "{xml}");
    let suite = suite_named(&doc, s(&trace))?;
    let cases = children(suite, "testcase");
    let skipped = outcome(cases[1]).context("no skipped")?;
    ensure!(
        skipped.has_tag_name("skipped")
            && attr(cases[1], "classname")? == "check.fragile"
            && attr(skipped, "message")?.starts_with(
                "a divergence rounding explains (not a failure without --strict): frame "
            )
            && attr(skipped, "message")?.contains("rounding explains it: "),
        "{xml}"
    );
    ensure!(result_of(cases[0]) == "passed", "the trace passes: {xml}");

    let (code, stdout, stderr) =
        run_bin(os!["check", s(&trace), "--strict", "--junit", s(&report)])?;
    ensure!(code == 1, "exit {code}\n{stdout}{stderr}");
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;
    ensure!(
        counts(doc.root_element())? == [1, 1, 0, 0],
        "--strict: {xml}"
    );
    let suite = suite_named(&doc, s(&trace))?;
    ensure!(
        property(suite, "strict") == Some("true"),
        "strict property: {xml}"
    );
    Ok(())
}

fn conform_junit_fails_exactly_the_failing_rules() -> anyhow::Result<()> {
    let dir = tempdir()?;
    let report = dir.path().join("c.xml");
    let engine = example_engine_command("--bug skip-vertex");
    let (code, stdout, stderr) = run_bin(os![
        "conform",
        "--engine",
        &engine,
        "--json",
        "--junit",
        s(&report),
        "--junit-detail",
        "sweeps"
    ])?;
    ensure!(code == 1, "exit {code}\n{stderr}");
    let json: Value =
        serde_json::from_str(&stdout).map_err(|e| anyhow::anyhow!("{e}: {stdout}"))?;
    let mut failing: Vec<String> = json["failing_rules"]
        .as_array()
        .context("failing_rules")?
        .iter()
        .filter_map(|v| v.as_str().map(str::to_string))
        .collect();
    failing.sort();
    ensure!(!failing.is_empty(), "the buggy engine fails rules");
    let rules = json["rules"].as_array().context("rules")?;

    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;
    let mut failed_rules: Vec<String> = Vec::new();
    let mut rule_cases = 0;
    let mut failed_cases = 0;
    for suite in children(doc.root_element(), "testsuite") {
        let group = attr(suite, "name")?;
        ensure!(
            property(suite, "engine") == Some(engine.as_str()),
            "engine property of {group}"
        );
        for case in children(suite, "testcase") {
            let name = attr(case, "name")?;
            ensure!(
                attr(case, "classname")? == format!("conform.{group}")
                    && name.split('.').next() == Some(group),
                "{name} in suite {group}"
            );
            match name.split_once('/') {
                None => {
                    rule_cases += 1;
                    if result_of(case) == "failure" {
                        failed_rules.push(name.to_string());
                        let rule = rules
                            .iter()
                            .find(|r| r["rule"] == name)
                            .with_context(|| format!("{name} not in the JSON"))?;
                        let message = attr(outcome(case).context("failure")?, "message")?;
                        let (failed, cases) = (
                            rule["failed"].as_u64().unwrap_or(0),
                            rule["cases"].as_u64().unwrap_or(0),
                        );
                        let want = format!(
                            "{failed} of {cases} {} {}; first failing case: {} (",
                            if cases == 1 { "case" } else { "cases" },
                            if failed == 1 { "fails" } else { "fail" },
                            rule["first_failure"]["case"].as_str().unwrap_or("?")
                        );
                        ensure!(message.starts_with(&want), "{name}: {message}\nwant {want}");
                    }
                }
                Some(_) => {
                    ensure!(result_of(case) == "failure", "divergent case {name} fails");
                    failed_cases += 1;
                }
            }
        }
    }
    failed_rules.sort();
    ensure!(
        failed_rules == failing,
        "failures {failed_rules:?}, failing_rules {failing:?}"
    );
    ensure!(
        rule_cases == rules.len(),
        "{rule_cases} rule cases, {} rules",
        rules.len()
    );
    ensure!(
        json["failed"].as_u64() == Some(failed_cases),
        "{failed_cases} failing case test cases, {} failed",
        json["failed"]
    );
    Ok(())
}

fn check_engine_junit_names_the_engine() -> anyhow::Result<()> {
    let dir = tempdir()?;
    let report = dir.path().join("e.xml");
    // An engine that ignores the margin diverges on a trace with one.
    let trace = at("traces/record_cube_corner_margin.mcap");
    let engine = example_engine_command("--bug ignore-margin");
    let (code, stdout, stderr) = run_bin(os![
        "check",
        s(&trace),
        "--engine",
        &engine,
        "--against",
        "expected",
        "--junit",
        s(&report)
    ])?;
    ensure!(code == 1, "exit {code}\n{stdout}{stderr}");
    let xml = read(&report)?;
    let doc = parse(&xml)?;
    counts_add_up(&doc)?;
    let suite = suite_named(&doc, s(&trace))?;
    ensure!(
        property(suite, "engine") == Some(engine.as_str())
            && property(suite, "against") == Some("expected"),
        "properties: {xml}"
    );
    let case = children(suite, "testcase")[0];
    let failure = outcome(case).context("no failure")?;
    ensure!(
        failure.has_tag_name("failure")
            && attr(failure, "message")?
                .contains("first divergence: frame 29, ball 0: kind expected "),
        "{xml}"
    );
    Ok(())
}

fn github_annotations_only_in_github_actions() -> anyhow::Result<()> {
    let dir = tempdir()?;
    // A name with the characters a property must escape.
    let trace = dir.path().join("a,b:c.mcap");
    std::fs::copy(at(WRONG_CONFIG), &trace)?;
    let run = |github: Option<&str>, json: bool| -> anyhow::Result<String> {
        let mut cmd = crate::support::bin();
        cmd.arg("check").arg(&trace);
        if json {
            cmd.arg("--json");
        }
        match github {
            Some(v) => cmd.env("GITHUB_ACTIONS", v),
            None => cmd.env_remove("GITHUB_ACTIONS"),
        };
        let out = cmd.output()?;
        ensure!(out.status.code() == Some(1), "exit {:?}", out.status.code());
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    };
    let stdout = run(Some("true"), false)?;
    let annotations: Vec<&str> = stdout.lines().filter(|l| l.starts_with("::")).collect();
    let file = s(&trace).replace(',', "%2C").replace(':', "%3A");
    ensure!(
        annotations
            == [
                format!(
                    "::error file={file},title=sweeptrace check%3A frame 2%2C ball 0 diverges::frame 2, ball 0: \
                     kind expected edge, got none; triangle expected 0, got null; feature expected 0, got null; \
                     alpha expected 0.46368, got 1 (|Δα| = 0.53632 > 1.0000e-6); normal expected [0, 0, 1], got null; \
                     contact expected [2, 0, 0], got null"
                ),
                format!(
                    "::error file={file},title=sweeptrace check%3A frame 3%2C ball 0 diverges::frame 3, ball 0: \
                     alpha expected 0.41667, got 0.43333 (|Δα| = 0.01667 > 1.0000e-6)"
                ),
            ],
        "annotations:\n{}",
        annotations.join("\n")
    );
    for (github, json) in [(None, false), (Some("false"), false), (Some("true"), true)] {
        let stdout = run(github, json)?;
        ensure!(
            !stdout.lines().any(|l| l.starts_with("::")),
            "GITHUB_ACTIONS={github:?}, --json {json}: annotations printed\n{stdout}"
        );
        if json {
            serde_json::from_str::<Value>(&stdout).map_err(|e| anyhow::anyhow!("--json: {e}"))?;
        }
    }
    Ok(())
}

fn junit_not_writable_fails_before_checking_and_leaves_nothing() -> anyhow::Result<()> {
    let dir = tempdir()?;
    let traces = at("traces");
    // A directory that does not exist.
    let missing = dir.path().join("no/such/dir/r.xml");
    let (code, stdout, stderr) = run_bin(os!["check", s(&traces), "--junit", s(&missing)])?;
    ensure!(
        code == 2
            && stdout.is_empty()
            && stderr.contains(&format!("creating the JUnit report {}", s(&missing))),
        "exit {code}\nstdout:\n{stdout}\nstderr:\n{stderr}"
    );
    // A directory as the file.
    let (code, stdout, stderr) = run_bin(os!["check", s(&traces), "--junit", s(dir.path())])?;
    ensure!(
        code == 2 && stdout.is_empty() && stderr.contains("is a directory"),
        "exit {code}\n{stdout}{stderr}"
    );
    // The run fails before the report is complete: no file, no temporary.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty)?;
    let report = dir.path().join("r.xml");
    let (code, _, stderr) = run_bin(os!["check", s(&empty), "--junit", s(&report)])?;
    ensure!(
        code == 2 && stderr.contains("no trace found"),
        "exit {code}: {stderr}"
    );
    let (code, _, stderr) = run_bin(os![
        "conform",
        "--engine",
        s(&dir.path().join("no-such-engine")),
        "--junit",
        s(&report)
    ])?;
    ensure!(
        code == 125,
        "engine that cannot start: exit {code}: {stderr}"
    );
    only_files(dir.path(), &["empty"])
}

fn junit_reports_validate_against_the_schema_and_read_back() -> anyhow::Result<Completion> {
    if let Err(skipped) = crate::support::python_with_modules(
        &["xmlschema", "junitparser"],
        "pip install xmlschema==4.3.2 junitparser==5.0.3",
    )? {
        return Ok(skipped);
    }
    let dir = tempdir()?;
    let file = |name: &str| dir.path().join(name);
    let not_a_trace = file("not_a_trace.mcap");
    std::fs::write(&not_a_trace, "plain text\n")?;
    let (scene, sweeps) = crate::repro::floor_and_sweeps(0.0, Facing::NonStrict);
    let fragile = file("fragile.mcap");
    std::fs::write(
        &fragile,
        crate::repro::recorded_by(&scene, &sweeps, 0.0, Facing::Strict)?,
    )?;
    let engine = example_engine_command("--bug skip-vertex");
    let runs: Vec<(&str, Vec<String>, i32)> = vec![
        ("pass.xml", vec!["check".into(), s(&at("traces")).into()], 0),
        (
            "fail.xml",
            vec![
                "check".into(),
                s(&at(WRONG_CONFIG)).into(),
                s(&at(TUNNEL)).into(),
                s(&not_a_trace).into(),
                "--junit-detail".into(),
                "sweeps".into(),
            ],
            2,
        ),
        ("fragile.xml", vec!["check".into(), s(&fragile).into()], 0),
        (
            "conform.xml",
            vec![
                "conform".into(),
                "--engine".into(),
                engine.clone(),
                "--junit-detail".into(),
                "sweeps".into(),
            ],
            1,
        ),
    ];
    let mut reports: Vec<PathBuf> = Vec::new();
    for (name, args, want) in &runs {
        let out = file(name);
        let mut argv: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
        argv.push(std::ffi::OsStr::new("--junit"));
        argv.push(out.as_os_str());
        let (code, _, stderr) = run_bin(&argv)?;
        ensure!(code == *want, "{name}: exit {code}, want {want}: {stderr}");
        reports.push(out);
    }
    let validate = |files: &[PathBuf]| {
        std::process::Command::new("python3")
            .arg(at("scripts/validate_junit.py"))
            .arg(at(SCHEMA))
            .args(files)
            .output()
            .map_err(|e| anyhow::anyhow!("running python3: {e}"))
    };
    let out = validate(&reports)?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    ensure!(
        out.status.success(),
        "validation failed:\n{}{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read_back: Vec<Value> = stdout
        .lines()
        .map(serde_json::from_str)
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow::anyhow!("{e}: {stdout}"))?;
    ensure!(read_back.len() == reports.len(), "{stdout}");
    for (report, back) in reports.iter().zip(&read_back) {
        let xml = read(report)?;
        let doc = parse(&xml)?;
        let c = counts(doc.root_element())?;
        let theirs = ["tests", "failures", "errors", "skipped"]
            .map(|k| back[k].as_u64().unwrap_or(u64::MAX));
        ensure!(
            theirs == c,
            "{}: junitparser reads {theirs:?}, the file says {c:?}",
            report.display()
        );
        let suites = back["suites"].as_array().context("suites")?;
        let ours = children(doc.root_element(), "testsuite");
        ensure!(suites.len() == ours.len(), "{}: suites", report.display());
        for (theirs, ours) in suites.iter().zip(ours) {
            let results: Vec<&str> = theirs["cases"]
                .as_array()
                .context("cases")?
                .iter()
                .filter_map(|c| c["result"].as_str())
                .collect();
            let want: Vec<&str> = children(ours, "testcase")
                .into_iter()
                .map(result_of)
                .collect();
            ensure!(
                results == want,
                "{}: junitparser reads {results:?}, want {want:?}",
                report.display()
            );
        }
    }
    // fail.xml: failures and the error as junitparser sees them.
    let fail = &read_back[1];
    ensure!(
        [
            &fail["tests"],
            &fail["failures"],
            &fail["errors"],
            &fail["skipped"]
        ]
        .map(|v| v.as_u64())
            == [Some(6), Some(5), Some(1), Some(0)],
        "fail.xml: {fail}"
    );
    let first = &fail["suites"][0]["cases"][0];
    ensure!(
        first["result"] == "failure"
            && first["message"]
                .as_str()
                .is_some_and(|m| m
                    .contains("first divergence: frame 2, ball 0: kind expected edge, got none")),
        "{first}"
    );
    ensure!(
        read_back[2]["skipped"] == 1,
        "fragile.xml: {}",
        read_back[2]
    );
    // The schema rejects what CI tools would not read: a case without a
    // name, counts that do not add up.
    let xml = read(&reports[0])?;
    let broken = file("broken.xml");
    let name = xml.find("<testcase name=\"").context("no testcase")?;
    let mut unnamed = xml.clone();
    unnamed.replace_range(name..name + "<testcase name=\"".len(), "<testcase label=\"");
    std::fs::write(&broken, unnamed)?;
    let miscounted = file("miscounted.xml");
    std::fs::write(
        &miscounted,
        xml.replacen("failures=\"0\"", "failures=\"1\"", 1),
    )?;
    for bad in [broken, miscounted] {
        let out = validate(std::slice::from_ref(&bad))?;
        ensure!(
            out.status.code() == Some(1),
            "{} was accepted: {}",
            bad.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(Completion::Completed)
}
