//! `sweeptrace_serve_engine`: examples/c/engine.c compiled with the system
//! C compiler against the static library passes `conform` (its contact
//! rules too, through `sweeptrace_serve_engine_contacts`) and `check
//! --engine` on the sample traces, its `--bug skip-vertex` fails exactly the
//! vertex rules and its `--bug contact-normal` exactly the contact rules
//! the Python engine's does, a C++ lambda engine passes a trace, and the loop's
//! documented results (a callback's error, a sweep before any scene, a
//! scene without triangles, invalid answers, unknown messages) hold.
//!
//! `conform` and `check --engine` run through the library functions the
//! `sweeptrace` binary calls (`conform::run`, `check_file_with_engine`), so
//! this crate's tests need no build of the binary (which links the viewer).
//!
//! Without a C compiler (`$CC`, else `cc`) the tests that need one are
//! skipped with a message; `SWEEPTRACE_REQUIRE_CC=1` makes that a failure.
//! The same holds for the C++ test and `$CXX`, else `c++`.

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;

use sweeptrace::conform::{ConformOptions, run, select, shell_quote};
use sweeptrace::core::Facing;
use sweeptrace::engine::protocol::{
    contact_line, parse_answer, parse_contacts, scene_line, sweep_line,
};
use sweeptrace::engine::{EngineCommand, EngineOptions};
use sweeptrace::suite::engine_check::check_file_with_engine;
use sweeptrace::suite::report::Against;
use sweeptrace::suite::{CheckOptions, Status, render_text};
use sweeptrace::trace::PendingTrace;
use sweeptrace::trace::{ContactMsg, ContactPointMsg};
use sweeptrace::{SceneMsg, SweepMsg};

/// Set to `1` to make the tests that need a C (or C++) compiler fail,
/// instead of being skipped, when there is none.
const REQUIRE_CC: &str = "SWEEPTRACE_REQUIRE_CC";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("capi/ has a parent")
        .to_path_buf()
}

/// This build's static library, beside the test binary in
/// `<target>/<profile>/deps/`.
fn static_library() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let path = exe
        .parent()
        .expect("the test binary is in <target>/<profile>/deps")
        .join(format!("{}sweeptrace_capi.a", std::env::consts::DLL_PREFIX));
    assert!(
        path.is_file(),
        "{} is missing: cargo builds it with the test",
        path.display()
    );
    path
}

/// The compiler `$variable` names, else `default`, if it runs; `None` (the
/// test is skipped) when it does not, unless [`REQUIRE_CC`] is `1`.
fn compiler(variable: &str, default: &str) -> Option<OsString> {
    let compiler = std::env::var_os(variable).unwrap_or_else(|| default.into());
    let runs = Command::new(&compiler)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if runs {
        return Some(compiler);
    }
    let missing = format!("no C/C++ compiler: `{}` cannot be run", compiler.display());
    if std::env::var_os(REQUIRE_CC).is_some_and(|v| v == "1") {
        panic!("{missing}, and {REQUIRE_CC}=1 requires it");
    }
    eprintln!("skipped: {missing}; {REQUIRE_CC}=1 makes this a failure");
    None
}

/// Compiles `source` (C99, or C++ with `cpp`) with every warning an error
/// against the static library, once per test run (into the target's test
/// directory); `None` when there is no compiler.
fn compile(source: &str, cpp: bool) -> Option<PathBuf> {
    static PROGRAMS: Mutex<BTreeMap<String, Option<PathBuf>>> = Mutex::new(BTreeMap::new());
    let mut programs = PROGRAMS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(program) = programs.get(source) {
        return program.clone();
    }
    let program = compile_now(&root().join(source), cpp);
    programs.insert(source.to_string(), program.clone());
    program
}

fn compile_now(source: &Path, cpp: bool) -> Option<PathBuf> {
    let compiler = if cpp {
        compiler("CXX", "c++")?
    } else {
        compiler("CC", "cc")?
    };
    let program =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(source.file_stem().expect("a file name"));
    let mut command = Command::new(&compiler);
    command
        .arg(if cpp { "-std=c++17" } else { "-std=c99" })
        .args(["-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&program)
        .arg(source)
        .arg("-I")
        .arg(root().join("capi/include"))
        .arg(static_library())
        .args(["-lpthread", "-ldl", "-lm"]);
    if cfg!(target_os = "linux") {
        // The debug library is large: keep the test programs small.
        command.args(["-Wl,--gc-sections", "-s"]);
    }
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", compiler.display()));
    assert!(
        output.status.success(),
        "compiling {} failed ({}):\n{}",
        source.display(),
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    Some(program)
}

fn command(program: &Path, args: &str) -> EngineCommand {
    let text = format!("{} {args}", shell_quote(&program.display().to_string()));
    EngineCommand::parse(text.trim()).expect("a valid engine command")
}

/// The C engine's conformance (with the contact rules when it answers
/// `contacts` queries): the rules that fail.
fn conform_failures(engine: &EngineCommand, contacts: bool) -> Vec<String> {
    let options = ConformOptions {
        strict: true,
        ..ConformOptions::default()
    };
    let cases = select(None, contacts).expect("every case");
    let report = run(engine, EngineOptions::default(), &cases, &options)
        .unwrap_or_else(|e| panic!("the engine cannot be started: {e}"));
    assert_eq!(report.error, None, "a fault of the engine");
    assert_eq!(report.cases, cases.len() as u64);
    report
        .rules
        .iter()
        .filter(|r| r.failed > 0)
        .map(|r| r.rule.to_string())
        .collect()
}

#[test]
fn c_engine_passes_every_conform_rule() {
    let Some(program) = compile("examples/c/engine.c", false) else {
        return;
    };
    let failing = conform_failures(&command(&program, ""), true);
    assert!(failing.is_empty(), "rules failing: {failing:?}");
}

#[test]
fn c_engine_contact_normal_bug_fails_exactly_the_contact_rules() {
    let Some(program) = compile("examples/c/engine.c", false) else {
        return;
    };
    // The rules tests/conform.rs lists for the Python engine's
    // contact-normal.
    let expected = [
        "contact.edge",
        "contact.vertex",
        "contact.flat-seam",
        "contact.shallow-convex-edge",
        "contact.concave-corner",
        "contact.speculative",
    ];
    let failing = conform_failures(&command(&program, "--bug contact-normal"), true);
    assert_eq!(failing, expected);
}

#[test]
fn c_engine_skip_vertex_bug_fails_exactly_the_vertex_rules() {
    let Some(program) = compile("examples/c/engine.c", false) else {
        return;
    };
    // The rules tests/conform.rs lists for the Python engine's skip-vertex.
    let expected = [
        "edge.miss.beyond-v1",
        "edge.miss.before-v0",
        "vertex.hit",
        "tie.shared-vertex",
        "tie.cube-corner",
        "margin.vertex-hit",
    ];
    let failing = conform_failures(&command(&program, "--bug skip-vertex"), true);
    assert_eq!(failing, expected);
}

#[test]
fn c_engine_passes_check_on_the_sample_traces() {
    let Some(program) = compile("examples/c/engine.c", false) else {
        return;
    };
    let engine = command(&program, "");
    let mut traces: Vec<PathBuf> = std::fs::read_dir(root().join("traces"))
        .expect("listing traces/")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .collect();
    traces.sort();
    assert!(!traces.is_empty(), "traces/ holds no sample trace");
    for trace in traces {
        let report = check_file_with_engine(
            &trace,
            &engine,
            EngineOptions::default(),
            Against::Core,
            &CheckOptions::default(),
        )
        .unwrap_or_else(|e| panic!("the engine cannot be started: {e}"));
        let text = render_text(&report);
        assert_eq!(report.status(), Status::Ok, "{text}");
        assert!(
            report.sweeps > 0 && report.compared == report.sweeps,
            "{text}"
        );
    }
}

#[test]
fn cpp_lambda_engine_passes_a_trace() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let Some(program) = compile("capi/tests/engines/lambda_engine.cpp", true) else {
        return;
    };
    // Two triangles at different heights; balls fall onto each and beside.
    let trace = dir.path().join("drops.mcap");
    let mut pending = PendingTrace::create(&trace).expect("creating the trace");
    let scene = SceneMsg {
        name: Some("steps".to_string()),
        vertices: vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            [10.0, 0.0, 1.0],
            [14.0, 0.0, 1.0],
            [10.0, 4.0, 1.0],
        ],
        triangles: vec![[0, 1, 2], [3, 4, 5]],
        margin: 0.0,
        facing: Facing::NonStrict,
    };
    let writer = pending.writer();
    writer.scene(0, &scene).expect("writing the scene");
    let starts = [
        [1.0, 1.0, 3.0],
        [11.0, 1.5, 4.0],
        [6.0, 1.0, 3.0],
        [1.2, 0.7, 2.5],
    ];
    for (frame, p0) in starts.iter().enumerate() {
        let sweep = SweepMsg {
            frame: frame as u64,
            ball: 0,
            radius: 0.5,
            p0: *p0,
            p1: [p0[0], p0[1], -3.0],
        };
        writer.sweep(frame as u64, &sweep).expect("writing a sweep");
    }
    pending.commit().expect("closing the trace");
    let report = check_file_with_engine(
        &trace,
        &command(&program, ""),
        EngineOptions::default(),
        Against::Core,
        &CheckOptions::default(),
    )
    .unwrap_or_else(|e| panic!("the engine cannot be started: {e}"));
    let text = render_text(&report);
    assert_eq!(report.status(), Status::Ok, "{text}");
    assert_eq!((report.sweeps, report.compared), (4, 4), "{text}");
}

/// The answers test engine (capi/tests/engines/answers.c); `None` without
/// a compiler.
fn answers_engine() -> Option<PathBuf> {
    compile("capi/tests/engines/answers.c", false)
}

fn run_engine(program: &Path, mode: &str, input: &str) -> Output {
    let mut child = Command::new(program)
        .arg(mode)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting the test engine");
    let written = child
        .stdin
        .take()
        .expect("its stdin")
        .write_all(input.as_bytes());
    // An engine that stops at a bad line may exit before reading the rest:
    // a closed pipe is then part of what is tested, not a failure.
    if let Err(e) = written {
        assert_eq!(
            e.kind(),
            std::io::ErrorKind::BrokenPipe,
            "writing its input: {e}"
        );
    }
    child.wait_with_output().expect("its output")
}

fn triangle_scene(name: Option<&str>, triangles: Vec<[u64; 3]>) -> String {
    scene_line(&SceneMsg {
        name: name.map(str::to_string),
        vertices: vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        triangles,
        margin: 0.0,
        facing: Facing::Strict,
    })
    .expect("a scene line")
}

fn sweep(frame: u64) -> String {
    sweep_line(&SweepMsg {
        frame,
        ball: 2,
        radius: 0.5,
        p0: [1.0, 1.0, 3.0],
        p1: [1.0, 1.0, -3.0],
    })
    .expect("a sweep line")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn answers_are_written_in_order_and_unknown_messages_ignored() {
    let Some(program) = answers_engine() else {
        return;
    };
    let input = format!(
        "{}{}{{\"type\":\"hello\",\"frame\":99}}\n\n{}",
        triangle_scene(Some("level"), vec![[0, 1, 2]]),
        sweep(0),
        sweep(1)
    );
    let output = run_engine(&program, "face", &input);
    assert_eq!(output.status.code(), Some(0), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    for (frame, line) in lines.iter().enumerate() {
        let answer = parse_answer(line.as_bytes()).expect("an outcome line");
        assert_eq!((answer.frame, answer.ball), (frame as u64, 2));
        assert_eq!(answer.alpha, 0.5);
        assert_eq!(answer.triangle, Some(Some(0)));
        assert_eq!(answer.feature, Some(None), "a face has no feature");
        assert_eq!(answer.normal, Some(Some([0.0, 0.0, 1.0])));
        assert!(line.starts_with("{\"type\":\"outcome\","), "{line}");
    }
    assert!(
        text(&output.stderr).contains("scene level with 1 triangles"),
        "{}",
        text(&output.stderr)
    );
}

#[test]
fn a_scene_without_triangles_is_passed_and_a_miss_answered() {
    let Some(program) = answers_engine() else {
        return;
    };
    let input = format!("{}{}", triangle_scene(None, vec![]), sweep(0));
    let output = run_engine(&program, "miss", &input);
    assert_eq!(output.status.code(), Some(0), "{}", text(&output.stderr));
    let answer = parse_answer(text(&output.stdout).trim().as_bytes()).expect("an outcome");
    assert_eq!(
        answer,
        sweeptrace::OutcomeMsg::miss(0, 2),
        "every field given, null"
    );
    assert!(text(&output.stderr).contains("scene (none) with 0 triangles"));
    // An answer naming a triangle of a scene that has none is invalid.
    let output = run_engine(&program, "face", &input);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(text(&output.stdout), "", "nothing written for it");
    assert!(
        text(&output.stderr).contains(
            "sweeptrace engine: invalid answer to frame 0, ball 2: outcome of frame 0, ball 2: \
             field `triangle`: index 0 is out of range (the scene has 0 triangles)"
        ),
        "{}",
        text(&output.stderr)
    );
}

/// Runs the answers engine in `mode` on a scene and sweeps 0 and 1: it
/// must return 1 with `message` on stderr after answering `answered` sweeps.
fn assert_fails(mode: &str, input: &str, answered: usize, message: &str) {
    let Some(program) = answers_engine() else {
        return;
    };
    let output = run_engine(&program, mode, input);
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{mode}: {stderr}");
    assert_eq!(
        text(&output.stdout).lines().count(),
        answered,
        "{mode}: {}",
        text(&output.stdout)
    );
    let expected = format!("sweeptrace engine: {message}\n");
    assert!(stderr.ends_with(&expected), "{mode}: {stderr}");
}

fn scene_and_two_sweeps() -> String {
    format!(
        "{}{}{}",
        triangle_scene(Some("level"), vec![[0, 1, 2]]),
        sweep(0),
        sweep(1)
    )
}

#[test]
fn a_callback_error_stops_the_loop_with_a_message() {
    assert_fails(
        "fail-sweep",
        &scene_and_two_sweeps(),
        1,
        "on_sweep returned 7 for frame 1, ball 2",
    );
    assert_fails(
        "fail-scene",
        &scene_and_two_sweeps(),
        0,
        "on_scene returned 3 for the scene `level` (input line 1)",
    );
}

#[test]
fn invalid_answers_are_not_written() {
    assert_fails(
        "nan",
        &scene_and_two_sweeps(),
        0,
        "invalid answer to frame 0, ball 2: field `alpha`: must be a number in [0, 1], got NaN",
    );
    assert_fails(
        "kind",
        &scene_and_two_sweeps(),
        0,
        "invalid answer to frame 0, ball 2: `kind` must be a SweeptraceKind \
         (0 none, 1 face, 2 edge, 3 vertex), got 9",
    );
}

#[test]
fn bad_input_and_a_null_callback_are_errors() {
    assert_fails(
        "miss",
        &sweep(0),
        0,
        "input line 1: the sweep of frame 0, ball 2 arrived before any scene",
    );
    assert_fails(
        "miss",
        &format!(
            "{}collision at 0.4\n",
            triangle_scene(None, vec![[0, 1, 2]])
        ),
        0,
        "input line 2 is not a protocol message: it is not valid JSON (expected value at line 1 column 1)",
    );
    assert_fails(
        "miss",
        &triangle_scene(None, vec![[0, 1, 7]]),
        0,
        "input line 1: scene: field `triangles[0][2]`: vertex index 7 is out of range \
         (the scene has 3 vertices)",
    );
    assert_fails(
        "null",
        &scene_and_two_sweeps(),
        0,
        "`engine->on_sweep` is a null pointer",
    );
}

fn contact_query(frame: u64) -> String {
    contact_line(&ContactMsg {
        frame,
        ball: 1,
        radius: 0.5,
        centre: [1.0, 1.0, 0.25],
        distance: 0.0,
    })
    .expect("a contact line")
}

#[test]
fn contact_queries_are_answered_through_the_contact_callback() {
    let Some(program) = answers_engine() else {
        return;
    };
    let input = format!(
        "{}{}{}",
        triangle_scene(Some("level"), vec![[0, 1, 2]]),
        contact_query(3),
        sweep(4)
    );
    let output = run_engine(&program, "contacts", &input);
    assert_eq!(output.status.code(), Some(0), "{}", text(&output.stderr));
    let stdout = text(&output.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    let answer = parse_contacts(lines[0].as_bytes()).expect("a contacts line");
    assert_eq!((answer.frame, answer.ball), (3, 1));
    assert_eq!(
        answer.contacts,
        vec![ContactPointMsg {
            triangle: 0,
            kind: Some(sweeptrace::Kind::Face),
            feature: None,
            point: Some([1.0, 1.0, 0.0]),
            normal: Some([0.0, 0.0, 1.0]),
            separation: Some(-0.25),
        }]
    );
    parse_answer(lines[1].as_bytes()).expect("the sweep's outcome after it");
    // Without a contact callback, a query is an error that says how to
    // serve one.
    let scene = triangle_scene(Some("level"), vec![[0, 1, 2]]);
    assert_fails(
        "miss",
        &format!("{scene}{}", contact_query(3)),
        0,
        "input line 2: a contact query (frame 3, ball 1), but sweeptrace_serve_engine answers \
         sweeps only: serve with sweeptrace_serve_engine_contacts, or check without --engine-contacts",
    );
    assert_fails(
        "contact-bad",
        &format!("{scene}{}", contact_query(3)),
        0,
        "invalid answer to the contact query of frame 3, ball 1: contact 0: `triangle` 5 is not \
         in the scene (1 triangle)",
    );
    assert_fails(
        "contact-fail",
        &format!("{scene}{}", contact_query(3)),
        0,
        "on_contact returned 4 for frame 3, ball 1",
    );
    assert_fails(
        "contact-null",
        &format!("{scene}{}", contact_query(3)),
        0,
        "`on_contact` is a null pointer",
    );
}

#[test]
fn minimal_engine_runs_through_conform_and_the_docs_show_it_unchanged() {
    let example = std::fs::read_to_string(root().join("examples/c/minimal_engine.c"))
        .expect("reading examples/c/minimal_engine.c");
    for doc in ["capi/README.md", "docs/ENGINE_PROTOCOL.md"] {
        let text = std::fs::read_to_string(root().join(doc)).expect("reading the docs");
        assert!(
            text.contains(&format!("```c\n{example}```\n")),
            "{doc} does not show examples/c/minimal_engine.c as it is: copy the file into its ```c block"
        );
    }
    let Some(program) = compile("examples/c/minimal_engine.c", false) else {
        return;
    };
    // It answers "no collision" everywhere: no fault, the miss rules pass,
    // the hit rules fail.
    let failing = conform_failures(&command(&program, ""), false);
    assert!(failing.contains(&"face.hit".to_string()), "{failing:?}");
    assert!(
        !failing.iter().any(|r| r.starts_with("face.miss")),
        "{failing:?}"
    );
}

/// The commands the docs show for building `examples/c/engine.c`: every
/// `cc ...` command naming it, in `capi/README.md`,
/// `docs/ENGINE_PROTOCOL.md` and the file's own header, from code blocks
/// (continuation lines joined) and inline code spans; each with the file
/// it came from.
fn documented_engine_commands() -> Vec<(String, String)> {
    let mut commands = Vec::new();
    let mut keep = |file: &str, command: String| {
        let command = command.split_whitespace().collect::<Vec<_>>().join(" ");
        if command.starts_with("cc ") && command.contains("examples/c/engine.c") {
            commands.push((file.to_string(), command));
        }
    };
    for doc in ["capi/README.md", "docs/ENGINE_PROTOCOL.md"] {
        let text = std::fs::read_to_string(root().join(doc)).expect("reading the doc");
        // Fenced blocks: lines, a trailing `\` continuing onto the next.
        let mut outside = String::new();
        for (i, part) in text.split("```").enumerate() {
            if i % 2 == 0 {
                outside.push_str(part);
                continue;
            }
            for command in part.replace("\\\n", " ").lines() {
                keep(doc, command.to_string());
            }
        }
        // Inline code spans, which may run over lines of prose.
        for (i, span) in outside.split('`').enumerate() {
            if i % 2 == 1 {
                keep(doc, span.replace('\n', " "));
            }
        }
    }
    let source = std::fs::read_to_string(root().join("examples/c/engine.c")).expect("engine.c");
    let header = &source[..source.find("*/").expect("a header comment")];
    let lines: Vec<&str> = header
        .lines()
        .map(|l| l.trim_start().trim_start_matches('*').trim())
        .collect();
    for command in lines.join("\n").replace("\\\n", " ").lines() {
        keep("examples/c/engine.c", command.to_string());
    }
    commands
}

/// Every documented command that builds `examples/c/engine.c` links (the
/// shared-library one too, which needs `-lm` for `sqrt`, `fmin`, `fmax`)
/// when run as shown, with `target/release` standing for this build's
/// libraries, and the engine it builds passes `conform`.
#[test]
fn documented_engine_build_commands_link_and_the_engine_runs() {
    let Some(compiler) = compiler("CC", "cc") else {
        return;
    };
    let commands = documented_engine_commands();
    for (file, count) in [
        ("capi/README.md", 2),
        ("docs/ENGINE_PROTOCOL.md", 2),
        ("examples/c/engine.c", 2),
    ] {
        let shown = commands.iter().filter(|(f, _)| f == file).count();
        assert_eq!(
            shown, count,
            "{file}: {shown} commands building engine.c, want {count}: {commands:?}"
        );
    }
    let libraries = static_library()
        .parent()
        .expect("the libraries' directory")
        .display()
        .to_string();
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (i, (file, command)) in commands.iter().enumerate() {
        assert!(
            command.contains(" -lm"),
            "{file}: `{command}` does not link the math library"
        );
        let program = dir.path().join(format!("engine_{i}"));
        let run = command
            .replacen("cc ", &format!("{} ", compiler.display()), 1)
            .replace("\"$PWD/target/release\"", &libraries)
            .replace("target/release", &libraries)
            .replace("-o engine", &format!("-o {}", program.display()));
        let output = Command::new("sh")
            .args(["-c", &run])
            .current_dir(root())
            .output()
            .expect("running sh");
        assert!(
            output.status.success(),
            "{file}: `{command}` failed ({}):\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
        let failing = conform_failures(&self::command(&program, ""), true);
        assert!(
            failing.is_empty(),
            "{file}: the engine `{command}` builds fails {failing:?}"
        );
    }
}
