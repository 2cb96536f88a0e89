/* The smallest engine served through the C API: it answers "no collision"
 * to every sweep. Put your engine's calls where the comments say.
 *   cc examples/c/minimal_engine.c -I capi/include -L target/release -lsweeptrace_capi \
 *      -Wl,-rpath,"$PWD/target/release" -o engine && sweeptrace conform --engine ./engine */
#include "sweeptrace.h"

static int on_scene(void *user, const SweeptraceScene *scene) {
    (void)user; /* build your mesh from scene->vertices, scene->triangles (valid until the next scene) */
    (void)scene;
    return 0;   /* nonzero: sweeptrace_serve_engine stops and returns 1 */
}

static int on_sweep(void *user, const SweeptraceSweep *sweep, SweeptraceAnswer *out) {
    (void)user; /* sweep your ball of sweep->radius from sweep->p0 to sweep->p1 */
    (void)sweep;
    out->kind = SWEEPTRACE_KIND_NONE; /* or FACE, EDGE, VERTEX, with out->alpha, and */
    out->alpha = 1.0;                 /* out->fields saying which of triangle, feature, */
    return 0;                         /* normal, contact you set */
}

int main(void) {
    const SweeptraceEngine engine = {on_scene, on_sweep};
    return sweeptrace_serve_engine(&engine, NULL);
}
