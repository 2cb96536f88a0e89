//! Bad calls return an error code and a message naming what is wrong, never
//! crash, and never leave a file under the target name.

use std::ffi::{CStr, CString, c_char};
use std::path::Path;
use std::ptr::{null, null_mut};

use sweeptrace_capi::*;

const VERTICES: [f64; 9] = [0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 4.0, 0.0];
const TRIANGLES: [u32; 3] = [0, 1, 2];
const P0: [f64; 3] = [1.0, 1.0, 3.0];
const P1: [f64; 3] = [1.0, 1.0, -3.0];

fn text(pointer: *const c_char) -> String {
    assert!(
        !pointer.is_null(),
        "an error message is never a null pointer"
    );
    // SAFETY: the library returns NUL-terminated strings.
    unsafe { CStr::from_ptr(pointer) }
        .to_string_lossy()
        .into_owned()
}

/// An open writer on `dir/name`, and the target path.
fn open(dir: &Path, name: &str) -> (*mut SweeptraceWriter, std::path::PathBuf) {
    let target = dir.join(name);
    let path = CString::new(target.to_str().expect("a UTF-8 path")).expect("no NUL");
    let mut writer = null_mut();
    // SAFETY: valid arguments.
    let status = unsafe { sweeptrace_writer_open(path.as_ptr(), &mut writer) };
    assert_eq!(
        status,
        SweeptraceStatus::Ok,
        "{}",
        text(sweeptrace_last_error())
    );
    (writer, target)
}

fn add_scene(
    writer: *mut SweeptraceWriter,
    vertices: &[f64],
    triangles: &[u32],
) -> SweeptraceStatus {
    // SAFETY: slices of 3 * count values.
    unsafe {
        sweeptrace_writer_add_scene(
            writer,
            0,
            null(),
            vertices.as_ptr(),
            vertices.len() / 3,
            triangles.as_ptr(),
            triangles.len() / 3,
            0.0,
            SweeptraceFacing::NonStrict as u32,
        )
    }
}

fn add_sweep(writer: *mut SweeptraceWriter, frame: u64, p0: [f64; 3]) -> SweeptraceStatus {
    // SAFETY: 3 doubles each.
    unsafe { sweeptrace_writer_add_sweep(writer, frame, frame, 0, 0.5, p0.as_ptr(), P1.as_ptr()) }
}

fn face_outcome(frame: u64) -> SweeptraceOutcome {
    SweeptraceOutcome {
        frame,
        ball: 0,
        kind: SweeptraceKind::Face as u32,
        alpha: 5.0 / 12.0,
        fields: SWEEPTRACE_FIELD_TRIANGLE | SWEEPTRACE_FIELD_NORMAL | SWEEPTRACE_FIELD_CONTACT,
        triangle: 0,
        feature: 0,
        normal: [0.0, 0.0, 1.0],
        contact: [1.0, 1.0, 0.0],
    }
}

fn add_expected(writer: *mut SweeptraceWriter, outcome: &SweeptraceOutcome) -> SweeptraceStatus {
    // SAFETY: a valid outcome.
    unsafe { sweeptrace_writer_add_expected(writer, outcome.frame, outcome) }
}

/// The writer's last error, which must mention every one of `words`.
fn assert_error(
    writer: *mut SweeptraceWriter,
    status: SweeptraceStatus,
    want: SweeptraceStatus,
    words: &[&str],
) {
    assert_eq!(status, want);
    // SAFETY: a live writer (or null).
    let message = text(unsafe { sweeptrace_writer_last_error(writer) });
    for word in words {
        assert!(
            message.contains(word),
            "the message {message:?} does not mention {word:?}"
        );
    }
    assert_eq!(
        text(sweeptrace_last_error()),
        message,
        "the thread's last error is the same"
    );
}

#[test]
fn null_pointers_are_errors_with_messages() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut writer = null_mut();
    // SAFETY: null pointers are part of what the API accepts.
    unsafe {
        assert_eq!(
            sweeptrace_writer_open(null(), &mut writer),
            SweeptraceStatus::NullPointer
        );
        assert!(writer.is_null());
        assert!(text(sweeptrace_last_error()).contains("`path`"));
        assert_eq!(
            sweeptrace_writer_open(c"x.mcap".as_ptr(), null_mut()),
            SweeptraceStatus::NullPointer
        );
        assert!(text(sweeptrace_last_error()).contains("`out_writer`"));
        assert_eq!(
            add_scene(null_mut(), &VERTICES, &TRIANGLES),
            SweeptraceStatus::NullPointer
        );
        assert!(text(sweeptrace_writer_last_error(null())).contains("`writer`"));
        assert_eq!(
            sweeptrace_writer_close(null_mut()),
            SweeptraceStatus::NullPointer
        );
        sweeptrace_writer_free(null_mut());
    }
    let (writer, target) = open(dir.path(), "nulls.mcap");
    // SAFETY: null pointers with non-zero counts, null points, null outcome.
    unsafe {
        let status = sweeptrace_writer_add_scene(
            writer,
            0,
            null(),
            null(),
            3,
            TRIANGLES.as_ptr(),
            1,
            0.0,
            0,
        );
        assert_error(
            writer,
            status,
            SweeptraceStatus::NullPointer,
            &["`vertices`"],
        );
        let status =
            sweeptrace_writer_add_scene(writer, 0, null(), VERTICES.as_ptr(), 3, null(), 1, 0.0, 0);
        assert_error(
            writer,
            status,
            SweeptraceStatus::NullPointer,
            &["`triangles`"],
        );
        assert_eq!(
            add_scene(writer, &VERTICES, &TRIANGLES),
            SweeptraceStatus::Ok
        );
        assert_eq!(
            text(sweeptrace_writer_last_error(writer)),
            "",
            "a success clears the writer's error"
        );
        let status = sweeptrace_writer_add_sweep(writer, 0, 0, 0, 0.5, null(), P1.as_ptr());
        assert_error(writer, status, SweeptraceStatus::NullPointer, &["`p0`"]);
        let status = sweeptrace_writer_add_expected(writer, 0, null());
        assert_error(
            writer,
            status,
            SweeptraceStatus::NullPointer,
            &["`outcome`"],
        );
        sweeptrace_writer_free(writer);
    }
    assert!(
        !target.exists(),
        "a writer freed without close leaves no file"
    );
}

#[test]
fn nan_and_out_of_range_values_are_refused_and_the_writer_goes_on() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (writer, target) = open(dir.path(), "values.mcap");
    let mut nan_vertex = VERTICES;
    nan_vertex[4] = f64::NAN;
    assert_error(
        writer,
        add_scene(writer, &nan_vertex, &TRIANGLES),
        SweeptraceStatus::InvalidArgument,
        &["values.mcap", "vertices[1][1]", "NaN"],
    );
    assert_error(
        writer,
        add_scene(writer, &VERTICES, &[0, 1, 3]),
        SweeptraceStatus::InvalidArgument,
        &["triangles[0][2]", "out of range"],
    );
    // SAFETY: valid pointers; a facing value that is not a SweeptraceFacing.
    let status = unsafe {
        sweeptrace_writer_add_scene(
            writer,
            0,
            null(),
            VERTICES.as_ptr(),
            3,
            TRIANGLES.as_ptr(),
            1,
            0.0,
            7,
        )
    };
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["`facing`", "7"],
    );
    // SAFETY: as above, a negative margin.
    let status = unsafe {
        sweeptrace_writer_add_scene(
            writer,
            0,
            null(),
            VERTICES.as_ptr(),
            3,
            TRIANGLES.as_ptr(),
            1,
            -1.0,
            0,
        )
    };
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["margin"],
    );

    assert_error(
        writer,
        add_sweep(writer, 0, P0),
        SweeptraceStatus::WrongOrder,
        &["before any `/scene`"],
    );
    assert_eq!(
        add_scene(writer, &VERTICES, &TRIANGLES),
        SweeptraceStatus::Ok
    );
    assert_error(
        writer,
        add_sweep(writer, 0, [1.0, f64::INFINITY, 3.0]),
        SweeptraceStatus::InvalidArgument,
        &["frame 0", "p0[1]"],
    );
    // SAFETY: 3 doubles each; a NaN radius.
    let status =
        unsafe { sweeptrace_writer_add_sweep(writer, 0, 0, 0, f64::NAN, P0.as_ptr(), P1.as_ptr()) };
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["radius"],
    );
    assert_eq!(add_sweep(writer, 0, P0), SweeptraceStatus::Ok);

    let mut outcome = face_outcome(0);
    outcome.triangle = 1;
    assert_error(
        writer,
        add_expected(writer, &outcome),
        SweeptraceStatus::InvalidArgument,
        &["`triangle`", "index 1 is out of range", "1 triangles"],
    );
    let mut outcome = face_outcome(0);
    outcome.alpha = f64::NAN;
    assert_error(
        writer,
        add_expected(writer, &outcome),
        SweeptraceStatus::InvalidArgument,
        &["alpha", "frame 0"],
    );
    let mut outcome = face_outcome(0);
    outcome.normal[2] = f64::NAN;
    assert_error(
        writer,
        add_expected(writer, &outcome),
        SweeptraceStatus::InvalidArgument,
        &["normal[2]"],
    );
    let mut outcome = face_outcome(0);
    outcome.kind = 9;
    assert_error(
        writer,
        add_expected(writer, &outcome),
        SweeptraceStatus::InvalidArgument,
        &["`kind`", "9"],
    );
    let mut outcome = face_outcome(0);
    outcome.kind = SweeptraceKind::Edge as u32;
    outcome.fields |= SWEEPTRACE_FIELD_FEATURE;
    outcome.feature = 3;
    assert_error(
        writer,
        add_expected(writer, &outcome),
        SweeptraceStatus::InvalidArgument,
        &["`feature`", "3"],
    );
    let mut outcome = face_outcome(0);
    outcome.fields = 1 << 7;
    assert_error(
        writer,
        add_expected(writer, &outcome),
        SweeptraceStatus::InvalidArgument,
        &["`fields`"],
    );
    assert_eq!(add_expected(writer, &face_outcome(0)), SweeptraceStatus::Ok);
    // SAFETY: 3 doubles each.
    let status =
        unsafe { sweeptrace_writer_add_sweep(writer, 5, 1, 0, 0.5, P0.as_ptr(), P1.as_ptr()) };
    assert_eq!(status, SweeptraceStatus::Ok);
    // SAFETY: a valid outcome, at a log time before the sweep's.
    let status = unsafe { sweeptrace_writer_add_expected(writer, 4, &face_outcome(1)) };
    assert_error(
        writer,
        status,
        SweeptraceStatus::WrongOrder,
        &["log_time", "4 ns"],
    );

    // Nothing refused was written: the trace reads and its one expectation
    // matches.
    // SAFETY: a live writer, closed then freed.
    unsafe {
        assert_eq!(sweeptrace_writer_close(writer), SweeptraceStatus::Ok);
        assert_error(
            writer,
            sweeptrace_writer_close(writer),
            SweeptraceStatus::Closed,
            &["closed"],
        );
        assert_error(
            writer,
            add_sweep(writer, 3, P0),
            SweeptraceStatus::Closed,
            &["closed"],
        );
        sweeptrace_writer_free(writer);
    }
    let report = sweeptrace::check_file(&target, &Default::default());
    assert_eq!(
        (report.sweeps, report.compared, report.divergent),
        (2, 1, 0),
        "{}",
        sweeptrace::suite::render_text(&report)
    );
}

#[test]
fn open_in_a_missing_directory_is_an_io_error_naming_the_path() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let target = dir.path().join("no such directory/run.mcap");
    let path = CString::new(target.to_str().expect("UTF-8")).expect("no NUL");
    let mut writer = null_mut();
    // SAFETY: valid arguments.
    let status = unsafe { sweeptrace_writer_open(path.as_ptr(), &mut writer) };
    assert_eq!(status, SweeptraceStatus::Io);
    assert!(writer.is_null());
    assert!(text(sweeptrace_last_error()).contains("no such directory/run.mcap"));
    assert_eq!(text(sweeptrace_status_name(status as u32)), "io");
    assert_eq!(text(sweeptrace_status_name(99)), "unknown");
}

#[test]
fn outcome_fields_for_a_kind_without_them_are_written_as_null() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (writer, target) = open(dir.path(), "none.mcap");
    assert_eq!(
        add_scene(writer, &VERTICES, &TRIANGLES),
        SweeptraceStatus::Ok
    );
    assert_eq!(
        add_sweep(writer, 0, [10.0, 10.0, 3.0]),
        SweeptraceStatus::Ok
    );
    // A miss that gives every field: each is written as null (the triangle
    // index 5 is not checked, as it is not written), and the check compares
    // them with the core's nulls.
    let outcome = SweeptraceOutcome {
        kind: SweeptraceKind::None as u32,
        alpha: 1.0,
        fields: SWEEPTRACE_FIELD_TRIANGLE
            | SWEEPTRACE_FIELD_FEATURE
            | SWEEPTRACE_FIELD_NORMAL
            | SWEEPTRACE_FIELD_CONTACT,
        triangle: 5,
        ..face_outcome(0)
    };
    assert_eq!(add_expected(writer, &outcome), SweeptraceStatus::Ok);
    // SAFETY: a live writer, closed then freed.
    unsafe {
        assert_eq!(sweeptrace_writer_close(writer), SweeptraceStatus::Ok);
        sweeptrace_writer_free(writer);
    }
    let bytes = std::fs::read(&target).expect("the trace");
    let expected = sweeptrace::TraceReader::new(bytes.as_slice(), "none.mcap")
        .filter_map(Result::ok)
        .find_map(|event| match event.body {
            sweeptrace::EventBody::Expected(outcome) => Some(outcome),
            _ => None,
        })
        .expect("one expected outcome");
    assert_eq!(
        (
            expected.triangle,
            expected.feature,
            expected.normal,
            expected.contact
        ),
        (Some(None), Some(None), Some(None), Some(None))
    );
    let report = sweeptrace::check_file(&target, &Default::default());
    assert_eq!(
        (report.compared, report.divergent),
        (1, 0),
        "{}",
        sweeptrace::suite::render_text(&report)
    );
}

#[test]
fn bad_expected_sources_are_refused_and_the_good_one_is_read_back() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (writer, target) = open(dir.path(), "source.mcap");
    let names = [c"fix_internal_edges".as_ptr(), c"dt".as_ptr()];
    let values = [c"true".as_ptr(), c"0.01".as_ptr()];
    let bad_names = [c"".as_ptr(), c"dt".as_ptr()];
    let nul_value = [c"true".as_ptr(), null()];
    let newline = [c"a\nb".as_ptr(), c"0.01".as_ptr()];
    let set = |engine: *const c_char,
               version: *const c_char,
               names: *const *const c_char,
               values: *const *const c_char,
               count: usize| {
        // SAFETY: null or NUL-terminated strings, arrays of `count` pointers.
        unsafe {
            sweeptrace_writer_set_expected_source(writer, engine, version, names, values, count)
        }
    };
    let (engine, version) = (c"my-engine".as_ptr(), c"2.1".as_ptr());
    // SAFETY: a null writer is accepted.
    let status = unsafe {
        sweeptrace_writer_set_expected_source(null_mut(), engine, version, null(), null(), 0)
    };
    assert_eq!(status, SweeptraceStatus::NullPointer);
    let status = set(null(), version, null(), null(), 0);
    assert_error(writer, status, SweeptraceStatus::NullPointer, &["`engine`"]);
    let status = set(c"".as_ptr(), version, null(), null(), 0);
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &[
            "source.mcap",
            "sweeptrace.expected_source",
            "`engine` is empty",
        ],
    );
    let status = set(engine, version, null(), values.as_ptr(), 2);
    assert_error(
        writer,
        status,
        SweeptraceStatus::NullPointer,
        &["`setting_names`"],
    );
    let status = set(engine, version, names.as_ptr(), nul_value.as_ptr(), 2);
    assert_error(
        writer,
        status,
        SweeptraceStatus::NullPointer,
        &["`setting_values[1]`"],
    );
    let status = set(engine, version, bad_names.as_ptr(), values.as_ptr(), 2);
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["empty name"],
    );
    let status = set(engine, version, names.as_ptr(), newline.as_ptr(), 2);
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["setting.fix_internal_edges", "control character"],
    );
    let status = set(engine, version, names.as_ptr(), values.as_ptr(), 65);
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["`setting_count` is 65"],
    );
    let long = CString::new("e".repeat(129)).expect("no NUL");
    let status = set(long.as_ptr(), version, null(), null(), 0);
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["129 bytes", "limit of 128"],
    );
    // Refused calls wrote nothing: the good one is the trace's only source.
    assert_eq!(
        set(engine, version, names.as_ptr(), values.as_ptr(), 2),
        SweeptraceStatus::Ok
    );
    let status = set(engine, version, null(), null(), 0);
    assert_error(
        writer,
        status,
        SweeptraceStatus::InvalidArgument,
        &["already written"],
    );
    assert_eq!(
        add_scene(writer, &VERTICES, &TRIANGLES),
        SweeptraceStatus::Ok
    );
    assert_eq!(add_sweep(writer, 0, P0), SweeptraceStatus::Ok);
    assert_eq!(add_expected(writer, &face_outcome(0)), SweeptraceStatus::Ok);
    // SAFETY: a live writer, closed then freed.
    unsafe {
        assert_eq!(sweeptrace_writer_close(writer), SweeptraceStatus::Ok);
        sweeptrace_writer_free(writer);
    }
    let bytes = std::fs::read(&target).expect("the trace");
    let mut reader = sweeptrace::TraceReader::new(bytes.as_slice(), "source.mcap");
    let events = reader.by_ref().collect::<Result<Vec<_>, _>>();
    assert_eq!(events.map(|e| e.len()).ok(), Some(3));
    let want = sweeptrace::trace::ExpectedSource::new("my-engine", "2.1")
        .setting("fix_internal_edges", "true")
        .setting("dt", "0.01");
    assert_eq!(reader.expected_source(), Some(&want));
    let sources = reader
        .stats()
        .metadata
        .iter()
        .filter(|(name, _)| name == "sweeptrace.expected_source")
        .count();
    assert_eq!(sources, 1, "{:?}", reader.stats().metadata);
}

#[test]
fn open_with_encoding_writes_cbor_and_refuses_an_unknown_encoding() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let target = dir.path().join("cbor.mcap");
    let path = CString::new(target.to_str().expect("a UTF-8 path")).expect("no NUL");
    let mut writer = null_mut();
    // SAFETY: valid arguments.
    let status = unsafe { sweeptrace_writer_open_with_encoding(path.as_ptr(), 7, &mut writer) };
    assert_eq!(status, SweeptraceStatus::InvalidArgument);
    assert!(
        writer.is_null(),
        "a writer was made for an unknown encoding"
    );
    let message = text(sweeptrace_last_error());
    assert!(
        message.contains("`encoding`") && message.contains("got 7"),
        "{message}"
    );
    assert!(
        std::fs::read_dir(dir.path())
            .expect("readable")
            .next()
            .is_none()
    );

    for (encoding, name) in [
        (SweeptraceEncoding::Cbor, "cbor"),
        (SweeptraceEncoding::Json, "json"),
    ] {
        // SAFETY: valid arguments.
        let status = unsafe {
            sweeptrace_writer_open_with_encoding(path.as_ptr(), encoding as u32, &mut writer)
        };
        assert_eq!(
            status,
            SweeptraceStatus::Ok,
            "{}",
            text(sweeptrace_last_error())
        );
        assert_eq!(
            add_scene(writer, &VERTICES, &TRIANGLES),
            SweeptraceStatus::Ok
        );
        assert_eq!(add_sweep(writer, 0, P0), SweeptraceStatus::Ok);
        assert_eq!(add_expected(writer, &face_outcome(0)), SweeptraceStatus::Ok);
        // SAFETY: a live writer, closed then freed once.
        unsafe {
            assert_eq!(sweeptrace_writer_close(writer), SweeptraceStatus::Ok);
            sweeptrace_writer_free(writer);
        }
        let bytes = std::fs::read(&target).expect("the trace was written");
        let mut reader = sweeptrace::TraceReader::new(bytes.as_slice(), "cbor.mcap");
        let events: Vec<_> = reader.by_ref().collect::<Result<_, _>>().expect("reads");
        assert_eq!(events.len(), 3);
        for topic in ["/scene", "/sweep", "/expected"] {
            assert_eq!(reader.stats().channels[topic].message_encoding, name);
        }
        match &events[1].body {
            sweeptrace::EventBody::Sweep(sweep) => assert_eq!(sweep.p0, P0),
            other => panic!("not a sweep: {other:?}"),
        }
    }
}
