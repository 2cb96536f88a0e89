#!/usr/bin/env python3
"""Writes the OBJ of docs/img/edge-classes.png: a 6 x 6 height field with a
valley along x = 3 (concave edges), a ridge along y = 3 (convex edges), flat
edges elsewhere, boundary edges around it, and triangle 15 wound the wrong
way (a flipped-triangle defect).

    python3 scripts/edge_classes_obj.py valley.obj
    sweeptrace record --mesh valley.obj -o valley.mcap --frames 90 --balls 3 \\
        --radius 0.2 --position 1.2,1.2,1.5 --velocity 1.2,1.0,0 \\
        --position-jitter 0.3 --velocity-jitter 0.3
    sweeptrace replay valley.mcap --rrd valley.rrd
"""

import sys

CELLS = 6
FLIPPED = 15


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else "valley.obj"
    lines = []
    for j in range(CELLS + 1):
        for i in range(CELLS + 1):
            z = 0.3 * abs(i - 3) - 0.2 * abs(j - 3)
            lines.append(f"v {i} {j} {z}")
    triangles = []
    for j in range(CELLS):
        for i in range(CELLS):
            a = j * (CELLS + 1) + i + 1  # OBJ indices start at 1
            triangles.append([a, a + 1, a + CELLS + 2])
            triangles.append([a, a + CELLS + 2, a + CELLS + 1])
    t = triangles[FLIPPED]
    triangles[FLIPPED] = [t[0], t[2], t[1]]
    lines += [f"f {a} {b} {c}" for a, b, c in triangles]
    with open(out, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
