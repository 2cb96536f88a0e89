//! The C API of the sweeptrace trace writer, for engines written in C, C++,
//! C# or Python (`ctypes`): open a trace file, say which engine computed
//! the expected outcomes, add scenes, sweeps and expected outcomes, close.
//!
//! Every function returns a [`SweeptraceStatus`]; on an error,
//! [`sweeptrace_writer_last_error`] gives the message (naming the file, the
//! message's frame and the field). Nothing panics across the boundary:
//! every function runs under `catch_unwind`, and a panic inside the library
//! is returned as [`SweeptraceStatus::Panic`] (the writer is then unusable
//! and its file is never completed). Pointers are checked for null, numbers
//! for being finite, indices against the scene, with the same validation as
//! the trace reader, so a trace written through this API always reads.
//!
//! The trace is written to a temporary file next to the target and renamed
//! to the target by [`sweeptrace_writer_close`]: a writer that is freed
//! without being closed, or a process that dies while writing, leaves no
//! file under the target name.
//!
//! It also serves an engine written in C or C++ to `sweeptrace check
//! --engine` and `sweeptrace conform --engine`:
//! [`sweeptrace_serve_engine`] runs the engine protocol
//! (docs/ENGINE_PROTOCOL.md) on standard input and output and calls the
//! engine back with each scene and sweep ([`SweeptraceEngine`]), so the
//! engine's author writes no JSON; [`sweeptrace_serve_engine_contacts`]
//! answers contact queries too (`--engine-contacts`, `conform
//! --contacts`), with a third callback.
//!
//! `include/sweeptrace.h` is generated from this file by cbindgen.

#![warn(missing_docs)]

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

use sweeptrace::trace::PendingTrace;
use sweeptrace::trace::source::MAX_SETTINGS;
use sweeptrace::trace::validate::validate_triangle;
use sweeptrace::{Encoding, ExpectedSource, OutcomeMsg, SceneMsg, SweepMsg, TraceError};
use sweeptrace::{Facing, Kind};

/// What a call came to.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweeptraceStatus {
    /// Success.
    Ok = 0,
    /// A pointer argument that must not be null is null.
    NullPointer = 1,
    /// An argument is invalid: a NaN or infinite number, a negative margin,
    /// a radius not above the margin, an index out of range, an unknown
    /// enum value, a path or name that is not valid text, a message above
    /// the reader's size limit.
    InvalidArgument = 2,
    /// A call out of order: a sweep before any scene, a `log_time_nanos`
    /// smaller than the previous call's.
    WrongOrder = 3,
    /// The writer was already closed, or an earlier error (I/O, panic)
    /// left it unable to complete the trace.
    Closed = 4,
    /// The file could not be created, written or renamed.
    Io = 5,
    /// The library panicked (a bug); the writer is unusable.
    Panic = 6,
}

/// The kind of a collision, for [`SweeptraceOutcome::kind`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweeptraceKind {
    /// Nothing touched: the ball moves all the way (`alpha` 1).
    None = 0,
    /// The inside of a triangle.
    Face = 1,
    /// An edge of a triangle.
    Edge = 2,
    /// A vertex of a triangle.
    Vertex = 3,
}

/// The facing rule of a scene (docs/SEMANTICS.md): which direction of
/// travel lets a triangle report a collision.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweeptraceFacing {
    /// `n · d ≤ 0`: toward the front, or parallel to the plane (default).
    NonStrict = 0,
    /// `n · d < 0`: strictly toward the front.
    Strict = 1,
}

/// The message encoding of a trace, for [`sweeptrace_writer_open_with_encoding`]
/// (docs/TRACE_FORMAT.md): the same messages either way.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweeptraceEncoding {
    /// JSON text (the default of [`sweeptrace_writer_open`]).
    Json = 0,
    /// CBOR: binary, every number an 8-byte double.
    Cbor = 1,
}

/// [`SweeptraceOutcome::fields`]: `triangle` is given.
pub const SWEEPTRACE_FIELD_TRIANGLE: u32 = 1;
/// [`SweeptraceOutcome::fields`]: `feature` is given.
pub const SWEEPTRACE_FIELD_FEATURE: u32 = 2;
/// [`SweeptraceOutcome::fields`]: `normal` is given.
pub const SWEEPTRACE_FIELD_NORMAL: u32 = 4;
/// [`SweeptraceOutcome::fields`]: `contact` is given; for a
/// [`SweeptraceContact`], its `point`.
pub const SWEEPTRACE_FIELD_CONTACT: u32 = 8;
/// [`SweeptraceContact::fields`]: `separation` is given.
pub const SWEEPTRACE_FIELD_SEPARATION: u32 = 16;
const ALL_FIELDS: u32 = SWEEPTRACE_FIELD_TRIANGLE
    | SWEEPTRACE_FIELD_FEATURE
    | SWEEPTRACE_FIELD_NORMAL
    | SWEEPTRACE_FIELD_CONTACT;

/// What an engine decided for one sweep: an `/expected` message.
///
/// `frame`, `ball`, `kind` and `alpha` are always written. The other fields
/// are written only when their bit is set in `fields` (a field left out is
/// not compared by `sweeptrace check`). A given field is written as its
/// value when the kind has one (`triangle`, `normal`, `contact` for a face,
/// edge or vertex; `feature` for an edge or vertex: the edge from vertex
/// `feature` to the next, or vertex `feature` of the triangle) and as
/// `null` otherwise.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SweeptraceOutcome {
    /// The sweep's frame.
    pub frame: u64,
    /// The sweep's ball.
    pub ball: u32,
    /// A [`SweeptraceKind`] value.
    pub kind: u32,
    /// Fraction of the sweep travelled before the contact, in `[0, 1]`.
    pub alpha: f64,
    /// Which of the fields below are given: `SWEEPTRACE_FIELD_*` or-ed.
    pub fields: u32,
    /// Index of the triangle hit, in the current scene.
    pub triangle: u32,
    /// Edge or vertex of the triangle hit: 0, 1 or 2.
    pub feature: u32,
    /// Unit normal at the contact, pointing toward the ball.
    pub normal: [f64; 3],
    /// Contact point on the mesh.
    pub contact: [f64; 3],
}

enum State {
    Open(Box<PendingTrace>),
    Closed,
    /// An I/O error or a panic: the trace cannot be completed.
    Broken,
}

/// A trace being written. Opaque: made by [`sweeptrace_writer_open`],
/// released by [`sweeptrace_writer_free`]. Use each writer from one thread
/// at a time; different writers may be used on different threads.
pub struct SweeptraceWriter {
    state: State,
    /// Triangles of the current scene, for checking expected triangles.
    scene_triangles: Option<usize>,
    last_error: CString,
}

thread_local! {
    static THREAD_LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// A failed call: its status and message.
struct Failure {
    status: SweeptraceStatus,
    message: String,
}

impl Failure {
    fn new(status: SweeptraceStatus, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }

    fn null(argument: &str) -> Failure {
        Failure::new(
            SweeptraceStatus::NullPointer,
            format!("`{argument}` is a null pointer"),
        )
    }

    fn invalid(message: impl Into<String>) -> Failure {
        Failure::new(SweeptraceStatus::InvalidArgument, message)
    }
}

impl From<TraceError> for Failure {
    fn from(error: TraceError) -> Failure {
        let status = match &error {
            TraceError::Invalid { .. }
            | TraceError::Json { .. }
            | TraceError::MessageTooLarge { .. }
            | TraceError::ExpectedSource { .. } => SweeptraceStatus::InvalidArgument,
            TraceError::SweepBeforeScene { .. } | TraceError::OutOfOrder { .. } => {
                SweeptraceStatus::WrongOrder
            }
            _ => SweeptraceStatus::Io,
        };
        Failure::new(status, error.to_string())
    }
}

/// A C string of `message` (an interior NUL, impossible in our messages,
/// would end it there).
fn c_message(message: &str) -> CString {
    let bytes: Vec<u8> = message.bytes().take_while(|&b| b != 0).collect();
    CString::new(bytes).unwrap_or_default()
}

fn set_thread_error(message: &str) {
    THREAD_LAST_ERROR.with(|slot| *slot.borrow_mut() = c_message(message));
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let detail = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".to_string());
    format!("internal error (a bug of sweeptrace, please report it): {detail}")
}

/// Runs `f` on the writer behind `writer`: catches panics, records the
/// error message on the writer and the thread.
///
/// # Safety
/// `writer` is null or a pointer from [`sweeptrace_writer_open`] not yet freed.
unsafe fn with_writer(
    writer: *mut SweeptraceWriter,
    f: impl FnOnce(&mut SweeptraceWriter) -> Result<(), Failure>,
) -> SweeptraceStatus {
    if writer.is_null() {
        let failure = Failure::null("writer");
        set_thread_error(&failure.message);
        return failure.status;
    }
    // SAFETY: non-null, and by the contract a live writer of ours.
    let writer = unsafe { &mut *writer };
    let result = catch_unwind(AssertUnwindSafe(|| f(writer)));
    let failure = match result {
        Ok(Ok(())) => {
            writer.last_error = CString::default();
            return SweeptraceStatus::Ok;
        }
        Ok(Err(failure)) => failure,
        Err(payload) => {
            writer.state = State::Broken;
            Failure::new(SweeptraceStatus::Panic, panic_message(payload.as_ref()))
        }
    };
    writer.last_error = c_message(&failure.message);
    set_thread_error(&failure.message);
    failure.status
}

impl SweeptraceWriter {
    /// The open trace, or why there is none.
    fn open_trace(&mut self) -> Result<&mut PendingTrace, Failure> {
        match &mut self.state {
            State::Open(trace) => Ok(trace),
            State::Closed => Err(Failure::new(
                SweeptraceStatus::Closed,
                "the writer is closed; open a new one to write another trace",
            )),
            State::Broken => Err(Failure::new(
                SweeptraceStatus::Closed,
                "an earlier error (I/O or internal) left the trace unfinishable; \
                 nothing was written under the target name",
            )),
        }
    }

    /// Runs a write; an I/O error breaks the writer (the container may be
    /// half-written), other errors leave it usable (nothing was written).
    fn write(
        &mut self,
        f: impl FnOnce(&mut PendingTrace) -> Result<(), TraceError>,
    ) -> Result<(), Failure> {
        let trace = self.open_trace()?;
        f(trace).map_err(|error| {
            let failure = Failure::from(error);
            if failure.status == SweeptraceStatus::Io {
                self.state = State::Broken;
            }
            failure
        })
    }
}

/// `count` triples of `T` at `pointer`, checked for null and size.
///
/// # Safety
/// A non-null `pointer` points to `3 * count` readable values.
unsafe fn triples<'a, T>(
    pointer: *const T,
    count: usize,
    argument: &str,
) -> Result<&'a [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if pointer.is_null() {
        return Err(Failure::null(argument));
    }
    let len = count
        .checked_mul(3)
        .filter(|&len| len <= isize::MAX as usize / std::mem::size_of::<T>().max(1))
        .ok_or_else(|| Failure::invalid(format!("`{argument}`: count {count} is too large")))?;
    // SAFETY: non-null, and by the contract `len` readable values.
    Ok(unsafe { std::slice::from_raw_parts(pointer, len) })
}

/// Three numbers at `pointer`.
///
/// # Safety
/// A non-null `pointer` points to 3 readable doubles.
unsafe fn point(pointer: *const f64, argument: &str) -> Result<[f64; 3], Failure> {
    if pointer.is_null() {
        return Err(Failure::null(argument));
    }
    // SAFETY: non-null, and by the contract 3 readable doubles.
    let values = unsafe { std::slice::from_raw_parts(pointer, 3) };
    Ok([values[0], values[1], values[2]])
}

fn kind_from(value: u32) -> Result<Kind, Failure> {
    Ok(match value {
        0 => Kind::None,
        1 => Kind::Face,
        2 => Kind::Edge,
        3 => Kind::Vertex,
        _ => {
            return Err(Failure::invalid(format!(
                "`kind` must be a SweeptraceKind (0 none, 1 face, 2 edge, 3 vertex), got {value}"
            )));
        }
    })
}

fn encoding_from(value: u32) -> Result<Encoding, Failure> {
    match value {
        0 => Ok(Encoding::Json),
        1 => Ok(Encoding::Cbor),
        _ => Err(Failure::invalid(format!(
            "`encoding` must be a SweeptraceEncoding (0 json, 1 cbor), got {value}"
        ))),
    }
}

fn facing_from(value: u32) -> Result<Facing, Failure> {
    match value {
        0 => Ok(Facing::NonStrict),
        1 => Ok(Facing::Strict),
        _ => Err(Failure::invalid(format!(
            "`facing` must be a SweeptraceFacing (0 non_strict, 1 strict), got {value}"
        ))),
    }
}

#[cfg(unix)]
fn path_from(bytes: &CStr) -> Result<PathBuf, Failure> {
    use std::os::unix::ffi::OsStrExt;
    Ok(PathBuf::from(std::ffi::OsStr::from_bytes(bytes.to_bytes())))
}

#[cfg(not(unix))]
fn path_from(bytes: &CStr) -> Result<PathBuf, Failure> {
    bytes
        .to_str()
        .map(PathBuf::from)
        .map_err(|e| Failure::invalid(format!("`path` is not valid UTF-8: {e}")))
}

/// Opens a trace to be written to `path` (UTF-8 or, on Unix, any bytes).
///
/// The file is written under a temporary name in the same directory
/// (`.NAME.partial-XXXXXX`) and renamed to `path` by
/// [`sweeptrace_writer_close`]. On success `*out_writer` is the new writer;
/// on failure it is set to null and [`sweeptrace_last_error`] says why.
///
/// # Safety
/// `path` is null or a NUL-terminated string; `out_writer` is null or
/// points to writable storage for a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_open(
    path: *const c_char,
    out_writer: *mut *mut SweeptraceWriter,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe { open(path, SweeptraceEncoding::Json as u32, out_writer) }
}

/// [`sweeptrace_writer_open`], writing the trace's messages in `encoding`,
/// a [`SweeptraceEncoding`] (JSON or CBOR). An unknown value returns
/// [`SweeptraceStatus::InvalidArgument`] and creates no file.
///
/// # Safety
/// As [`sweeptrace_writer_open`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_open_with_encoding(
    path: *const c_char,
    encoding: u32,
    out_writer: *mut *mut SweeptraceWriter,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe { open(path, encoding, out_writer) }
}

/// The two `open` functions.
///
/// # Safety
/// As [`sweeptrace_writer_open`].
unsafe fn open(
    path: *const c_char,
    encoding: u32,
    out_writer: *mut *mut SweeptraceWriter,
) -> SweeptraceStatus {
    let result = catch_unwind(|| -> Result<*mut SweeptraceWriter, Failure> {
        if out_writer.is_null() {
            return Err(Failure::null("out_writer"));
        }
        // SAFETY: non-null, writable by the contract.
        unsafe { *out_writer = std::ptr::null_mut() };
        if path.is_null() {
            return Err(Failure::null("path"));
        }
        let encoding = encoding_from(encoding)?;
        // SAFETY: non-null, NUL-terminated by the contract.
        let path = path_from(unsafe { CStr::from_ptr(path) })?;
        if path.as_os_str().is_empty() {
            return Err(Failure::invalid("`path` is empty"));
        }
        let trace = PendingTrace::create_with_encoding(&path, encoding).map_err(Failure::from)?;
        Ok(Box::into_raw(Box::new(SweeptraceWriter {
            state: State::Open(Box::new(trace)),
            scene_triangles: None,
            last_error: CString::default(),
        })))
    });
    let failure = match result {
        Ok(Ok(writer)) => {
            // SAFETY: checked non-null above (an Ok implies it).
            unsafe { *out_writer = writer };
            return SweeptraceStatus::Ok;
        }
        Ok(Err(failure)) => failure,
        Err(payload) => Failure::new(SweeptraceStatus::Panic, panic_message(payload.as_ref())),
    };
    set_thread_error(&failure.message);
    failure.status
}

/// A C string argument as UTF-8 text.
///
/// # Safety
/// A non-null `pointer` is NUL-terminated.
unsafe fn text<'a>(pointer: *const c_char, argument: &str) -> Result<&'a str, Failure> {
    if pointer.is_null() {
        return Err(Failure::null(argument));
    }
    // SAFETY: non-null, NUL-terminated by the contract.
    unsafe { CStr::from_ptr(pointer) }
        .to_str()
        .map_err(|e| Failure::invalid(format!("`{argument}` is not valid UTF-8: {e}")))
}

/// Says who computed the trace's expected outcomes: the engine's name
/// (`engine`, not empty), its version (`version`; null or empty when not
/// known) and `setting_count` settings that bear on its answers, the
/// `i`-th named `setting_names[i]` with the value `setting_values[i]`
/// (`"fix_internal_edges"`, `"false"`). Written into the trace as its
/// `sweeptrace.expected_source` metadata record (docs/TRACE_FORMAT.md);
/// `sweeptrace info` and `sweeptrace check` show it.
///
/// Call it at most once per trace, best right after
/// [`sweeptrace_writer_open`]. Every string is UTF-8 without control
/// characters; the engine's name and version are at most 128 bytes, a
/// setting's name 128 and its value 1024, at most 64 settings, names not
/// empty (a repeated name keeps its last value). An invalid argument, or a
/// second call, returns [`SweeptraceStatus::InvalidArgument`] and writes
/// nothing.
///
/// # Safety
/// `writer` is a live writer or null; `engine` and `version` are null or
/// NUL-terminated; `setting_names` and `setting_values` are null (only
/// with a count of 0) or point to `setting_count` pointers, each null or
/// NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_set_expected_source(
    writer: *mut SweeptraceWriter,
    engine: *const c_char,
    version: *const c_char,
    setting_names: *const *const c_char,
    setting_values: *const *const c_char,
    setting_count: usize,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe {
        with_writer(writer, |w| {
            let engine = text(engine, "engine")?;
            let version = if version.is_null() {
                ""
            } else {
                text(version, "version")?
            };
            if setting_count > MAX_SETTINGS {
                return Err(Failure::invalid(format!(
                    "`setting_count` is {setting_count}, above the limit of {MAX_SETTINGS}"
                )));
            }
            let mut source = ExpectedSource::new(engine, version);
            if setting_count > 0 {
                if setting_names.is_null() {
                    return Err(Failure::null("setting_names"));
                }
                if setting_values.is_null() {
                    return Err(Failure::null("setting_values"));
                }
                // SAFETY: non-null, `setting_count` pointers by the contract.
                let names = std::slice::from_raw_parts(setting_names, setting_count);
                // SAFETY: as above.
                let values = std::slice::from_raw_parts(setting_values, setting_count);
                for (i, (&name, &value)) in names.iter().zip(values).enumerate() {
                    let name = text(name, &format!("setting_names[{i}]"))?;
                    let value = text(value, &format!("setting_values[{i}]"))?;
                    source = source.setting(name, value);
                }
            }
            w.write(|trace| trace.writer().expected_source(&source))
        })
    }
}

/// Adds a scene: the triangle mesh the sweeps after it are tested against.
///
/// `vertices` holds `vertex_count` points as `x, y, z` triples;
/// `triangles` holds `triangle_count` triples of vertex indices,
/// counter-clockwise seen from the front. `name` may be null. `margin` is
/// the engine's margin `ε` (`≥ 0`), `facing` a [`SweeptraceFacing`].
///
/// # Safety
/// `writer` is a live writer or null; `name` is null or NUL-terminated;
/// `vertices` and `triangles` are null (only with a count of 0) or point
/// to `3 * count` values.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn sweeptrace_writer_add_scene(
    writer: *mut SweeptraceWriter,
    log_time_nanos: u64,
    name: *const c_char,
    vertices: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    margin: f64,
    facing: u32,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe {
        with_writer(writer, |w| {
            let name = if name.is_null() {
                None
            } else {
                Some(
                    CStr::from_ptr(name)
                        .to_str()
                        .map_err(|e| Failure::invalid(format!("`name` is not valid UTF-8: {e}")))?
                        .to_string(),
                )
            };
            let coordinates = triples(vertices, vertex_count, "vertices")?;
            let indices = triples(triangles, triangle_count, "triangles")?;
            let facing = facing_from(facing)?;
            let scene = SceneMsg {
                name,
                vertices: coordinates
                    .chunks_exact(3)
                    .map(|v| [v[0], v[1], v[2]])
                    .collect(),
                triangles: indices
                    .chunks_exact(3)
                    .map(|t| [u64::from(t[0]), u64::from(t[1]), u64::from(t[2])])
                    .collect(),
                margin,
                facing,
            };
            w.write(|trace| trace.writer().scene(log_time_nanos, &scene))?;
            w.scene_triangles = Some(triangle_count);
            Ok(())
        })
    }
}

/// Adds a sweep: ball `ball` of radius `radius` moving from `p0` to `p1`
/// (3 doubles each) at frame `frame`. A scene must have been added before.
///
/// # Safety
/// `writer` is a live writer or null; `p0` and `p1` are null or point to 3
/// doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_add_sweep(
    writer: *mut SweeptraceWriter,
    log_time_nanos: u64,
    frame: u64,
    ball: u32,
    radius: f64,
    p0: *const f64,
    p1: *const f64,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe {
        with_writer(writer, |w| {
            let sweep = SweepMsg {
                frame,
                ball,
                radius,
                p0: point(p0, "p0")?,
                p1: point(p1, "p1")?,
            };
            w.write(|trace| trace.writer().sweep(log_time_nanos, &sweep))
        })
    }
}

/// Adds what the engine decided for a sweep (an `/expected` message), for
/// `sweeptrace check` to compare with. See [`SweeptraceOutcome`] for which
/// fields are written.
///
/// # Safety
/// `writer` is a live writer or null; `outcome` is null or points to a
/// [`SweeptraceOutcome`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_add_expected(
    writer: *mut SweeptraceWriter,
    log_time_nanos: u64,
    outcome: *const SweeptraceOutcome,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe {
        with_writer(writer, |w| {
            if outcome.is_null() {
                return Err(Failure::null("outcome"));
            }
            let message = outcome_message(&*outcome, w.scene_triangles)?;
            w.write(|trace| trace.writer().expected(log_time_nanos, &message))
        })
    }
}

/// The `/expected` message of `outcome`, its triangle checked against the
/// current scene's `scene_triangles`.
fn outcome_message(
    outcome: &SweeptraceOutcome,
    scene_triangles: Option<usize>,
) -> Result<OutcomeMsg, Failure> {
    let kind = kind_from(outcome.kind)?;
    let at = format!("outcome of frame {}, ball {}", outcome.frame, outcome.ball);
    if outcome.fields & !ALL_FIELDS != 0 {
        return Err(Failure::invalid(format!(
            "{at}: `fields` has unknown bits {:#x} (SWEEPTRACE_FIELD_* or-ed)",
            outcome.fields & !ALL_FIELDS
        )));
    }
    let given = |bit: u32| outcome.fields & bit != 0;
    let hit = kind != Kind::None;
    let on_feature = matches!(kind, Kind::Edge | Kind::Vertex);
    fn field<T>(given: bool, meaningful: bool, value: T) -> Option<Option<T>> {
        given.then_some(meaningful.then_some(value))
    }
    let message = OutcomeMsg {
        frame: outcome.frame,
        ball: outcome.ball,
        alpha: outcome.alpha,
        kind,
        triangle: field(given(SWEEPTRACE_FIELD_TRIANGLE), hit, outcome.triangle),
        // Above 255 it stays above 2, which is refused below.
        feature: field(
            given(SWEEPTRACE_FIELD_FEATURE),
            on_feature,
            u8::try_from(outcome.feature).unwrap_or(u8::MAX),
        ),
        normal: field(given(SWEEPTRACE_FIELD_NORMAL), hit, outcome.normal),
        contact: field(given(SWEEPTRACE_FIELD_CONTACT), hit, outcome.contact),
    };
    if let Some(Some(_)) = message.triangle {
        let Some(count) = scene_triangles else {
            return Err(Failure::new(
                SweeptraceStatus::WrongOrder,
                format!("{at}: `triangle` is given but no scene was added yet"),
            ));
        };
        // The Rust writer's rule (`TraceWriter::expected`).
        validate_triangle(&message, count)
            .map_err(|p| Failure::invalid(format!("{at}: field `{}`: {}", p.field, p.problem)))?;
    }
    if on_feature && given(SWEEPTRACE_FIELD_FEATURE) && outcome.feature > 2 {
        return Err(Failure::invalid(format!(
            "{at}: field `feature`: must be 0, 1 or 2, got {}",
            outcome.feature
        )));
    }
    Ok(message)
}

/// Finishes the trace and renames it to its target path. After it (success
/// or not) the writer accepts no more messages; it must still be released
/// with [`sweeptrace_writer_free`]. Closing twice returns
/// [`SweeptraceStatus::Closed`].
///
/// # Safety
/// `writer` is a live writer or null.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_close(
    writer: *mut SweeptraceWriter,
) -> SweeptraceStatus {
    // SAFETY: the contract is the caller's.
    unsafe {
        with_writer(writer, |w| {
            w.open_trace()?;
            match std::mem::replace(&mut w.state, State::Closed) {
                State::Open(trace) => trace.commit().map_err(Failure::from),
                _ => Ok(()),
            }
        })
    }
}

/// Releases a writer. A writer that was not closed is abandoned: its
/// temporary file is removed and nothing is written under the target name.
/// Null is accepted and does nothing.
///
/// # Safety
/// `writer` is null or a live writer, which must not be used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_free(writer: *mut SweeptraceWriter) {
    if writer.is_null() {
        return;
    }
    // SAFETY: by the contract a live writer of ours, released once.
    let writer = unsafe { Box::from_raw(writer) };
    // Dropping removes the temporary file; a panic there is not let out.
    let _ = catch_unwind(AssertUnwindSafe(move || drop(writer)));
}

/// The message of the writer's last failed call (naming the file, frame
/// and field), or an empty string when its last call succeeded. Valid until
/// the next call with this writer. With a null writer: the calling thread's
/// last error, as [`sweeptrace_last_error`].
///
/// # Safety
/// `writer` is null or a live writer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_writer_last_error(
    writer: *const SweeptraceWriter,
) -> *const c_char {
    if writer.is_null() {
        return sweeptrace_last_error();
    }
    // SAFETY: by the contract a live writer of ours.
    unsafe { (*writer).last_error.as_ptr() }
}

/// The message of the calling thread's last failed call (any writer, and
/// calls that have no writer: a failed [`sweeptrace_writer_open`], a null
/// writer), or an empty string. Valid until the thread's next failing call.
#[unsafe(no_mangle)]
pub extern "C" fn sweeptrace_last_error() -> *const c_char {
    THREAD_LAST_ERROR
        .try_with(|slot| slot.borrow().as_ptr())
        .unwrap_or(c"".as_ptr())
}

/// The name of a status (`"ok"`, `"null_pointer"`, ...), for messages.
/// Unknown values give `"unknown"`.
#[unsafe(no_mangle)]
pub extern "C" fn sweeptrace_status_name(status: u32) -> *const c_char {
    let name: &'static CStr = match status {
        0 => c"ok",
        1 => c"null_pointer",
        2 => c"invalid_argument",
        3 => c"wrong_order",
        4 => c"closed",
        5 => c"io",
        6 => c"panic",
        _ => c"unknown",
    };
    name.as_ptr()
}

// ---------------------------------------------------------------------------
// Serving an engine: the engine protocol (docs/ENGINE_PROTOCOL.md) on the
// process's standard input and output, with the engine as two callbacks.

/// A scene, as [`sweeptrace_serve_engine`] gives it to
/// [`SweeptraceEngine::on_scene`]. Every pointer in it stays valid until the
/// next scene arrives (the next `on_scene` call) or the loop returns; copy
/// what you need to keep longer.
#[repr(C)]
#[derive(Debug)]
pub struct SweeptraceScene {
    /// The scene's name (UTF-8, NUL-terminated), or null when it has none.
    /// A name holding a NUL character is cut there.
    pub name: *const c_char,
    /// `vertex_count` points as `x, y, z` triples (`3 * vertex_count`
    /// doubles, all finite); null when `vertex_count` is 0.
    pub vertices: *const f64,
    /// How many vertices `vertices` holds.
    pub vertex_count: usize,
    /// `triangle_count` triples of vertex indices (each below
    /// `vertex_count`), counter-clockwise seen from the front; null when
    /// `triangle_count` is 0. Degenerate triangles are passed as they are.
    pub triangles: *const u32,
    /// How many triangles `triangles` holds. A scene with none is passed
    /// like any other: every sweep against it misses.
    pub triangle_count: usize,
    /// The margin `ε` (`≥ 0`, finite): detect at `ρ = radius - margin`.
    pub margin: f64,
    /// The facing rule.
    pub facing: SweeptraceFacing,
}

/// A sweep, as [`sweeptrace_serve_engine`] gives it to
/// [`SweeptraceEngine::on_sweep`]: ball `ball` of radius `radius` moving
/// from `p0` to `p1`, against the last scene. The numbers are finite and
/// `radius` is above the scene's margin.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SweeptraceSweep {
    /// The sweep's frame.
    pub frame: u64,
    /// The sweep's ball.
    pub ball: u32,
    /// The ball's radius.
    pub radius: f64,
    /// Start of the ball's center.
    pub p0: [f64; 3],
    /// End of the ball's center.
    pub p1: [f64; 3],
}

/// An engine's answer to one sweep, filled in by
/// [`SweeptraceEngine::on_sweep`]; the loop writes it as the sweep's
/// outcome line (with the sweep's frame and ball).
///
/// Before each call it holds "no collision" (`kind` none, `alpha` 1,
/// `fields` 0), so a callback that sets nothing answers a miss. `fields`
/// says which of `triangle`, `feature`, `normal` and `contact` the engine
/// gives (`SWEEPTRACE_FIELD_*` or-ed); a field left out is not compared. A
/// given field is written as its value when the kind has one (`triangle`,
/// `normal`, `contact` for a face, edge or vertex; `feature` for an edge
/// or vertex) and as `null` otherwise, exactly as [`SweeptraceOutcome`].
///
/// An invalid answer (a NaN or `alpha` outside `[0, 1]`, a `kind` that is
/// not a [`SweeptraceKind`], unknown bits in `fields`, a given `feature`
/// above 2 on an edge or vertex, a given `triangle` out of the scene's
/// range, a given `normal` or `contact` that is not finite) is not written:
/// the loop prints why on stderr and returns 1.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SweeptraceAnswer {
    /// A [`SweeptraceKind`] value.
    pub kind: u32,
    /// Fraction of the sweep travelled before the contact, in `[0, 1]`.
    pub alpha: f64,
    /// Which of the fields below are given: `SWEEPTRACE_FIELD_*` or-ed.
    pub fields: u32,
    /// Index of the triangle hit, in the current scene.
    pub triangle: u32,
    /// Edge or vertex of the triangle hit: 0, 1 or 2 (the edge from vertex
    /// `feature` to the next, or vertex `feature`).
    pub feature: u32,
    /// Unit normal at the contact, pointing toward the ball.
    pub normal: [f64; 3],
    /// Contact point on the mesh.
    pub contact: [f64; 3],
}

impl SweeptraceAnswer {
    const MISS: SweeptraceAnswer = SweeptraceAnswer {
        kind: SweeptraceKind::None as u32,
        alpha: 1.0,
        fields: 0,
        triangle: 0,
        feature: 0,
        normal: [0.0; 3],
        contact: [0.0; 3],
    };
}

/// Called with each scene: return 0, or nonzero to stop the loop (it then
/// returns 1 after printing an error naming the scene).
pub type SweeptraceSceneFn =
    Option<unsafe extern "C" fn(user: *mut c_void, scene: *const SweeptraceScene) -> c_int>;

/// Called with each sweep: fill in `*out` and return 0, or return nonzero
/// to stop the loop (it then returns 1 after printing an error naming the
/// sweep; nothing is written for it).
pub type SweeptraceSweepFn = Option<
    unsafe extern "C" fn(
        user: *mut c_void,
        sweep: *const SweeptraceSweep,
        out: *mut SweeptraceAnswer,
    ) -> c_int,
>;

/// An engine for [`sweeptrace_serve_engine`]: its two callbacks, both
/// required. The callbacks must not write to standard output (it carries
/// the answers; log to stderr) and must not unwind (a C++ exception must
/// not leave them).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SweeptraceEngine {
    /// Receives each scene.
    pub on_scene: SweeptraceSceneFn,
    /// Answers each sweep.
    pub on_sweep: SweeptraceSweepFn,
}

/// A contact query, as [`sweeptrace_serve_engine_contacts`] gives it to
/// its `on_contact` callback: what does a ball of `radius` centred at
/// `centre` touch in the last scene, counting a triangle up to `distance`
/// beyond touching (the engine's speculative contact distance; 0: only
/// what touches). The numbers are finite, `radius > 0`, `distance ≥ 0`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SweeptraceContactQuery {
    /// The query's frame.
    pub frame: u64,
    /// The query's ball.
    pub ball: u32,
    /// The ball's radius.
    pub radius: f64,
    /// The ball's centre.
    pub centre: [f64; 3],
    /// The contact distance.
    pub distance: f64,
}

/// One contact of an engine's answer to a contact query, added with
/// [`sweeptrace_contacts_add`]. `triangle` is always given (an index in
/// the current scene); `fields` says which of the others are
/// (`SWEEPTRACE_FIELD_FEATURE`: `kind` and, on an edge or vertex,
/// `feature`; `SWEEPTRACE_FIELD_CONTACT`: `point`;
/// `SWEEPTRACE_FIELD_NORMAL`: `normal`; `SWEEPTRACE_FIELD_SEPARATION`:
/// `separation`); a field left out is not compared.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SweeptraceContact {
    /// The triangle touched, in the current scene.
    pub triangle: u32,
    /// Which of the fields below are given: `SWEEPTRACE_FIELD_*` or-ed.
    pub fields: u32,
    /// A [`SweeptraceKind`]: face, edge or vertex.
    pub kind: u32,
    /// Edge or vertex of the triangle: 0, 1 or 2.
    pub feature: u32,
    /// The point of the triangle touched.
    pub point: [f64; 3],
    /// The normal, pointing toward the ball's centre.
    pub normal: [f64; 3],
    /// The signed separation: the distance from the point to the centre,
    /// less the radius (negative: penetration).
    pub separation: f64,
}

/// The contacts of one answer, filled in by `on_contact` with
/// [`sweeptrace_contacts_add`]. Opaque; valid during the call only.
pub struct SweeptraceContacts {
    contacts: Vec<SweeptraceContact>,
}

/// Adds `*contact` to the answer `contacts` (copied). Returns 0, or 1 when
/// a pointer is null (nothing is added). The contacts are checked when the
/// callback returns.
///
/// # Safety
/// `contacts` is the pointer `on_contact` was given, during that call;
/// `contact` is null or points to a [`SweeptraceContact`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_contacts_add(
    contacts: *mut SweeptraceContacts,
    contact: *const SweeptraceContact,
) -> c_int {
    if contacts.is_null() || contact.is_null() {
        return 1;
    }
    // SAFETY: both non-null and valid by the contract.
    unsafe { (*contacts).contacts.push(*contact) };
    0
}

/// Called with each contact query: add the contacts the engine reports
/// with [`sweeptrace_contacts_add`] (none: it touches nothing) and return
/// 0, or return nonzero to stop the loop (it then returns 1 after printing
/// an error naming the query; nothing is written for it).
pub type SweeptraceContactFn = Option<
    unsafe extern "C" fn(
        user: *mut c_void,
        query: *const SweeptraceContactQuery,
        contacts: *mut SweeptraceContacts,
    ) -> c_int,
>;

/// The contacts `list` as the protocol's answer to `query`, checked
/// against a scene of `triangles` triangles.
fn contacts_message(
    query: &SweeptraceContactQuery,
    list: &[SweeptraceContact],
    triangles: usize,
) -> Result<sweeptrace::trace::ContactsMsg, String> {
    use sweeptrace::trace::ContactPointMsg;
    let mut contacts = Vec::with_capacity(list.len());
    for (i, c) in list.iter().enumerate() {
        let at = format!("contact {i}");
        if c.fields
            & !(SWEEPTRACE_FIELD_FEATURE
                | SWEEPTRACE_FIELD_CONTACT
                | SWEEPTRACE_FIELD_NORMAL
                | SWEEPTRACE_FIELD_SEPARATION)
            != 0
        {
            return Err(format!(
                "{at}: `fields` has unknown bits {:#x} (SWEEPTRACE_FIELD_FEATURE, _CONTACT, _NORMAL, _SEPARATION or-ed)",
                c.fields
            ));
        }
        if c.triangle as usize >= triangles {
            return Err(format!(
                "{at}: `triangle` {} is not in the scene ({})",
                c.triangle,
                sweeptrace::numbers::counted(triangles as u64, "triangle", "triangles")
            ));
        }
        let given = |bit: u32| c.fields & bit != 0;
        let (kind, feature) = if given(SWEEPTRACE_FIELD_FEATURE) {
            let kind = match c.kind {
                k if k == SweeptraceKind::Face as u32 => Kind::Face,
                k if k == SweeptraceKind::Edge as u32 => Kind::Edge,
                k if k == SweeptraceKind::Vertex as u32 => Kind::Vertex,
                k => {
                    return Err(format!(
                        "{at}: `kind` {k} is not face, edge or vertex (SweeptraceKind)"
                    ));
                }
            };
            let feature =
                (kind != Kind::Face).then_some(u8::try_from(c.feature).unwrap_or(u8::MAX));
            (Some(kind), feature)
        } else {
            (None, None)
        };
        contacts.push(ContactPointMsg {
            triangle: c.triangle,
            kind,
            feature,
            point: given(SWEEPTRACE_FIELD_CONTACT).then_some(c.point),
            normal: given(SWEEPTRACE_FIELD_NORMAL).then_some(c.normal),
            separation: given(SWEEPTRACE_FIELD_SEPARATION).then_some(c.separation),
        });
    }
    let message = sweeptrace::trace::ContactsMsg {
        frame: query.frame,
        ball: query.ball,
        contacts,
    };
    sweeptrace::trace::validate::validate_contacts(&message)
        .map_err(|p| format!("field `{}`: {}", p.field, p.problem))?;
    Ok(message)
}

/// Why the loop stopped early.
struct Stop(String);

/// The current scene's storage, kept alive for the engine's pointers.
struct SceneData {
    name: Option<CString>,
    vertices: Vec<f64>,
    triangles: Vec<u32>,
    margin: f64,
}

/// The loop of [`sweeptrace_serve_engine`] over `input` and `output`.
///
/// # Safety
/// The callbacks are callable with `user` as the contract says.
unsafe fn serve(
    on_scene: unsafe extern "C" fn(*mut c_void, *const SweeptraceScene) -> c_int,
    on_sweep: unsafe extern "C" fn(
        *mut c_void,
        *const SweeptraceSweep,
        *mut SweeptraceAnswer,
    ) -> c_int,
    on_contact: SweeptraceContactFn,
    user: *mut c_void,
    input: &mut impl std::io::BufRead,
    output: &mut impl std::io::Write,
) -> Result<(), Stop> {
    use sweeptrace::engine::protocol::{Request, answer_line, contacts_line, parse_request};
    use sweeptrace::trace::validate::{
        validate_contact, validate_outcome, validate_scene, validate_sweep,
    };

    let mut scene: Option<SceneData> = None;
    let mut line = Vec::new();
    let mut number = 0u64;
    loop {
        line.clear();
        let read = input
            .read_until(b'\n', &mut line)
            .map_err(|e| Stop(format!("cannot read standard input: {e}")))?;
        if read == 0 {
            return Ok(());
        }
        number += 1;
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let at = format!("input line {number}");
        let request = parse_request(&line)
            .map_err(|e| Stop(format!("{at} is not a protocol message: {e}")))?;
        match request {
            Request::Other(_) => {}
            // Without a contact callback, say so rather than leave
            // sweeptrace waiting for an answer.
            Request::Contact(contact) => {
                let which = format!("frame {}, ball {}", contact.frame, contact.ball);
                let Some(on_contact) = on_contact else {
                    return Err(Stop(format!(
                        "{at}: a contact query ({which}), but sweeptrace_serve_engine answers sweeps only: serve with sweeptrace_serve_engine_contacts, or check without --engine-contacts"
                    )));
                };
                let Some(current) = &scene else {
                    return Err(Stop(format!(
                        "{at}: the contact query of {which} arrived before any scene"
                    )));
                };
                validate_contact(&contact).map_err(|p| {
                    Stop(format!(
                        "{at}: contact query of {which}: field `{}`: {}",
                        p.field, p.problem
                    ))
                })?;
                let view = SweeptraceContactQuery {
                    frame: contact.frame,
                    ball: contact.ball,
                    radius: contact.radius,
                    centre: contact.centre,
                    distance: contact.distance,
                };
                let mut list = SweeptraceContacts {
                    contacts: Vec::new(),
                };
                // SAFETY: the callback's contract is the caller's; `list`
                // lives through the call.
                let status = unsafe { on_contact(user, &view, &mut list) };
                if status != 0 {
                    return Err(Stop(format!("on_contact returned {status} for {which}")));
                }
                let message = contacts_message(&view, &list.contacts, current.triangles.len() / 3)
                    .map_err(|m| {
                        Stop(format!(
                            "invalid answer to the contact query of {which}: {m}"
                        ))
                    })?;
                let text = contacts_line(&message).map_err(|e| Stop(e.to_string()))?;
                output
                    .write_all(text.as_bytes())
                    .and_then(|()| output.flush())
                    .map_err(|e| Stop(format!("cannot write the answer to {which}: {e}")))?;
            }
            Request::Scene(message) => {
                validate_scene(&message).map_err(|p| {
                    Stop(format!("{at}: scene: field `{}`: {}", p.field, p.problem))
                })?;
                let mut triangles = Vec::with_capacity(message.triangles.len() * 3);
                for index in message.triangles.iter().flatten() {
                    // Below the vertex count (validated), which fits a u32
                    // unless the scene has more than 2^32 vertices.
                    triangles.push(u32::try_from(*index).map_err(|_| {
                        Stop(format!(
                            "{at}: scene: vertex index {index} does not fit the C API's uint32_t"
                        ))
                    })?);
                }
                let data = SceneData {
                    name: message.name.as_deref().map(c_message),
                    vertices: message.vertices.iter().flatten().copied().collect(),
                    triangles,
                    margin: message.margin,
                };
                let view = SweeptraceScene {
                    name: data.name.as_ref().map_or(std::ptr::null(), |n| n.as_ptr()),
                    vertices: if data.vertices.is_empty() {
                        std::ptr::null()
                    } else {
                        data.vertices.as_ptr()
                    },
                    vertex_count: message.vertices.len(),
                    triangles: if data.triangles.is_empty() {
                        std::ptr::null()
                    } else {
                        data.triangles.as_ptr()
                    },
                    triangle_count: message.triangles.len(),
                    margin: data.margin,
                    facing: match message.facing {
                        Facing::NonStrict => SweeptraceFacing::NonStrict,
                        Facing::Strict => SweeptraceFacing::Strict,
                    },
                };
                // The previous scene's storage lives until here: replaced
                // only once the engine has the new one.
                scene = Some(data);
                // SAFETY: the callback's contract is the caller's; `view`
                // points into `scene`, alive until the next scene.
                let status = unsafe { on_scene(user, &view) };
                if status != 0 {
                    let name = message.name.map_or_else(String::new, |n| format!(" `{n}`"));
                    return Err(Stop(format!(
                        "on_scene returned {status} for the scene{name} ({at})"
                    )));
                }
            }
            Request::Sweep(sweep) => {
                let which = format!("frame {}, ball {}", sweep.frame, sweep.ball);
                let Some(current) = &scene else {
                    return Err(Stop(format!(
                        "{at}: the sweep of {which} arrived before any scene"
                    )));
                };
                validate_sweep(&sweep, Some(current.margin)).map_err(|p| {
                    Stop(format!(
                        "{at}: sweep of {which}: field `{}`: {}",
                        p.field, p.problem
                    ))
                })?;
                let view = SweeptraceSweep {
                    frame: sweep.frame,
                    ball: sweep.ball,
                    radius: sweep.radius,
                    p0: sweep.p0,
                    p1: sweep.p1,
                };
                let mut answer = SweeptraceAnswer::MISS;
                // SAFETY: the callback's contract is the caller's.
                let status = unsafe { on_sweep(user, &view, &mut answer) };
                if status != 0 {
                    return Err(Stop(format!("on_sweep returned {status} for {which}")));
                }
                let outcome = SweeptraceOutcome {
                    frame: sweep.frame,
                    ball: sweep.ball,
                    kind: answer.kind,
                    alpha: answer.alpha,
                    fields: answer.fields,
                    triangle: answer.triangle,
                    feature: answer.feature,
                    normal: answer.normal,
                    contact: answer.contact,
                };
                let invalid =
                    |message: String| Stop(format!("invalid answer to {which}: {message}"));
                let message = outcome_message(&outcome, Some(current.triangles.len() / 3))
                    .map_err(|f| invalid(f.message))?;
                validate_outcome(&message)
                    .map_err(|p| invalid(format!("field `{}`: {}", p.field, p.problem)))?;
                let text = answer_line(&message).map_err(|e| invalid(e.to_string()))?;
                output
                    .write_all(text.as_bytes())
                    .and_then(|()| output.flush())
                    .map_err(|e| Stop(format!("cannot write the answer to {which}: {e}")))?;
            }
        }
    }
}

/// Runs the engine protocol (docs/ENGINE_PROTOCOL.md) on the process's
/// standard input and output: reads each line sweeptrace sends, calls
/// `engine->on_scene(user, scene)` for a scene and
/// `engine->on_sweep(user, sweep, answer)` for a sweep, writes and flushes
/// each answer as its outcome line, in order, and ignores messages of an
/// unknown type (and blank lines). Your engine is a `main` that calls it:
/// `return sweeptrace_serve_engine(&engine, NULL);`.
///
/// Returns 0 at the end of input (stdin closed), having printed nothing
/// more. Returns 1 after printing one line `sweeptrace engine: ...` on
/// stderr (also given by [`sweeptrace_last_error`]) when:
/// - `engine` or one of its callbacks is null (nothing is read);
/// - a callback returns nonzero (the message names the scene or sweep and
///   the value returned);
/// - a sweep arrives before any scene;
/// - an answer is invalid (see [`SweeptraceAnswer`]): nothing is written
///   for it;
/// - an input line is not a protocol message (not JSON, no `type`, a
///   missing, mistyped or unknown field of a scene or sweep) or its values
///   are invalid (a NaN, an index out of range, a radius not above the
///   margin): the message names the input line and the field;
/// - reading or writing fails, or the library panics (a bug).
///
/// sweeptrace then reports the engine's exit while the sweep awaited its
/// answer, with these stderr lines. Nothing panics across the boundary.
/// Call it from one thread; it returns only at the end.
///
/// # Safety
/// `engine` is null or points to a [`SweeptraceEngine`] whose callbacks
/// are null or valid functions, safe to call with `user`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_serve_engine(
    engine: *const SweeptraceEngine,
    user: *mut c_void,
) -> c_int {
    // SAFETY: the caller's contract is `serve_stdio`'s.
    unsafe { serve_stdio(engine, None, user) }
}

/// [`sweeptrace_serve_engine`], answering contact queries too (`sweeptrace
/// check --engine ... --engine-contacts`, `sweeptrace conform --contacts`):
/// for each, `on_contact(user, query, contacts)` adds the contacts the
/// engine reports with [`sweeptrace_contacts_add`], and the loop writes
/// them as the query's `contacts` line. Returns as
/// [`sweeptrace_serve_engine`] does, and 1 also when `on_contact` is null
/// (nothing is read), returns nonzero (the message names the query), or
/// gives an invalid contact (a `triangle` out of the scene, unknown bits
/// in `fields`, a `kind` that is not face, edge or vertex, a `feature`
/// above 2, a point, normal or separation that is not finite, a zero
/// normal): nothing is written for that query.
///
/// # Safety
/// As [`sweeptrace_serve_engine`]; `on_contact` is null or a valid
/// function, safe to call with `user`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sweeptrace_serve_engine_contacts(
    engine: *const SweeptraceEngine,
    on_contact: SweeptraceContactFn,
    user: *mut c_void,
) -> c_int {
    if on_contact.is_none() {
        return fail_serving("`on_contact` is a null pointer".to_string());
    }
    // SAFETY: the caller's contract is `serve_stdio`'s.
    unsafe { serve_stdio(engine, on_contact, user) }
}

/// Prints `sweeptrace engine: MESSAGE` on stderr, keeps it as the thread's
/// last error, returns 1.
fn fail_serving(message: String) -> c_int {
    set_thread_error(&message);
    let _ = catch_unwind(|| {
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "sweeptrace engine: {message}");
    });
    1
}

/// The loop of both serving functions on the process's standard input and
/// output, under `catch_unwind`.
///
/// # Safety
/// As [`sweeptrace_serve_engine_contacts`].
unsafe fn serve_stdio(
    engine: *const SweeptraceEngine,
    on_contact: SweeptraceContactFn,
    user: *mut c_void,
) -> c_int {
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<(), Stop> {
        if engine.is_null() {
            return Err(Stop("`engine` is a null pointer".to_string()));
        }
        // SAFETY: non-null, a SweeptraceEngine by the contract.
        let engine = unsafe { *engine };
        let on_scene = engine
            .on_scene
            .ok_or_else(|| Stop("`engine->on_scene` is a null pointer".to_string()))?;
        let on_sweep = engine
            .on_sweep
            .ok_or_else(|| Stop("`engine->on_sweep` is a null pointer".to_string()))?;
        let stdin = std::io::stdin();
        let stdout = std::io::stdout();
        // SAFETY: the callbacks' contract is the caller's.
        unsafe {
            serve(
                on_scene,
                on_sweep,
                on_contact,
                user,
                &mut stdin.lock(),
                &mut stdout.lock(),
            )
        }
    }));
    match result {
        Ok(Ok(())) => 0,
        Ok(Err(Stop(message))) => fail_serving(message),
        Err(payload) => fail_serving(panic_message(payload.as_ref())),
    }
}
