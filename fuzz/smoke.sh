#!/usr/bin/env bash
# Fuzz smoke run of fuzz_targets/scene_to_atlas.rs ("from bytes to atlas"), short enough for CI:
#
#   fuzz/smoke.sh [SECONDS]        # default 60
#
# Builds the target with cargo-fuzz (libFuzzer + AddressSanitizer, debug assertions on), starts
# from the seed corpus fuzz/corpus/scene_to_atlas/ (read only: new inputs go to a temporary
# working corpus, deleted afterwards) and fuzzes for SECONDS. Exit status 0 when nothing was found;
# otherwise non-zero, with the crashing input saved under fuzz/artifacts/scene_to_atlas/ and
# its panic message printed.
#
# Needs cargo-fuzz (installed from crates.io when missing) and a toolchain that accepts -Z flags:
# nightly when rustup has one, else the stable toolchain with RUSTC_BOOTSTRAP=1.
# Findings already reported and awaiting fixes are skipped by the target; SCENE_TO_ATLAS_ALL=1
# fuzzes them too.
set -euo pipefail

seconds="${1:-60}"
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here"

if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "smoke.sh: installing cargo-fuzz" >&2
    cargo install cargo-fuzz --locked
fi

if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    cargo=(cargo +nightly fuzz)
else
    echo "smoke.sh: no nightly toolchain; using stable with RUSTC_BOOTSTRAP=1" >&2
    export RUSTC_BOOTSTRAP=1
    cargo=(cargo fuzz)
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/scene_to_atlas_smoke.XXXXXX")"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/corpus" "$work/tmp"

options=(
    -max_total_time="$seconds"
    -max_len=16384
    -timeout=10
    -rss_limit_mb=4096
    -malloc_limit_mb=1024
    -dict=scene_to_atlas.dict
    -close_fd_mask=3 # load_obj's warnings would flood the log; crashes are re-run below
    -print_final_stats=1
)

status=0
# The target writes its OBJ/MTL files under TMPDIR.
TMPDIR="$work/tmp" "${cargo[@]}" run -a scene_to_atlas "$work/corpus" corpus/scene_to_atlas \
    -- "${options[@]}" || status=$?

if [ "$status" -ne 0 ]; then
    echo "smoke.sh: the fuzzer found something (exit $status); re-running the saved inputs:" >&2
    for input in artifacts/scene_to_atlas/*; do
        [ -f "$input" ] || continue
        echo "=== $input" >&2
        TMPDIR="$work/tmp" "${cargo[@]}" run -a scene_to_atlas "$input" 2>&1 |
            grep -E -A12 "panicked at|ERROR: (AddressSanitizer|libFuzzer)" >&2 || true
    done
fi
exit "$status"
