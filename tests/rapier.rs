//! The Rapier recorder (`examples/rapier_record.rs`) runs and writes a
//! trace that passes `check` with the options examples/rapier/README.md
//! gives a Rapier user, and fails without them; the trace names Rapier as
//! its expectations' source.

use libtest_mimic::Trial;
use sweeptrace::regress::{
    CheckOptions, Field, FieldSet, Status, Tolerances, check_file, render_text,
};
use sweeptrace::sim::BuiltinScene;

use crate::ensure;
use crate::rapier_record::{Args, run};
use crate::trial;
use anyhow::Context as _;

pub fn tests() -> Vec<Trial> {
    vec![trial!(
        rapier_recording_passes_check_with_the_readme_options
    )]
}

fn rapier_recording_passes_check_with_the_readme_options() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let output = dir.path().join("rapier_mini_golf.mcap");
    let mut options = BuiltinScene::MiniGolf.sim_options();
    options.frames = 60;
    options.margin = 0.0;
    let (sweeps, hits, starting_in_contact) = run(Args {
        scene: Some(BuiltinScene::MiniGolf),
        mesh: None,
        output: output.clone(),
        options,
    })
    .map_err(anyhow::Error::msg)?;
    ensure!(
        sweeps == 8 * 60 && hits > 0,
        "{sweeps} sweeps, {hits} hits, {starting_in_contact} starting in contact"
    );
    // `--fields kind,alpha --tolerance 1e-5`
    let readme = CheckOptions {
        tolerances: Tolerances {
            alpha: 1e-5,
            fields: FieldSet::of(&[Field::Kind, Field::Alpha]),
            ..Tolerances::default()
        },
        ..CheckOptions::default()
    };
    let report = check_file(&output, &readme);
    ensure!(
        report.status() == Status::Ok
            && report.compared + report.sweeps_without_expectation == sweeps
            && report.sweeps_without_expectation == starting_in_contact,
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
