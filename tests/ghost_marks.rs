//! Ghost contacts in `replay`'s outputs (issue 24): the outcome lines'
//! `ghost` field, the Rerun recording's `world/ball/{ball}/ghost` mark and
//! the Foxglove file's `/ghosts` topic, set exactly at the expectations
//! `check` calls ghost contacts (the tilted seam of `ghost`'s fixtures).

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use libtest_mimic::{Completion, Trial};
use serde_json::Value;

use crate::ghost::{is_tilted, seam_floor, sweeps_along, tilted, trace, write};
use crate::support::run_bin;
use crate::{ensure, trial};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(ghost_field_on_the_tilted_seam_sweeps_only),
        trial!(ghost_mark_in_the_recording_at_the_ghost_frames),
        trial!(ghost_mark_in_the_foxglove_file_validates),
    ]
}

/// The seam floor's trace, its expectations tilted at [`is_tilted`]'s
/// sweeps when `tilt`, else all of them the faces' normal (no ghost).
fn seam_trace(dir: &tempfile::TempDir, tilt: bool) -> anyhow::Result<PathBuf> {
    let bytes = trace(&seam_floor(), &sweeps_along(|x| x, 0.0), 0, 2, |f, b| {
        if tilt && is_tilted(f, b) {
            tilted()
        } else {
            [0.0, 0.0, 1.0]
        }
    })?;
    write(&bytes, dir, if tilt { "seam.mcap" } else { "flat.mcap" })
}

/// `sweeptrace replay TRACE ARGS...`, which must succeed.
fn replay(trace: &Path, args: &[&std::ffi::OsStr]) -> anyhow::Result<String> {
    let mut all: Vec<&std::ffi::OsStr> = vec!["replay".as_ref(), trace.as_os_str()];
    all.extend_from_slice(args);
    let (code, out, err) = run_bin(&all)?;
    ensure!(code == 0, "replay exit {code}\n{out}\n{err}");
    Ok(out)
}

fn ghost_field_on_the_tilted_seam_sweeps_only() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = seam_trace(&dir, true)?;
    let out = replay(&path, &["--outcomes".as_ref(), "-".as_ref()])?;
    let lines: Vec<Value> = out
        .lines()
        .map(serde_json::from_str)
        .collect::<Result<_, _>>()?;
    ensure!(lines.len() == 12, "{} lines:\n{out}", lines.len());
    for v in &lines {
        let frame = v["frame"].as_u64().context("frame")?;
        let ball = u32::try_from(v["ball"].as_u64().context("ball")?)?;
        let g = v.get("ghost").context("no ghost field")?;
        if !is_tilted(frame, ball) {
            ensure!(g.is_null(), "frame {frame}, ball {ball}: ghost {g}");
            continue;
        }
        ensure!(
            g["triangle"] == 0
                && g["feature"] == 2
                && g["kind"] == "edge"
                && g["place"] == "flat"
                && g["neighbour"] == 1,
            "frame {frame}, ball {ball}: ghost {g}"
        );
        let angle = g["angle_degrees"].as_f64().unwrap_or(f64::NAN);
        ensure!((angle - 10.0).abs() < 1e-9, "angle {angle}");
        // The sentence `check` writes.
        let text = g["text"].as_str().context("no text")?;
        ensure!(
            text.starts_with(&format!(
                "frame {frame}, ball {ball}: edge 0.2, an internal flat edge shared with \
                 triangle 1: the expected normal is 10.0° from the faces' normal (0, 0, 1)"
            )) && text.ends_with("would be bumped"),
            "text {text}"
        );
    }
    // None on the untilted trace.
    let flat = seam_trace(&dir, false)?;
    let out = replay(&flat, &["--outcomes".as_ref(), "-".as_ref()])?;
    for line in out.lines() {
        let v: Value = serde_json::from_str(line)?;
        ensure!(v.get("ghost") == Some(&Value::Null), "line {line}");
    }
    Ok(())
}

fn ghost_mark_in_the_recording_at_the_ghost_frames() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let path = seam_trace(&dir, true)?;
    let rrd = dir.path().join("seam.rrd");
    replay(&path, &["--rrd".as_ref(), rrd.as_os_str()])?;
    let d = crate::replay::decode_rrd(&rrd)?;
    let label = "ghost contact 10.0°: edge 0.2 is internal and flat";
    for ball in 0..3u32 {
        let entity = format!("/world/ball/{ball}/ghost");
        let want: Vec<i64> = (0..4)
            .filter(|&f| is_tilted(f, ball))
            .map(|f| f as i64)
            .collect();
        for component in ["Points3D:positions", "Arrows3D:vectors"] {
            let got: Vec<i64> = d.frames_with(&entity, component).into_iter().collect();
            ensure!(
                got == want,
                "{entity} {component}: frames {got:?}, want {want:?}"
            );
        }
        // Cleared at the ball's next sweep without one.
        for &f in &want {
            if f < 3 && !is_tilted(f as u64 + 1, ball) {
                ensure!(
                    d.frames_with(&entity, "Clear:is_recursive")
                        .contains(&(f + 1)),
                    "{entity}: not cleared at frame {}",
                    f + 1
                );
            }
        }
        // One label says it, at the expected ball's (the sweep diverges:
        // the expectation names an edge) or else on the mark, never both.
        for &f in &want {
            let on_mark = d.texts_at(&entity, "Points3D:labels", f);
            let expected = format!("/world/ball/{ball}/expected");
            let on_ball = d.texts_at(&expected, "Ellipsoids3D:labels", f);
            let saying = on_mark
                .iter()
                .chain(&on_ball)
                .filter(|t| t.contains(label))
                .count();
            ensure!(
                saying == 1,
                "frame {f}, ball {ball}: mark {on_mark:?}, expected ball {on_ball:?}"
            );
        }
    }
    // Not on a trace without ghost contacts.
    let flat = seam_trace(&dir, false)?;
    let rrd = dir.path().join("flat.rrd");
    replay(&flat, &["--rrd".as_ref(), rrd.as_os_str()])?;
    let d = crate::replay::decode_rrd(&rrd)?;
    let ghosts: Vec<&String> = d
        .components
        .keys()
        .filter(|e| e.ends_with("/ghost"))
        .collect();
    ensure!(ghosts.is_empty(), "ghost entities {ghosts:?}");
    Ok(())
}

fn ghost_mark_in_the_foxglove_file_validates() -> anyhow::Result<Completion> {
    let dir = tempfile::tempdir()?;
    let path = seam_trace(&dir, true)?;
    let file = dir.path().join("seam.foxglove.mcap");
    replay(&path, &["--foxglove".as_ref(), file.as_os_str()])?;
    let bytes = std::fs::read(&file)?;
    let all = crate::foxglove::messages(&bytes)?;
    let ghosts = crate::foxglove::on(&all, "/ghosts");
    let sweeps = crate::foxglove::on(&all, "/numbers");
    ensure!(
        ghosts.len() == 12 && sweeps.len() == 12,
        "{} ghost messages, {} sweeps",
        ghosts.len(),
        sweeps.len()
    );
    for (g, n) in ghosts.iter().zip(&sweeps) {
        let frame = n["frame"].as_u64().context("frame")?;
        let ball = u32::try_from(n["ball"].as_u64().context("ball")?)?;
        let id = format!("ghost/{ball}");
        if !is_tilted(frame, ball) {
            ensure!(
                g["entities"] == serde_json::json!([]) && g["deletions"][0]["id"] == id.as_str(),
                "frame {frame}, ball {ball}: {g}"
            );
            continue;
        }
        let e = &g["entities"][0];
        ensure!(e["id"] == id.as_str(), "entity {e}");
        ensure!(
            e["spheres"].as_array().map(Vec::len) == Some(1)
                && e["arrows"].as_array().map(Vec::len) == Some(2)
                && e["texts"].as_array().map(Vec::len) == Some(1),
            "entity {e}"
        );
        ensure!(
            e["texts"][0]["text"] == "ghost contact 10.0°: edge 0.2 is internal and flat",
            "text {}",
            e["texts"][0]
        );
        // At the expected contact, on the seam below the ball.
        let p = &e["spheres"][0]["pose"]["position"];
        let (x, y, z) = (
            p["x"].as_f64().unwrap_or(f64::NAN),
            p["y"].as_f64().unwrap_or(f64::NAN),
            p["z"].as_f64().unwrap_or(f64::NAN),
        );
        ensure!((x - y).abs() < 1e-9 && z.abs() < 1e-9, "marker at {p}");
    }
    let dump = dir.path().join("seam.jsonl");
    Ok(
        match crate::foxglove::validate_foxglove_file(&file, 1, 12, &dump)? {
            Some(why) => Completion::ignored_with(why),
            None => Completion::Completed,
        },
    )
}
