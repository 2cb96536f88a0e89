#!/usr/bin/env bash
# Writes what the command line prints for a fixed set of inputs into a
# folder, so that a refactoring can be shown to change no behaviour:
#
#   scripts/behaviour_snapshot.sh BIN OUT_DIR
#   (build the old binary, snapshot; build the new one, snapshot; then)
#   diff -r OLD_DIR NEW_DIR
#
# Covered: `sweep --all` and `sweep --json` over every built-in scene on a
# fixed set of paths, `replay --outcomes` and `check --json` on every
# sample trace and fixture, `info --json`, `diff` of one trace under two
# margins, and the exit code of every command.
set -uo pipefail
cd "$(dirname "$0")/.."

if [ "$#" -ne 2 ]; then
    echo "usage: $0 BIN OUT_DIR" >&2
    exit 2
fi
BIN="$1"
OUT="$2"
mkdir -p "$OUT"

# run NAME ARGS...: stdout to NAME.out, stderr to NAME.err, exit code to NAME.code.
run() {
    local name="$1"
    shift
    "$BIN" "$@" >"$OUT/$name.out" 2>"$OUT/$name.err"
    echo "$?" >"$OUT/$name.code"
    # Wall-clock times differ from run to run: not behaviour.
    sed -i 's/^time: .*/time: (not compared)/' "$OUT/$name.err"
}

paths=(
    "0,3,0.2 0.9,-3,0.2"
    "1.25,0.125,3 1.25,0.125,-3"
    "1.4,1.4,1.4 -0.2,-0.2,-0.2"
    "2,-0.3,3 2,-0.3,-3"
    "-0.3,-0.2,3 -0.3,-0.2,-3"
    "1,1,3 1,1,-3"
    "0.5,0.5,0.4 0.5,0.5,-1"
    "5,5,5 6,6,6"
    "0,0,10 0,0,-10"
    "3,1,4 -2,0.5,-1"
)
for scene in cube triangle mini_golf bowl box; do
    i=0
    for p in "${paths[@]}"; do
        read -r from to <<<"$p"
        run "sweep.$scene.$i.all" sweep --scene "$scene" --radius 0.5 --from "$from" --to "$to" --all
        run "sweep.$scene.$i.json" sweep --scene "$scene" --radius 0.5 --from "$from" --to "$to" --json
        run "sweep.$scene.$i.strict" sweep --scene "$scene" --radius 0.5 --margin 0.1 \
            --facing strict --from "$from" --to "$to"
        i=$((i + 1))
    done
done
run sweep.bad_radius sweep --scene cube --radius -1 --from 0,0,3 --to 0,0,-3
run sweep.bad_scene sweep --scene nowhere --from 0,0,3 --to 0,0,-3

for trace in traces/*.mcap tests/fixtures/*.mcap; do
    name="$(basename "$trace" .mcap)"
    run "replay.$name" replay "$trace" --outcomes -
    run "check.$name" check "$trace" --json
    run "check_text.$name" check "$trace"
    run "info.$name" info "$trace" --json
done
run diff.margins diff traces/record_bowl_margin.mcap traces/record_bowl_margin.mcap --margin-b 0.2
run check.dir check traces --json

# A truncated trace: every command must give the same exit code.
truncated="$(mktemp --suffix=.mcap)"
head -c 30000 traces/record_mini_golf.mcap >"$truncated"
run truncated.replay replay "$truncated" --outcomes -
run truncated.check check "$truncated"
run truncated.info info "$truncated"
rm -f "$truncated"
# Temporary names differ between runs; keep only the file names.
sed -i -E 's#/tmp/[^ :]*\.mcap#TRUNCATED.mcap#g' "$OUT"/truncated.*
# Wall-clock figures differ between runs.
sed -i -E 's/time in the core: [0-9.]+ s/time in the core: T s/' "$OUT"/*.err
