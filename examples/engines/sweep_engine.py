#!/usr/bin/env python3
"""A swept-sphere vs triangle-mesh engine in plain Python (standard library
only) that speaks sweeptrace's engine protocol (docs/ENGINE_PROTOCOL.md).

It implements docs/SEMANTICS.md: the face test, the edge test in the edge's
standardized frame, the vertex test, the facing rule, the margin, and the
combination of hits with the tie window. Use it as a reference to read, or
check it:

    sweeptrace conform --engine "python3 examples/engines/sweep_engine.py"
    sweeptrace check traces/ --engine "python3 examples/engines/sweep_engine.py"

`--bug NAME` switches on a deliberate mistake, to see what sweeptrace
reports about an engine that has it:

    skip-vertex     never runs the vertex test (corners are missed)
    ignore-margin   detects at the radius r instead of rho = r - margin
    strict-facing   always uses the strict facing rule n.d < 0
    tie-highest-triangle
                    among simultaneous hits of one kind, takes the highest
                    triangle index (the rule: the lowest)
    tie-vertex-first
                    among simultaneous hits, prefers a vertex over an edge
                    and an edge over a face (the rule: face < edge < vertex)
    glued           a ball that starts within rho of a triangle's plane, over
                    it, and moves away is a face hit at alpha 0 (the rule: no
                    collision)
    first-hit       answers the lowest triangle on the path, not the nearest
                    (a walk that stops at its first hit)
    loose-bary      a face hit whose touch point lies within 1 % of the
                    altitude from an edge is reported as that edge
    wide-active-edges
                    at an edge whose two faces meet below 30 degrees, the
                    primary triangle's normal instead of the tie's average
    ghost-flat      at an edge shared by two coplanar triangles, the normal
                    leans 10 degrees toward the edge
    lost-leaf       in a mesh of more than 64 triangles, the second half of
                    them is never tested (a lost leaf of a tree)
    contact-normal  contact queries answer the geometric normal (centre
                    minus closest point) instead of the face normal: ghost
                    contacts on flat seams
    contact-no-distance  contact queries ignore the contact distance: only
                    triangles within the radius are reported
    contact-back-faces  contact queries report triangles whose back faces
                    the centre too

It also answers contact queries (`contact` lines, sent by `check
--engine-contacts`): every triangle within the radius plus the contact
distance, its closest point and feature, the separation and the face normal
(docs/SEMANTICS.md, "Contacts").
"""

import argparse
import json
import math
import sys

# The constants of docs/SEMANTICS.md ("How sweeptrace implements it").
PARALLEL_TOLERANCE = 1e-12
DEGENERATE_TOLERANCE = 1e-12
TIE_WINDOW_ULPS = 1024.0
EPSILON = sys.float_info.epsilon

BUGS = (
    "skip-vertex",
    "ignore-margin",
    "strict-facing",
    "tie-highest-triangle",
    "tie-vertex-first",
    "glued",
    "first-hit",
    "loose-bary",
    "wide-active-edges",
    "ghost-flat",
    "lost-leaf",
    "contact-normal",
    "contact-no-distance",
    "contact-back-faces",
)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


def norm(a):
    return math.sqrt(dot(a, a))


def amax(a):
    return max(abs(a[0]), abs(a[1]), abs(a[2]))


class Triangle:
    """A usable triangle with its front normal and its edges' standard frames."""

    def __init__(self, index, a, b, c, normal):
        self.index = index
        self.vertices = (a, b, c)
        self.normal = normal
        self.edges = [self.frame(a, b), self.frame(b, c), self.frame(c, a)]
        centre = scale(add(add(a, b), c), 1.0 / 3.0)
        self.centre = centre
        self.reach = max(norm(sub(v, centre)) for v in (a, b, c))

    def frame(self, v0, v1):
        # The standard frame: v0 at the origin, v1 on +x, +y the front normal.
        edge = sub(v1, v0)
        length = norm(edge)
        x = scale(edge, 1.0 / length)
        y = sub(self.normal, scale(x, dot(x, self.normal)))
        y = scale(y, 1.0 / norm(y))
        z = cross(x, y)
        return (v0, x, y, z, length)


def load_scene(msg):
    vertices = [tuple(v) for v in msg["vertices"]]
    triangles = []
    for index, (i, j, k) in enumerate(msg["triangles"]):
        if i == j or j == k or i == k:
            continue
        a, b, c = vertices[i], vertices[j], vertices[k]
        n = cross(sub(b, a), sub(c, a))
        longest = max(dot(sub(b, a), sub(b, a)), dot(sub(c, b), sub(c, b)), dot(sub(a, c), sub(a, c)))
        area2 = norm(n)
        if not area2 > DEGENERATE_TOLERANCE * longest or math.isinf(area2):
            continue  # degenerate: left out of every test
        triangles.append(Triangle(index, a, b, c, scale(n, 1.0 / area2)))
    count = len(msg["triangles"])
    bound = 0.0
    for t in triangles:
        for v in t.vertices:
            bound = max(bound, amax(v))
    return {
        "triangles": triangles,
        "count": count,
        "bound": bound,
        "margin": float(msg.get("margin", 0.0)),
        "facing": msg.get("facing", "non_strict"),
    }


def solve(a, b, c, disc):
    """Roots s0 <= s1 of a s^2 + b s + c = 0 in the stable form, or None."""
    if disc < 0.0 or a <= 0.0:
        return None
    root = math.sqrt(disc)
    q = -0.5 * (b + root) if b >= 0.0 else -0.5 * (b - root)
    if q == 0.0:
        if c > 0.0:
            return None
        if c == 0.0:
            return (0.0, 0.0)
        r = math.sqrt(-c / a)
        return (-r, r)
    r0, r1 = q / a, c / q
    return (r0, r1) if r0 <= r1 else (r1, r0)


def sweep(scene, radius, p0, p1, bugs):
    margin = 0.0 if "ignore-margin" in bugs else scene["margin"]
    strict = scene["facing"] == "strict" or "strict-facing" in bugs
    rho = radius - margin
    d = sub(p1, p0)
    length = norm(d)
    s = max(amax(p0), amax(p1), scene["bound"]) + rho
    rounding = EPSILON * s
    tie_distance = TIE_WINDOW_ULPS * rounding
    window = min(TIE_WINDOW_ULPS * rounding / length, 1.0) if length > 0.0 else 0.0
    midpoint = scale(add(p0, p1), 0.5)

    def allows(v):
        return v < 0.0 if strict else v <= 0.0

    if "glued" in bugs:
        for t in scene["triangles"]:
            h = dot(t.normal, sub(p0, t.vertices[0]))
            touch = sub(p0, scale(t.normal, h))
            if dot(t.normal, d) > 0.0 and abs(h) <= rho and min(weights(t, touch)) >= 0.0:
                return answer(0.0, "face", t.index, None, t.normal, touch)
    hits = []  # (alpha, kind order, triangle, feature, contact, normal)
    for t in scene["triangles"]:
        if "lost-leaf" in bugs and scene["count"] > 64 and 2 * t.index >= scene["count"]:
            continue
        # Cheap rejection: the path's segment never comes near the triangle.
        if norm(sub(t.centre, midpoint)) > t.reach + rho + 0.5 * length + 1e-9 * s:
            continue
        n = t.normal
        a = t.vertices[0]
        facing = dot(n, d)
        # Face.
        h0 = dot(n, sub(p0, a))
        if h0 >= rho and abs(facing) > PARALLEL_TOLERANCE * length and allows(facing):
            beta = (h0 - rho) / -facing
            if beta <= 1.0:
                touch = sub(add(p0, scale(d, beta)), scale(n, rho))
                pa, pb, pc = (sub(v, touch) for v in t.vertices)
                areas = (dot(n, cross(pb, pc)), dot(n, cross(pc, pa)), dot(n, cross(pa, pb)))
                lengths = (t.edges[1][4], t.edges[2][4], t.edges[0][4])
                distance = min(areas[i] / lengths[i] for i in range(3))
                if distance >= -tie_distance:
                    hits.append((beta, 0, t.index, None, touch, n))
        # Edges, each in its standard frame.
        for e, (v0, x, y, z, edge_length) in enumerate(t.edges):
            m0, m1 = sub(p0, v0), sub(p1, v0)
            x0, y0, z0 = dot(x, m0), dot(y, m0), dot(z, m0)
            x1, y1, z1 = dot(x, m1), dot(y, m1), dot(z, m1)
            dy, dz = y1 - y0, z1 - z0
            qa = dy * dy + dz * dz
            if qa <= (PARALLEL_TOLERANCE * length) ** 2:
                continue  # parallel to the edge
            qb = 2.0 * (y0 * dy + z0 * dz)
            qc = y0 * y0 + z0 * z0 - rho * rho
            w = y0 * dz - z0 * dy
            roots = solve(qa, qb, qc, 4.0 * (rho * rho * qa - w * w))
            if roots is None or roots[0] < 0.0 or roots[0] > 1.0:
                continue
            s0 = roots[0]
            xc = x0 + s0 * (x1 - x0)
            if xc < -tie_distance or xc > edge_length + tie_distance or not allows(facing):
                continue
            hits.append((s0, 1, t.index, e, add(v0, scale(x, xc)), n))
        # Vertices.
        if "skip-vertex" in bugs:
            continue
        qa = dot(d, d)
        if qa == 0.0:
            continue  # not moving
        for k, v in enumerate(t.vertices):
            m = sub(p0, v)
            qb = 2.0 * dot(d, m)
            qc = dot(m, m) - rho * rho
            c = cross(d, m)
            roots = solve(qa, qb, qc, 4.0 * (rho * rho * qa - dot(c, c)))
            if roots is None or roots[0] < 0.0 or roots[0] > 1.0 or not allows(facing):
                continue
            hits.append((roots[0], 2, t.index, k, v, n))
    if not hits:
        return {"alpha": 1.0, "kind": "none", "triangle": None, "feature": None, "normal": None, "contact": None}
    if "first-hit" in bugs:
        first = min(h[2] for h in hits)
        hits = [h for h in hits if h[2] == first]
    alpha = min(h[0] for h in hits)
    tied = [h for h in hits if h[0] <= alpha + window]
    # The tie order: kind (face < edge < vertex), then triangle, then feature.
    kind_key = (lambda h: -h[1]) if "tie-vertex-first" in bugs else (lambda h: h[1])
    triangle_key = (lambda h: -h[2]) if "tie-highest-triangle" in bugs else (lambda h: h[2])
    primary = min(tied, key=lambda h: (kind_key(h), triangle_key(h), -1 if h[3] is None else h[3]))
    total, seen = (0.0, 0.0, 0.0), set()
    for h in sorted(tied, key=lambda h: h[2]):
        if h[2] not in seen:
            seen.add(h[2])
            total = add(total, h[5])
    size = norm(total)
    normal = scale(total, 1.0 / size) if size > 1e-9 else primary[5]
    kind, feature = ("face", "edge", "vertex")[primary[1]], primary[3]
    by_index = {t.index: t for t in scene["triangles"]}
    own = by_index[primary[2]]
    if "loose-bary" in bugs and kind == "face":
        w = weights(own, primary[4])
        k = min(range(3), key=lambda i: w[i])
        if w[k] <= 1e-2:
            kind, feature = "edge", (k + 1) % 3
    if "wide-active-edges" in bugs and kind == "edge":
        # The other triangles of the tie whose normal is within 30 degrees.
        near = [h for h in tied if h[2] != primary[2] and dot(h[5], own.normal) > math.cos(math.radians(30))]
        if any(dot(h[5], own.normal) < 1.0 - 1e-12 for h in near):
            normal = own.normal
    if "ghost-flat" in bugs:
        # An edge hit of the tie on an edge shared with a coplanar triangle.
        for h in tied:
            t = by_index[h[2]]
            coplanar = any(g[2] != h[2] and dot(g[5], t.normal) >= 1.0 - 1e-12 for g in tied)
            if h[1] == 1 and coplanar:
                v0, x = t.edges[h[3]][0], t.edges[h[3]][1]
                out = cross(x, t.normal)
                angle = math.radians(10.0)
                normal = add(scale(t.normal, math.cos(angle)), scale(out, math.sin(angle)))
                break
    return answer(alpha, kind, primary[2], feature, normal, primary[4])


def weights(t, p):
    """The barycentric weights of point p (in t's plane) in triangle t."""
    pa, pb, pc = (sub(v, p) for v in t.vertices)
    n = t.normal
    areas = (dot(n, cross(pb, pc)), dot(n, cross(pc, pa)), dot(n, cross(pa, pb)))
    total = areas[0] + areas[1] + areas[2]
    return tuple(a / total for a in areas)


def answer(alpha, kind, triangle, feature, normal, contact):
    return {
        "alpha": alpha,
        "kind": kind,
        "triangle": triangle,
        "feature": feature,
        "normal": list(normal),
        "contact": list(contact),
    }


def closest(t, p):
    """The point of triangle t nearest to p and its feature (Ericson 5.1.5),
    an edge's point computed in its standard frame: (kind, index, point)."""
    a, b, c = t.vertices
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    d1, d2 = dot(ab, ap), dot(ac, ap)
    if d1 <= 0.0 and d2 <= 0.0:
        return "vertex", 0, a
    bp = sub(p, b)
    d3, d4 = dot(ab, bp), dot(ac, bp)
    if d3 >= 0.0 and d4 <= d3:
        return "vertex", 1, b
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return edge_point(t, 0, p)
    cp = sub(p, c)
    d5, d6 = dot(ab, cp), dot(ac, cp)
    if d6 >= 0.0 and d5 <= d6:
        return "vertex", 2, c
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return edge_point(t, 2, p)
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        return edge_point(t, 1, p)
    denom = 1.0 / (va + vb + vc)
    v, w = vb * denom, vc * denom
    return "face", None, add(add(a, scale(ab, v)), scale(ac, w))


def edge_point(t, e, p):
    """The point of edge e nearest to p, in the edge's standard frame."""
    v0, x, _y, _z, length = t.edges[e]
    along = min(max(dot(sub(p, v0), x), 0.0), length)
    return "edge", e, add(v0, scale(x, along))


def contacts(scene, msg, bugs):
    """The answer to a contact query: one contact per triangle in reach."""
    centre, radius = tuple(msg["centre"]), msg["radius"]
    reach = radius + (0.0 if "contact-no-distance" in bugs else msg.get("distance", 0.0))
    found = []
    for t in scene["triangles"]:
        kind, feature, point = closest(t, centre)
        towards = sub(centre, point)
        gap = norm(towards)
        behind = dot(t.normal, towards) < 0.0 and "contact-back-faces" not in bugs
        if gap > reach or behind:
            continue  # out of reach, or its back faces the ball
        normal = t.normal
        if "contact-normal" in bugs and gap > 0.0:
            normal = scale(towards, 1.0 / gap)
        contact = {"triangle": t.index, "kind": kind, "point": list(point),
                   "normal": list(normal), "separation": gap - radius}
        if feature is not None:
            contact["feature"] = feature
        found.append(contact)
    return {"type": "contacts", "frame": msg["frame"], "ball": msg.get("ball", 0), "contacts": found}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bug", action="append", default=[], choices=BUGS, help="switch on a deliberate mistake")
    args = parser.parse_args()
    bugs = set(args.bug)
    scene = None
    out = sys.stdout
    for line in sys.stdin:
        msg = json.loads(line)
        if msg["type"] == "scene":
            scene = load_scene(msg)
        elif msg["type"] == "sweep":
            answer = sweep(scene, msg["radius"], tuple(msg["p0"]), tuple(msg["p1"]), bugs)
            answer["type"] = "outcome"
            answer["frame"] = msg["frame"]
            answer["ball"] = msg.get("ball", 0)
            out.write(json.dumps(answer) + "\n")
            out.flush()
        elif msg["type"] == "contact":
            out.write(json.dumps(contacts(scene, msg, bugs)) + "\n")
            out.flush()


if __name__ == "__main__":
    main()
