/* Writes a small sweeptrace trace through the C API: one triangle, three
 * sweeps of a ball and, for each, what the engine decided.
 *
 *   cc examples/c/write_trace.c -I capi/include -L target/release -lsweeptrace_capi \
 *      -Wl,-rpath,"$PWD/target/release" -o write_trace
 *   ./write_trace run.mcap && sweeptrace check run.mcap
 */
#include <stdio.h>
#include "sweeptrace.h"

/* Prints the writer's last error and returns 1 when `status` is not OK. */
static int failed(SweeptraceStatus status, const SweeptraceWriter *writer, const char *what) {
    if (status == SWEEPTRACE_STATUS_OK) return 0;
    fprintf(stderr, "%s: %s: %s\n", what, sweeptrace_status_name(status),
            sweeptrace_writer_last_error(writer));
    return 1;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT.mcap\n", argv[0]);
        return 2;
    }
    SweeptraceWriter *writer = NULL;
    if (sweeptrace_writer_open(argv[1], &writer) != SWEEPTRACE_STATUS_OK) {
        fprintf(stderr, "open: %s\n", sweeptrace_last_error());
        return 1;
    }
    /* Who computes the expected outcomes below: the engine, its version and
     * the settings that bear on its answers (shown by info and check). */
    const char *setting_names[] = {"margin", "two_sided_triangles"};
    const char *setting_values[] = {"0", "false"};
    int error = failed(sweeptrace_writer_set_expected_source(writer, "example-engine", "1.0",
                                                             setting_names, setting_values, 2),
                       writer, "expected source");
    /* One triangle in the plane z = 0, its front facing +z. */
    const double vertices[] = {0, 0, 0, 4, 0, 0, 0, 4, 0};
    const uint32_t triangles[] = {0, 1, 2};
    error = error || failed(sweeptrace_writer_add_scene(writer, 0, "level", vertices, 3, triangles,
                                                        1, 0.0, SWEEPTRACE_FACING_NON_STRICT),
                            writer, "scene");

    /* A ball of radius 0.5 falling onto the face, onto the edge y = 0, and
     * moving beside the triangle; the engine's answer for each (the normal
     * is the triangle's, also for an edge hit: docs/SEMANTICS.md). */
    const double from[3][3] = {{1, 1, 3}, {2, -0.3, 3}, {10, 10, 3}};
    const double to[3][3] = {{1, 1, -3}, {2, -0.3, -3}, {11, 10, 3}};
    const SweeptraceOutcome answers[3] = {
        {.kind = SWEEPTRACE_KIND_FACE, .alpha = 5.0 / 12.0, .fields = SWEEPTRACE_FIELD_TRIANGLE |
         SWEEPTRACE_FIELD_NORMAL | SWEEPTRACE_FIELD_CONTACT, .triangle = 0,
         .normal = {0, 0, 1}, .contact = {1, 1, 0}},
        {.kind = SWEEPTRACE_KIND_EDGE, .alpha = 13.0 / 30.0, .fields = SWEEPTRACE_FIELD_TRIANGLE |
         SWEEPTRACE_FIELD_FEATURE | SWEEPTRACE_FIELD_NORMAL | SWEEPTRACE_FIELD_CONTACT,
         .triangle = 0, .feature = 0, .normal = {0, 0, 1}, .contact = {2, 0, 0}},
        {.kind = SWEEPTRACE_KIND_NONE, .alpha = 1.0},
    };
    for (uint64_t frame = 0; frame < 3 && !error; frame++) {
        uint64_t log_time_nanos = frame * 16666667;
        error = failed(sweeptrace_writer_add_sweep(writer, log_time_nanos, frame, 0, 0.5,
                                                   from[frame], to[frame]),
                       writer, "sweep");
        SweeptraceOutcome answer = answers[frame];
        answer.frame = frame;
        answer.ball = 0;
        error = error || failed(sweeptrace_writer_add_expected(writer, log_time_nanos, &answer),
                                writer, "expected");
    }
    /* Without a successful close nothing appears under the target name. */
    error = error || failed(sweeptrace_writer_close(writer), writer, "close");
    sweeptrace_writer_free(writer);
    return error;
}
