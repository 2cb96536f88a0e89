#!/usr/bin/env bash
# Rebuilds the sample traces in traces/ bit for bit with the recorder:
#
#     scripts/regenerate_traces.sh            # uses target/debug/sweeptrace (built if needed)
#     scripts/regenerate_traces.sh --release  # uses target/release/sweeptrace
#     SWEEPTRACE_BIN=path/to/sweeptrace scripts/regenerate_traces.sh  # no build
#
# Run from anywhere inside the repository. Every trace is deterministic: the
# same seed and options give the same bytes (no wall clock; the file's
# library string names the crate version, so a version bump changes them).
# Together they cover face, edge and vertex collisions, misses, several
# balls, a non-zero margin and the strict facing rule (tests/record.rs checks
# this coverage).
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ -n "${SWEEPTRACE_BIN:-}" ]]; then
    bin="$SWEEPTRACE_BIN"
elif [[ "${1:-}" == "--release" ]]; then
    cargo build --release --quiet
    bin=target/release/sweeptrace
else
    cargo build --quiet
    bin=target/debug/sweeptrace
fi
mkdir -p traces

record() {
    local out="$1"
    shift
    "$bin" record "$@" -o "traces/$out" > /dev/null
    echo "wrote traces/$out"
}

# Mini-golf: putts up the ramp, off its drop, into the cup and off the walls
# (face and edge collisions, misses; 4 balls).
record record_mini_golf.mcap --scene mini_golf --balls 4 --frames 300 --seed 1
# Balls dropped around a corner of the cube with a margin of 0.05: vertex,
# edge and face collisions, then falls off the cube (stopped at the bounds).
record record_cube_corner_margin.mcap --scene cube --balls 8 --frames 120 --seed 3 --margin 0.05
# The bowl with a margin: balls circling and flying over the rim.
record record_bowl_margin.mcap --scene bowl --balls 4 --frames 300 --seed 2 --margin 0.02
# Inside the closed box, strict facing rule.
record record_box_strict.mcap --scene box --balls 4 --frames 240 --seed 4 --facing strict
# A small terrain (48 x 48 cells, 4,608 triangles): boulders rolling over crests.
record record_terrain.mcap --scene terrain --terrain-cells 48 --balls 4 --frames 300 --seed 5
