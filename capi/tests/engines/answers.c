/* A test engine for sweeptrace_serve_engine's documented results: its
 * answer to every sweep is chosen by argv[1].
 *   miss          kind none, every field given (null)
 *   face          a face hit on triangle 0 at alpha 0.5, every field given
 *   nan           alpha NaN
 *   kind          kind 9
 *   fail-scene    on_scene returns 3
 *   fail-sweep    on_sweep returns 7 for frame 1 (answers frame 0)
 *   null          on_sweep is a null pointer
 * and to every contact query, served with sweeptrace_serve_engine_contacts
 * in these modes:
 *   contacts        one contact on triangle 0: its face at the centre's
 *                   projection, normal +z, separation z - radius
 *   contact-bad     a contact on triangle 5 (out of a 1-triangle scene)
 *   contact-fail    on_contact returns 4
 *   contact-null    on_contact is a null pointer
 * (the others serve with sweeptrace_serve_engine: no contact callback).
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

static int on_contact(void *user, const SweeptraceContactQuery *query, SweeptraceContacts *contacts) {
    (void)user;
    if (strcmp(mode, "contact-fail") == 0) return 4;
    SweeptraceContact contact = {0};
    contact.triangle = strcmp(mode, "contact-bad") == 0 ? 5 : 0;
    contact.fields = SWEEPTRACE_FIELD_FEATURE | SWEEPTRACE_FIELD_CONTACT | SWEEPTRACE_FIELD_NORMAL |
                     SWEEPTRACE_FIELD_SEPARATION;
    contact.kind = SWEEPTRACE_KIND_FACE;
    contact.point[0] = query->centre[0];
    contact.point[1] = query->centre[1];
    contact.normal[2] = 1.0;
    contact.separation = query->centre[2] - query->radius;
    return sweeptrace_contacts_add(contacts, &contact);
}

int main(int argc, char **argv) {
    if (argc != 2) return 2;
    mode = argv[1];
    SweeptraceEngine engine = {on_scene, on_sweep};
    if (strcmp(mode, "null") == 0) engine.on_sweep = NULL;
    if (strncmp(mode, "contact", 7) == 0)
        return sweeptrace_serve_engine_contacts(&engine, strcmp(mode, "contact-null") == 0 ? NULL : on_contact,
                                                NULL);
    return sweeptrace_serve_engine(&engine, NULL);
}
