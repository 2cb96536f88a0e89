/* A test engine for sweeptrace_serve_engine's documented results: its
 * answer to every sweep is chosen by argv[1].
 *   miss          kind none, every field given (null)
 *   face          a face hit on triangle 0 at alpha 0.5, every field given
 *   nan           alpha NaN
 *   kind          kind 9
 *   fail-scene    on_scene returns 3
 *   fail-sweep    on_sweep returns 7 for frame 1 (answers frame 0)
 *   null          on_sweep is a null pointer
 * It logs each scene's name and triangle count on stderr. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "sweeptrace.h"

static const char *mode;

static int on_scene(void *user, const SweeptraceScene *scene) {
    (void)user;
    fprintf(stderr, "scene %s with %zu triangles\n", scene->name ? scene->name : "(none)",
            scene->triangle_count);
    return strcmp(mode, "fail-scene") == 0 ? 3 : 0;
}

static int on_sweep(void *user, const SweeptraceSweep *sweep, SweeptraceAnswer *out) {
    (void)user;
    if (strcmp(mode, "fail-sweep") == 0 && sweep->frame == 1) return 7;
    out->fields = SWEEPTRACE_FIELD_TRIANGLE | SWEEPTRACE_FIELD_FEATURE | SWEEPTRACE_FIELD_NORMAL |
                  SWEEPTRACE_FIELD_CONTACT;
    if (strcmp(mode, "face") == 0) {
        out->kind = SWEEPTRACE_KIND_FACE;
        out->alpha = 0.5;
        out->triangle = 0;
        out->normal[2] = 1.0;
    } else if (strcmp(mode, "nan") == 0) {
        out->alpha = NAN;
    } else if (strcmp(mode, "kind") == 0) {
        out->kind = 9;
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc != 2) return 2;
    mode = argv[1];
    SweeptraceEngine engine = {on_scene, on_sweep};
    if (strcmp(mode, "null") == 0) engine.on_sweep = NULL;
    return sweeptrace_serve_engine(&engine, NULL);
}
