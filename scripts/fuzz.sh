#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang with AddressSanitizer + UndefinedBehaviorSanitizer)
# and runs each on a copy of its seed corpus (fuzz/corpus/<target>).
#   scripts/fuzz.sh [SECONDS]   each target for SECONDS (default 10)
#   RUNS=N scripts/fuzz.sh      each target for N inputs instead
# env: FUZZ_TARGETS="trajectory dataset ..." (default all), BUILD_DIR (default build-fuzz),
# REUSE_BUILD=1: BUILD_DIR is already configured for fuzzing (e.g. by
# `FUZZ=1 scripts/sanitize.sh address`, whose tests then share the build), only build the targets.
# Prints one line per target: inputs tried, seconds, result; a crash, sanitizer report, leak,
# timeout (an input taking over 10 s) or uncaught exception other than InputError fails the
# script, with the input saved under BUILD_DIR/crashes/.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-10}
targets=${FUZZ_TARGETS:-"trajectory dataset mask_list run_log vocabulary map_file settings rosbag"}
BUILD_DIR=${BUILD_DIR:-"$ROOT/build-fuzz"}
JOBS=${JOBS:-$(nproc)}
"$ROOT/scripts/install_deps.sh"
command -v clang++ >/dev/null || { echo "scripts/fuzz.sh needs clang++ (apt-get install clang)" >&2; exit 2; }
GEN=()
if command -v ninja >/dev/null 2>&1; then GEN=(-G Ninja); fi
if [ -z "${REUSE_BUILD:-}" ]; then
  cmake -S "$ROOT" -B "$BUILD_DIR" "${GEN[@]}" -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DDETSLAM_SANITIZE="address,undefined" -DDETSLAM_FUZZ=ON \
    -DDETSLAM_BUILD_TESTS=OFF -DDETSLAM_BUILD_BENCH=OFF >/dev/null
elif ! grep -q "^DETSLAM_FUZZ:BOOL=ON" "$BUILD_DIR/CMakeCache.txt" 2>/dev/null; then
  echo "REUSE_BUILD: $BUILD_DIR is not configured with DETSLAM_FUZZ=ON" >&2
  exit 2
fi
start=$(date +%s)
# shellcheck disable=SC2086
cmake --build "$BUILD_DIR" -j "$JOBS" --target $(printf 'fuzz_%s ' $targets)
echo "[fuzz] build: $(( $(date +%s) - start )) s"
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$BUILD_DIR/crashes"
failed=0
for t in $targets; do
  mkdir -p "$work/$t"
  cp "$ROOT/fuzz/corpus/$t/"* "$work/$t/"
  limit=(-max_total_time="$seconds")
  if [ -n "${RUNS:-}" ]; then limit=(-runs="$RUNS"); fi
  set +e
  "$BUILD_DIR/fuzz/fuzz_$t" "$work/$t" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$BUILD_DIR/crashes/${t}_" >"$work/$t.log" 2>&1
  rc=$?
  set -e
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$t.log" | tail -1)
  secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$work/$t.log" | tail -1)
  if [ "$rc" -eq 0 ]; then
    echo "[fuzz] $t: ${runs:-?} inputs in ${secs:-?} s, no crash, hang or leak"
  else
    failed=1
    echo "[fuzz] $t: FAILED (exit $rc) after ${runs:-?} inputs; input saved in $BUILD_DIR/crashes/"
    grep -E "ERROR|SUMMARY|terminate|what\(\)|deadly signal|Test unit written" "$work/$t.log" | head -20
  fi
done
exit "$failed"
