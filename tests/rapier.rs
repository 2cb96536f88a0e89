//! The Rapier recorder (`examples/rapier_record.rs`) runs and writes a
//! trace that passes `check` with the options examples/rapier/README.md
//! gives a Rapier user, and fails without them; the trace names Rapier as
//! its expectations' source.

use libtest_mimic::Trial;
use sweeptrace::judge::Tolerances;
use sweeptrace::sim::scenes::BuiltinScene;
use sweeptrace::suite::{CheckOptions, Status, check_file, render_text};

use crate::ensure;
use crate::rapier_record::{Args, Expect, run};
use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(rapier_recording_passes_check_with_the_readme_options),
        trial!(rapier_ghosts_on_a_floor_go_with_fix_internal_edges),
        trial!(rapier_floor_contacts_trace_lists_its_ghosts),
    ]
}

/// The recorder's arguments for one ball rolling across
/// examples/rapier/floor.obj (examples/rapier/README.md, "Ghost contacts").
fn floor_args(output: &std::path::Path, fix: bool, expect: Expect) -> Args {
    let options = sweeptrace::sim::SimOptions {
        balls: 1,
        frames: 180,
        radius: 0.1,
        position: [0.3, 0.35, 0.12],
        velocity: [1.2, 0.5, 0.0],
        margin: 0.0,
        ..Default::default()
    };
    Args {
        scene: None,
        mesh: Some(root().join("examples/rapier/floor.obj")),
        output: output.to_path_buf(),
        options,
        fix_internal_edges: fix,
        expect,
    }
}

fn root() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// On the triangulated flat floor Rapier's solver makes ghost contacts
/// (an edge contact on a flat seam, its normal leaning) without
/// `FIX_INTERNAL_EDGES` and none with it; its shape cast, the recorder's
/// expectations, has none either way (the cast does not use the flag).
fn rapier_ghosts_on_a_floor_go_with_fix_internal_edges() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let mut ghosts = Vec::new();
    for fix in [false, true] {
        let output = dir.path().join(format!("floor_{fix}.mcap"));
        let counts = run(floor_args(&output, fix, Expect::Cast)).map_err(anyhow::Error::msg)?;
        let report = check_file(&output, &CheckOptions::default());
        ensure!(
            report.ghosts.count == 0 && report.compared > 0,
            "fix {fix}: the shape cast's answers hold ghosts\n{}",
            render_text(&report)
        );
        ghosts.push(counts.solver.ghosts);
        ensure!(counts.solver.manifolds > 0, "fix {fix}: no solver contacts");
    }
    ensure!(
        ghosts[0] > 0 && ghosts[1] == 0,
        "solver ghost contacts without / with the flag: {ghosts:?}"
    );
    // As solver contacts, the same run's ghosts are what `check` lists.
    let output = dir.path().join("floor_contacts.mcap");
    let counts = run(floor_args(&output, false, Expect::Contacts)).map_err(anyhow::Error::msg)?;
    let report = check_file(&output, &CheckOptions::default());
    ensure!(
        report.ghosts.count > 0 && report.ghosts.count <= counts.solver.ghosts,
        "check lists {} ghosts, the solver made {}\n{}",
        report.ghosts.count,
        counts.solver.ghosts,
        render_text(&report)
    );
    Ok(())
}

/// The committed solver-contact trace (tests/fixtures/rapier_floor_contacts.mcap,
/// recorded with the arguments of `floor_args` and `--expect contacts`: a
/// contact query per step answered with the solver's touching contacts):
/// `check` lists exactly its eight ghost contacts, on flat seams, and the
/// trace fails; recorded with `FIX_INTERNAL_EDGES` the same run's contacts
/// pass (the flag drops the neighbour's edge contact at a seam, a place its
/// face already has).
fn rapier_floor_contacts_trace_lists_its_ghosts() -> anyhow::Result<()> {
    let path = root().join("tests/fixtures/rapier_floor_contacts.mcap");
    let report = check_file(&path, &CheckOptions::default());
    let listed: Vec<(u64, u32, u8)> = report
        .ghosts
        .contacts
        .iter()
        .map(|g| (g.frame, g.triangle, g.feature))
        .collect();
    ensure!(
        listed
            == [
                (20, 18, 0),
                (22, 3, 1),
                (93, 20, 2),
                (94, 20, 2),
                (95, 20, 2),
                (173, 56, 0),
                (174, 41, 1),
                (175, 41, 1)
            ]
            && report.ghosts.count == 8
            && report
                .ghosts
                .contacts
                .iter()
                .all(|g| g.place == sweeptrace::replay::ghost::GhostPlace::Flat
                    && g.angle_degrees > 1.0)
            && report.status() == Status::Fail,
        "{listed:?}\n{}",
        render_text(&report)
    );
    ensure!(
        report.contacts.compared == 180 && report.compared == 0,
        "{:?}",
        report.contacts
    );
    let dir = tempfile::tempdir()?;
    let fixed = dir.path().join("floor_fixed.mcap");
    let mut args = floor_args(&fixed, true, Expect::Contacts);
    args.fix_internal_edges = true;
    run(args).map_err(anyhow::Error::msg)?;
    let with_flag = check_file(&fixed, &CheckOptions::default());
    ensure!(
        with_flag.status() == Status::Ok
            && with_flag.ghosts.count == 0
            && with_flag.contacts.compared == 180,
        "with FIX_INTERNAL_EDGES:\n{}",
        render_text(&with_flag)
    );
    let source = report.expected_source.context("no expected source")?;
    ensure!(
        source.settings.get("expectations").map(String::as_str) == Some("solver_contacts"),
        "{source:?}"
    );
    Ok(())
}

fn rapier_recording_passes_check_with_the_readme_options() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let output = dir.path().join("rapier_mini_golf.mcap");
    let mut options = BuiltinScene::MiniGolf.sim_options();
    options.frames = 60;
    options.margin = 0.0;
    let counts = run(Args {
        scene: Some(BuiltinScene::MiniGolf),
        mesh: None,
        output: output.clone(),
        options,
        fix_internal_edges: false,
        expect: Expect::Cast,
    })
    .map_err(anyhow::Error::msg)?;
    let (sweeps, hits, starting_in_contact) =
        (counts.sweeps, counts.hits, counts.starting_in_contact);
    ensure!(
        sweeps == 8 * 60 && hits > 0,
        "{sweeps} sweeps, {hits} hits, {starting_in_contact} starting in contact"
    );
    // `--normal contact --tolerance 1e-5 --contact-tolerance 1e-5`: every
    // field compared, under Rapier's normal convention.
    let readme = CheckOptions {
        tolerances: Tolerances {
            alpha: 1e-5,
            contact: 1e-5,
            ..Tolerances::default()
        },
        replay: sweeptrace::replay::ReplayOptions {
            conventions: sweeptrace::conventions::EngineConventions {
                normal: sweeptrace::conventions::NormalRule::Contact,
                ..Default::default()
            },
            ..Default::default()
        },
        ..CheckOptions::default()
    };
    let report = check_file(&output, &readme);
    ensure!(
        report.status() == Status::Ok
            && report.compared + report.expectations.missing == sweeps
            && report.expectations.missing == starting_in_contact,
        "{}",
        render_text(&report)
    );
    // The trace says who computed its expectations: Rapier, the version
    // linked, and its settings.
    let source = report
        .expected_source
        .as_ref()
        .context("no expected source")?;
    ensure!(
        source.engine == "rapier3d-f64"
            && source.version == rapier3d_f64::VERSION
            && source
                .settings
                .get("fix_internal_edges")
                .map(String::as_str)
                == Some("false")
            && source.settings.get("dt")
                == Some(&BuiltinScene::MiniGolf.sim_options().time_step.to_string()),
        "{source:?}"
    );
    let text = render_text(&report);
    ensure!(
        text.lines().nth(1).is_some_and(|l| {
            l.starts_with(&format!(
                "  expectations from rapier3d-f64 {} (",
                rapier3d_f64::VERSION
            )) && l.contains("fix_internal_edges = false")
        }),
        "{text}"
    );
    // With the defaults Rapier's α (to about 1e-5) does not pass.
    let report = check_file(&output, &CheckOptions::default());
    ensure!(report.status() == Status::Fail, "{}", render_text(&report));
    Ok(())
}
