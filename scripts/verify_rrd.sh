#!/usr/bin/env bash
# Replays every trace in traces/ (or the traces given as arguments) into a
# Rerun recording and checks each one with Rerun's own `rerun rrd verify`.
#
# The viewer's Python package (rerun-sdk, the version the crate pins) is
# installed into a virtual environment outside the repository unless a
# `rerun` of that version is already on PATH.
#
#   scripts/verify_rrd.sh                  # every traces/*.mcap
#   scripts/verify_rrd.sh a.mcap b.mcap    # these
#   VENV=/some/dir scripts/verify_rrd.sh   # another venv location
set -euo pipefail
cd "$(dirname "$0")/.."

RERUN_VERSION=0.36.3
VENV="${VENV:-$HOME/.cache/sweeptrace/venv}"

if command -v rerun >/dev/null 2>&1 && rerun --version 2>/dev/null | grep -q " $RERUN_VERSION"; then
    RERUN=rerun
else
    if [ ! -x "$VENV/bin/python" ]; then
        python3 -m venv "$VENV"
    fi
    "$VENV/bin/pip" install --quiet --disable-pip-version-check "rerun-sdk==$RERUN_VERSION"
    RERUN="$VENV/bin/rerun"
fi
# No usage data from CI runs.
"$RERUN" analytics disable >/dev/null 2>&1 || true

if [ "$#" -gt 0 ]; then
    traces=("$@")
else
    shopt -s nullglob
    traces=(traces/*.mcap)
    shopt -u nullglob
fi
if [ "${#traces[@]}" -eq 0 ]; then
    echo "verify_rrd: no traces found in traces/" >&2
    exit 1
fi

cargo build --quiet --bin sweeptrace
BIN="${CARGO_TARGET_DIR:-target}/debug/sweeptrace"

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
failed=0
for trace in "${traces[@]}"; do
    name="$(basename "$trace" .mcap)"
    for detail in primary candidates all; do
        rrd="$out/$name.$detail.rrd"
        if ! "$BIN" replay "$trace" --rrd "$rrd" --detail "$detail" >"$out/log" 2>&1; then
            # Exit code 1 is a trace that ends early: its recording is still complete.
            if [ ! -f "$rrd" ]; then
                echo "FAIL $trace ($detail): replay wrote no recording" >&2
                cat "$out/log" >&2
                failed=1
                continue
            fi
        fi
        if "$RERUN" rrd verify "$rrd" >"$out/verify" 2>&1; then
            echo "ok   $trace ($detail): $(tail -n 1 "$out/verify")"
        else
            echo "FAIL $trace ($detail): rerun rrd verify" >&2
            cat "$out/verify" >&2
            failed=1
        fi
    done
done
exit "$failed"
