"""Writes a small sweeptrace trace through the C API with ctypes (Python's
standard library only): one triangle, three sweeps, the engine's answers.

    python3 write_trace_ctypes.py target/release/libsweeptrace_capi.so run.mcap
    sweeptrace check run.mcap
"""

import ctypes
import sys

STATUS_OK = 0
KIND_NONE, KIND_FACE, KIND_EDGE = 0, 1, 2
FACING_NON_STRICT = 0
FIELD_TRIANGLE, FIELD_FEATURE, FIELD_NORMAL, FIELD_CONTACT = 1, 2, 4, 8

Vec3 = ctypes.c_double * 3


class Outcome(ctypes.Structure):
    """struct SweeptraceOutcome of sweeptrace.h."""

    _fields_ = [
        ("frame", ctypes.c_uint64),
        ("ball", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("alpha", ctypes.c_double),
        ("fields", ctypes.c_uint32),
        ("triangle", ctypes.c_uint32),
        ("feature", ctypes.c_uint32),
        ("normal", Vec3),
        ("contact", Vec3),
    ]


def load(path):
    """The library, with the signatures of sweeptrace.h."""
    lib = ctypes.CDLL(path)
    writer_p = ctypes.c_void_p
    double_p = ctypes.POINTER(ctypes.c_double)
    lib.sweeptrace_writer_open.argtypes = [ctypes.c_char_p, ctypes.POINTER(writer_p)]
    char_pp = ctypes.POINTER(ctypes.c_char_p)
    lib.sweeptrace_writer_set_expected_source.argtypes = [
        writer_p, ctypes.c_char_p, ctypes.c_char_p, char_pp, char_pp, ctypes.c_size_t,
    ]
    lib.sweeptrace_writer_add_scene.argtypes = [
        writer_p, ctypes.c_uint64, ctypes.c_char_p, double_p, ctypes.c_size_t,
        ctypes.POINTER(ctypes.c_uint32), ctypes.c_size_t, ctypes.c_double, ctypes.c_uint32,
    ]
    lib.sweeptrace_writer_add_sweep.argtypes = [
        writer_p, ctypes.c_uint64, ctypes.c_uint64, ctypes.c_uint32, ctypes.c_double,
        double_p, double_p,
    ]
    lib.sweeptrace_writer_add_expected.argtypes = [
        writer_p, ctypes.c_uint64, ctypes.POINTER(Outcome),
    ]
    lib.sweeptrace_writer_close.argtypes = [writer_p]
    lib.sweeptrace_writer_free.argtypes = [writer_p]
    lib.sweeptrace_writer_free.restype = None
    lib.sweeptrace_writer_last_error.argtypes = [writer_p]
    lib.sweeptrace_writer_last_error.restype = ctypes.c_char_p
    lib.sweeptrace_last_error.argtypes = []
    lib.sweeptrace_last_error.restype = ctypes.c_char_p
    for name in ("open", "set_expected_source", "add_scene", "add_sweep", "add_expected", "close"):
        getattr(lib, "sweeptrace_writer_" + name).restype = ctypes.c_int
    return lib


class TraceError(Exception):
    """A call of the C API failed."""


def checked(lib, writer, status, what):
    if status != STATUS_OK:
        message = lib.sweeptrace_writer_last_error(writer).decode()
        raise TraceError(f"{what}: status {status}: {message}")


def main(library, out):
    lib = load(library)
    writer = ctypes.c_void_p()
    if lib.sweeptrace_writer_open(out.encode(), ctypes.byref(writer)) != STATUS_OK:
        raise TraceError("open: " + lib.sweeptrace_last_error().decode())
    try:
        # Who computes the expected outcomes below, and its settings.
        settings = {"margin": "0", "two_sided_triangles": "false"}
        names = (ctypes.c_char_p * len(settings))(*(k.encode() for k in settings))
        values = (ctypes.c_char_p * len(settings))(*(v.encode() for v in settings.values()))
        checked(lib, writer, lib.sweeptrace_writer_set_expected_source(
            writer, b"example-engine", b"1.0", names, values, len(settings)), "expected source")
        vertices = (ctypes.c_double * 9)(0, 0, 0, 4, 0, 0, 0, 4, 0)
        triangles = (ctypes.c_uint32 * 3)(0, 1, 2)
        checked(lib, writer, lib.sweeptrace_writer_add_scene(
            writer, 0, b"level", vertices, 3, triangles, 1, 0.0, FACING_NON_STRICT), "scene")
        hit = FIELD_TRIANGLE | FIELD_NORMAL | FIELD_CONTACT
        sweeps = [
            ((1, 1, 3), (1, 1, -3),
             Outcome(kind=KIND_FACE, alpha=5 / 12, fields=hit, triangle=0,
                     normal=Vec3(0, 0, 1), contact=Vec3(1, 1, 0))),
            ((2, -0.3, 3), (2, -0.3, -3),
             Outcome(kind=KIND_EDGE, alpha=13 / 30, fields=hit | FIELD_FEATURE, triangle=0,
                     feature=0, normal=Vec3(0, 0, 1), contact=Vec3(2, 0, 0))),
            ((10, 10, 3), (11, 10, 3), Outcome(kind=KIND_NONE, alpha=1.0)),
        ]
        for frame, (p0, p1, answer) in enumerate(sweeps):
            log_time_nanos = frame * 16666667
            checked(lib, writer, lib.sweeptrace_writer_add_sweep(
                writer, log_time_nanos, frame, 0, 0.5, Vec3(*p0), Vec3(*p1)), "sweep")
            answer.frame, answer.ball = frame, 0
            checked(lib, writer, lib.sweeptrace_writer_add_expected(
                writer, log_time_nanos, ctypes.byref(answer)), "expected")
        checked(lib, writer, lib.sweeptrace_writer_close(writer), "close")
    finally:
        # Without a successful close nothing appears under the target name.
        lib.sweeptrace_writer_free(writer)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(f"usage: {sys.argv[0]} LIBRARY OUT.mcap")
    try:
        main(sys.argv[1], sys.argv[2])
    except TraceError as error:
        sys.exit(f"error: {error}")
