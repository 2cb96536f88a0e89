#!/usr/bin/env python3
"""Sort the divergences of a `sweeptrace check --engine ... --json` report
on the Rapier engine (standard library only), sweep by sweep, into causes:

  "Leaving" and "behind" are judged with the exact geometry of the triangle
  the engine names (its vertices read from the trace's first scene, the
  only one of each sample trace, through the engine protocol: --sweeptrace
  BIN): q is its nearest point to the centre at the engine's alpha, and the
  path leaves it when d . (q - centre) <= 0.

  leaving_alpha0   a hit at alpha 0 for a ball that starts within its radius
                   of the triangle (up to 1e-3 r) and leaves it, where the
                   reference has no hit at alpha 0: Rapier's
                   stopAtPenetration = true. No [engine] value declares it
                   yet: initial_overlap = "alpha0" asks for an approach.
  alpha0_facing    a hit at alpha 0 for a ball within its radius that moves
                   toward the triangle's nearest point, where the reference
                   has no hit at alpha 0: under initial_overlap = "alpha0"
                   the core judges "toward" by the face's facing rule, not at
                   that point; without alpha0 declared (the report's
                   conventions), the reference ignores the overlap
                   (alpha0_undeclared).
  alpha0_member    a hit at alpha 0 where the reference has one too, on
                   another triangle or feature: a member of the alpha-0 tie
                   (the ball within its radius of both), which the report
                   counts as a kind and triangle mismatch because its normal
                   or contact differs (note: whether the engine's normal is
                   the contact normal, centre minus contact).
  leaving_grazing  a hit with alpha > 0 on a triangle the path leaves at that
                   alpha, where the reference has no hit or a later one: a
                   false hit while leaving at a grazing angle.
  back_side        a hit on a triangle whose plane the centre starts behind
                   (and approaches): Rapier's trimesh is two-sided
                   (sides = "two").
  past_end         a hit the reference places beyond the path's end (the
                   engine's test is beyond_end).
  missed           no hit where the reference has one.
  edge_normal      the same decision at an edge or vertex, only the normal
                   differs, and the engine's normal is the contact normal
                   (centre at alpha minus contact): Rapier's convention at
                   every edge, where the table's reference (normal = "face")
                   wants the face normal.
  accuracy         the same decision (kind, triangle and feature, or a member
                   of the tie), alpha, contact or normal beyond the f32
                   bound: Rapier's GJK/EPA tolerances. Split by the fields
                   that differ; sizes in units of the f32 budget
                   16 u32 S (u32 = 2^-24, S = max |p0|, |p1| + r).
  feature          another kind or feature of a hit on the same surface at
                   alpha > 0 (the witness point, off by Rapier's tolerance,
                   falls inside a face instead of on its edge, or the
                   reverse).
  seam_bump        an edge or vertex hit earlier than the reference's hit (on
                   another triangle, or none), where the centre at the
                   engine's alpha is farther than r from the triangle: the
                   ball bumps into an edge it does not reach, at a seam.
  other            anything else (listed one by one).

The first that applies wins, in this order. `expected` in the report is the
engine's answer and `got` the core's. Run check with `--max-details 100000`
so that the report holds every divergence:

    sweeptrace check traces/ --engine "node examples/engines/rapier-js/engine.js" \\
        --config examples/engines/rapier-js/sweeptrace.toml --json --max-details 100000 > report.json
    python3 examples/engines/rapier-js/classify.py report.json
"""

import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile
from collections import Counter, defaultdict

U32 = 2.0 ** -24
BUDGET = 16  # the f32 budget in units of u32 S (docs/ENGINES.md, precision)
CAUSES = [
    "leaving_alpha0", "alpha0_facing", "alpha0_undeclared", "alpha0_member", "leaving_grazing", "back_side", "past_end",
    "missed", "edge_normal", "accuracy", "feature", "seam_bump", "other",
]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def norm(a):
    return math.sqrt(dot(a, a))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def angle(a, b):
    c = dot(a, b) / (norm(a) * norm(b))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def closest_point(p, a, b, c):
    """The point of triangle (a, b, c) nearest p (Ericson)."""
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    d1, d2 = dot(ab, ap), dot(ac, ap)
    if d1 <= 0 and d2 <= 0:
        return a
    bp = sub(p, b)
    d3, d4 = dot(ab, bp), dot(ac, bp)
    if d3 >= 0 and d4 <= d3:
        return b
    cp = sub(p, c)
    d5, d6 = dot(ab, cp), dot(ac, cp)
    vc, vb, va = d1 * d4 - d3 * d2, d5 * d2 - d1 * d6, d3 * d6 - d5 * d4
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        return [a[i] + ab[i] * d1 / (d1 - d3) for i in range(3)]
    if d6 >= 0 and d5 <= d6:
        return c
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        return [a[i] + ac[i] * d2 / (d2 - d6) for i in range(3)]
    if va <= 0 and d4 - d3 >= 0 and d5 - d6 >= 0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return [b[i] + (c[i] - b[i]) * w for i in range(3)]
    denom = va + vb + vc
    return [a[i] + ab[i] * vb / denom + ac[i] * vc / denom for i in range(3)]


def verdict(dv):
    tests = dv.get("expected_tests") or []
    return tests[0].get("verdict") if tests else None


def measure(dv, corners):
    E, C, I = dv["expected"], dv["got"], dv["inputs"]
    p0, p1, r = I["p0"], I["p1"], I["radius"]
    d = sub(p1, p0)
    m = {
        "E": E, "C": C, "r": r, "d": d, "len": norm(d),
        "S": max(max(map(abs, p0)), max(map(abs, p1))) + r,
        "fields": {f["field"] for f in dv["fields"]},
        "verdict": verdict(dv), "frame": dv["frame"], "ball": dv["ball"],
        "fragile": dv.get("fragile", []),
    }
    m["unit"] = BUDGET * U32 * m["S"]
    if E["kind"] != "none":
        a, b, c = corners[E["triangle"]]
        n = cross(sub(b, a), sub(c, a))
        centre = [p0[i] + E["alpha"] * d[i] for i in range(3)]
        q = closest_point(centre, a, b, c)
        m["dist"] = norm(sub(centre, q))  # the exact distance at the engine's alpha
        q0 = closest_point(p0, a, b, c)
        m["dist0"] = norm(sub(p0, q0))
        # At alpha 0: how far the engine's contact and normal are from the
        # exact nearest point of its triangle and the normal toward p0.
        m["contact_off0"] = norm(sub(E["contact"], q0))
        m["normal_off0"] = angle(E["normal"], sub(p0, q0)) if m["dist0"] > 0 else None
        m["approaching"] = dot(d, sub(q, centre)) > 0
        m["behind"] = dot(n, sub(p0, a)) < 0
        arm = sub(centre, E["contact"])
        m["contact_normal_angle"] = angle(E["normal"], arm) if norm(arm) > 0 else None
    if E["kind"] != "none" and C["kind"] != "none":
        m["dalpha_path"] = abs(E["alpha"] - C["alpha"]) * m["len"]  # along the path
        m["dcontact"] = norm(sub(E["contact"], C["contact"]))
        m["dnormal"] = angle(E["normal"], C["normal"])
    return m


def same_decision(m):
    E, C = m["E"], m["C"]
    if E["kind"] == "none" or C["kind"] == "none":
        return False
    if not m["fields"] & {"kind", "triangle", "feature"}:
        return True
    # Another member of a tie the core flags, at the same alpha.
    return "tie" in m["fragile"] and "alpha" not in m["fields"]


def classify(m, alpha0):
    E, C, F = m["E"], m["C"], m["fields"]
    hit, core_hit = E["kind"] != "none", C["kind"] != "none"
    if not hit:
        return ("missed", "") if core_hit else ("other", "")
    core_later = not core_hit or C["alpha"] > E["alpha"]
    if E["alpha"] == 0 and core_later and m["dist0"] <= m["r"] * (1 + 1e-3):
        if not m["approaching"]:
            return "leaving_alpha0", ""
        return ("alpha0_facing", "") if alpha0 else ("alpha0_undeclared", "")
    if E["alpha"] == 0 and C["alpha"] == 0 and F & {"kind", "triangle", "feature"} and m["dist0"] <= m["r"] * (1 + 1e-3):
        contact_normal = m["contact_normal_angle"] is not None and m["contact_normal_angle"] < 0.5
        return "alpha0_member", f"{C['kind']} -> {E['kind']}, " + ("the contact normal" if contact_normal else "another normal")
    if E["alpha"] > 0 and not m["approaching"] and core_later:
        return "leaving_grazing", ""
    if m["behind"] and m["approaching"]:
        return "back_side", ""
    if m["verdict"] == "beyond_end":
        return "past_end", ""
    if same_decision(m):
        if F == {"normal"} and E["kind"] in ("edge", "vertex") and m["contact_normal_angle"] is not None \
                and m["contact_normal_angle"] < 0.5:
            return "edge_normal", ""
        return "accuracy", ",".join(sorted(F - {"triangle", "feature"}))
    if E["kind"] in ("edge", "vertex") and core_later and m["dist"] > m["r"] * (1 + 1e-5):
        return "seam_bump", ""
    if core_hit and (E["triangle"] == C["triangle"] or m.get("dcontact", math.inf) < 1e-2 * m["r"]):
        return "feature", f"{C['kind']} -> {E['kind']}"
    return "other", ""


def serve_scene_dump(path):
    """An engine that writes the first scene it is sent to `path` (JSON) and
    answers every sweep with no collision: how the triangles' vertices are
    read from a trace, through the engine protocol."""
    written = False
    for line in sys.stdin:
        if not line.strip():
            continue
        msg = json.loads(line)
        if msg.get("type") == "scene" and not written:
            with open(path, "w") as f:
                json.dump({"vertices": msg["vertices"], "triangles": msg["triangles"]}, f)
            written = True
        elif msg.get("type") == "sweep":
            print(json.dumps({"frame": msg["frame"], "ball": msg.get("ball", 0), "alpha": 1.0, "kind": "none"}), flush=True)


def scene_of(sweeptrace, trace, scratch):
    """The corners of every triangle of the trace's scene, read by running
    `sweeptrace check TRACE --engine` with this script as the engine."""
    out = os.path.join(scratch, "scene.json")
    engine = f"{shlex.quote(sys.executable)} {shlex.quote(os.path.abspath(__file__))} --dump-scene {shlex.quote(out)}"
    subprocess.run([sweeptrace, "check", trace, "--engine", engine, "--no-config", "--max-details", "0"],
                   capture_output=True, check=False)
    with open(out) as f:
        scene = json.load(f)
    return [[scene["vertices"][i] for i in t] for t in scene["triangles"]]


def pct(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def describe(trace, m):
    def ans(x):
        if x["kind"] == "none":
            return "none"
        feat = "" if x.get("feature") is None else f".{x['feature']}"
        return f"{x['kind']} {x['triangle']}{feat} alpha {x['alpha']:.7g}"
    name = trace.rsplit("/", 1)[-1]
    return f"{name} frame {m['frame']} ball {m['ball']}: engine {ans(m['E'])}, core {ans(m['C'])}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", nargs="?", help="the JSON report of check --engine --json --max-details 100000 ('-': stdin)")
    ap.add_argument("--sweeptrace", default="sweeptrace", help="the sweeptrace binary that reads the traces' scenes (default: sweeptrace on PATH)")
    ap.add_argument("--dump-scene", metavar="FILE", help=argparse.SUPPRESS)
    ap.add_argument("--list", default="other", help="causes whose sweeps are listed one by one, comma-separated (default other)")
    args = ap.parse_args()
    if args.dump_scene:
        return serve_scene_dump(args.dump_scene)
    if not args.report:
        ap.error("the report is required")
    listed = set(args.list.split(","))
    report = json.load(sys.stdin if args.report == "-" else open(args.report))
    per_trace = defaultdict(Counter)
    rows = defaultdict(list)
    for t in report["traces"]:
        if len(t["divergences"]) != t["divergent"]:
            sys.exit(f"{t['trace']}: {len(t['divergences'])} of {t['divergent']} divergences in the report: rerun with --max-details 100000")
        with tempfile.TemporaryDirectory() as scratch:
            corners = scene_of(args.sweeptrace, t["trace"], scratch)
        for dv in t["divergences"]:
            m = measure(dv, corners)
            cause, note = classify(m, (t.get("conventions") or {}).get("initial_overlap") == "alpha0")
            per_trace[t["trace"]][cause] += 1
            rows[cause].append((t["trace"], m, note))
    total = Counter()
    print("divergences by cause, per trace:")
    for trace, c in per_trace.items():
        total.update(c)
        print(f"  {trace}: {sum(c.values())}: " + ", ".join(f"{k} {c[k]}" for k in CAUSES if c[k]))
    print(f"  total: {sum(total.values())}: " + ", ".join(f"{k} {total[k]}" for k in CAUSES if total[k]))
    for cause in CAUSES:
        if not rows[cause]:
            continue
        found = rows[cause]
        notes = Counter(n for _, _, n in found if n)
        print(f"\n{cause}: {len(found)}" + (" (" + "; ".join(f"{n}: {k}" for n, k in notes.most_common()) + ")" if notes else ""))
        trace, m, _ = found[0]
        print(f"  e.g. {describe(trace, m)}")
        if cause in ("leaving_alpha0", "alpha0_facing", "alpha0_undeclared", "alpha0_member"):
            v = [m["dist0"] / m["r"] for _, m, _ in found]
            print(f"  start's distance to the triangle / r: min {min(v):.9g}, median {pct(v, 0.5):.9g}, max {max(v):.9g}")
            v = [m["contact_off0"] / m["unit"] for _, m, _ in found]
            w = [m["normal_off0"] for _, m, _ in found if m["normal_off0"] is not None]
            print(f"  the engine's contact from the exact nearest point of its triangle, in f32 budgets: median {pct(v, 0.5):.3g}, max {max(v):.4g}; "
                  f"its normal from the exact one (centre minus that point): median {pct(w, 0.5):.3g} deg, max {max(w):.3g} deg")
        if cause in ("leaving_grazing", "past_end", "back_side", "seam_bump", "other"):
            v = [(m["dist"] - m["r"]) / m["r"] for _, m, _ in found]
            print(f"  (distance at the engine's alpha - r) / r: min {min(v):.3g}, median {pct(v, 0.5):.3g}, max {max(v):.3g}")
        if cause == "accuracy":
            for key, what in (("dcontact", "contact distance"), ("dalpha_path", "|dalpha| |d|")):
                v = [(m[key] / m["unit"], m) for _, m, _ in found if m[key] > 0]
                if v:
                    worst = max(v, key=lambda x: x[0])
                    print(f"  {what} in f32 budgets: median {pct([x for x, _ in v], 0.5):.3g}, "
                          f"max {worst[0]:.4g} ({worst[1][key]:.3g} with r = {worst[1]['r']}: {describe('', worst[1])})")
            v = [(m["dnormal"], m) for _, m, _ in found if "normal" in m["fields"]]
            if v:
                worst = max(v, key=lambda x: x[0])
                print(f"  normal angle (deg) where it differs: median {pct([x for x, _ in v], 0.5):.3g}, max {worst[0]:.3g} ({describe('', worst[1])})")
            early = sum(1 for _, m, _ in found if "alpha" in m["fields"] and m["E"]["alpha"] < m["C"]["alpha"])
            late = sum(1 for _, m, _ in found if "alpha" in m["fields"] and m["E"]["alpha"] > m["C"]["alpha"])
            print(f"  alpha: {early} earlier than the core's, {late} later")
        if cause in listed:
            for trace, m, note in found:
                print(f"  - {describe(trace, m)} [{','.join(sorted(m['fields']))}; verdict {m['verdict']}; "
                      f"fragile {m['fragile']}] {note}")


if __name__ == "__main__":
    main()
