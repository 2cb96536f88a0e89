#!/usr/bin/env bash
# Checks that cargo-nextest's hash partitions split the trace test cases
# (one test per file in traces/) so that N partitions together run every
# trace exactly once: the sharding recipe of docs/REGRESSION.md.
#
#   scripts/check_partitions.sh        # 2 partitions
#   scripts/check_partitions.sh 3      # 3 partitions
set -euo pipefail
cd "$(dirname "$0")/.."

N="${1:-2}"
if ! command -v cargo-nextest >/dev/null 2>&1; then
    echo "check_partitions: cargo-nextest is not installed (cargo install cargo-nextest)" >&2
    exit 1
fi

list() {
    cargo nextest list --test integration "$@" 2>/dev/null |
        sed -n 's/^.* \(check::trace::.*\)$/\1/p' | sort
}

all="$(list)"
if [ -z "$all" ]; then
    echo "check_partitions: no trace test cases found" >&2
    exit 1
fi
together="$(for k in $(seq 1 "$N"); do list --partition "hash:$k/$N"; done | sort)"
if [ "$together" != "$all" ]; then
    echo "check_partitions: $N partitions do not run every trace exactly once" >&2
    diff <(echo "$all") <(echo "$together") >&2 || true
    exit 1
fi
echo "ok: $(echo "$all" | wc -l) trace cases, each in exactly one of $N partitions"
