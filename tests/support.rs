//! Helpers shared by the test modules.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use sweeptrace::core::record::{CollectRecords, EdgeRecord, FaceRecord, TestRecord, VertexRecord};
use sweeptrace::core::{Broadphase, Facing, Mesh, Options, Outcome, Sweep, sweep_mesh_with};

/// Fails the test with a message unless `cond` holds.
#[macro_export]
macro_rules! ensure {
    ($cond:expr, $($arg:tt)+) => {
        if $cond {
        } else {
            anyhow::bail!($($arg)+);
        }
    };
}

/// The `sweeptrace` binary of this build.
pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_sweeptrace"))
}

/// Runs the binary with `args`: exit code (-1 when killed by a signal),
/// stdout, stderr.
pub fn run_bin(args: &[&std::ffi::OsStr]) -> anyhow::Result<(i32, String, String)> {
    let out = bin()
        .args(args)
        .output()
        .map_err(|e| anyhow::anyhow!("running sweeptrace: {e}"))?;
    Ok((
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

/// [`run_bin`] with `dir` as the working directory.
pub fn run_bin_in(
    dir: &std::path::Path,
    args: &[&std::ffi::OsStr],
) -> anyhow::Result<(i32, String, String)> {
    run_program_in(
        std::path::Path::new(env!("CARGO_BIN_EXE_sweeptrace")),
        dir,
        args,
    )
}

/// Runs `program` (another build of the binary) with `args` in `dir`:
/// exit code (-1 when killed by a signal), stdout, stderr.
pub fn run_program_in(
    program: &std::path::Path,
    dir: &std::path::Path,
    args: &[&std::ffi::OsStr],
) -> anyhow::Result<(i32, String, String)> {
    let out = std::process::Command::new(program)
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| anyhow::anyhow!("running {} in {}: {e}", program.display(), dir.display()))?;
    Ok((
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

/// `&[&OsStr]` of the arguments, for [`run_bin`].
#[macro_export]
macro_rules! os {
    ($($a:expr),* $(,)?) => { &[$(std::ffi::OsStr::new($a)),*] };
}

/// Runs `f` on a thread of its own and fails if it has not returned within
/// `limit`, so that a test whose code under test hangs fails instead of
/// hanging the whole run (the stuck thread is left behind; the test binary
/// ends with the run).
pub fn with_timeout<T: Send + 'static, E: Fail + Send + 'static>(
    limit: Duration,
    f: impl FnOnce() -> Result<T, E> + Send + 'static,
) -> Result<T, E> {
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name("test body".to_string())
        .spawn(move || {
            // The receiver is gone only after a timeout: nobody is listening.
            let _ = tx.send(f());
        })
        .map_err(|e| E::fail(format!("cannot start the test thread: {e}")))?;
    match rx.recv_timeout(limit) {
        Ok(result) => result,
        Err(RecvTimeoutError::Timeout) => Err(E::fail(format!(
            "did not finish within {} s (hangs?)",
            limit.as_secs_f64()
        ))),
        Err(RecvTimeoutError::Disconnected) => Err(E::fail("the test body panicked".to_string())),
    }
}

/// An error a test can fail with: `anyhow::Error` (the tests' own), or a
/// `String`.
pub trait Fail: Sized {
    /// The error of a failed check, from its message.
    fn fail(message: String) -> Self;
    /// The whole message, with the context chain.
    fn message(self) -> String;
}

impl Fail for anyhow::Error {
    fn fail(message: String) -> Self {
        anyhow::Error::msg(message)
    }
    fn message(self) -> String {
        format!("{self:#}")
    }
}

impl Fail for String {
    fn fail(message: String) -> Self {
        message
    }
    fn message(self) -> String {
        self
    }
}

/// Set to `1` to make the tests that compare a committed fixture with
/// what its generator makes today rewrite the fixture instead
/// (`SWEEPTRACE_BLESS=1 cargo test --test integration -- fixture`).
pub const BLESS: &str = "SWEEPTRACE_BLESS";

/// Compares the committed fixture at `path` with `bytes`, what its
/// generator makes today; with [`BLESS`] set to `1`, writes `bytes` there
/// instead (under a temporary name, then renamed).
pub fn compare_or_bless(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<()> {
    use anyhow::Context as _;
    if std::env::var(BLESS).as_deref() == Ok("1") {
        let temp = path.with_extension("blessing");
        std::fs::write(&temp, bytes).with_context(|| format!("writing {}", temp.display()))?;
        return std::fs::rename(&temp, path)
            .with_context(|| format!("renaming {} to {}", temp.display(), path.display()));
    }
    let committed = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    ensure!(
        committed == bytes,
        "{} differs from what its generator makes today: if the change is intended, \
         rewrite it with `{BLESS}=1 cargo test --test integration -- fixture`",
        path.display()
    );
    Ok(())
}

/// Set to `1` (CI does) to make the tests that need Python's `mcap`
/// package fail, instead of being skipped, when it cannot be imported.
pub const REQUIRE_PYTHON: &str = "SWEEPTRACE_REQUIRE_PYTHON";

/// Whether `python3` on `PATH` can import `mcap`: `Ok(Ok(()))` when it
/// can, `Ok(Err(completion))` for a test to skip with the reason, an error
/// when [`REQUIRE_PYTHON`] requires it.
pub fn python_with_mcap() -> anyhow::Result<Result<(), libtest_mimic::Completion>> {
    let missing = match std::process::Command::new("python3")
        .args(["-c", "import mcap"])
        .output()
    {
        Ok(o) if o.status.success() => return Ok(Ok(())),
        Ok(o) => format!(
            "python3 cannot import the `mcap` package ({})",
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("no message")
        ),
        Err(e) => format!("python3 cannot be run ({e})"),
    };
    if std::env::var_os(REQUIRE_PYTHON).is_some_and(|v| v == "1") {
        anyhow::bail!(
            "{missing}, and {REQUIRE_PYTHON}=1 requires this cross-check \
             (`pip install mcap==1.6.0` and put that Python first on PATH)"
        );
    }
    Ok(Err(libtest_mimic::Completion::ignored_with(format!(
        "skipped: {missing}; {REQUIRE_PYTHON}=1 makes this a failure"
    ))))
}

/// Whether `python3` on `PATH` can import every module of `modules`
/// (`pip install` hint: `install`), as [`python_with_mcap`] does for
/// `mcap`: `Ok(Err(completion))` to skip, an error when
/// [`REQUIRE_PYTHON`] requires them.
pub fn python_with_modules(
    modules: &[&str],
    install: &str,
) -> anyhow::Result<Result<(), libtest_mimic::Completion>> {
    let missing = match std::process::Command::new("python3")
        .args(["-c", &format!("import {}", modules.join(", "))])
        .output()
    {
        Ok(o) if o.status.success() => return Ok(Ok(())),
        Ok(o) => format!(
            "python3 cannot import {} ({})",
            modules.join(", "),
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("no message")
        ),
        Err(e) => format!("python3 cannot be run ({e})"),
    };
    if std::env::var_os(REQUIRE_PYTHON).is_some_and(|v| v == "1") {
        anyhow::bail!(
            "{missing}, and {REQUIRE_PYTHON}=1 requires this check \
             (`{install}` and put that Python first on PATH)"
        );
    }
    Ok(Err(libtest_mimic::Completion::ignored_with(format!(
        "skipped: {missing}; {REQUIRE_PYTHON}=1 makes this a failure"
    ))))
}

/// `|a - b| ≤ tol`, or an error naming `what`.
pub fn close(what: &str, got: f64, want: f64, tol: f64) -> anyhow::Result<()> {
    if (got - want).abs() <= tol {
        Ok(())
    } else {
        Err(anyhow::anyhow!(
            "{what}: got {got}, want {want} (tolerance {tol})"
        ))
    }
}

/// A mesh from vertices and triangles that must be valid.
pub fn mesh(vertices: &[[f64; 3]], triangles: &[[u64; 3]]) -> Mesh {
    Mesh::new(vertices.to_vec(), triangles).expect("test mesh is valid")
}

/// The triangle T of SEMANTICS.md's worked examples, `(0, 0, 0)`,
/// `(4, 0, 0)`, `(0, 4, 0)`, front `+z`, as a scene of margin `margin`
/// under the non-strict facing rule.
pub fn scene_t(margin: f64) -> sweeptrace::trace::SceneMsg {
    sweeptrace::trace::SceneMsg {
        name: Some("triangle_t".into()),
        vertices: vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        triangles: vec![[0, 1, 2]],
        margin,
        facing: sweeptrace::Facing::NonStrict,
    }
}

/// The triangle T of SEMANTICS.md's worked examples, as a mesh.
pub fn triangle_t() -> Mesh {
    let t = scene_t(0.0);
    mesh(&t.vertices, &t.triangles)
}

/// Runs an exhaustive explained sweep.
pub fn run(
    mesh: &Mesh,
    p0: [f64; 3],
    p1: [f64; 3],
    radius: f64,
    margin: f64,
    facing: Facing,
) -> (Outcome, Vec<TestRecord>) {
    let mut obs = CollectRecords::default();
    let o = sweep_mesh_with(
        mesh,
        &Sweep::new(p0, p1, radius),
        &Options {
            margin,
            facing,
            ..Options::default()
        },
        Broadphase::Exhaustive,
        &mut obs,
    )
    .expect("valid sweep");
    (o, obs.records)
}

/// The face record of triangle `t`.
pub fn face(records: &[TestRecord], t: u32) -> FaceRecord {
    records
        .iter()
        .find_map(|r| match r {
            TestRecord::Face(f) if f.triangle == t => Some(*f),
            _ => None,
        })
        .expect("face record present")
}

/// The record of edge `e` of triangle `t`.
pub fn edge(records: &[TestRecord], t: u32, e: u8) -> EdgeRecord {
    records
        .iter()
        .find_map(|r| match r {
            TestRecord::Edge(x) if x.triangle == t && x.edge == e => Some(*x),
            _ => None,
        })
        .expect("edge record present")
}

/// The record of vertex `v` of triangle `t`.
pub fn vertex(records: &[TestRecord], t: u32, v: u8) -> VertexRecord {
    records
        .iter()
        .find_map(|r| match r {
            TestRecord::Vertex(x) if x.triangle == t && x.vertex == v => Some(*x),
            _ => None,
        })
        .expect("vertex record present")
}

/// A `3 × 3` floor of unit squares at z = 0, two triangles each, fronts +z,
/// with triangle 9 wound the other way (flipped): 12 boundary edges and 21
/// flat ones (the turned triangle's edges are classified as if it were
/// turned back), one defect.
pub fn flipped_floor() -> sweeptrace::trace::SceneMsg {
    let mut vertices = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            vertices.push([f64::from(i), f64::from(j), 0.0]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..3u64 {
        for i in 0..3u64 {
            let a = j * 4 + i;
            triangles.push([a, a + 1, a + 5]);
            triangles.push([a, a + 5, a + 4]);
        }
    }
    triangles[9].swap(1, 2);
    sweeptrace::trace::SceneMsg {
        name: Some("flipped floor".into()),
        vertices,
        triangles,
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

/// A trace of `scene` and `sweeps`, each sweep logged at
/// `1_000_000 (frame + 1)` ns and followed by the core's outcome for it as
/// its `/expected` message.
pub fn core_trace(
    scene: &sweeptrace::trace::SceneMsg,
    sweeps: &[sweeptrace::trace::SweepMsg],
) -> anyhow::Result<Vec<u8>> {
    let m = mesh(&scene.vertices, &scene.triangles);
    let options = sweeptrace::Options {
        margin: scene.margin,
        facing: scene.facing,
        ..Options::default()
    };
    let mut w = sweeptrace::trace::TraceWriter::new(std::io::Cursor::new(Vec::new()))?;
    w.scene(0, scene)?;
    for s in sweeps {
        let t = 1_000_000 * (s.frame + 1);
        w.sweep(t, s)?;
        let o =
            sweeptrace::sweep_mesh(&m, &sweeptrace::Sweep::new(s.p0, s.p1, s.radius), &options)?;
        w.expected(
            t,
            &sweeptrace::trace::OutcomeMsg::from_outcome(s.frame, s.ball, &o),
        )?;
    }
    Ok(w.finish()?.into_inner())
}

/// A trace event: `body` logged at `log_time_nanos`, message `index` of its file.
pub fn event(
    log_time_nanos: u64,
    index: u64,
    body: sweeptrace::trace::EventBody,
) -> sweeptrace::trace::TraceEvent {
    sweeptrace::trace::TraceEvent {
        header: sweeptrace::trace::EventHeader {
            log_time_nanos,
            index,
        },
        body,
    }
}

/// Writes `event` through `w` at its `log_time` (its index is the writer's).
pub fn write_event<W: std::io::Write + std::io::Seek>(
    w: &mut sweeptrace::trace::TraceWriter<W>,
    event: &sweeptrace::trace::TraceEvent,
) -> Result<(), sweeptrace::trace::TraceError> {
    use sweeptrace::trace::EventBody;
    let log_time_nanos = event.header.log_time_nanos;
    match &event.body {
        EventBody::Scene(scene) => w.scene(log_time_nanos, scene),
        EventBody::Sweep(sweep) => w.sweep(log_time_nanos, sweep),
        EventBody::Expected(outcome) => w.expected(log_time_nanos, outcome),
        EventBody::Contact(contact) => w.contact(log_time_nanos, contact),
        EventBody::ExpectedContacts(contacts) => w.expected_contacts(log_time_nanos, contacts),
    }
}

/// The lines of the tests that came close in `sweep`'s text report (those
/// after its `tests that came close ...` line, indented).
pub fn close_tests(out: &str) -> Vec<&str> {
    out.lines()
        .skip_while(|l| !l.starts_with("tests that came close"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .collect()
}

/// The command of the Node example engine in `examples/engines/NAME`
/// (`node …/engine.js`) when node runs and its `package` is installed;
/// otherwise the reason to skip, or an error under
/// `SWEEPTRACE_REQUIRE_NODE=1` (CI installs them).
pub fn node_engine(
    name: &str,
    package: &str,
) -> anyhow::Result<Result<String, libtest_mimic::Completion>> {
    const REQUIRE_NODE: &str = "SWEEPTRACE_REQUIRE_NODE";
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(name);
    let installed = dir.join("node_modules").join(package).is_dir();
    let missing = match std::process::Command::new("node").arg("--version").output() {
        Ok(o) if o.status.success() && installed => None,
        Ok(o) if o.status.success() => Some(format!(
            "examples/engines/{name} has no node_modules (run `npm ci --prefix \
             examples/engines/{name}`)"
        )),
        _ => Some("node cannot be run".to_string()),
    };
    match missing {
        None => Ok(Ok(format!("node {}", dir.join("engine.js").display()))),
        Some(m) if std::env::var_os(REQUIRE_NODE).is_some_and(|v| v == "1") => {
            anyhow::bail!("{m}, and {REQUIRE_NODE}=1 requires it")
        }
        Some(m) => Ok(Err(libtest_mimic::Completion::ignored_with(format!(
            "skipped: {m}; {REQUIRE_NODE}=1 makes this a failure"
        )))),
    }
}

/// `python3 scripts/read_with_python.py TRACE ARGS...` (the independent
/// reader): `Ok(())` when it accepts the trace, the error with its output
/// when it does not.
pub fn read_with_python(trace: &std::path::Path, args: &[&str]) -> anyhow::Result<()> {
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/read_with_python.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(trace)
        .args(args)
        .output()?;
    anyhow::ensure!(
        out.status.success(),
        "scripts/read_with_python.py {args:?} refused it: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(())
}
