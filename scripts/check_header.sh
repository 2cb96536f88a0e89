#!/usr/bin/env bash
# Checks that the C API's header, capi/include/sweeptrace.h, is what
# cbindgen generates from capi/src/lib.rs (with capi/cbindgen.toml).
#   scripts/check_header.sh           # exit 1 and a diff when it is not
#   scripts/check_header.sh --bless   # rewrite it
# Needs cbindgen on PATH (cargo install cbindgen --locked --version 0.29.2).
set -euo pipefail
cd "$(dirname "$0")/.."

header=capi/include/sweeptrace.h
generated=$(mktemp)
trap 'rm -f "$generated"' EXIT
cbindgen --quiet --config capi/cbindgen.toml --output "$generated" capi/src/lib.rs

if [ "${1:-}" = "--bless" ]; then
    cp "$generated" "$header"
    echo "wrote $header"
elif ! diff -u "$header" "$generated"; then
    echo "error: $header is not what cbindgen generates from capi/src/lib.rs; rewrite it with: scripts/check_header.sh --bless" >&2
    exit 1
fi
