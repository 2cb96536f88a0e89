//! Regression checking, blessing and diffing.
//!
//! Every `*.mcap` under `traces/` and `examples/rapier/` (found at run
//! time, so adding a trace needs no code) is a test case of its own, checked
//! with the same library code as `sweeptrace check`, with the settings its
//! `sweeptrace.toml` files give it (for a trace recorded by another engine,
//! such as the Rapier sample: `examples/sweeptrace.toml`).
//!
//! The fixture `tests/fixtures/wrong_engine_config.mcap` is made by
//! `fixture_bytes` below, from the project's own writer; a test compares
//! it with the committed file, and rewrites the file with
//! `SWEEPTRACE_BLESS=1 cargo test --test integration -- fixture`.
//! Its scene declares margin 0.1; its `/expected` outcomes were computed
//! with margin 0 (an engine configuration the scene does not declare), so
//! the first divergent sweep is frame 2 (expected an edge hit on edge 0.0,
//! the core finds nothing at ρ = 0.4) and frame 3 differs in α.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use libtest_mimic::Trial;
use sweeptrace::conventions::Source;
use sweeptrace::core::Kind;
use sweeptrace::judge::{Field, FieldSet, Tolerances, compare};
use sweeptrace::replay::ReplayOptions;
use sweeptrace::suite::bless::bless_bytes;
use sweeptrace::suite::config::{Overrides, settings_for};
use sweeptrace::suite::diff::{Side, diff};
use sweeptrace::suite::discovery::find_traces;
use sweeptrace::suite::{CheckOptions, Status, check_file, check_reader, render_json, render_text};
use sweeptrace::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceReader, TraceWriter};

use crate::ensure;
use crate::os;
use crate::support::run_bin;
use crate::support::scene_t;
use crate::trial;
use anyhow::Context as _;

const FIXTURE: &str = "tests/fixtures/wrong_engine_config.mcap";

pub fn tests() -> Vec<Trial> {
    let mut trials = vec![
        trial!(compare_only_fields_present),
        trial!(compare_null_is_compared),
        trial!(compare_tolerances),
        trial!(compare_nan_never_matches),
        trial!(compare_only_selected_fields),
        trial!(check_fields_option_binary),
        trial!(rapier_sample_needs_its_settings_file),
        trial!(differences_below_the_shown_digits_are_shown_in_full),
        trial!(blessed_trace_passes),
        trial!(wrong_engine_config_fixture_fails_with_frame_and_reason),
        trial!(wrong_engine_config_fixture_binary_exit_1),
        trial!(wrong_engine_config_fixture_is_what_its_generator_makes),
        trial!(report_json_fixture_is_what_check_makes),
        trial!(no_expected_channel_is_not_a_pass),
        trial!(binary_errors_exit_2),
        trial!(trace_discovery_in_directories),
        trial!(bless_round_trip_fixes_wrong_expectations),
        trial!(bless_keeps_foreign_channel_metadata_attachment),
        trial!(bless_binary_requires_output_and_keeps_input),
        trial!(diff_same_trace_is_same),
        trial!(diff_strict_facing_reports_first_divergence),
        trial!(diff_binary_exit_codes),
    ];
    trials.extend(trace_trials());
    trials
}

/// One trial per `*.mcap` under `traces/` and `examples/rapier/`, found at
/// run time.
fn trace_trials() -> Vec<Trial> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dirs: Vec<PathBuf> = ["traces", "examples/rapier"]
        .iter()
        .map(|d| root.join(d))
        .filter(|d| d.is_dir())
        .collect();
    if dirs.is_empty() {
        return Vec::new();
    }
    match find_traces(&dirs) {
        Ok(paths) => paths
            .into_iter()
            .map(|path| {
                let name = path
                    .strip_prefix(root)
                    .unwrap_or(&path)
                    .display()
                    .to_string();
                trial(&format!("check::trace::{name}"), move || {
                    let settings = settings_for(&path, &Overrides::default())?;
                    let report =
                        check_file(&path, &settings.check_options(CheckOptions::default()));
                    ensure!(report.status() == Status::Ok, "{}", render_text(&report));
                    Ok(())
                })
            })
            .collect(),
        Err(e) => vec![trial("check::trace::discovery", move || {
            Err::<(), _>(anyhow::Error::from(e))
        })],
    }
}

// ---------------------------------------------------------------- helpers

fn sweep(frame: u64, p0: [f64; 3], p1: [f64; 3]) -> SweepMsg {
    SweepMsg {
        frame,
        ball: 0,
        radius: 0.5,
        p0,
        p1,
    }
}

/// The sweeps of the fixture: two misses, an edge hit that needs ρ ≥ 0.45,
/// the face of worked example 1, a miss.
fn fixture_sweeps() -> Vec<SweepMsg> {
    vec![
        sweep(0, [10.0, 10.0, 3.0], [11.0, 10.0, 3.0]),
        sweep(1, [10.0, 10.0, 3.0], [10.0, 11.0, 3.0]),
        sweep(2, [2.0, -0.45, 3.0], [2.0, -0.45, -3.0]),
        sweep(3, [1.0, 1.0, 3.0], [1.0, 1.0, -3.0]),
        sweep(4, [10.0, 10.0, 3.0], [11.0, 11.0, 3.0]),
    ]
}

/// A trace of `scene` and `sweeps`, with the given expectations logged
/// right after their sweeps.
fn write_trace(scene: &SceneMsg, sweeps: &[SweepMsg], expected: &[OutcomeMsg]) -> Vec<u8> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
    w.scene(0, scene).expect("scene");
    for s in sweeps {
        let t = 1_000_000 * (s.frame + 1);
        w.sweep(t, s).expect("sweep");
        for e in expected
            .iter()
            .filter(|e| e.frame == s.frame && e.ball == s.ball)
        {
            w.expected(t, e).expect("expected");
        }
    }
    w.finish().expect("finish").into_inner()
}

/// Blesses `bytes` in memory with `options`.
fn bless_with(bytes: &[u8], options: ReplayOptions) -> anyhow::Result<Vec<u8>> {
    bless_bytes(bytes, "<memory>", Cursor::new(Vec::new()), options)
        .map(|(_, c)| c.into_inner())
        .map_err(anyhow::Error::from)
}

/// The fixture's bytes: scene margin 0.1, expectations from margin 0.
fn fixture_bytes() -> anyhow::Result<Vec<u8>> {
    let plain = write_trace(&scene_t(0.1), &fixture_sweeps(), &[]);
    bless_with(
        &plain,
        ReplayOptions {
            conventions: sweeptrace::conventions::EngineConventions {
                margin: sweeptrace::conventions::MarginRule::Fixed(0.0),
                ..Default::default()
            },
            ..ReplayOptions::default()
        },
    )
}

/// The fixtures whose report's JSON is pinned under `tests/fixtures/report/`:
/// between them divergences, an inference, ghost contacts and a tunnel.
const REPORT_FIXTURES: [&str; 3] = [
    "wrong_engine_config",
    "rapier_floor_contacts",
    "tunnel_floor",
];

/// The JSON of a report, its keys in the order the report serializes them
/// (`check --json` sorts them), is the committed one: a change of the
/// report's shape changes no key, no value and no order. Rewritten with
/// `SWEEPTRACE_BLESS=1 cargo test --test integration -- fixture`.
fn report_json_fixture_is_what_check_makes() -> anyhow::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    for name in REPORT_FIXTURES {
        let file = std::fs::File::open(dir.join(format!("{name}.mcap")))?;
        let report = check_reader(file, &format!("{name}.mcap"), &CheckOptions::default());
        let mut json = serde_json::to_string_pretty(&report)?;
        json.push('\n');
        crate::support::compare_or_bless(
            &dir.join(format!("report/{name}.json")),
            json.as_bytes(),
        )?;
    }
    Ok(())
}

fn check_bytes(bytes: &[u8]) -> sweeptrace::suite::TraceReport {
    check_reader(bytes, "<memory>", &CheckOptions::default())
}

fn fixture_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(FIXTURE)
}

fn full(frame: u64, alpha: f64, kind: Kind) -> OutcomeMsg {
    OutcomeMsg {
        frame,
        ball: 0,
        alpha,
        kind,
        triangle: Some(Some(0)),
        feature: Some(Some(0)),
        normal: Some(Some([0.0, 0.0, 1.0])),
        contact: Some(Some([1.0, 1.0, 0.0])),
    }
}

// ---------------------------------------------------------------- compare

fn compare_only_fields_present() -> anyhow::Result<()> {
    let got = full(0, 0.5, Kind::Face);
    let expected = OutcomeMsg {
        triangle: None,
        feature: None,
        normal: None,
        contact: None,
        ..full(0, 0.5, Kind::Face)
    };
    // Absent fields are not compared even though `got` differs there.
    let got_other = OutcomeMsg {
        triangle: Some(Some(7)),
        normal: Some(Some([1.0, 0.0, 0.0])),
        ..got
    };
    let d = compare(&expected, &got_other, &Tolerances::default());
    ensure!(d.is_empty(), "absent fields were compared: {d:?}");
    let expected_tri = OutcomeMsg {
        triangle: Some(Some(0)),
        ..expected
    };
    let d = compare(&expected_tri, &got_other, &Tolerances::default());
    ensure!(
        d.len() == 1 && d[0].field == Field::Triangle,
        "a present triangle must be compared: {d:?}"
    );
    Ok(())
}

fn compare_null_is_compared() -> anyhow::Result<()> {
    let got = full(0, 0.5, Kind::Face);
    let expected = OutcomeMsg {
        normal: Some(None),
        contact: None,
        triangle: None,
        feature: None,
        ..got
    };
    let d = compare(&expected, &got, &Tolerances::default());
    ensure!(
        d.len() == 1 && d[0].field == Field::Normal,
        "a null normal must be compared: {d:?}"
    );
    Ok(())
}

fn compare_tolerances() -> anyhow::Result<()> {
    let tol = Tolerances {
        alpha: 1e-3,
        normal_degrees: 1.0,
        contact: 0.01,
        ..Tolerances::default()
    };
    let expected = full(0, 0.5, Kind::Face);
    // 0.5° off, α 5e-4 off, contact 0.005 off: all within.
    let a = 0.5f64.to_radians();
    let got = OutcomeMsg {
        alpha: 0.5005,
        normal: Some(Some([a.sin(), 0.0, a.cos()])),
        contact: Some(Some([1.005, 1.0, 0.0])),
        ..expected
    };
    let d = compare(&expected, &got, &tol);
    ensure!(d.is_empty(), "within tolerance: {d:?}");
    // 2° off, α 2e-3 off, contact 0.02 off: all out.
    let a = 2f64.to_radians();
    let got = OutcomeMsg {
        alpha: 0.502,
        normal: Some(Some([a.sin(), 0.0, a.cos()])),
        contact: Some(Some([1.02, 1.0, 0.0])),
        ..expected
    };
    let fields: Vec<Field> = compare(&expected, &got, &tol)
        .iter()
        .map(|f| f.field)
        .collect();
    ensure!(
        fields == vec![Field::Alpha, Field::Normal, Field::Contact],
        "outside tolerance: {fields:?}"
    );
    Ok(())
}

/// An engine that reports the contact normal at an edge hit (Rapier does):
/// the normal differs from the core's face normal, and `--fields` leaves it
/// out of the comparison.
fn compare_only_selected_fields() -> anyhow::Result<()> {
    let got = full(0, 0.5, Kind::Edge);
    let expected = OutcomeMsg {
        normal: Some(Some([0.0, -0.6, 0.8])),
        ..got
    };
    let all = compare(&expected, &got, &Tolerances::default());
    ensure!(
        all.len() == 1 && all[0].field == Field::Normal,
        "every field: {all:?}"
    );
    let fields = FieldSet::of(&[Field::Kind, Field::Alpha]);
    let tol = Tolerances {
        fields,
        ..Tolerances::default()
    };
    let some = compare(&expected, &got, &tol);
    ensure!(some.is_empty(), "kind and alpha only: {some:?}");
    // Outside the set nothing is compared, inside it still is.
    let wrong_alpha = OutcomeMsg {
        alpha: 0.75,
        ..expected
    };
    let d = compare(&wrong_alpha, &got, &tol);
    ensure!(d.len() == 1 && d[0].field == Field::Alpha, "alpha: {d:?}");
    ensure!(
        fields.names() == "kind,alpha" && !fields.is_all() && FieldSet::ALL.is_all(),
        "names: {}",
        fields.names()
    );
    Ok(())
}

fn rapier_sample() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/rapier/rapier_mini_golf.mcap")
}

/// `check --fields`: the report names the compared fields; an unknown
/// field is a usage error (exit 2).
fn check_fields_option_binary() -> anyhow::Result<()> {
    let trace = rapier_sample();
    // Before the path: the option takes one comma-separated value, not the
    // path after it.
    let (code, out, err) = run_bin(os![
        "check",
        "--fields",
        "kind,alpha",
        trace.as_os_str(),
        "--tolerance",
        "1e-5"
    ])?;
    ensure!(code == 0, "exit {code}: {out}{err}");
    ensure!(out.contains("fields compared: kind,alpha"), "{out}");
    let (code, out, err) = run_bin(os!["check", trace.as_os_str(), "--fields", "kind,colour"])?;
    ensure!(
        code == 2 && err.contains("colour"),
        "unknown field: exit {code}: {out}{err}"
    );
    Ok(())
}

/// The Rapier-recorded sample passes with no options, by the settings of
/// `examples/sweeptrace.toml`, every field compared, and fails without
/// that file or either part of its settings (Rapier reports the contact
/// normal at an edge hit, its `[engine]` table's `normal = "contact"`; its
/// α and witness points are accurate to about 1e-5), so every setting is
/// needed and the test of the sample can fail.
fn rapier_sample_needs_its_settings_file() -> anyhow::Result<()> {
    let trace = rapier_sample();
    let settings = settings_for(&trace, &Overrides::default())?;
    let tolerances = settings.tolerances();
    ensure!(
        tolerances.fields == FieldSet::ALL
            && tolerances.alpha == 1e-5
            && tolerances.contact == 1e-5
            && tolerances.normal_degrees == Tolerances::default().normal_degrees
            && settings.engine.conventions().normal == sweeptrace::conventions::NormalRule::Contact
            && !settings.strict.value
            && !settings.allow_tunnels.value,
        "the settings changed ({settings:?}): update this test"
    );
    let normal = settings
        .engine
        .normal
        .clone()
        .map_or(Source::Default, |s| s.source);
    for source in [&normal, &settings.alpha.source] {
        ensure!(
            matches!(source, Source::File { file, .. } if file == "examples/sweeptrace.toml"),
            "{source:?}"
        );
    }
    let (code, out, err) = run_bin(os!["check", trace.as_os_str()])?;
    ensure!(code == 0, "with its settings file: exit {code}: {out}{err}");
    let (code, out, err) = run_bin(os!["check", "--no-config", trace.as_os_str()])?;
    ensure!(code == 1, "default options: exit {code}: {out}{err}");
    let (code, out, err) = run_bin(os!["check", trace.as_os_str(), "--normal", "face"])?;
    ensure!(
        code == 1
            && out.contains("1 of 553 compared sweeps diverges")
            && out.contains("normal: expected"),
        "the face normal: exit {code}: {out}{err}"
    );
    // The command line overrides the file, key by key.
    let (code, out, err) = run_bin(os![
        "check",
        trace.as_os_str(),
        "--tolerance",
        "1e-6",
        "--contact-tolerance",
        "1e-6"
    ])?;
    ensure!(
        code == 1 && out.contains("alpha: expected"),
        "default tolerances: exit {code}: {out}{err}"
    );
    Ok(())
}

fn compare_nan_never_matches() -> anyhow::Result<()> {
    let expected = full(0, 0.5, Kind::Face);
    let got = OutcomeMsg {
        alpha: f64::NAN,
        normal: Some(Some([f64::NAN, 0.0, 1.0])),
        ..expected
    };
    let fields: Vec<Field> = compare(&expected, &got, &Tolerances::default())
        .iter()
        .map(|f| f.field)
        .collect();
    ensure!(
        fields == vec![Field::Alpha, Field::Normal],
        "NaN must differ: {fields:?}"
    );
    Ok(())
}

// ---------------------------------------------------------------- check

fn blessed_trace_passes() -> anyhow::Result<()> {
    let plain = write_trace(&scene_t(0.1), &fixture_sweeps(), &[]);
    let blessed = bless_with(&plain, ReplayOptions::default())?;
    let report = check_bytes(&blessed);
    ensure!(report.status() == Status::Ok, "{}", render_text(&report));
    ensure!(
        report.compared == 5 && report.expectations.missing == 0,
        "counts: {report:?}"
    );
    ensure!(
        render_text(&report).starts_with("ok "),
        "text: {}",
        render_text(&report)
    );
    Ok(())
}

fn check_fixture_report(report: &sweeptrace::suite::TraceReport) -> anyhow::Result<()> {
    let text = render_text(report);
    ensure!(
        report.status() == Status::Fail,
        "status {:?}\n{text}",
        report.status()
    );
    ensure!(
        report.divergent == 2,
        "two sweeps diverge (2 and 3):\n{text}"
    );
    let first = report
        .divergences
        .details
        .first()
        .context("no divergence detail")?;
    ensure!(
        first.frame == 2,
        "first divergent frame is 2, got {}",
        first.frame
    );
    ensure!(
        first.fields.iter().any(|f| f.field == Field::Kind),
        "frame 2 differs in kind: {:?}",
        first.fields
    );
    ensure!(
        text.contains("first divergence: frame 2, ball 0"),
        "names the first frame:\n{text}"
    );
    ensure!(
        text.contains("kind: expected edge, got none"),
        "the reason:\n{text}"
    );
    // The test that would have produced the expected edge, and why not:
    // at ρ = 0.4 the path never comes within ρ of edge 0's line.
    ensure!(
        text.contains("expected result's test: edge 0.0: ") && text.contains("< 0 (never within ρ"),
        "explains the expected test:\n{text}"
    );
    ensure!(
        text.contains("margin 0.1"),
        "names the margin used:\n{text}"
    );
    ensure!(text.contains("edge -> none: 1"), "summary by kind:\n{text}");
    Ok(())
}

fn wrong_engine_config_fixture_fails_with_frame_and_reason() -> anyhow::Result<()> {
    let report = check_file(&fixture_path(), &CheckOptions::default());
    check_fixture_report(&report)?;
    // The committed fixture is what the generator makes.
    let fresh = check_bytes(&fixture_bytes()?);
    check_fixture_report(&fresh)?;
    let json: serde_json::Value = serde_json::from_str(&render_json(&[report], 1))?;
    ensure!(json["exit_code"] == 1, "json exit code: {json}");
    ensure!(
        json["traces"][0]["divergences"][0]["frame"] == 2,
        "json first frame: {json}"
    );
    Ok(())
}

fn wrong_engine_config_fixture_binary_exit_1() -> anyhow::Result<()> {
    let fixture = fixture_path();
    let (code, out, err) = run_bin(os!["check", fixture.as_os_str()])?;
    ensure!(code == 1, "exit {code}\n{out}\n{err}");
    ensure!(out.starts_with("FAIL "), "stdout:\n{out}");
    ensure!(out.contains("first divergence: frame 2"), "stdout:\n{out}");
    let (code, out, err) = run_bin(os!["check", fixture.as_os_str(), "--json"])?;
    ensure!(code == 1, "exit {code}\n{out}\n{err}");
    let json: serde_json::Value =
        serde_json::from_str(&out).map_err(|e| anyhow::anyhow!("{e}: {out}"))?;
    ensure!(json["traces"][0]["status"] == "fail", "json: {json}");
    ensure!(json["exit_code"] == 1, "json exit code: {json}");
    // A tolerance wide enough for frame 3's α still fails on frame 2's kind.
    let (code, _, _) = run_bin(os!["check", fixture.as_os_str(), "--tolerance", "0.5"])?;
    ensure!(code == 1, "exit {code} with a wide α tolerance");
    Ok(())
}

fn no_expected_channel_is_not_a_pass() -> anyhow::Result<()> {
    let plain = write_trace(&scene_t(0.0), &fixture_sweeps(), &[]);
    let report = check_bytes(&plain);
    ensure!(
        report.status() == Status::NoExpectations,
        "status {:?}",
        report.status()
    );
    let text = render_text(&report);
    ensure!(
        text.starts_with("NO EXPECTATIONS")
            && text.contains("the /expected channel holds no message"),
        "{text}"
    );
    // Without the channel at all.
    let raw = foreign_trace_with(false)?;
    let text = render_text(&check_bytes(&raw));
    ensure!(
        text.starts_with("NO EXPECTATIONS") && text.contains("no /expected channel"),
        "{text}"
    );
    // Through the binary: exit 2.
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("plain.mcap");
    std::fs::write(&path, &plain)?;
    let (code, out, _) = run_bin(os!["check", path.as_os_str()])?;
    ensure!(
        code == 2 && out.contains("NO EXPECTATIONS"),
        "exit {code}: {out}"
    );
    Ok(())
}

fn binary_errors_exit_2() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let missing = dir.path().join("missing.mcap");
    let (code, out, _) = run_bin(os!["check", missing.as_os_str()])?;
    ensure!(
        code == 2 && out.contains("ERROR"),
        "missing file: exit {code}: {out}"
    );
    let garbage = dir.path().join("garbage.mcap");
    std::fs::write(&garbage, b"not an mcap file")?;
    let (code, out, _) = run_bin(os!["check", garbage.as_os_str()])?;
    ensure!(
        code == 2 && out.contains("ERROR"),
        "garbage: exit {code}: {out}"
    );
    // A truncated good trace: an error, never a pass.
    let good = bless_with(
        &write_trace(&scene_t(0.0), &fixture_sweeps(), &[]),
        ReplayOptions::default(),
    )?;
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &good[..good.len() * 2 / 3])?;
    let (code, out, _) = run_bin(os!["check", cut.as_os_str()])?;
    ensure!(code == 3, "truncated: exit {code}: {out}");
    // Every command gives a truncated trace the same exit code (3,
    // incomplete input), as the README's table says.
    let outcomes = dir.path().join("cut.jsonl");
    let commands: [&[&std::ffi::OsStr]; 3] = [
        os!["info", cut.as_os_str()],
        os![
            "replay",
            cut.as_os_str(),
            "--outcomes",
            outcomes.as_os_str()
        ],
        os!["check", cut.as_os_str(), "--json"],
    ];
    for args in commands {
        let (code, _, err) = run_bin(args)?;
        ensure!(
            code == 3,
            "{args:?} on a truncated trace: exit {code}: {err}"
        );
    }
    let (code, _, err) = run_bin(os!["check", missing.as_os_str(), "--tolerance", "nan"])?;
    ensure!(code == 2, "NaN tolerance: exit {code}: {err}");
    Ok(())
}

fn trace_discovery_in_directories() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let sub = dir.path().join("b");
    std::fs::create_dir_all(&sub)?;
    let good = bless_with(
        &write_trace(&scene_t(0.0), &fixture_sweeps(), &[]),
        ReplayOptions::default(),
    )?;
    std::fs::write(dir.path().join("a.mcap"), &good)?;
    std::fs::write(sub.join("c.mcap"), &good)?;
    std::fs::write(sub.join("notes.txt"), b"x")?;
    let found = find_traces(&[dir.path().to_path_buf()])?;
    let names: Vec<String> = found
        .iter()
        .map(|p| {
            p.strip_prefix(dir.path())
                .unwrap_or(p)
                .display()
                .to_string()
        })
        .collect();
    ensure!(
        names
            == vec![
                "a.mcap".to_string(),
                format!("b{}c.mcap", std::path::MAIN_SEPARATOR)
            ],
        "found {names:?}"
    );
    let (code, out, err) = run_bin(os!["check", dir.path().as_os_str()])?;
    ensure!(code == 0, "exit {code}\n{out}\n{err}");
    ensure!(out.contains("2 traces: 2 ok"), "{out}");
    // One failing trace among passing ones: exit 1, and an .rrd of it.
    std::fs::copy(fixture_path(), sub.join("wrong.mcap"))?;
    let rrd_dir = dir.path().join("rrd");
    let (code, out, err) = run_bin(os![
        "check",
        dir.path().as_os_str(),
        "--rrd-on-failure",
        rrd_dir.as_os_str()
    ])?;
    ensure!(code == 1, "exit {code}\n{out}\n{err}");
    let rrd = rrd_dir.join("wrong.rrd");
    let size = std::fs::metadata(&rrd).map(|m| m.len()).unwrap_or(0);
    ensure!(size > 0, "no recording at {}: {err}", rrd.display());
    Ok(())
}

// ---------------------------------------------------------------- bless

fn bless_round_trip_fixes_wrong_expectations() -> anyhow::Result<()> {
    let wrong = fixture_bytes()?;
    ensure!(
        check_bytes(&wrong).status() == Status::Fail,
        "the input must fail"
    );
    let blessed = bless_with(&wrong, ReplayOptions::default())?;
    let report = check_bytes(&blessed);
    ensure!(report.status() == Status::Ok, "{}", render_text(&report));
    ensure!(
        report.compared == 5 && report.expectations.unmatched == 0,
        "one expectation per sweep, old ones gone: {report:?}"
    );
    // Blessing twice gives the same bytes (deterministic writer).
    let twice = bless_with(&blessed, ReplayOptions::default())?;
    ensure!(twice == blessed, "bless is not idempotent");
    Ok(())
}

/// A trace written with the raw `mcap` writer: a foreign channel with its
/// own schema, a channel without schema, a metadata record, an attachment,
/// and wrong expectations.
fn foreign_trace() -> anyhow::Result<Vec<u8>> {
    foreign_trace_with(true)
}

/// [`foreign_trace`], with or without its `/expected` channel.
fn foreign_trace_with(with_expected: bool) -> anyhow::Result<Vec<u8>> {
    use sweeptrace::trace::schemas::{OUTCOME_SCHEMA_JSON, SCENE_SCHEMA_JSON, SWEEP_SCHEMA_JSON};
    let mut w = mcap::WriteOptions::new()
        .library("some-engine 3.1")
        .profile("game")
        .create(Cursor::new(Vec::new()))?;
    let none = BTreeMap::new();
    let scene_s = w.add_schema(
        "sweeptrace.Scene",
        "jsonschema",
        SCENE_SCHEMA_JSON.as_bytes(),
    )?;
    let sweep_s = w.add_schema(
        "sweeptrace.Sweep",
        "jsonschema",
        SWEEP_SCHEMA_JSON.as_bytes(),
    )?;
    let out_s = w.add_schema(
        "sweeptrace.Outcome",
        "jsonschema",
        OUTCOME_SCHEMA_JSON.as_bytes(),
    )?;
    let cam_s = w.add_schema("game.Camera", "protobuf", b"\x0a\x05hello")?;
    let scene_c = w.add_channel(scene_s, "/scene", "json", &none)?;
    let sweep_c = w.add_channel(sweep_s, "/sweep", "json", &none)?;
    let out_c = if with_expected {
        w.add_channel(out_s, "/expected", "json", &none)?
    } else {
        0
    };
    let cam_meta = BTreeMap::from([("fps".to_string(), "60".to_string())]);
    let cam_c = w.add_channel(cam_s, "/camera", "protobuf", &cam_meta)?;
    let log_c = w.add_channel(0, "/log", "text", &none)?;
    w.write_metadata(&mcap::records::Metadata {
        name: "engine".into(),
        metadata: BTreeMap::from([("gravity".to_string(), "-9.81".to_string())]),
    })?;
    let put = |w: &mut mcap::Writer<Cursor<Vec<u8>>>, c: u16, t: u64, data: &[u8]| {
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: c,
                sequence: 0,
                log_time: t,
                publish_time: t,
            },
            data,
        )
        .map_err(anyhow::Error::from)
    };
    let json = |v: &dyn erased::Ser| v.json();
    put(&mut w, scene_c, 0, &json(&scene_t(0.0)))?;
    for (i, s) in fixture_sweeps().iter().enumerate() {
        let t = 10 + i as u64 * 10;
        put(&mut w, cam_c, t, &[1, 2, 3, i as u8])?;
        put(&mut w, sweep_c, t, &json(s))?;
        // Wrong on purpose: everything hits the face at α = 0.
        let wrong = OutcomeMsg {
            frame: s.frame,
            ball: 0,
            alpha: 0.0,
            kind: Kind::Face,
            triangle: None,
            feature: None,
            normal: None,
            contact: None,
        };
        if with_expected {
            put(&mut w, out_c, t, &json(&wrong))?;
        }
        put(
            &mut w,
            log_c,
            t + 1,
            format!("frame {}", s.frame).as_bytes(),
        )?;
    }
    w.attach(&mcap::Attachment {
        log_time: 5,
        create_time: 6,
        name: "calibration.txt".into(),
        media_type: "text/plain".into(),
        data: Cow::Borrowed(b"k = 1.5"),
    })?;
    w.finish()?;
    Ok(w.into_inner().into_inner())
}

mod erased {
    /// Serializes any message to JSON bytes (keeps the helper closure simple).
    pub trait Ser {
        fn json(&self) -> Vec<u8>;
    }
    impl<T: serde::Serialize> Ser for T {
        fn json(&self) -> Vec<u8> {
            serde_json::to_vec(self).expect("messages serialize")
        }
    }
}

/// Everything in a file but the `/expected` messages and the container's
/// own bookkeeping: (schemas, channels, messages by topic, metadata, attachments).
type Contents = (
    Vec<(String, String, Vec<u8>)>,
    Vec<(String, String, String, BTreeMap<String, String>)>,
    BTreeMap<String, Vec<(u64, Vec<u8>)>>,
    Vec<(String, BTreeMap<String, String>)>,
    Vec<(String, String, u64, u64, Vec<u8>)>,
    String,
);

fn contents(bytes: &[u8]) -> anyhow::Result<Contents> {
    let mut schemas = BTreeMap::new();
    let mut channels = BTreeMap::new();
    let mut messages: BTreeMap<String, Vec<(u64, Vec<u8>)>> = BTreeMap::new();
    let mut metadata = Vec::new();
    let mut attachments = Vec::new();
    let mut header = String::new();
    for r in mcap::read::ChunkFlattener::new(bytes)? {
        match r? {
            mcap::records::Record::Header(h) => header = format!("{} / {}", h.profile, h.library),
            mcap::records::Record::Schema { header, data } => {
                schemas.insert(header.id, (header.name, header.encoding, data.into_owned()));
            }
            mcap::records::Record::Channel(c) => {
                let schema = schemas
                    .get(&c.schema_id)
                    .map(|s| s.0.clone())
                    .unwrap_or_default();
                channels.insert(c.id, (c.topic, schema, c.message_encoding, c.metadata));
            }
            mcap::records::Record::Message { header, data } => {
                let topic = channels
                    .get(&header.channel_id)
                    .map(|c| c.0.clone())
                    .unwrap_or_default();
                messages
                    .entry(topic)
                    .or_default()
                    .push((header.log_time, data.into_owned()));
            }
            mcap::records::Record::Metadata(m) => metadata.push((m.name, m.metadata)),
            mcap::records::Record::Attachment { header, data, .. } => attachments.push((
                header.name,
                header.media_type,
                header.log_time,
                header.create_time,
                data.into_owned(),
            )),
            mcap::records::Record::DataEnd(_) => break,
            _ => {}
        }
    }
    let mut schemas: Vec<_> = schemas.into_values().collect();
    schemas.sort();
    let mut channels: Vec<_> = channels.into_values().collect();
    channels.sort();
    Ok((schemas, channels, messages, metadata, attachments, header))
}

fn bless_keeps_foreign_channel_metadata_attachment() -> anyhow::Result<()> {
    let input = foreign_trace()?;
    ensure!(
        check_bytes(&input).status() == Status::Fail,
        "input expectations are wrong"
    );
    let output = bless_with(&input, ReplayOptions::default())?;
    let report = check_bytes(&output);
    ensure!(report.status() == Status::Ok, "{}", render_text(&report));
    let (s_in, c_in, mut m_in, md_in, a_in, h_in) = contents(&input)?;
    let (s_out, c_out, mut m_out, md_out, a_out, h_out) = contents(&output)?;
    ensure!(s_in == s_out, "schemas:\n{s_in:?}\n{s_out:?}");
    ensure!(c_in == c_out, "channels:\n{c_in:?}\n{c_out:?}");
    // Every metadata record is kept; the expectations' source (sweeptrace
    // now) is written first.
    ensure!(
        md_out
            .first()
            .is_some_and(|(name, entries)| name == "sweeptrace.expected_source"
                && entries.get("engine").map(String::as_str) == Some("sweeptrace"))
            && md_out[1..] == md_in[..],
        "metadata:\n{md_in:?}\n{md_out:?}"
    );
    ensure!(
        a_in == a_out && a_out.len() == 1,
        "attachments:\n{a_in:?}\n{a_out:?}"
    );
    ensure!(h_in == h_out, "header: {h_in} vs {h_out}");
    let exp_in = m_in.remove("/expected").unwrap_or_default();
    let exp_out = m_out.remove("/expected").unwrap_or_default();
    ensure!(m_in == m_out, "messages of the other channels changed");
    ensure!(
        exp_in.len() == 5 && exp_out.len() == 5 && exp_in != exp_out,
        "expectations: {} in, {} out",
        exp_in.len(),
        exp_out.len()
    );
    ensure!(
        m_out.get("/camera").map(Vec::len) == Some(5) && m_out.get("/log").map(Vec::len) == Some(5),
        "foreign messages: {:?}",
        m_out.keys().collect::<Vec<_>>()
    );
    // The reader still reads it (log times in order).
    let events = TraceReader::new(output.as_slice(), "<blessed>").count();
    ensure!(
        events == 11,
        "1 scene + 5 sweeps + 5 expected, got {events}"
    );
    Ok(())
}

fn bless_binary_requires_output_and_keeps_input() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let input = dir.path().join("wrong.mcap");
    std::fs::copy(fixture_path(), &input)?;
    let before = std::fs::read(&input)?;
    let (code, _, err) = run_bin(os!["bless", input.as_os_str()])?;
    ensure!(
        code == 2 && err.contains("-o"),
        "no output named: exit {code}: {err}"
    );
    let out = dir.path().join("blessed.mcap");
    let (code, _, err) = run_bin(os!["bless", input.as_os_str(), "-o", out.as_os_str()])?;
    ensure!(code == 0, "bless -o: exit {code}: {err}");
    let after = std::fs::read(&input)?;
    ensure!(before == after, "the input changed");
    let (code, stdout, _) = run_bin(os!["check", out.as_os_str()])?;
    ensure!(code == 0, "check after bless: exit {code}: {stdout}");
    let (code, _, err) = run_bin(os!["bless", input.as_os_str(), "--in-place"])?;
    ensure!(code == 0, "bless --in-place: exit {code}: {err}");
    let (code, stdout, _) = run_bin(os!["check", input.as_os_str()])?;
    ensure!(
        code == 0,
        "check after bless --in-place: exit {code}: {stdout}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())?
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains(".partial-"))
        .collect();
    ensure!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    // A trace that ends early is refused (exit 3, as every command gives
    // for one) and nothing is written.
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &before[..before.len() / 2])?;
    let never = dir.path().join("never.mcap");
    let (code, _, err) = run_bin(os!["bless", cut.as_os_str(), "-o", never.as_os_str()])?;
    ensure!(
        code == 3 && !never.exists(),
        "truncated input: exit {code}: {err}"
    );
    Ok(())
}

// ---------------------------------------------------------------- diff

/// A ball rolling parallel to T's plane (n·d = 0) into edge 0: an edge hit
/// under `non_strict`, nothing under `strict`; plus the fixture's sweeps.
fn facing_trace() -> Vec<u8> {
    let mut sweeps = fixture_sweeps();
    sweeps.push(sweep(5, [2.0, -3.0, 0.3], [2.0, 1.0, 0.3]));
    write_trace(&scene_t(0.0), &sweeps, &[])
}

fn diff_same_trace_is_same() -> anyhow::Result<()> {
    let bytes = facing_trace();
    let side = |o| Side::replay(TraceReader::new(bytes.as_slice(), "t"), "t", o);
    let a = side(ReplayOptions::default())?;
    let b = side(ReplayOptions::default())?;
    let r = diff(&a, &b, &Tolerances::default());
    ensure!(r.is_same() && r.compared == 6, "{r:?}");
    Ok(())
}

fn diff_strict_facing_reports_first_divergence() -> anyhow::Result<()> {
    let bytes = facing_trace();
    let side = |o| Side::replay(TraceReader::new(bytes.as_slice(), "t"), "t", o);
    let a = side(ReplayOptions::default())?;
    let b = side(ReplayOptions {
        conventions: sweeptrace::conventions::EngineConventions {
            facing: sweeptrace::conventions::FacingRule::Strict,
            ..Default::default()
        },
        ..ReplayOptions::default()
    })?;
    let r = diff(&a, &b, &Tolerances::default());
    let text = sweeptrace::suite::diff::render_diff_text(&r);
    ensure!(!r.is_same() && r.different == 1, "{text}");
    let first = r.first.as_ref().context("no first divergence")?;
    ensure!(first.frame == 5, "first divergence at frame 5: {text}");
    ensure!(r.by_kind.get("edge -> none") == Some(&1), "{text}");
    ensure!(
        text.contains("first divergence: frame 5, ball 0")
            && text.contains("A's test in B: edge 0.0: s0 = 0.65 in [0, 1], xc = 2 in [0, 4], n·d = 0 fails the facing rule: back-facing"),
        "{text}"
    );
    Ok(())
}

fn diff_binary_exit_codes() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let t = dir.path().join("t.mcap");
    std::fs::write(&t, facing_trace())?;
    let (code, out, err) = run_bin(os!["diff", t.as_os_str(), t.as_os_str()])?;
    ensure!(code == 0, "same: exit {code}\n{out}\n{err}");
    let (code, out, err) = run_bin(os![
        "diff",
        t.as_os_str(),
        t.as_os_str(),
        "--facing-b",
        "strict"
    ])?;
    ensure!(code == 1, "strict: exit {code}\n{out}\n{err}");
    ensure!(out.contains("first divergence: frame 5"), "{out}");
    let (code, out, _) = run_bin(os![
        "diff",
        t.as_os_str(),
        t.as_os_str(),
        "--margin-b",
        "0.1",
        "--json"
    ])?;
    let json: serde_json::Value =
        serde_json::from_str(&out).map_err(|e| anyhow::anyhow!("{e}: {out}"))?;
    ensure!(
        code == 1 && json["same_outcomes"] == false,
        "margin: exit {code}: {json}"
    );
    ensure!(
        json["first"]["frame"] == 2,
        "margin changes frame 2 first: {json}"
    );
    let missing = dir.path().join("missing.mcap");
    let (code, _, _) = run_bin(os!["diff", t.as_os_str(), missing.as_os_str()])?;
    ensure!(code == 2, "missing: exit {code}");
    Ok(())
}

// ---------------------------------------------------------------- fixture

/// The Rapier sample differs from the core by about 1e-6 (more than the
/// default tolerances): the two sides of each differing field never read
/// the same in the report (they are printed in full when their short forms
/// agree), and a test that decides the sweep is said to be the same test
/// with other numbers, not a question about the margin.
fn differences_below_the_shown_digits_are_shown_in_full() -> anyhow::Result<()> {
    let trace = rapier_sample();
    // Without its settings file (examples/sweeptrace.toml), which excuses
    // those differences.
    let (code, out, err) = run_bin(os![
        "check",
        "--no-config",
        trace.as_os_str(),
        "--max-details",
        "8"
    ])?;
    ensure!(code == 1, "exit {code}: {out}{err}");
    let mut fields = 0;
    for line in out.lines().map(str::trim) {
        let Some((field, rest)) = line.split_once(": expected ") else {
            continue;
        };
        if !["alpha", "normal", "contact"].contains(&field) {
            continue;
        }
        let (expected, got) = rest
            .split_once(", got ")
            .with_context(|| format!("no `got` in `{line}`"))?;
        let got = got.split(" (").next().unwrap_or(got);
        ensure!(expected != got, "the two sides read the same: `{line}`");
        fields += 1;
    }
    ensure!(fields >= 8, "{fields} differing fields found in:\n{out}");
    ensure!(
        out.contains("the same test with other numbers")
            || out.contains("only the fields above differ"),
        "{out}"
    );
    Ok(())
}

/// The committed fixture is byte for byte what its generator
/// (`fixture_bytes`) makes today (`SWEEPTRACE_BLESS=1` rewrites it).
fn wrong_engine_config_fixture_is_what_its_generator_makes() -> anyhow::Result<()> {
    crate::support::compare_or_bless(&fixture_path(), &fixture_bytes()?)
}
