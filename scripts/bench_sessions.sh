#!/usr/bin/env bash
# Whole-command measurements on traces shaped like real sessions: a
# height-field terrain of about 10^3 or 10^5 triangles, 1, 8 or 64 balls
# rolling and bouncing over it (`sweeptrace record`, seeded, so the same
# arguments give the same trace), 10^5 to 10^6 short sweeps.
#
# For each trace it runs, each under `/usr/bin/time -v`:
#   info                       reading and decoding the trace alone (the floor)
#   replay --outcomes FILE     the outcome lines
#   replay --rrd FILE          the recording at `primary`
#   replay --rrd --detail candidates --frames 0..F   the first ~20,000 sweeps
# and prints one tab-separated line per command: wall and CPU seconds, max
# RSS, and for recordings the file's size, bytes per sweep, and (when the
# `rerun` command of rerun-sdk 0.36.3 is on PATH) its entity paths and
# chunks.
#
#   scripts/bench_sessions.sh                      # the whole matrix, 10^5 sweeps
#   SWEEPS=1000000 BALLS=64 CELLS=224 scripts/bench_sessions.sh   # one case
#   BIN=path/to/sweeptrace OUT=dir scripts/bench_sessions.sh
#
# BALLS and CELLS are space-separated lists (cells per side: 22 gives 968
# triangles, 224 gives 100,352); DETAILS chooses the commands (default
# "outcomes primary candidates"). The traces and outputs go to OUT (default
# a new temporary directory, removed at the end unless KEEP=1).
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET="${CARGO_TARGET_DIR:-target}"
BIN="${BIN:-$TARGET/release/sweeptrace}"
SWEEPS="${SWEEPS:-100000}"
BALLS="${BALLS:-1 8 64}"
CELLS="${CELLS:-22 224}"
DETAILS="${DETAILS:-outcomes primary candidates}"
SEED="${SEED:-1}"
CANDIDATE_SWEEPS="${CANDIDATE_SWEEPS:-20000}"

if [ ! -x "$BIN" ]; then
    echo "bench_sessions: no binary at $BIN (cargo build --release, or set BIN)" >&2
    exit 2
fi
if [ ! -x /usr/bin/time ]; then
    echo "bench_sessions: /usr/bin/time is missing (apt-get install time)" >&2
    exit 2
fi
if [ -n "${OUT:-}" ]; then
    mkdir -p "$OUT"
else
    OUT="$(mktemp -d)"
    if [ "${KEEP:-0}" != 1 ]; then
        trap 'rm -rf "$OUT"' EXIT
    fi
fi

# Runs a command under /usr/bin/time -v; prints "wall cpu max_rss_MB".
timed() {
    local log="$OUT/time.log"
    /usr/bin/time -v -o "$log" "$@" >/dev/null 2>"$OUT/stderr.log" || {
        echo "bench_sessions: failed: $*" >&2
        cat "$OUT/stderr.log" >&2
        exit 2
    }
    awk -F': ' '
        /Elapsed \(wall clock\)/ { n = split($2, p, ":"); wall = 0; for (i = 1; i <= n; i++) wall = wall * 60 + p[i] }
        /User time/ { cpu += $2 }
        /System time/ { cpu += $2 }
        /Maximum resident set size/ { rss = $2 / 1024 }
        END { printf "%.2f\t%.2f\t%.1f", wall, cpu, rss }' "$log"
}

# Entity paths and chunks of a recording ("-" without the rerun command).
recording_stats() {
    if command -v rerun >/dev/null 2>&1; then
        rerun rrd stats "$1" 2>/dev/null | awk '
            /^num_chunks =/ { gsub(/[^0-9]/, "", $0); chunks = $0 }
            /^num_entity_paths =/ { gsub(/[^0-9]/, "", $0); entities = $0 }
            END { printf "%s\t%s", entities, chunks }'
    else
        printf -- "-\t-"
    fi
}

printf "balls\ttriangles\tsweeps\tcommand\twall_s\tcpu_s\tmax_rss_MB\trrd_bytes\tbytes_per_sweep\tentity_paths\tchunks\n"
for cells in $CELLS; do
    triangles=$((2 * cells * cells))
    for balls in $BALLS; do
        # One sweep per ball and frame, plus the sub-steps of collisions
        # (about 0.6 more per ball and frame on the terrain): about SWEEPS
        # sweeps in all; the actual count is printed.
        frames=$(((SWEEPS * 5 / 8 + balls - 1) / balls))
        trace="$OUT/terrain${cells}_balls${balls}_seed${SEED}.mcap"
        if [ ! -f "$trace" ]; then
            "$BIN" record --scene terrain --terrain-cells "$cells" --balls "$balls" \
                --seed "$SEED" --frames "$frames" -o "$trace" >"$OUT/record.log"
        fi
        sweeps="$("$BIN" info "$trace" --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["sweeps"])')"
        row() { printf "%s\t%s\t%s\t%s\t%s\n" "$balls" "$triangles" "$sweeps" "$1" "$2"; }
        row "info" "$(timed "$BIN" info "$trace")	-	-	-	-"
        for detail in $DETAILS; do
            case "$detail" in
            outcomes)
                row "replay --outcomes" "$(timed "$BIN" replay "$trace" --outcomes "$OUT/out.jsonl")	-	-	-	-"
                ;;
            primary | candidates | all)
                rrd="$OUT/out.rrd"
                extra=()
                if [ "$detail" != primary ]; then
                    # About the first CANDIDATE_SWEEPS sweeps (whole frames).
                    last=$(((CANDIDATE_SWEEPS * 5 / 8 + balls - 1) / balls))
                    extra=(--frames "0..$last")
                fi
                times="$(timed "$BIN" replay "$trace" --rrd "$rrd" --detail "$detail" "${extra[@]}")"
                # Sweeps recorded, from the replay's summary.
                n="$(sed -n 's/^\([0-9]*\) sweeps replayed.*/\1/p' "$OUT/stderr.log")"
                size="$(stat -c %s "$rrd")"
                printf "%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n" "$balls" "$triangles" "$n" \
                    "replay --rrd --detail $detail" "$times" "$size" "$((size / n))" "$(recording_stats "$rrd")"
                rm -f "$rrd"
                ;;
            *)
                echo "bench_sessions: unknown DETAILS entry $detail" >&2
                exit 2
                ;;
            esac
        done
    done
done
