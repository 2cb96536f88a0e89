#!/usr/bin/env python3
"""Classify the divergences of a `sweeptrace check --engine ... --json` report
(standard library only), sweep by sweep, into the causes MEASUREMENTS.md uses
for the Jolt engine:

  a  single-precision rounding: the same decision (kind, and the triangle and
     feature or another member of the core's tie set), the answers differ only
     by rounding: delta = |dalpha| * |n . d| (the shift along the engine's
     contact normal) <= ROUNDING_EPS * S, S = max(|p0|inf, |p1|inf) + r
  b  initial overlap: the engine answers alpha = 0 because the ball starts
     within rho of the surface (|p0 - contact| < rho); the core looks for the
     first contact along the path and ignores such starts
  c  no margin: the scene declares a margin eps > 0 and Jolt has none: it hits
     at distance r (|p(alpha) - contact| = r, earlier than the core's rho), or
     answers alpha = 0 for a start between rho and r from the surface
  d  normal convention: the same decision on an edge or vertex, the normal
     differs: Jolt reports the contact normal (centre - contact), the rules
     the triangle's front normal (averaged over tied triangles)
  e  tie member choice: the engine names another triangle or feature than
     the core's, at an alpha within rounding, where the core flags a tie
  f  anything else (listed one by one)

The first matching rule wins, in the order c, b, then a/d/e by the fields that
differ. The report must hold every divergence: run check with
`--max-details 100000`. In the report `expected` is the engine's answer and
`got` the core's.

    sweeptrace check traces/ --engine "node examples/engines/jolt/engine.js" \\
        --json --max-details 100000 > report.json
    python3 examples/engines/jolt/classify.py report.json
    python3 examples/engines/jolt/classify.py report.json --verify-margin sweeptrace

`--verify-margin BIN` replays every (c) sweep with `BIN sweep --trace ...
--margin 0 --json` and counts how many the core then decides as the engine
did (same kind, and triangle/feature or contact point, alpha within
rounding). The alpha = 0 starts do not agree there (the core ignores a start
within its rho, now r); `node engine.js --honour-margin` (a sphere of radius
r - eps) is the check for them.
"""

import argparse
import json
import math
import subprocess
import sys
from collections import Counter, defaultdict

ROUNDING_EPS = 32 * 2.0 ** -23  # 32 float32 epsilons of the sweep's scale
CATEGORIES = {
    "a": "single-precision rounding",
    "b": "initial overlap at alpha 0 (start within rho)",
    "c": "no margin (Jolt detects at r, the rules at rho = r - eps)",
    "d": "normal convention at edges/vertices",
    "e": "tie member choice",
    "f": "anything else",
}


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def norm(a):
    return math.sqrt(dot(a, a))


def angle(a, b):
    if a is None or b is None:
        return None
    c = dot(a, b) / (norm(a) * norm(b))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def measure(dv):
    """The numbers a divergence is classified by."""
    E, C, I = dv["expected"], dv["got"], dv["inputs"]
    p0, p1, r, eps = I["p0"], I["p1"], I["radius"], I["margin"]
    d = sub(p1, p0)
    m = {
        "E": E, "C": C, "r": r, "eps": eps, "rho": r - eps, "d": d, "len": norm(d),
        "S": max(max(map(abs, p0)), max(map(abs, p1))) + r,
        "fields": {f["field"] for f in dv["fields"]},
        "dalpha": abs(E["alpha"] - C["alpha"]),
        "frame": dv["frame"], "ball": dv["ball"], "fragile": dv.get("fragile", []),
    }
    if E["kind"] != "none" and E.get("contact"):
        centre = [p0[i] + E["alpha"] * d[i] for i in range(3)]
        m["d0"] = norm(sub(p0, E["contact"]))  # start to the engine's contact
        m["dat"] = norm(sub(centre, E["contact"]))  # centre at alpha to it
    if E.get("normal"):
        m["delta"] = m["dalpha"] * abs(dot(E["normal"], d))  # shift along the contact normal
    if C.get("normal"):
        m["n_dot_d"] = dot(C["normal"], d)  # the rules' (face) normal . d
    m["angle"] = angle(E.get("normal"), C.get("normal"))
    return m


def rounding_only(m):
    return "delta" in m and m["delta"] <= ROUNDING_EPS * m["S"]


def classify(m):
    E, C, F = m["E"], m["C"], m["fields"]
    hit, core_later = E["kind"] != "none", C["kind"] == "none" or C["alpha"] > E["alpha"]
    if m["eps"] > 0 and hit and core_later and "d0" in m:
        if E["alpha"] == 0 and m["d0"] >= m["rho"]:
            return "c", "start between rho and r: alpha 0"
        if E["alpha"] > 0 and abs(m["dat"] - m["r"]) < m["eps"] / 2:
            return "c", "hit at distance r"
    if hit and E["alpha"] == 0 and core_later and "d0" in m and m["d0"] < m["rho"]:
        if not (F <= {"alpha", "contact", "normal"} and rounding_only(m)):
            return "b", "start within rho"
    if hit and not F & {"kind", "triangle", "feature"}:  # the same decision, or another member of its tie set
        member = "another tie member" if (E["kind"], E["triangle"], E.get("feature")) != (C["kind"], C["triangle"], C.get("feature")) else "same feature"
        if "normal" in F and E["kind"] in ("edge", "vertex"):
            return "d", member
        if "normal" not in F and rounding_only(m):
            return "a", member
    if hit and C["kind"] != "none" and F & {"kind", "triangle", "feature"} and "tie" in m["fragile"] and rounding_only(m):
        return "e", "fragile tie"
    return "f", ""


def pct(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def verify_margin(binary, trace, m):
    out = subprocess.run([binary, "sweep", "--trace", trace, "--frame", str(m["frame"]), "--ball", str(m["ball"]),
                          "--margin", "0", "--json"], capture_output=True, text=True, check=True).stdout
    o = json.loads(out)["outcome"]
    E = m["E"]
    same = o["kind"] == E["kind"] and o["triangle"] == E["triangle"] and o.get("feature") == E.get("feature")
    # another member of a tie (a shared edge or vertex): the same kind and contact point
    member = o["kind"] == E["kind"] and o["contact"] is not None and norm(sub(o["contact"], E["contact"])) <= 1e-5 * m["S"]
    return same or member, abs(o["alpha"] - E["alpha"])


def describe(trace, m):
    E, C = m["E"], m["C"]
    def ans(x):
        if x["kind"] == "none":
            return "none"
        feat = "" if x.get("feature") is None else f".{x['feature']}"
        return f"{x['kind']} {x['triangle']}{feat} alpha {x['alpha']:.9g}"
    return f"{trace} frame {m['frame']} ball {m['ball']}: engine {ans(E)}, core {ans(C)}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", help="the JSON report of check --engine --json --max-details 100000 ('-': stdin)")
    ap.add_argument("--verify-margin", metavar="SWEEPTRACE", help="replay the (c) sweeps at margin 0 with this binary")
    ap.add_argument("--list", default="f", help="categories whose sweeps are listed one by one (default f)")
    args = ap.parse_args()
    report = json.load(sys.stdin if args.report == "-" else open(args.report))
    per_trace = defaultdict(Counter)
    members = defaultdict(list)
    for t in report["traces"]:
        if len(t["divergences"]) != t["divergent"]:
            sys.exit(f"{t['trace']}: {len(t['divergences'])} of {t['divergent']} divergences in the report: rerun with --max-details 100000")
        for dv in t["divergences"]:
            m = measure(dv)
            cat, note = classify(m)
            per_trace[t["trace"]][cat] += 1
            members[cat].append((t["trace"], m, note))
    total = Counter()
    print("divergences by category (a-f), per trace:")
    for trace, c in per_trace.items():
        total.update(c)
        print(f"  {trace}: {sum(c.values())}: " + ", ".join(f"{k} {c[k]}" for k in sorted(c)))
    print(f"  total: {sum(total.values())}: " + ", ".join(f"{k} {total[k]}" for k in sorted(total)))
    for cat in sorted(members):
        rows = members[cat]
        notes = Counter(n for _, _, n in rows if n)
        print(f"\n({cat}) {CATEGORIES[cat]}: {len(rows)}" + (" (" + ", ".join(f"{n}: {k}" for n, k in notes.most_common()) + ")" if notes else ""))
        trace, m, _ = rows[0]
        print(f"  e.g. {describe(trace, m)}")
        if cat == "a":
            da = [m["dalpha"] for _, m, _ in rows]
            dl = [m["dalpha"] * m["len"] for _, m, _ in rows]
            rel = [m["delta"] / m["S"] for _, m, _ in rows]
            for name, v in (("|dalpha|", da), ("|dalpha|*|d|", dl), ("delta/S", rel)):
                print(f"  {name}: median {pct(v, 0.5):.3g}, 90% {pct(v, 0.9):.3g}, 99% {pct(v, 0.99):.3g}, max {max(v):.3g}")
            trace, m, _ = max(rows, key=lambda x: x[1]["dalpha"])
            print(f"  largest |dalpha| {m['dalpha']:.4g}: {describe(trace, m)}; |d| {m['len']:.4g}, "
                  f"n.d {m.get('n_dot_d', float('nan')):.4g} (cos {abs(m.get('n_dot_d', 0)) / m['len']:.3g}), delta {m['delta']:.3g}, S {m['S']:.3g}")
        if cat == "b":
            v = [m["d0"] / m["rho"] for _, m, _ in rows]
            print(f"  |p0 - contact| / rho: min {min(v):.4g}, median {pct(v, 0.5):.4g}, max {max(v):.4g}")
        if cat == "d":
            v = [m["angle"] for _, m, _ in rows]
            rnd = sum(1 for _, m, _ in rows if "alpha" not in m["fields"] or rounding_only(m))
            print(f"  normal angle (deg): min {min(v):.3g}, median {pct(v, 0.5):.3g}, max {max(v):.3g}; alpha within rounding on {rnd} of {len(rows)}")
        if cat == "c" and args.verify_margin:
            agree, count = Counter(), Counter()
            for trace, m, note in rows:
                same, gap = verify_margin(args.verify_margin, trace, m)
                count[note] += 1
                # the same decision, alpha within rounding (the shift along the normal, as in (a))
                if same and gap * abs(dot(m["E"]["normal"], m["d"])) <= ROUNDING_EPS * m["S"]:
                    agree[note] += 1
            for note in count:
                print(f"  replayed at margin 0 ({note}): the core decides as the engine on {agree[note]} of {count[note]}")
        if cat in args.list:
            for trace, m, note in rows:
                extra = f"|dalpha| {m['dalpha']:.3g}, |d| {m['len']:.3g}"
                if m.get("angle") is not None:
                    extra += f", normals {m['angle']:.3g} deg apart"
                print(f"  - {describe(trace, m)} [{','.join(sorted(m['fields']))}; {extra}; fragile {m['fragile']}] {note}")


if __name__ == "__main__":
    main()
