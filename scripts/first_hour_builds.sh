#!/usr/bin/env bash
# What a new user waits for before the tour, from an empty target
# directory: the README's main command (`cargo run -- replay
# traces/record_mini_golf.mcap`, which builds the binary), then its test
# command (`cargo test && cargo test -p sweeptrace-capi`, which builds the
# tests and runs them), then the tour's four commands on the binary the
# first command built (target/debug, as the README's tour says). Prints
# one tab-separated line per step (wall seconds, user + system CPU
# seconds), the total, the load average before and after, and the size of
# the target directory.
#
#   scripts/first_hour_builds.sh                # a fresh target dir under $TMPDIR
#   KEEP=1 scripts/first_hour_builds.sh         # keep it (its path is printed)
#
# The registry's sources must already be downloaded (`cargo fetch`), so
# that the network is not measured. CONTRIBUTING.md ("Build times") has
# the figures. Run it on a quiet machine: the times are wall times.
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
target="$(mktemp -d "${TMPDIR:-/tmp}/first-hour-target.XXXXXX")"
work="$(mktemp -d "${TMPDIR:-/tmp}/first-hour-work.XXXXXX")"
cleanup() {
    rm -rf "$work"
    if [[ "${KEEP:-0}" != 1 ]]; then rm -rf "$target"; fi
}
trap cleanup EXIT
export CARGO_TARGET_DIR="$target"

cd "$root"
cargo fetch --locked >/dev/null

# step NAME DIR COMMAND...: runs COMMAND in DIR under /usr/bin/time and
# prints NAME, wall seconds and CPU seconds.
total=0
step() {
    local name="$1" dir="$2"
    shift 2
    local times="$work/time.txt"
    (cd "$dir" && /usr/bin/time -f '%e %U %S' -o "$times" "$@") >"$work/$name.log" 2>&1 || {
        echo "error: step '$name' failed; its output:" >&2
        tail -n 30 "$work/$name.log" >&2
        exit 1
    }
    read -r wall user sys <"$times"
    total=$(awk -v a="$total" -v b="$wall" 'BEGIN { print a + b }')
    printf '%s\t%s s wall\t%s s CPU\n' "$name" "$wall" "$(awk -v a="$user" -v b="$sys" 'BEGIN { print a + b }')"
}

echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
step "cargo run -- replay (main command)" "$work" \
    cargo run --locked --manifest-path "$root/Cargo.toml" -- replay "$root/traces/record_mini_golf.mcap"
step "cargo test && cargo test -p sweeptrace-capi" "$root" \
    sh -c 'cargo test --locked && cargo test --locked -p sweeptrace-capi'
export PATH="$target/debug:$PATH"
step "tour: record, replay --rrd, check" "$work" sh -c \
    'sweeptrace record --scene mini_golf -o golf.mcap && sweeptrace replay golf.mcap --rrd golf.rrd && sweeptrace check golf.mcap'
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
printf 'total\t%s s wall\n' "$total"
printf 'target dir\t%s\n' "$(du -sh "$target" | cut -f1)"
if [[ "${KEEP:-0}" == 1 ]]; then echo "target dir kept: $target"; fi
