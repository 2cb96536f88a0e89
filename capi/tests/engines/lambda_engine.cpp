// A C++ engine: a lambda with captured state, called through the C API's
// `void *user`. It knows faces only (the plane and inside test of one
// triangle at a time), enough for a trace of face hits and clear misses.
#include <cmath>
#include <cstdio>
#include <vector>
#include "sweeptrace.h"

template <class Scene, class Sweep> struct Callbacks {
    Scene scene;
    Sweep sweep;
    static int on_scene(void *user, const SweeptraceScene *s) {
        return static_cast<Callbacks *>(user)->scene(*s);
    }
    static int on_sweep(void *user, const SweeptraceSweep *s, SweeptraceAnswer *out) {
        return static_cast<Callbacks *>(user)->sweep(*s, *out);
    }
};

template <class Scene, class Sweep> int serve(Scene scene, Sweep sweep) {
    Callbacks<Scene, Sweep> callbacks{scene, sweep};
    const SweeptraceEngine engine{&decltype(callbacks)::on_scene, &decltype(callbacks)::on_sweep};
    return sweeptrace_serve_engine(&engine, &callbacks);
}

int main() {
    struct Triangle { double a[3], b[3], c[3]; };
    std::vector<Triangle> triangles;
    double margin = 0.0;
    long answered = 0;
    auto on_scene = [&](const SweeptraceScene &scene) {
        triangles.clear();
        margin = scene.margin;
        for (size_t t = 0; t < scene.triangle_count; t++) {
            Triangle tri;
            for (int k = 0; k < 3; k++) {
                tri.a[k] = scene.vertices[3 * scene.triangles[3 * t] + k];
                tri.b[k] = scene.vertices[3 * scene.triangles[3 * t + 1] + k];
                tri.c[k] = scene.vertices[3 * scene.triangles[3 * t + 2] + k];
            }
            triangles.push_back(tri);
        }
        return 0;
    };
    // Triangles in planes z = const facing +z, balls falling straight down.
    auto on_sweep = [&](const SweeptraceSweep &sweep, SweeptraceAnswer &out) {
        answered++;
        out.fields = SWEEPTRACE_FIELD_TRIANGLE | SWEEPTRACE_FIELD_NORMAL | SWEEPTRACE_FIELD_CONTACT;
        double rho = sweep.radius - margin, x = sweep.p0[0], y = sweep.p0[1];
        for (size_t t = 0; t < triangles.size(); t++) {
            const Triangle &tri = triangles[t];
            auto side = [&](const double *u, const double *v) {
                return (v[0] - u[0]) * (y - u[1]) - (v[1] - u[1]) * (x - u[0]);
            };
            if (side(tri.a, tri.b) < 0 || side(tri.b, tri.c) < 0 || side(tri.c, tri.a) < 0) continue;
            out.kind = SWEEPTRACE_KIND_FACE;
            out.alpha = (sweep.p0[2] - rho - tri.a[2]) / (sweep.p0[2] - sweep.p1[2]);
            out.triangle = static_cast<uint32_t>(t);
            out.normal[0] = 0; out.normal[1] = 0; out.normal[2] = 1;
            out.contact[0] = x; out.contact[1] = y; out.contact[2] = tri.a[2];
            break;
        }
        return 0;
    };
    int status = serve(on_scene, on_sweep);
    std::fprintf(stderr, "the lambda answered %ld sweeps\n", answered);
    return status;
}
