/* A swept-sphere vs triangle-mesh engine in plain C, served to sweeptrace
 * through the C API (sweeptrace_serve_engine_contacts: no JSON here). It is
 * examples/engines/sweep_engine.py ported line for line: the face test,
 * the edge test in the edge's standardized frame, the vertex test, the
 * facing rule, the margin, and the combination of hits with the tie window
 * (docs/SEMANTICS.md); and its contact queries: every triangle whose
 * closest point is within the radius plus the contact distance, the point
 * by Ericson's regions (an edge's computed in its standard frame), the
 * face normal (docs/SEMANTICS.md, "Contacts").
 *
 *   cargo build --release -p sweeptrace-capi
 *   cc -std=c99 -Wall -Wextra -Werror examples/c/engine.c -I capi/include \
 *      target/release/libsweeptrace_capi.a -lpthread -ldl -lm -o engine
 * or, against the shared library (-lm: sqrt, fmin and fmax are in libm):
 *   cc -std=c99 -Wall -Wextra -Werror examples/c/engine.c -I capi/include \
 *      -L target/release -lsweeptrace_capi -lm -Wl,-rpath,"$PWD/target/release" -o engine
 *   sweeptrace conform --engine ./engine
 *   sweeptrace check traces/ --engine ./engine
 *
 * `--bug skip-vertex` switches on a deliberate mistake (the vertex test
 * never runs, so corners are missed), `--bug contact-normal` another (the
 * contacts' normal is the geometric one, centre minus point: ghost contacts
 * on flat seams), to see what sweeptrace reports.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sweeptrace.h"

/* The constants of docs/SEMANTICS.md ("How sweeptrace implements it"). */
#define PARALLEL_TOLERANCE 1e-12
#define DEGENERATE_TOLERANCE 1e-12
#define TIE_WINDOW_ULPS 1024.0

typedef struct { double x, y, z; } Vec3;

static Vec3 vec(const double *p) { Vec3 v = {p[0], p[1], p[2]}; return v; }
static Vec3 sub(Vec3 a, Vec3 b) { Vec3 v = {a.x - b.x, a.y - b.y, a.z - b.z}; return v; }
static Vec3 add(Vec3 a, Vec3 b) { Vec3 v = {a.x + b.x, a.y + b.y, a.z + b.z}; return v; }
static Vec3 scale(Vec3 a, double s) { Vec3 v = {a.x * s, a.y * s, a.z * s}; return v; }
static double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static Vec3 cross(Vec3 a, Vec3 b) {
    Vec3 v = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return v;
}
static double norm(Vec3 a) { return sqrt(dot(a, a)); }
static double amax(Vec3 a) { return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z))); }
static void put(double *out, Vec3 v) { out[0] = v.x; out[1] = v.y; out[2] = v.z; }

/* An edge's standard frame: v0 at the origin, v1 on +x, +y the front normal. */
typedef struct { Vec3 v0, x, y, z; double length; } Frame;

/* A usable (non-degenerate) triangle of the scene. */
typedef struct {
    uint32_t index;     /* in the scene */
    Vec3 vertices[3];
    Vec3 normal;        /* unit, front */
    Frame edges[3];     /* edge k runs from vertex k to vertex k + 1 */
    Vec3 centre;
    double reach;       /* the largest distance from the centre to a vertex */
} Triangle;

typedef struct {
    Triangle *triangles;
    size_t count;
    double bound;       /* the largest |coordinate| of a usable triangle's vertex */
    double margin;
    int strict;         /* facing rule: n.d < 0 instead of n.d <= 0 */
    int skip_vertex;    /* --bug skip-vertex */
    int contact_normal; /* --bug contact-normal */
} Engine;

static Frame frame(Vec3 v0, Vec3 v1, Vec3 normal) {
    Frame f;
    Vec3 edge = sub(v1, v0);
    f.v0 = v0;
    f.length = norm(edge);
    f.x = scale(edge, 1.0 / f.length);
    f.y = sub(normal, scale(f.x, dot(f.x, normal)));
    f.y = scale(f.y, 1.0 / norm(f.y));
    f.z = cross(f.x, f.y);
    return f;
}

static int on_scene(void *user, const SweeptraceScene *scene) {
    Engine *engine = user;
    free(engine->triangles);
    engine->triangles = calloc(scene->triangle_count ? scene->triangle_count : 1, sizeof(Triangle));
    if (!engine->triangles) return 1;
    engine->count = 0;
    engine->bound = 0.0;
    engine->margin = scene->margin;
    engine->strict = scene->facing == SWEEPTRACE_FACING_STRICT;
    for (size_t t = 0; t < scene->triangle_count; t++) {
        const uint32_t *i = &scene->triangles[3 * t];
        if (i[0] == i[1] || i[1] == i[2] || i[0] == i[2]) continue;
        Vec3 a = vec(&scene->vertices[3 * i[0]]), b = vec(&scene->vertices[3 * i[1]]),
             c = vec(&scene->vertices[3 * i[2]]);
        Vec3 n = cross(sub(b, a), sub(c, a));
        double longest = fmax(dot(sub(b, a), sub(b, a)),
                              fmax(dot(sub(c, b), sub(c, b)), dot(sub(a, c), sub(a, c))));
        double area2 = norm(n);
        if (!(area2 > DEGENERATE_TOLERANCE * longest) || isinf(area2)) continue; /* degenerate */
        Triangle *tri = &engine->triangles[engine->count++];
        tri->index = (uint32_t)t;
        tri->vertices[0] = a; tri->vertices[1] = b; tri->vertices[2] = c;
        tri->normal = scale(n, 1.0 / area2);
        for (int k = 0; k < 3; k++)
            tri->edges[k] = frame(tri->vertices[k], tri->vertices[(k + 1) % 3], tri->normal);
        tri->centre = scale(add(add(a, b), c), 1.0 / 3.0);
        tri->reach = 0.0;
        for (int k = 0; k < 3; k++) {
            tri->reach = fmax(tri->reach, norm(sub(tri->vertices[k], tri->centre)));
            engine->bound = fmax(engine->bound, amax(tri->vertices[k]));
        }
    }
    return 0;
}

/* Roots s0 <= s1 of a s^2 + b s + c = 0 in the stable form; 0 when none. */
static int solve(double a, double b, double c, double disc, double *s0, double *s1) {
    if (disc < 0.0 || a <= 0.0) return 0;
    double root = sqrt(disc);
    double q = b >= 0.0 ? -0.5 * (b + root) : -0.5 * (b - root);
    if (q == 0.0) {
        if (c > 0.0) return 0;
        double r = c == 0.0 ? 0.0 : sqrt(-c / a);
        *s0 = -r; *s1 = r;
        return 1;
    }
    double r0 = q / a, r1 = c / q;
    *s0 = fmin(r0, r1); *s1 = fmax(r0, r1);
    return 1;
}

/* A candidate contact: kind 0 face, 1 edge, 2 vertex (the tie order). */
typedef struct { double alpha; int kind; uint32_t triangle; int feature; Vec3 contact, normal; } Hit;

typedef struct { Hit *items; size_t count, capacity; } Hits;

static int push(Hits *hits, Hit hit) {
    if (hits->count == hits->capacity) {
        size_t capacity = hits->capacity ? 2 * hits->capacity : 16;
        Hit *items = realloc(hits->items, capacity * sizeof(Hit));
        if (!items) return 1;
        hits->items = items;
        hits->capacity = capacity;
    }
    hits->items[hits->count++] = hit;
    return 0;
}

/* Whether the hit a comes before b in the tie order: kind, triangle, feature. */
static int before(const Hit *a, const Hit *b) {
    if (a->kind != b->kind) return a->kind < b->kind;
    if (a->triangle != b->triangle) return a->triangle < b->triangle;
    return a->feature < b->feature;
}

static int on_sweep(void *user, const SweeptraceSweep *sweep, SweeptraceAnswer *out) {
    const Engine *engine = user;
    double rho = sweep->radius - engine->margin;
    Vec3 p0 = vec(sweep->p0), p1 = vec(sweep->p1), d = sub(p1, p0);
    double length = norm(d);
    double s = fmax(fmax(amax(p0), amax(p1)), engine->bound) + rho;
    double rounding = DBL_EPSILON * s;
    double tie_distance = TIE_WINDOW_ULPS * rounding;
    double window = length > 0.0 ? fmin(TIE_WINDOW_ULPS * rounding / length, 1.0) : 0.0;
    Vec3 midpoint = scale(add(p0, p1), 0.5);
    Hits hits = {NULL, 0, 0};
    int error = 0;

    for (size_t t = 0; t < engine->count && !error; t++) {
        const Triangle *tri = &engine->triangles[t];
        /* Cheap rejection: the path's segment never comes near the triangle. */
        if (norm(sub(tri->centre, midpoint)) > tri->reach + rho + 0.5 * length + 1e-9 * s) continue;
        Vec3 n = tri->normal;
        double facing = dot(n, d);
        int allowed = engine->strict ? facing < 0.0 : facing <= 0.0;
        /* Face. */
        double h0 = dot(n, sub(p0, tri->vertices[0]));
        if (h0 >= rho && fabs(facing) > PARALLEL_TOLERANCE * length && allowed) {
            double beta = (h0 - rho) / -facing;
            if (beta <= 1.0) {
                Vec3 touch = sub(add(p0, scale(d, beta)), scale(n, rho));
                double distance = INFINITY;
                for (int k = 0; k < 3; k++) {
                    /* The signed distance from the touch point to the edge opposite vertex k. */
                    Vec3 pb = sub(tri->vertices[(k + 1) % 3], touch);
                    Vec3 pc = sub(tri->vertices[(k + 2) % 3], touch);
                    distance = fmin(distance, dot(n, cross(pb, pc)) / tri->edges[(k + 1) % 3].length);
                }
                if (distance >= -tie_distance) {
                    Hit hit = {beta, 0, tri->index, -1, touch, n};
                    error = error || push(&hits, hit);
                }
            }
        }
        /* Edges, each in its standard frame. */
        for (int e = 0; e < 3; e++) {
            const Frame *f = &tri->edges[e];
            Vec3 m0 = sub(p0, f->v0), m1 = sub(p1, f->v0);
            double x0 = dot(f->x, m0), y0 = dot(f->y, m0), z0 = dot(f->z, m0);
            double x1 = dot(f->x, m1), y1 = dot(f->y, m1), z1 = dot(f->z, m1);
            double dy = y1 - y0, dz = z1 - z0;
            double qa = dy * dy + dz * dz;
            double parallel = PARALLEL_TOLERANCE * length;
            if (qa <= parallel * parallel) continue; /* parallel to the edge */
            double qb = 2.0 * (y0 * dy + z0 * dz);
            double qc = y0 * y0 + z0 * z0 - rho * rho;
            double w = y0 * dz - z0 * dy;
            double s0, s1;
            if (!solve(qa, qb, qc, 4.0 * (rho * rho * qa - w * w), &s0, &s1) || s0 < 0.0 || s0 > 1.0)
                continue;
            double xc = x0 + s0 * (x1 - x0);
            if (xc < -tie_distance || xc > f->length + tie_distance || !allowed) continue;
            Hit hit = {s0, 1, tri->index, e, add(f->v0, scale(f->x, xc)), n};
            error = error || push(&hits, hit);
        }
        /* Vertices. */
        if (engine->skip_vertex) continue;
        double qa = dot(d, d);
        if (qa == 0.0) continue; /* not moving */
        for (int k = 0; k < 3; k++) {
            Vec3 m = sub(p0, tri->vertices[k]);
            double qb = 2.0 * dot(d, m);
            double qc = dot(m, m) - rho * rho;
            Vec3 c = cross(d, m);
            double s0, s1;
            if (!solve(qa, qb, qc, 4.0 * (rho * rho * qa - dot(c, c)), &s0, &s1) || s0 < 0.0 ||
                s0 > 1.0 || !allowed)
                continue;
            Hit hit = {s0, 2, tri->index, k, tri->vertices[k], n};
            error = error || push(&hits, hit);
        }
    }
    if (error) {
        fprintf(stderr, "engine: out of memory\n");
        free(hits.items);
        return 1;
    }

    out->fields = SWEEPTRACE_FIELD_TRIANGLE | SWEEPTRACE_FIELD_FEATURE | SWEEPTRACE_FIELD_NORMAL |
                  SWEEPTRACE_FIELD_CONTACT;
    if (hits.count == 0) { /* kind none, alpha 1: the answer's initial value */
        free(hits.items);
        return 0;
    }
    /* The earliest hit, then the tie set: the hits within the window of it. */
    double alpha = hits.items[0].alpha;
    for (size_t i = 1; i < hits.count; i++) alpha = fmin(alpha, hits.items[i].alpha);
    const Hit *primary = NULL;
    for (size_t i = 0; i < hits.count; i++) {
        const Hit *h = &hits.items[i];
        if (h->alpha <= alpha + window && (!primary || before(h, primary))) primary = h;
    }
    /* The normal: the average of the tied triangles' normals, each triangle once. */
    Vec3 total = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < hits.count; i++) {
        const Hit *h = &hits.items[i];
        int seen = !(h->alpha <= alpha + window);
        for (size_t j = 0; j < i && !seen; j++)
            seen = hits.items[j].triangle == h->triangle && hits.items[j].alpha <= alpha + window;
        if (!seen) total = add(total, h->normal);
    }
    double size = norm(total);
    Vec3 normal = size > 1e-9 ? scale(total, 1.0 / size) : primary->normal;

    out->kind = (uint32_t[]){SWEEPTRACE_KIND_FACE, SWEEPTRACE_KIND_EDGE, SWEEPTRACE_KIND_VERTEX}[primary->kind];
    out->alpha = alpha;
    out->triangle = primary->triangle;
    out->feature = primary->feature < 0 ? 0 : (uint32_t)primary->feature;
    put(out->normal, normal);
    put(out->contact, primary->contact);
    free(hits.items);
    return 0;
}

/* The point of edge k of `t` nearest to p, computed in the edge's standard
 * frame: the centre's first coordinate there, clamped to [0, L]. */
static Vec3 edge_point(const Triangle *t, int k, Vec3 p) {
    const Frame *f = &t->edges[k];
    double along = fmin(fmax(dot(sub(p, f->v0), f->x), 0.0), f->length);
    return add(f->v0, scale(f->x, along));
}

/* The point of `t` nearest to p and its feature (Ericson, Real-Time
 * Collision Detection, 5.1.5): kind SWEEPTRACE_KIND_FACE, _EDGE or _VERTEX,
 * and the edge or vertex index. */
static Vec3 closest(const Triangle *t, Vec3 p, uint32_t *kind, uint32_t *feature) {
    Vec3 a = t->vertices[0], b = t->vertices[1], c = t->vertices[2];
    Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    *feature = 0;
    *kind = SWEEPTRACE_KIND_VERTEX;
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    Vec3 bp = sub(p, b);
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { *feature = 1; return b; }
    double vc = d1 * d4 - d3 * d2;
    *kind = SWEEPTRACE_KIND_EDGE;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return edge_point(t, 0, p);
    Vec3 cp = sub(p, c);
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { *kind = SWEEPTRACE_KIND_VERTEX; *feature = 2; return c; }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { *feature = 2; return edge_point(t, 2, p); }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) { *feature = 1; return edge_point(t, 1, p); }
    double denom = 1.0 / (va + vb + vc);
    *kind = SWEEPTRACE_KIND_FACE;
    return add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)));
}

/* A contact query: one contact per usable triangle within the radius plus
 * the contact distance whose front faces the centre (one-sided). */
static int on_contact(void *user, const SweeptraceContactQuery *query, SweeptraceContacts *contacts) {
    const Engine *engine = user;
    Vec3 centre = vec(query->centre);
    double reach = query->radius + query->distance;
    for (size_t i = 0; i < engine->count; i++) {
        const Triangle *t = &engine->triangles[i];
        SweeptraceContact contact = {0};
        Vec3 point = closest(t, centre, &contact.kind, &contact.feature);
        Vec3 towards = sub(centre, point);
        double gap = norm(towards);
        if (gap > reach || dot(t->normal, towards) < 0.0) continue;
        Vec3 normal = t->normal;
        if (engine->contact_normal && gap > 0.0) normal = scale(towards, 1.0 / gap);
        contact.triangle = t->index;
        contact.fields = SWEEPTRACE_FIELD_FEATURE | SWEEPTRACE_FIELD_CONTACT |
                         SWEEPTRACE_FIELD_NORMAL | SWEEPTRACE_FIELD_SEPARATION;
        put(contact.point, point);
        put(contact.normal, normal);
        contact.separation = gap - query->radius;
        if (sweeptrace_contacts_add(contacts, &contact) != 0) return 1;
    }
    return 0;
}

int main(int argc, char **argv) {
    Engine engine = {0};
    for (int i = 1; i < argc; i++) {
        if (i + 1 < argc && strcmp(argv[i], "--bug") == 0 && strcmp(argv[i + 1], "skip-vertex") == 0) {
            engine.skip_vertex = 1;
            i++;
        } else if (i + 1 < argc && strcmp(argv[i], "--bug") == 0 && strcmp(argv[i + 1], "contact-normal") == 0) {
            engine.contact_normal = 1;
            i++;
        } else {
            fprintf(stderr, "usage: %s [--bug skip-vertex | --bug contact-normal]\n", argv[0]);
            return 2;
        }
    }
    const SweeptraceEngine callbacks = {on_scene, on_sweep};
    int status = sweeptrace_serve_engine_contacts(&callbacks, on_contact, &engine);
    free(engine.triangles);
    return status;
}
