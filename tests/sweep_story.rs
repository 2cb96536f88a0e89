//! `sweep` tells the whole story of one sweep (issue 34): a floor of two
//! triangles with triangle 1 wound the other way (`cw.obj`), and a ball
//! recorded falling onto it (`record --mesh cw.obj`). `check` finds the
//! tunnel through the flipped triangle; `sweep` on that frame, from the
//! trace or from the OBJ with the same path, names the same tunnel in the
//! same words, the flipped triangle within reach, and lists the face test
//! of the triangle the ball fell through with why it did not count. Every
//! run is of the real binary, in a temporary directory.

use std::path::Path;

use anyhow::Context as _;
use libtest_mimic::Trial;

use crate::support::run_bin_in;
use crate::{ensure, os, trial};

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(sweep_from_the_trace_names_the_tunnel_and_the_flipped_triangle),
        trial!(sweep_on_the_obj_lists_the_triangle_under_the_ball),
        trial!(sweep_names_a_tunnel_between_sweeps_as_check_does),
        trial!(sweep_json_says_the_conventions_it_ran_under),
        trial!(a_library_user_gets_the_story_sweep_tells),
    ]
}

/// The square `[0, 4]²` at `z = 0` in two triangles: 0 faces `+z`, 1 (the
/// half `y ≥ x`) is wound the other way.
const CW_OBJ: &str = "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nf 1 2 3\nf 1 4 3\n";

/// Writes `cw.obj` in `dir` and records one ball dropped from `(1, 3, 2)`
/// (over triangle 1) onto it as `cw.mcap`.
fn cw_floor(dir: &Path) -> anyhow::Result<()> {
    std::fs::write(dir.join("cw.obj"), CW_OBJ)?;
    let (code, out, err) = run_bin_in(dir, os!["mesh", "cw.obj"])?;
    ensure!(
        code == 1 && out.contains("1 flipped") && out.contains("triangle 1"),
        "mesh: exit {code}\n{out}{err}"
    );
    let (code, out, err) = run_bin_in(
        dir,
        os![
            "record",
            "--mesh",
            "cw.obj",
            "-o",
            "cw.mcap",
            "--balls",
            "1",
            "--position",
            "1,3,2",
            "--radius",
            "0.5"
        ],
    )?;
    ensure!(code == 0, "record: exit {code}\n{out}{err}");
    Ok(())
}

/// The one tunnel `check --json` finds in `cw.mcap`: its frame and the
/// line `check` prints for it.
fn checked_tunnel(dir: &Path) -> anyhow::Result<(u64, String)> {
    let (code, out, err) = run_bin_in(dir, os!["check", "cw.mcap", "--json"])?;
    ensure!(code == 1, "check: exit {code}\n{out}{err}");
    let json: serde_json::Value = serde_json::from_str(&out).context("check --json")?;
    let details = json["traces"][0]["tunnel_details"]
        .as_array()
        .context("no tunnel_details")?;
    ensure!(details.len() == 1, "{details:?}");
    let frame = details[0]["frame"].as_u64().context("no frame")?;
    let (_, text, _) = run_bin_in(dir, os!["check", "cw.mcap"])?;
    let line = text
        .lines()
        .find_map(|l| l.trim_start().strip_prefix("tunnel: "))
        .with_context(|| format!("no tunnel line:\n{text}"))?
        .to_string();
    ensure!(
        line.contains("through triangle 1 (back to front)")
            && line.ends_with("through the flipped triangle 1"),
        "{line}"
    );
    Ok((frame, line))
}

fn sweep_from_the_trace_names_the_tunnel_and_the_flipped_triangle() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    cw_floor(dir.path())?;
    let (frame, line) = checked_tunnel(dir.path())?;
    let frame = frame.to_string();
    let (code, out, err) = run_bin_in(
        dir.path(),
        os!["sweep", "--trace", "cw.mcap", "--frame", &frame],
    )?;
    ensure!(code == 0, "sweep: exit {code}\n{out}{err}");
    ensure!(
        out.contains(&format!("\ntunnel: {line}\n")),
        "not check's tunnel line `{line}`:\n{out}"
    );
    ensure!(
        out.contains("defects within reach") && out.contains("\n  the flipped triangle 1 at 0\n"),
        "no flipped triangle within reach:\n{out}"
    );
    ensure!(
        !out.contains("no test came close"),
        "the triangle it fell through is not listed:\n{out}"
    );
    let face = out
        .lines()
        .find(|l| l.starts_with("  face 1:"))
        .with_context(|| format!("face 1 not listed:\n{out}"))?;
    ensure!(
        face.contains("back to front: back-facing: the ball comes from behind (n·d = +"),
        "{face}"
    );

    let (code, out, err) = run_bin_in(
        dir.path(),
        os!["sweep", "--trace", "cw.mcap", "--frame", &frame, "--json"],
    )?;
    ensure!(code == 0, "sweep --json: exit {code}\n{out}{err}");
    let json: serde_json::Value = serde_json::from_str(&out)?;
    let tunnel = &json["tunnels"][0];
    ensure!(
        tunnel["kind"] == "during_sweep"
            && tunnel["triangle"] == 1
            && tunnel["back_to_front"] == true
            && tunnel["through"]["kind"] == "flipped"
            && tunnel["through"]["triangles"] == serde_json::json!([1])
            && tunnel["text"] == line.as_str(),
        "{tunnel}"
    );
    let near = &json["defects_within_reach"][0];
    ensure!(
        near["kind"] == "flipped" && near["distance"] == 0.0,
        "{}",
        json["defects_within_reach"]
    );
    let tests = json["tests"].as_array().context("no tests")?;
    let face = tests
        .iter()
        .find(|t| t["test"] == "face" && t["triangle"] == 1)
        .with_context(|| format!("face 1 not in the tests: {tests:?}"))?;
    ensure!(
        face["crossing"]["back_to_front"] == true
            && face["crossing"]["text"]
                .as_str()
                .is_some_and(|t| t.contains("the ball comes from behind")),
        "{face}"
    );
    Ok(())
}

fn sweep_on_the_obj_lists_the_triangle_under_the_ball() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    std::fs::write(dir.path().join("cw.obj"), CW_OBJ)?;
    let args = os![
        "sweep", "--mesh", "cw.obj", "--from", "1,3,2", "--to", "1,3,-2"
    ];
    let (code, out, err) = run_bin_in(dir.path(), args)?;
    ensure!(code == 0, "exit {code}\n{out}{err}");
    ensure!(
        out.contains(
            "\ntunnel: through triangle 1 (back to front) during its sweep at (1, 3, 0), \
             through the flipped triangle 1\n"
        ),
        "{out}"
    );
    let listed = crate::support::close_tests(&out);
    ensure!(
        listed.first().is_some_and(|l| l.starts_with("  face 1:")
            && l.ends_with("back-facing: the ball comes from behind (n·d = +4)")),
        "the face it fell through is not first:\n{out}"
    );
    // Beside the floor: no tunnel, nothing within reach, and the mesh's
    // defect still counted.
    let (code, out, err) = run_bin_in(
        dir.path(),
        os![
            "sweep", "--mesh", "cw.obj", "--from", "6,3,2", "--to", "6,3,-2"
        ],
    )?;
    ensure!(code == 0, "exit {code}\n{out}{err}");
    ensure!(
        !out.contains("tunnel:")
            && out.contains("defects within reach: none (the mesh has 1 defect;"),
        "{out}"
    );
    Ok(())
}

/// A ball moved through a wall between two sweeps
/// (tests/fixtures/tunnel_wall_teleport.mcap): `sweep` on the second one
/// replays the trace up to it and names the tunnel as `check` does.
fn sweep_names_a_tunnel_between_sweeps_as_check_does() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let trace = "tests/fixtures/tunnel_wall_teleport.mcap";
    let (_, checked, _) = run_bin_in(root, os!["check", trace])?;
    let line = checked
        .lines()
        .find_map(|l| l.trim_start().strip_prefix("tunnel: "))
        .with_context(|| format!("no tunnel line:\n{checked}"))?;
    ensure!(
        line.contains("between its sweeps of frames 1 and 2"),
        "{line}"
    );
    let (code, out, err) = run_bin_in(root, os!["sweep", "--trace", trace, "--frame", "2"])?;
    ensure!(code == 0, "exit {code}\n{out}{err}");
    ensure!(out.contains(&format!("\ntunnel: {line}\n")), "{out}");
    Ok(())
}

/// Issue 44: `sweep --json` omitted the conventions its answer was computed
/// under. Declared by flags, they are in the document as `check --json`
/// says them; under the rules there is no `conventions` key.
fn sweep_json_says_the_conventions_it_ran_under() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let trace = root.join("traces/record_mini_golf.mcap");
    let sweep = |more: &[&str]| -> anyhow::Result<serde_json::Value> {
        let mut args: Vec<&std::ffi::OsStr> = vec![
            "sweep".as_ref(),
            "--trace".as_ref(),
            trace.as_os_str(),
            "--frame".as_ref(),
            "55".as_ref(),
            "--ball".as_ref(),
            "1".as_ref(),
            "--json".as_ref(),
            "--no-config".as_ref(),
        ];
        args.extend(more.iter().map(std::ffi::OsStr::new));
        let (code, out, err) = run_bin_in(root, &args)?;
        ensure!(code == 0, "exit {code}: {err}");
        serde_json::from_str(&out).with_context(|| out.clone())
    };
    let declared = sweep(&[
        "--precision",
        "f32",
        "--initial-overlap",
        "alpha0",
        "--ties",
        "any",
    ])?;
    let conventions = &declared["conventions"];
    ensure!(
        conventions["precision"] == "f32"
            && conventions["initial_overlap"] == "alpha0"
            && conventions["ties"] == "any",
        "conventions: {conventions}"
    );
    let rules = sweep(&[])?;
    ensure!(
        rules.get("conventions").is_none(),
        "under the rules: {rules}"
    );
    Ok(())
}

/// `explain_sweep` is the story `sweep` renders, for a library user: on
/// the same floor and path, the same tunnel through the flipped triangle,
/// the flipped triangle within reach, the one defect, and a record of
/// every triangle's face, edge and vertex tests.
fn a_library_user_gets_the_story_sweep_tells() -> anyhow::Result<()> {
    use sweeptrace::conventions::NormalRule;
    use sweeptrace::core::{Options, Sweep};
    let vertices = vec![
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [4.0, 4.0, 0.0],
        [0.0, 4.0, 0.0],
    ];
    let triangles = [[0, 1, 2], [0, 3, 2]];
    let mesh = sweeptrace::Mesh::new(vertices.clone(), &triangles)?;
    let topology = sweeptrace::Topology::new(&vertices, &triangles)?;
    let sweep = Sweep::new([1.0, 3.0, 2.0], [1.0, 3.0, -2.0], 0.5);
    let story = sweeptrace::replay::explain_sweep(
        &mesh,
        Some(&topology),
        &sweep,
        &Options::default(),
        NormalRule::Face,
        None,
    )?;
    ensure!(story.outcome.hit.is_none(), "{:?}", story.outcome);
    ensure!(
        story.tunnels.len() == 1
            && story.tunnels[0]
                .sentence(None)
                .contains("through the flipped triangle 1"),
        "{:?}",
        story.tunnels
    );
    ensure!(
        story
            .within_reach
            .iter()
            .any(|d| d.text.contains("triangle 1"))
            && story.defects == Some(1),
        "{:?} {:?}",
        story.within_reach,
        story.defects
    );
    // Each triangle: its face, three edges and three vertices.
    ensure!(story.records.len() == 14, "{} records", story.records.len());
    ensure!(
        story.crossings.iter().any(|c| c.triangle == 1),
        "{:?}",
        story.crossings
    );
    Ok(())
}
