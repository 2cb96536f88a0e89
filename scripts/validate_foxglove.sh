#!/usr/bin/env bash
# Writes `sweeptrace replay --foxglove` files of every sample trace in
# traces/ (and of the fixtures with divergences and tunnels, which the
# samples lack), reads each back with Python's `mcap` package
# (scripts/foxglove_dump.py) and validates every message of every channel
# against Foxglove's published JSON Schemas with Node and ajv
# (tests/foxglove/validate.mjs; @foxglove/schemas and ajv pinned by
# tests/foxglove/package-lock.json). Also checks that the schema copies in
# schemas/foxglove/ equal the package's, and holds every message of a
# `record --contacts` trace to the trace format's own schemas.
#
# Installs what it needs: node and npm with apt when missing, the npm
# packages with `npm ci`, Python's mcap into a virtualenv outside the
# repository. The sample traces are small (about 2,000 sweeps at most), so
# every frame is validated; set FRAMES=A..B to limit the frames of a large
# trace.
#
#   scripts/validate_foxglove.sh                 # the samples and fixtures
#   scripts/validate_foxglove.sh a.mcap b.mcap   # these
set -euo pipefail
cd "$(dirname "$0")/.."

VENV="${VENV:-$HOME/.cache/sweeptrace/venv}"

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "installing node and npm with apt" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq nodejs npm >/dev/null
fi
npm ci --prefix tests/foxglove --no-audit --no-fund --loglevel=error >/dev/null

if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import mcap" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet --disable-pip-version-check mcap==1.6.0
fi
PYTHON="$VENV/bin/python"

if [ "$#" -gt 0 ]; then
    traces=("$@")
else
    shopt -s nullglob
    traces=(traces/*.mcap examples/rapier/rapier_mini_golf.mcap tests/fixtures/wrong_engine_config.mcap tests/fixtures/tunnel_floor.mcap)
    shopt -u nullglob
fi
if [ "${#traces[@]}" -eq 0 ]; then
    echo "validate_foxglove: no traces found in traces/" >&2
    exit 1
fi

cargo build --quiet --bin sweeptrace
BIN="${CARGO_TARGET_DIR:-target}/debug/sweeptrace"
frames=()
if [ -n "${FRAMES:-}" ]; then frames=(--frames "$FRAMES"); fi

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
node tests/foxglove/validate.mjs --check-copies schemas/foxglove
dumps=()
failed=0
# A recording with contact queries: its Foxglove file too (the contact
# queries' channels), and below its own messages against the trace
# format's schemas.
contacts_ok=0
if "$BIN" record --scene mini_golf --frames 100 --contacts -o "$out/contacts.mcap" >"$out/log" 2>&1; then
    contacts_ok=1
    traces+=("$out/contacts.mcap")
else
    echo "FAIL record --contacts" >&2
    cat "$out/log" >&2
    failed=1
fi
for trace in "${traces[@]}"; do
    name="$(basename "$trace" .mcap)"
    file="$out/$name.foxglove.mcap"
    if ! "$BIN" replay "$trace" --foxglove "$file" "${frames[@]}" >"$out/log" 2>&1 || [ ! -f "$file" ]; then
        echo "FAIL $trace: replay --foxglove" >&2
        cat "$out/log" >&2
        failed=1
        continue
    fi
    # "wrote the Foxglove file F (S scenes, N sweeps, M messages)", in the
    # singular for a count of one ("1 scene")
    counts="$(grep -o '([0-9]* scenes\?, [0-9]* sweeps\?' "$out/log" | tr -dc '0-9 ' | tr -s ' ')"
    read -r scenes sweeps <<<"$counts"
    if ! "$PYTHON" scripts/foxglove_dump.py "$file" --scenes "$scenes" --sweeps "$sweeps" \
        --dump "$out/$name.jsonl"; then
        failed=1
        continue
    fi
    dumps+=("$out/$name.jsonl")
done
# The trace format's own schemas (schemas/*.schema.json, embedded in every
# trace): a recording with contact queries, every message held to the
# schema of its channel.
if [ "$contacts_ok" = 1 ] \
    && "$PYTHON" scripts/foxglove_dump.py "$out/contacts.mcap" --trace --dump "$out/contacts.trace.jsonl"; then
    dumps+=("$out/contacts.trace.jsonl")
else
    echo "FAIL the dump of the record --contacts trace" >&2
    failed=1
fi
if [ "${#dumps[@]}" -gt 0 ]; then
    node tests/foxglove/validate.mjs "${dumps[@]}" || failed=1
fi
exit "$failed"
