//! Contact queries as traces (issue 45): `record --contacts` writes a
//! `/contact` query after every sweep with the core's contacts as
//! `/expected_contacts`; `check` judges them against the core's contact
//! set. Each verdict is shown to catch the bug it is for: a recorded trace
//! passes, and the same trace with one seeded mistake in its answers fails
//! naming it (a missing contact, an extra one, a tilted normal, a wrong
//! separation, a wrong feature, a ghost contact on a flat seam).

use std::io::Cursor;
use std::path::Path;

use anyhow::ensure;
use libtest_mimic::{Completion, Trial};
use sweeptrace::trace::{
    ContactMsg, ContactPointMsg, ContactsMsg, EventBody, SceneMsg, TraceEvent, TraceReader,
    TraceWriter,
};
use sweeptrace::{Kind, Status};

use crate::support::{bin, write_event};
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(a_recorded_contact_trace_passes_check_in_json_and_cbor),
        trial!(each_seeded_contact_mistake_fails_check_naming_it),
        trial!(a_geometric_normal_on_a_flat_seam_is_a_ghost_contact),
        trial!(contacts_pass_by_an_engine_check_and_say_so),
        trial!(an_engine_answers_contact_queries_with_engine_contacts),
        trial!(infer_config_finds_the_contact_normal_from_contact_queries),
        trial!(diff_compares_the_contact_sets_of_two_traces),
        trial!(bad_contact_messages_are_refused_with_the_field),
        trial!(python_reads_the_contact_channels),
        trial!(the_recording_draws_each_query_and_marks_its_ghosts),
        trial!(the_contacts_drawn_do_not_depend_on_the_threads),
        trial!(the_layout_plots_the_followed_balls_contact_queries),
        trial!(a_divergent_contact_query_is_a_junit_failure_and_an_annotation),
        trial!(a_seam_contact_may_be_dropped_where_flat_not_where_concave),
    ]
}

/// `record --scene mini_golf --contacts` (200 frames) into `dir`.
pub(crate) fn record(dir: &Path, extra: &[&str]) -> anyhow::Result<std::path::PathBuf> {
    let path = dir.join(format!("golf{}.mcap", extra.len()));
    let out = bin()
        .args([
            "record",
            "--scene",
            "mini_golf",
            "--frames",
            "200",
            "--contacts",
            "-o",
        ])
        .arg(&path)
        .args(extra)
        .output()?;
    ensure!(
        out.status.success(),
        "record failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(path)
}

fn events(path: &Path) -> anyhow::Result<Vec<TraceEvent>> {
    let bytes = std::fs::read(path)?;
    let name = path.display().to_string();
    Ok(TraceReader::new(Cursor::new(bytes), &name).collect::<Result<Vec<_>, _>>()?)
}

/// `check TRACE --json`: exit code and the trace's report.
fn check_json(path: &Path, extra: &[&str]) -> anyhow::Result<(i32, serde_json::Value)> {
    let out = bin()
        .arg("check")
        .arg(path)
        .args(extra)
        .arg("--json")
        .output()?;
    let report: serde_json::Value = serde_json::from_slice(&out.stdout)
        .map_err(|e| anyhow::anyhow!("{e}: {}", String::from_utf8_lossy(&out.stderr)))?;
    Ok((out.status.code().unwrap_or(-1), report["traces"][0].clone()))
}

/// `check TRACE`: exit code and the text.
fn check_text(path: &Path) -> anyhow::Result<(i32, String)> {
    let out = bin().arg("check").arg(path).output()?;
    Ok((
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    ))
}

fn a_recorded_contact_trace_passes_check_in_json_and_cbor() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    for extra in [
        &[][..],
        &["--encoding", "cbor"],
        &["--contact-distance", "0.02"],
    ] {
        let path = record(dir.path(), extra)?;
        let (code, report) = check_json(&path, &[])?;
        ensure!(code == 0, "{extra:?}: exit {code}: {report:#}");
        let contacts = &report["contacts"];
        let queries = contacts["queries"].as_u64().unwrap_or(0);
        ensure!(queries > 1000, "{extra:?}: {contacts}");
        ensure!(
            contacts["compared"] == queries && contacts["divergent"] == 0,
            "{contacts}"
        );
        // The queries are not all empty: balls rest and roll on the green.
        let touching = events(&path)?
            .iter()
            .filter(|e| matches!(&e.body, EventBody::ExpectedContacts(c) if !c.contacts.is_empty()))
            .count();
        ensure!(
            touching > 300,
            "{extra:?}: only {touching} answers have contacts"
        );
    }
    Ok(())
}

/// The recorded trace with `seed` applied to the first answer it returns
/// `true` for, written to `dir`.
fn seeded(
    dir: &Path,
    source: &[TraceEvent],
    name: &str,
    mut seed: impl FnMut(&mut ContactsMsg) -> bool,
) -> anyhow::Result<std::path::PathBuf> {
    let path = dir.join(format!("{name}.mcap"));
    let mut w = TraceWriter::new(std::fs::File::create(&path)?)?;
    let mut done = false;
    for event in source {
        let mut event = event.clone();
        if let EventBody::ExpectedContacts(c) = &mut event.body
            && !done
        {
            done = seed(c);
        }
        write_event(&mut w, &event)?;
    }
    w.finish()?;
    ensure!(done, "{name}: no answer to seed");
    Ok(path)
}

fn each_seeded_contact_mistake_fails_check_naming_it() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let source = events(&record(dir.path(), &[])?)?;
    let tilt = |n: [f64; 3], degrees: f64| {
        // Rotate about an axis perpendicular to n.
        let n = nalgebra::Vector3::from(n);
        let axis = n
            .cross(&nalgebra::Vector3::x())
            .try_normalize(1e-9)
            .unwrap_or(nalgebra::Vector3::y());
        let r = nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(axis),
            degrees.to_radians(),
        );
        (r * n).into()
    };
    type Seed = Box<dyn FnMut(&mut ContactsMsg) -> bool>;
    let cases: Vec<(&str, Seed, &str)> = vec![
        (
            "dropped",
            Box::new(|c: &mut ContactsMsg| c.contacts.pop().is_some()),
            "missing: the ball touches triangle",
        ),
        (
            "extra",
            Box::new(|c: &mut ContactsMsg| {
                // A triangle far from a ball resting on the green (the cup's
                // walls are the last triangles).
                let far = if c.contacts.iter().any(|p| p.triangle == 55) {
                    0
                } else {
                    55
                };
                c.contacts.push(ContactPointMsg {
                    triangle: far,
                    kind: None,
                    feature: None,
                    point: None,
                    normal: None,
                    separation: None,
                });
                true
            }),
            "extra: triangle",
        ),
        (
            "tilted",
            Box::new(move |c: &mut ContactsMsg| match c.contacts.first_mut() {
                Some(p) => {
                    p.normal = p.normal.map(|n| tilt(n, 5.0));
                    true
                }
                None => false,
            }),
            "5.000° from the expected",
        ),
        (
            "half_normal",
            Box::new(|c: &mut ContactsMsg| match c.contacts.first_mut() {
                Some(p) => {
                    p.normal = p.normal.map(|n| n.map(|x| 0.5 * x));
                    true
                }
                None => false,
            }),
            "|n| = 0.5, not a unit vector",
        ),
        (
            "separation",
            Box::new(|c: &mut ContactsMsg| match c.contacts.first_mut() {
                Some(p) => {
                    p.separation = p.separation.map(|s| s + 1e-3);
                    true
                }
                None => false,
            }),
            "separation from triangle",
        ),
        (
            "point",
            Box::new(|c: &mut ContactsMsg| match c.contacts.first_mut() {
                Some(p) => {
                    p.point = p.point.map(|[x, y, z]| [x + 1e-3, y, z]);
                    true
                }
                None => false,
            }),
            "from the closest point",
        ),
        (
            "feature",
            Box::new(|c: &mut ContactsMsg| {
                match c.contacts.iter_mut().find(|p| p.kind == Some(Kind::Face)) {
                    Some(p) => {
                        p.kind = Some(Kind::Vertex);
                        p.feature = Some(0);
                        true
                    }
                    None => false,
                }
            }),
            "but the point lies in the region of its face",
        ),
    ];
    for (name, seed, words) in cases {
        let path = seeded(dir.path(), &source, name, seed)?;
        let (code, text) = check_text(&path)?;
        ensure!(code == 1, "{name}: exit {code}: {text}");
        ensure!(
            text.contains("1 of ")
                && text.contains("diverges (the reported contacts are not the core's contact set)")
                && text.contains(words),
            "{name}: the report does not name it ({words:?}):\n{text}"
        );
    }
    Ok(())
}

/// Two coplanar triangles (a flat seam along x = 1, triangle 0's edge 1)
/// and a ball whose centre is over triangle 1, 0.05 from the seam:
/// triangle 0's closest point is on the seam, where its geometric normal
/// leans 11.8° from the faces'.
fn seam_trace(path: &Path, normal: [f64; 3]) -> anyhow::Result<()> {
    let scene = SceneMsg {
        name: Some("seam".into()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [1, 3, 2]],
        margin: 0.0,
        facing: Default::default(),
    };
    let mut w = TraceWriter::new(std::fs::File::create(path)?)?;
    w.scene(0, &scene)?;
    let query = ContactMsg {
        frame: 0,
        ball: 0,
        radius: 0.25,
        centre: [1.05, 0.5, 0.24],
        distance: 0.0,
    };
    w.contact(1, &query)?;
    let point =
        |triangle: u32, kind: Kind, feature: Option<u8>, point: [f64; 3], normal: [f64; 3]| {
            ContactPointMsg {
                triangle,
                kind: Some(kind),
                feature,
                point: Some(point),
                normal: Some(normal),
                separation: None,
            }
        };
    w.expected_contacts(
        1,
        &ContactsMsg {
            frame: 0,
            ball: 0,
            contacts: vec![
                point(0, Kind::Edge, Some(1), [1.0, 0.5, 0.0], normal),
                point(1, Kind::Face, None, [1.05, 0.5, 0.0], [0.0, 0.0, 1.0]),
            ],
        },
    )?;
    w.finish()?;
    Ok(())
}

fn a_geometric_normal_on_a_flat_seam_is_a_ghost_contact() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let good = dir.path().join("good.mcap");
    seam_trace(&good, [0.0, 0.0, 1.0])?;
    let (code, text) = check_text(&good)?;
    ensure!(code == 0, "the face normal at the seam fails: {text}");
    let ghost = dir.path().join("ghost.mcap");
    let lean = nalgebra::Vector3::new(0.05, 0.0, 0.24).normalize();
    seam_trace(&ghost, lean.into())?;
    let (code, text) = check_text(&ghost)?;
    ensure!(code == 1, "exit {code}: {text}");
    ensure!(
        text.contains(
            "ghost contact: frame 0, ball 0: edge 0.1, an internal flat edge shared with triangle 1"
        ) && text.contains("11.8° from the faces' normal"),
        "{text}"
    );
    // Declared as the engine's convention, the contact normal is still a
    // ghost there (as for sweeps), unless ghosts are allowed.
    let out = bin()
        .arg("check")
        .arg(&ghost)
        .args(["--normal", "contact", "--allow-ghosts"])
        .output()?;
    ensure!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    Ok(())
}

fn contacts_pass_by_an_engine_check_and_say_so() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("seam.mcap");
    seam_trace(&path, [0.0, 0.0, 1.0])?;
    // A sweep too, so that the engine has something to answer.
    let mut events = events(&path)?;
    let sweep = sweeptrace::SweepMsg {
        frame: 0,
        ball: 0,
        radius: 0.25,
        p0: [1.5, 0.2, 1.0],
        p1: [1.5, 0.2, 0.0],
    };
    events.insert(
        1,
        TraceEvent {
            header: events[0].header,
            body: EventBody::Sweep(sweep),
        },
    );
    let with_sweep = dir.path().join("with_sweep.mcap");
    let mut w = TraceWriter::new(std::fs::File::create(&with_sweep)?)?;
    for e in &events {
        write_event(&mut w, e)?;
    }
    w.finish()?;
    // Without an engine, the trace's contacts are judged.
    let report = sweeptrace::check_file(&with_sweep, &sweeptrace::CheckOptions::default());
    ensure!(report.contacts.compared == 1, "{:?}", report.contacts);
    ensure!(report.status() != Status::Fail, "{:?}", report.status());
    // An engine is not asked for contacts: the report says so, and the
    // recording engine's contacts are not passed off as the engine's.
    let engine = crate::engine::example_engine_command("");
    let out = bin()
        .arg("check")
        .arg(&with_sweep)
        .args(["--engine", &engine])
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    ensure!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    ensure!(
        text.contains("contacts: 1 query, 0 compared, 0 diverge, 1 not judged (an engine is asked for contacts only with --engine-contacts"),
        "{text}"
    );
    Ok(())
}

/// `check --engine-contacts`: the queries go to the engine, its answers
/// replace the trace's. The exact Python engine passes; with its
/// `contact-normal` bug (the geometric normal everywhere) the report lists
/// its ghost contacts as the engine's and its normals off the face's.
fn an_engine_answers_contact_queries_with_engine_contacts() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = record(dir.path(), &[])?;
    let run = |bug: &str| -> anyhow::Result<(i32, String)> {
        let engine = crate::engine::example_engine_command(bug);
        let out = bin()
            .arg("check")
            .arg(&path)
            .args(["--engine", &engine, "--engine-contacts"])
            .output()?;
        Ok((
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
        ))
    };
    let (code, text) = run("")?;
    ensure!(code == 0, "exit {code}: {text}");
    ensure!(
        text.contains("contacts: 2238 queries, 2238 compared, 0 diverge"),
        "{text}"
    );
    let (code, text) = run("--bug contact-normal")?;
    ensure!(code == 1, "exit {code}: {text}");
    ensure!(
        text.contains(
            "ghost contacts (an edge or vertex contact on an internal flat or concave place"
        ) && text.contains("the engine's normal is")
            && text.contains("contact queries diverge")
            && text.contains("from the expected (0, 0, 1)"),
        "{text}"
    );
    Ok(())
}

/// `--infer-config` with `--engine-contacts` judges the engine's contacts
/// under each convention tried: on conform's contact cases (contact
/// queries only), an engine that answers the geometric normal everywhere
/// is found to use `normal = "contact"`, by the contact queries alone, and
/// the clean engine the rules. Checked with the printed file, the normals
/// agree; its ghost contacts still fail (no convention excuses them).
fn infer_config_finds_the_contact_normal_from_contact_queries() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("contact_cases.mcap");
    let out = bin()
        .args(["conform", "--case", "contact", "--write-trace"])
        .arg(&trace)
        .output()?;
    ensure!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let infer = |bug: &str| -> anyhow::Result<(String, String)> {
        let engine = crate::engine::example_engine_command(bug);
        let out = bin()
            .arg("check")
            .arg(&trace)
            .args(["--engine", &engine, "--engine-contacts", "--infer-config"])
            .output()?;
        ensure!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        Ok((
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        ))
    };
    let (toml, progress) = infer("--bug contact-normal")?;
    ensure!(
        toml.contains("normal = \"contact\"")
            && toml.contains(
                "# Contact queries: 8 of 17 fail under the rules; under these conventions: 0."
            )
            && progress.contains(
                "tried the rules: 0 of 0 compared sweeps and 8 of 17 contact queries fail"
            ),
        "{toml}\n{progress}"
    );
    let config = dir.path().join("sweeptrace.toml");
    std::fs::write(&config, &toml)?;
    let engine = crate::engine::example_engine_command("--bug contact-normal");
    let out = bin()
        .arg("check")
        .arg(&trace)
        .args([
            "--engine",
            &engine,
            "--engine-contacts",
            "--json",
            "--config",
        ])
        .arg(&config)
        .output()?;
    let report: serde_json::Value = serde_json::from_slice(&out.stdout)?;
    let t = &report["traces"][0];
    ensure!(
        out.status.code() == Some(1)
            && t["contacts"]["divergent"] == 0
            && t["ghosts"].as_u64() == Some(3),
        "under the inferred table: {t:#}"
    );
    let (toml, _) = infer("")?;
    ensure!(
        toml.contains("# No convention fits better than the rules")
            && toml.contains("# Contact queries: 0 of 17 fail under the rules"),
        "{toml}"
    );
    Ok(())
}

/// `diff` answers each side's contact queries with the core and compares
/// the sets: the same trace twice is the same; triangle T raised by an
/// eighth changes the contact of the query both sides share, and a
/// query on one side only is counted and named. Text and JSON.
fn diff_compares_the_contact_sets_of_two_traces() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let write = |name: &str, lift: f64, frames: &[u64]| -> anyhow::Result<std::path::PathBuf> {
        let path = dir.path().join(name);
        let mut scene = crate::support::scene_t(0.0);
        for v in &mut scene.vertices {
            v[2] += lift;
        }
        let mut w = TraceWriter::new(std::fs::File::create(&path)?)?;
        w.scene(0, &scene)?;
        for &frame in frames {
            let query = ContactMsg {
                frame,
                ball: 0,
                radius: 0.5,
                centre: [1.0, 1.0, 0.25],
                distance: 0.0,
            };
            w.contact(1 + frame, &query)?;
        }
        w.finish()?;
        Ok(path)
    };
    let a = write("a.mcap", 0.0, &[0, 1])?;
    let b = write("b.mcap", 0.125, &[0])?;
    let run = |x: &Path, y: &Path, json: bool| -> anyhow::Result<(i32, String)> {
        let mut command = bin();
        command.arg("diff").arg(x).arg(y);
        if json {
            command.arg("--json");
        }
        // The raised triangle is another scene: compared on purpose.
        command.arg("--allow-different-scenes");
        let out = command.output()?;
        Ok((
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
        ))
    };
    let (code, text) = run(&a, &a, false)?;
    ensure!(
        code == 0 && text.contains("contacts: 2 contact queries, the same contact sets"),
        "exit {code}:\n{text}"
    );
    let (code, text) = run(&a, &b, false)?;
    ensure!(
        code == 1
            && text.contains("contacts: 1 of 1 contact query differs; 1 only in A, 0 only in B")
            && text.contains(
                "first contact difference: frame 0, ball 0: triangle 0: separation -0.25 in A, -0.375 in B"
            )
            && text.contains("  A: triangle 0 (face) at (1, 1, 0), separation -0.25")
            && text.contains("first contact query on one side only: frame 1, ball 0, in A"),
        "exit {code}:\n{text}"
    );
    let (code, json) = run(&a, &b, true)?;
    let doc: serde_json::Value = serde_json::from_str(&json)?;
    let c = &doc["contacts"];
    ensure!(
        code == 1
            && doc["same_outcomes"] == false
            && c["compared"] == 1
            && c["different"] == 1
            && c["only_in_a"] == 1
            && c["first"]["b"][0]["separation"] == -0.375,
        "{doc:#}"
    );
    Ok(())
}

fn bad_contact_messages_are_refused_with_the_field() -> anyhow::Result<()> {
    let mut w = TraceWriter::new(Cursor::new(Vec::new()))?;
    let scene = crate::support::scene_t(0.0);
    // Before any scene.
    let query = ContactMsg {
        frame: 3,
        ball: 0,
        radius: 0.5,
        centre: [0.0, 0.0, 1.0],
        distance: 0.0,
    };
    let err = w.contact(0, &query).expect_err("a query before a scene");
    ensure!(
        err.to_string()
            .contains("a contact query comes before any `/scene` message"),
        "{err}"
    );
    w.scene(0, &scene)?;
    for (bad, field) in [
        (
            ContactMsg {
                radius: -1.0,
                ..query
            },
            "radius",
        ),
        (
            ContactMsg {
                centre: [f64::NAN, 0.0, 0.0],
                ..query
            },
            "centre[0]",
        ),
        (
            ContactMsg {
                distance: -0.1,
                ..query
            },
            "distance",
        ),
        (
            ContactMsg {
                radius: f64::MAX,
                distance: f64::MAX,
                ..query
            },
            "overflows",
        ),
    ] {
        let err = w.contact(1, &bad).expect_err("refused");
        ensure!(err.to_string().contains(field), "{field}: {err}");
    }
    let zero = ContactPointMsg {
        triangle: 0,
        kind: Some(Kind::Face),
        feature: None,
        point: None,
        normal: Some([0.0; 3]),
        separation: None,
    };
    let err = w
        .expected_contacts(
            1,
            &ContactsMsg {
                frame: 3,
                ball: 0,
                contacts: vec![zero],
            },
        )
        .expect_err("a zero normal");
    ensure!(err.to_string().contains("contacts[0].normal"), "{err}");
    let far = ContactPointMsg {
        triangle: 7,
        normal: None,
        ..zero
    };
    let err = w
        .expected_contacts(
            1,
            &ContactsMsg {
                frame: 3,
                ball: 0,
                contacts: vec![far],
            },
        )
        .expect_err("a triangle the scene does not have");
    ensure!(err.to_string().contains("contacts[0].triangle"), "{err}");
    // `--contact-distance` needs `--contacts`; a negative one is refused.
    let out = bin()
        .args([
            "record",
            "--contact-distance",
            "0.1",
            "-o",
            "/nonexistent/x.mcap",
        ])
        .output()?;
    ensure!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--contacts"));
    let out = bin()
        .args([
            "record",
            "--contacts",
            "--contact-distance=-1",
            "-o",
            "/nonexistent/x.mcap",
        ])
        .output()?;
    ensure!(
        !out.status.success()
            && String::from_utf8_lossy(&out.stderr).contains("--contact-distance")
    );
    Ok(())
}

fn python_reads_the_contact_channels() -> anyhow::Result<Completion> {
    if let Err(skip) = crate::support::python_with_mcap()? {
        return Ok(skip);
    }
    let dir = tempfile::tempdir()?;
    let path = record(dir.path(), &[])?;
    let n = events(&path)?
        .iter()
        .filter(|e| matches!(e.body, EventBody::Contact(_)))
        .count()
        .to_string();
    crate::support::read_with_python(&path, &["--contacts", &n, "--expected-contacts", &n])?;
    ensure!(
        crate::support::read_with_python(&path, &["--contacts", "1"]).is_err(),
        "the script accepted a wrong count"
    );
    Ok(Completion::Completed)
}

/// `replay --rrd` of Rapier's solver-contact fixture draws each contact
/// query at its frame (points and normals), labels the ghost contacts with
/// their angle, logs them to the divergences, and plots the count per ball.
fn the_recording_draws_each_query_and_marks_its_ghosts() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let rrd = dir.path().join("contacts.rrd");
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/rapier_floor_contacts.mcap");
    let out = bin()
        .arg("replay")
        .arg(&fixture)
        .arg("--rrd")
        .arg(&rrd)
        .arg("--json")
        .output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    ensure!(out.status.success(), "{stderr}");
    ensure!(
        stderr.contains("contacts: 180 queries drawn (159 contacts, 1 diverging from the core's, 8 ghost contacts)"),
        "{stderr}"
    );
    // The same counts for scripts, in the summary.
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout)?;
    ensure!(
        summary["contacts"]
            == serde_json::json!({
                "queries": 180,
                "drawn": {"queries": 180, "contacts": 159, "divergent": 1, "ghosts": 8},
            }),
        "{}",
        summary["contacts"]
    );
    let d = crate::replay::decode_rrd(&rrd)?;
    let drawn = d.frames_with("/world/ball/0/contacts", "Points3D:positions");
    // 150 of the 180 queries have contacts (the ball is in the air in the
    // others); every query is plotted.
    let normals = d.frames_with("/world/ball/0/contacts/normals", "Arrows3D:vectors");
    let plotted = d.frames_with("/plots/contacts/ball/0", "Scalars:scalars");
    ensure!(
        (drawn.len(), normals.len(), plotted.len()) == (150, 150, 180),
        "points, normals, plot at {}, {}, {} frames",
        drawn.len(),
        normals.len(),
        plotted.len()
    );
    let labels = d.texts_at("/world/ball/0/contacts", "Points3D:labels", 93);
    ensure!(
        labels
            .iter()
            .any(|l| l == "ghost contact 5.4°: edge 20.2 is internal and flat"),
        "frame 93: {labels:?}"
    );
    // Its sweeps have no expectation: the ghosts alone make the layout
    // that leads with the divergences' log the active one; it plots the
    // ball's contact queries.
    ensure!(d.blueprints() == 2, "{} blueprints", d.blueprints());
    let active = &d.view_origins()[1];
    ensure!(
        active.iter().any(|o| o == "/plots/contacts/ball/0")
            && active.iter().any(|o| o == "/divergences"),
        "the active layout's views: {active:?}"
    );
    let series = d.texts_at("/plots/contacts/ball/0", "SeriesLines:names", i64::MIN);
    ensure!(
        series == ["contacts", "ghost contacts"],
        "the plot's series: {series:?}"
    );
    let log = d.texts_at("/divergences", "TextLog:text", 93);
    ensure!(
        log.iter()
            .any(|l| l.starts_with("ghost contact: frame 93, ball 0: edge 20.2")),
        "frame 93's log: {log:?}"
    );
    Ok(())
}

/// The contact queries are judged in parallel batches and drawn in order:
/// a recording made on one thread has the same content as one made on
/// four, row for row (2,238 queries of the mini-golf course, several
/// batches), and the Foxglove file is the same byte for byte; the same
/// again for each file written alone (with both, the queries are judged
/// once for the two).
fn the_contacts_drawn_do_not_depend_on_the_threads() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    // Every fifth answer with a contact turned upside down, so that the
    // divergences' log gets lines from several balls in one frame, whose
    // order is the trace's.
    let mut n = 0;
    let mut flipped = Vec::new();
    for mut event in events(&record(dir.path(), &[])?)? {
        if let EventBody::ExpectedContacts(c) = &mut event.body
            && let Some(normal) = c.contacts.first_mut().and_then(|c| c.normal.as_mut())
        {
            n += 1;
            if n % 5 == 0 {
                *normal = normal.map(|x| -x);
            }
        }
        flipped.push(event);
    }
    let trace = dir.path().join("flipped.mcap");
    let mut w = TraceWriter::new(std::fs::File::create(&trace)?)?;
    for event in &flipped {
        write_event(&mut w, event)?;
    }
    w.finish()?;
    let mut contents = Vec::new();
    let mut foxglove = Vec::new();
    for threads in ["1", "4"] {
        let rrd = dir.path().join(format!("t{threads}.rrd"));
        let mcap = dir.path().join(format!("t{threads}.foxglove.mcap"));
        let out = bin()
            .arg("replay")
            .arg(&trace)
            .args(["--threads", threads, "--rrd"])
            .arg(&rrd)
            .arg("--foxglove")
            .arg(&mcap)
            .output()?;
        let stderr = String::from_utf8_lossy(&out.stderr);
        ensure!(out.status.success(), "{stderr}");
        ensure!(stderr.contains("contacts: 2238 queries drawn"), "{stderr}");
        contents.push(crate::replay::rrd_content(&rrd)?);
        foxglove.push(std::fs::read(&mcap)?);
    }
    ensure!(
        contents[0]
            .keys()
            .any(|(e, _)| e == "/world/ball/0/contacts"),
        "no contacts drawn: {:?}",
        contents[0].keys().take(20).collect::<Vec<_>>()
    );
    if let Some(d) = crate::replay::first_content_difference(&contents[0], &contents[1]) {
        anyhow::bail!("one thread against four: {d}");
    }
    ensure!(foxglove[0] == foxglove[1], "the Foxglove files differ");
    // Both files are drawn from one judgement of each query; each alone
    // (its own judgement) is the same.
    let alone = |output: &str, file: &Path| -> anyhow::Result<String> {
        let out = bin()
            .arg("replay")
            .arg(&trace)
            .arg(output)
            .arg(file)
            .output()?;
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        ensure!(out.status.success(), "{stderr}");
        Ok(stderr)
    };
    let mcap = dir.path().join("alone.foxglove.mcap");
    let stderr = alone("--foxglove", &mcap)?;
    ensure!(
        stderr.contains("contacts in the Foxglove file: 2238 queries drawn"),
        "{stderr}"
    );
    ensure!(
        std::fs::read(&mcap)? == foxglove[0],
        "the Foxglove file written alone differs from the one written beside the recording"
    );
    let rrd = dir.path().join("alone.rrd");
    alone("--rrd", &rrd)?;
    if let Some(d) =
        crate::replay::first_content_difference(&crate::replay::rrd_content(&rrd)?, &contents[0])
    {
        anyhow::bail!("the recording alone against beside the Foxglove file: {d}");
    }
    Ok(())
}

/// A trace whose contact queries all agree gets, at the end, the first
/// layout again with a plot of the followed ball's contacts and ghost
/// contacts (the queries are drawn after the sweeps); a trace without
/// contact queries, or a replay following a ball that has none, keeps the
/// first layout only.
fn the_layout_plots_the_followed_balls_contact_queries() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = record(dir.path(), &[])?;
    let sweeps_only = Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_mini_golf.mcap");
    let origins = |trace: &Path, extra: &[&str]| -> anyhow::Result<Vec<Vec<String>>> {
        let rrd = dir.path().join("layout.rrd");
        let out = bin()
            .arg("replay")
            .arg(trace)
            .arg("--rrd")
            .arg(&rrd)
            .args(extra)
            .output()?;
        ensure!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        Ok(crate::replay::decode_rrd(&rrd)?.view_origins().to_vec())
    };
    let plot = |ball: u32| format!("/plots/contacts/ball/{ball}");
    let with = origins(&trace, &[])?;
    ensure!(with.len() == 2, "{} layouts: {with:?}", with.len());
    ensure!(
        !with[0].contains(&plot(0)) && with[1].contains(&plot(0)),
        "the layouts' views: {with:?}"
    );
    ensure!(
        !with[1].iter().any(|o| o == "/divergences"),
        "the queries agree, yet the layout leads with the divergences: {:?}",
        with[1]
    );
    // Following ball 1 (its queries only drawn): its plot.
    let one = origins(&trace, &["--ball", "1"])?;
    ensure!(
        one.len() == 2 && one[1].contains(&plot(1)),
        "following ball 1: {one:?}"
    );
    let without = origins(&sweeps_only, &[])?;
    ensure!(
        without.len() == 1 && !without[0].iter().any(|o| o.starts_with("/plots/contacts")),
        "a trace without contact queries: {without:?}"
    );
    Ok(())
}

/// A trace that fails on a contact query only: its JUnit test case is a
/// `contact_divergence` failure whose message names the query and its
/// problem, with `--junit-detail sweeps` the query is a test case of its
/// own, and in GitHub Actions it is an annotation.
fn a_divergent_contact_query_is_a_junit_failure_and_an_annotation() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let source = events(&record(dir.path(), &[])?)?;
    let path = seeded(dir.path(), &source, "dropped", |c| {
        c.contacts.pop().is_some()
    })?;
    let xml = dir.path().join("report.xml");
    let out = bin()
        .arg("check")
        .arg(&path)
        .arg("--junit")
        .arg(&xml)
        .args(["--junit-detail", "sweeps"])
        .env("GITHUB_ACTIONS", "true")
        .output()?;
    ensure!(out.status.code() == Some(1), "exit {:?}", out.status.code());
    let text = std::fs::read_to_string(&xml)?;
    let doc = roxmltree::Document::parse(&text)?;
    let failure = |class: &str| {
        doc.descendants()
            .filter(|n| n.has_tag_name("testcase") && n.attribute("classname") == Some(class))
            .filter_map(|n| n.children().find(|c| c.has_tag_name("failure")))
            .map(|f| {
                (
                    f.attribute("type").unwrap_or("").to_string(),
                    f.attribute("message").unwrap_or("").to_string(),
                )
            })
            .collect::<Vec<_>>()
    };
    let trace = failure("check");
    ensure!(
        trace.len() == 1
            && trace[0].0 == "contact_divergence"
            && trace[0].1.contains(
                "1 of 2238 contact queries diverge; first: contact query, frame 2, ball 2: missing"
            ),
        "{trace:?}"
    );
    let query = failure("check.contact_query");
    ensure!(
        query.len() == 1
            && query[0].1.starts_with(
                "contact query, frame 2, ball 2: missing: the ball touches triangle 5"
            ),
        "{query:?}"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    ensure!(
        stdout.lines().any(|l| l.starts_with("::error ")
            && l.contains("title=sweeptrace check%3A contact query%2C frame 2%2C ball 2 diverges")),
        "{stdout}"
    );
    Ok(())
}

/// The judgement's one excuse for a missing place: at a flat seam an
/// engine may keep only the face contact of the triangle the ball rests on
/// (Rapier's `FIX_INTERNAL_EDGES`), since the seam's normal would be the
/// same face normal. At a concave seam (a valley) both faces push, so the
/// same dropped contact still fails.
fn a_seam_contact_may_be_dropped_where_flat_not_where_concave() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    // Triangle 1 across the seam x = 1 rises by `rise` at x = 2.
    let check_dropped = |rise: f64| -> anyhow::Result<(i32, String)> {
        let path = dir.path().join(format!("seam_{rise}.mcap"));
        let scene = SceneMsg {
            name: Some("seam".into()),
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [2.0, 0.0, rise],
            ],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
            margin: 0.0,
            facing: Default::default(),
        };
        let mut w = TraceWriter::new(std::fs::File::create(&path)?)?;
        w.scene(0, &scene)?;
        let query = ContactMsg {
            frame: 0,
            ball: 0,
            radius: 0.25,
            centre: [1.05, 0.5, 0.24],
            distance: 0.0,
        };
        w.contact(1, &query)?;
        // Only triangle 1 (whatever its feature), none at triangle 0's edge.
        let only = ContactPointMsg {
            triangle: 1,
            kind: None,
            feature: None,
            point: None,
            normal: None,
            separation: None,
        };
        w.expected_contacts(
            1,
            &ContactsMsg {
                frame: 0,
                ball: 0,
                contacts: vec![only],
            },
        )?;
        w.finish()?;
        check_text(&path)
    };
    let (code, text) = check_dropped(0.0)?;
    ensure!(code == 0, "flat seam: {text}");
    let (code, text) = check_dropped(0.364)?; // a 20-degree valley
    ensure!(
        code == 1 && text.contains("missing: the ball touches triangle 0 (edge 1)"),
        "concave seam: {text}"
    );
    Ok(())
}
