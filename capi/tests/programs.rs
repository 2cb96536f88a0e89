//! The C example, compiled with the system C compiler, and the Python
//! `ctypes` example write traces through the built library; the traces pass
//! the same check as `sweeptrace check` (the library's `check_file`).

use std::path::{Path, PathBuf};
use std::process::Command;

use sweeptrace::ExpectedSource;
use sweeptrace::suite::{CheckOptions, Status, check_file, render_text};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("capi/ has a parent")
        .to_path_buf()
}

/// Where cargo put this build's libraries: beside the test binary, in
/// `<target>/<profile>/deps/` (a test build does not copy them up to
/// `<target>/<profile>/`, where an older build's may lie).
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    exe.parent()
        .expect("the test binary is in <target>/<profile>/deps")
        .to_path_buf()
}

/// The shared library (`libsweeptrace_capi.so`, `.dylib`, `sweeptrace_capi.dll`).
fn shared_library() -> PathBuf {
    let name = format!(
        "{}sweeptrace_capi{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    let path = library_dir().join(name);
    assert!(
        path.is_file(),
        "{} is missing: cargo builds it with the test",
        path.display()
    );
    path
}

/// Runs `command`, fails the test with its output unless it succeeds.
fn run(what: &str, command: &mut Command) {
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run {command:?}: {e}"));
    assert!(
        output.status.success(),
        "{what} failed ({}):\n{}{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// `sweeptrace check`'s verdict on the trace: ok, with all three sweeps
/// compared with an expectation, which the report says came from the
/// examples' engine with its settings.
fn assert_check_passes(trace: &Path) {
    let report = check_file(trace, &CheckOptions::default());
    let source = ExpectedSource::new("example-engine", "1.0")
        .setting("margin", "0")
        .setting("two_sided_triangles", "false");
    assert_eq!(
        report.expected_source.as_ref(),
        Some(&source),
        "{}",
        render_text(&report)
    );
    assert!(
        render_text(&report).contains(
            "\n  expectations from example-engine 1.0 (margin = 0, two_sided_triangles = false)\n"
        ),
        "{}",
        render_text(&report)
    );
    assert!(
        report.status() == Status::Ok,
        "check does not pass:\n{}",
        render_text(&report)
    );
    assert_eq!(
        (report.sweeps, report.compared, report.divergent),
        (3, 3, 0),
        "{}",
        render_text(&report)
    );
    // capi/README.md shows this report, for the trace written as run.mcap.
    let shown = render_text(&report).replace(&trace.display().to_string(), "run.mcap");
    let readme = std::fs::read_to_string(root().join("capi/README.md")).expect("capi/README.md");
    assert!(
        readme.contains(&format!("```text\n{shown}```\n")),
        "capi/README.md should show `sweeptrace check run.mcap`'s report as it is:\n{shown}"
    );
}

#[test]
fn c_example_compiled_with_the_system_compiler_writes_a_trace_that_check_passes() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let program = dir.path().join("write_trace");
    let compiler = std::env::var_os("CC").unwrap_or_else(|| "cc".into());
    let library_dir = library_dir();
    // Fails on warnings too: capi/README.md shows this file.
    run(
        "compiling examples/c/write_trace.c",
        Command::new(&compiler)
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-o"])
            .arg(&program)
            .arg(root().join("examples/c/write_trace.c"))
            .arg("-I")
            .arg(root().join("capi/include"))
            .arg("-L")
            .arg(&library_dir)
            .arg("-lsweeptrace_capi")
            .arg(format!("-Wl,-rpath,{}", library_dir.display())),
    );
    shared_library();
    let trace = dir.path().join("run.mcap");
    run("the compiled C example", Command::new(&program).arg(&trace));
    assert_check_passes(&trace);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .expect("listing the directory")
        .filter_map(Result::ok)
        .map(|e| e.file_name())
        .filter(|n| n.to_string_lossy().contains(".partial-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn python_ctypes_example_writes_a_trace_that_check_passes() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let trace = dir.path().join("run.mcap");
    run(
        "examples/python/write_trace_ctypes.py (needs python3 on PATH)",
        Command::new("python3")
            .arg(root().join("examples/python/write_trace_ctypes.py"))
            .arg(shared_library())
            .arg(&trace),
    );
    assert_check_passes(&trace);
}

#[test]
fn process_ending_before_close_leaves_no_file_under_the_target_name() {
    // The ctypes example's library, driven by a Python process that dies
    // (os._exit, no cleanup) between adding a sweep and closing.
    let dir = tempfile::tempdir().expect("a temporary directory");
    let trace = dir.path().join("killed.mcap");
    let script = format!(
        "import ctypes, os, sys\n\
         sys.path.insert(0, {examples:?})\n\
         import write_trace_ctypes as w\n\
         lib = w.load({library:?})\n\
         writer = ctypes.c_void_p()\n\
         assert lib.sweeptrace_writer_open({trace:?}.encode(), ctypes.byref(writer)) == 0\n\
         v = (ctypes.c_double * 9)(0, 0, 0, 4, 0, 0, 0, 4, 0)\n\
         t = (ctypes.c_uint32 * 3)(0, 1, 2)\n\
         assert lib.sweeptrace_writer_add_scene(writer, 0, None, v, 3, t, 1, 0.0, 0) == 0\n\
         os._exit(0)\n",
        examples = root().join("examples/python").display().to_string(),
        library = shared_library().display().to_string(),
        trace = trace.display().to_string(),
    );
    run(
        "a Python process killed before closing",
        Command::new("python3").arg("-c").arg(script),
    );
    assert!(
        !trace.exists(),
        "{} exists although the writer was never closed",
        trace.display()
    );
}

#[test]
fn readme_shows_the_tested_c_example_unchanged() {
    let example = std::fs::read_to_string(root().join("examples/c/write_trace.c"))
        .expect("reading examples/c/write_trace.c");
    let readme =
        std::fs::read_to_string(root().join("capi/README.md")).expect("reading capi/README.md");
    assert!(
        readme.contains(&format!("```c\n{example}```\n")),
        "capi/README.md does not show examples/c/write_trace.c as it is: copy the file into its ```c block"
    );
}
