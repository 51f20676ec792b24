#!/usr/bin/env bash
# AddressSanitizer stress run (issue 37, docs/testing.md "Sanitizer stress run").
#
# Builds the workspace with AddressSanitizer (nightly Rust) into target/asan, then runs:
#   1. every test binary, JOBS binaries at a time, each with its default parallel test threads,
#      ROUNDS times (GL contexts made and dropped in many threads at once);
#   2. the GL layer's own context and transfer tests THREAD_ROUNDS times (contexts made and
#      dropped in four threads, two contexts in one thread, disturbed pixel-store state), and
#      the test whose threads end as the process ends alone, EXIT_RUNS times (the exit-time
#      double free in libglvnd's per-thread EGL state, docs/perf-log.md 2026-12-03);
#   3. SOLVES solves on each backend (EGL and OSMesa), GPU and CPU solver, and `validate --quick`;
#   4. the interactive viewer's window context under Xvfb (a screenshot run), VIEWER_RUNS times;
#   5. the driver matrix, `radiosity check --drivers all`;
#   6. without the sanitizer (an ordinary release build, whose timing is the users'), the test
#      binaries whose tests draw in several threads at once, PARALLEL_RUNS times each: llvmpipe
#      crashed when two threads' contexts drew at once (docs/perf-log.md, 2026-12-04), which the
#      sanitized build's timing hid.
# Every run must exit 0 and no log may hold a sanitizer report; the summary gives the runs, the
# crashes (a signal, or a sanitizer or heap report), the other failures (a failed test, an
# error exit) and the minutes. Exit status 0 only if all is clean.
#
# Environment: ROUNDS (2), JOBS (2), THREAD_ROUNDS (20), EXIT_RUNS (200), SOLVES (6),
# VIEWER_RUNS (2), PARALLEL_RUNS (4), PARALLEL_TESTS (tuning concurrent_solves validation speed_guard),
# RUN_TIMEOUT (seconds one run may take, 1800: a hang fails), LOG_DIR (target/asan/stress-<date>). Needs `rustup toolchain install nightly`, Mesa's EGL and
# OSMesa drivers, and xvfb-run (the same packages as .ci/run).
set -uo pipefail
cd "$(dirname "$0")/.."

ROUNDS=${ROUNDS:-2}
JOBS=${JOBS:-2}
THREAD_ROUNDS=${THREAD_ROUNDS:-20}
EXIT_RUNS=${EXIT_RUNS:-200}
RUN_TIMEOUT=${RUN_TIMEOUT:-1800}
SOLVES=${SOLVES:-6}
VIEWER_RUNS=${VIEWER_RUNS:-2}
PARALLEL_RUNS=${PARALLEL_RUNS:-4}
PARALLEL_TESTS=${PARALLEL_TESTS:-tuning concurrent_solves validation speed_guard}
TRIPLE=x86_64-unknown-linux-gnu
TARGET_DIR=target/asan
LOG_DIR=${LOG_DIR:-$TARGET_DIR/stress-$(date +%Y%m%d-%H%M%S)}
mkdir -p "$LOG_DIR"
LOG_DIR=$(cd "$LOG_DIR" && pwd)

# detect_leaks=0: Mesa keeps its screen and caches to the end on purpose.
# verify_asan_link_order=0: tests/api_trace.rs preloads apitrace's wrapper before the runtime.
export ASAN_OPTIONS=detect_leaks=0:verify_asan_link_order=0
export RUSTFLAGS=-Zsanitizer=address
export RUSTDOCFLAGS=-Zsanitizer=address

started=$(date +%s)
runs=0
crashes=0
failures=0

# What AddressSanitizer and glibc's malloc print when they find the heap damaged.
HEAP_REPORT='ERROR: AddressSanitizer|double free or corruption|corrupted (size|double-linked|unsorted|top)|free\(\): |malloc\(\): |malloc_consolidate\(\)|realloc\(\): '

# verdict NAME EXIT: 0 if the run of NAME exited 0 and its log holds no sanitizer or heap report;
# 1 if it crashed (killed by a signal, or a sanitizer or heap report); 2 if it failed otherwise.
verdict() {
    local log="$LOG_DIR/$1.log"
    if [ "$2" -eq 124 ]; then
        echo "TIMED OUT: $1 (after $RUN_TIMEOUT s), see $log"
        return 2
    elif [ "$2" -ge 128 ] || grep -Eq "$HEAP_REPORT" "$log"; then
        echo "CRASHED: $1 (exit $2), see $log"
        grep -E -m 5 "$HEAP_REPORT|panicked" "$log" | sed 's/^/    /'
        return 1
    elif [ "$2" -ne 0 ]; then
        echo "FAILED: $1 (exit $2), see $log"
        grep -E -m 5 "panicked|^error" "$log" | sed 's/^/    /'
        return 2
    fi
}

# count VERDICT: add one run with that verdict to the totals; the verdict again.
count() {
    runs=$((runs + 1))
    case $1 in
        1) crashes=$((crashes + 1)) ;;
        2) failures=$((failures + 1)) ;;
    esac
    return "$1"
}

# run NAME COMMAND...: one run, its output in LOG_DIR/NAME.log, counted; 0 if clean.
run() {
    local name=$1
    shift
    timeout -k 10 "$RUN_TIMEOUT" "$@" >"$LOG_DIR/$name.log" 2>&1
    verdict "$name" $?
    count $?
}

echo "== building with AddressSanitizer into $TARGET_DIR (logs: $LOG_DIR)"
build=(cargo +nightly test --release --target "$TRIPLE" --target-dir "$TARGET_DIR" --workspace --no-run)
if ! "${build[@]}" --message-format=json >"$LOG_DIR/build.json" 2>"$LOG_DIR/build.log"; then
    tail -20 "$LOG_DIR/build.log"
    echo "the ASan build failed"
    exit 1
fi
mapfile -t tests < <(jq -r 'select(.profile.test == true) | .executable // empty' "$LOG_DIR/build.json" | sort -u)
bin="$PWD/$TARGET_DIR/$TRIPLE/release/radiosity"
[ -x "$bin" ] || { echo "no ASan radiosity binary at $bin"; exit 1; }
echo "   ${#tests[@]} test binaries"

echo "== 1. test binaries, $JOBS at a time, $ROUNDS rounds"
for round in $(seq "$ROUNDS"); do
    pids=()
    for t in "${tests[@]}"; do
        name="round$round-$(basename "$t")"
        (timeout -k 10 "$RUN_TIMEOUT" "$t" >"$LOG_DIR/$name.log" 2>&1; verdict "$name" $?) &
        pids+=($!)
        # At most JOBS binaries at once.
        while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do sleep 1; done
    done
    for pid in "${pids[@]}"; do
        wait "$pid"
        count $?
    done
done

echo "== 2. the GL layer's context and transfer tests, $THREAD_ROUNDS times"
lib_tests=$(printf '%s\n' "${tests[@]}" | grep '/gpu_radiosity-' | head -1)
for i in $(seq "$THREAD_ROUNDS"); do
    run "gl-contexts-$i" "$lib_tests" gl::
done
# Alone, so that the process ends as the test's threads do; logs of passing runs are dropped.
echo "   and the threads that end as the process ends, $EXIT_RUNS times"
exit_test=gl::context::tests::threads_that_end_as_the_process_ends
for i in $(seq "$EXIT_RUNS"); do
    run "exit-race-$i" "$lib_tests" "$exit_test" --exact && rm -f "$LOG_DIR/exit-race-$i.log"
done

echo "== 3. solves on each backend, $SOLVES each"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
for backend in egl osmesa; do
    for i in $(seq "$SOLVES"); do
        solver=gpu
        [ $((i % 3)) -eq 0 ] && solver=cpu
        scene=""
        [ $((i % 2)) -eq 0 ] && scene=scenes/box/box.obj
        run "solve-$backend-$solver-$i" "$bin" solve $scene --backend "$backend" --solver "$solver" \
            --max-shots 40 --out "$scratch/$backend-$i"
    done
    run "validate-$backend" "$bin" validate --quick --backend "$backend"
done

echo "== 4. the viewer's window context under Xvfb, $VIEWER_RUNS times"
for i in $(seq "$VIEWER_RUNS"); do
    run "viewer-$i" env WINIT_X11_SCALE_FACTOR=1 xvfb-run -a -s "-screen 0 1280x1024x24" \
        "$bin" view --screenshot "$scratch/view-$i.png" --after-shots 8
done

echo "== 5. the driver matrix"
run "drivers" "$bin" check --drivers all --diff-dir "$scratch/diff" --json "$LOG_DIR/drivers.json"

echo "== 6. without the sanitizer: the tests that draw in several threads, $PARALLEL_RUNS times each"
plain=(env -u RUSTFLAGS -u RUSTDOCFLAGS cargo test --release --no-run)
if ! "${plain[@]}" --message-format=json >"$LOG_DIR/plain-build.json" 2>"$LOG_DIR/plain-build.log"; then
    tail -20 "$LOG_DIR/plain-build.log"
    echo "the release build failed"
    exit 1
fi
for name in $PARALLEL_TESTS; do
    t=$(jq -r 'select(.profile.test == true and .target.name == "'"$name"'") | .executable // empty' \
        "$LOG_DIR/plain-build.json" | head -1)
    [ -x "$t" ] || { echo "no test binary $name"; exit 1; }
    for i in $(seq "$PARALLEL_RUNS"); do
        run "parallel-$name-$i" "$t"
    done
done

minutes=$(( ($(date +%s) - started + 30) / 60 ))
echo "== $runs runs, $crashes crashed, $failures failed otherwise, $minutes minutes (logs: $LOG_DIR)"
[ "$crashes" -eq 0 ] && [ "$failures" -eq 0 ]
