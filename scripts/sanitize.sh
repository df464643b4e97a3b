#!/usr/bin/env bash
# Builds detslam with sanitizers and runs tests under them; any report fails the run.
#   scripts/sanitize.sh address   AddressSanitizer + UndefinedBehaviorSanitizer (+ LeakSanitizer):
#                                 every unit test and the integration set below
#   scripts/sanitize.sh thread    ThreadSanitizer: the tests of the threaded runner and its parts
# Build folders: build-asan / build-tsan (override with BUILD_DIR). Extra arguments go to ctest
# instead of the default selection, e.g. scripts/sanitize.sh address -R Map; TARGETS="a b" builds
# only those targets (then select their tests with -L unit: tests of unbuilt binaries carry no
# label). CXX_COMPILER=clang++ builds with clang; FUZZ=1 (address only, implies clang) also
# instruments the parsers' modules for libFuzzer and builds the fuzz targets in the same folder, for
# `REUSE_BUILD=1 BUILD_DIR=... scripts/fuzz.sh`; UNITY=1 makes a unity build (several sources
# per compiler run: about half the time from scratch, as CI builds); BUILD_ONLY=1 builds and stops
# (CI builds the sanitizer folders in the background while the Release tests run).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
kind=${1:-address}
shift || true
case "$kind" in
  address) flags="address,undefined"; dir_default="$ROOT/build-asan" ;;
  thread) flags="thread"; dir_default="$ROOT/build-tsan" ;;
  *) echo "usage: scripts/sanitize.sh address|thread [ctest arguments]" >&2; exit 2 ;;
esac
BUILD_DIR=${BUILD_DIR:-$dir_default}
JOBS=${JOBS:-$(nproc)}
"$ROOT/scripts/install_deps.sh"
GEN=()
if command -v ninja >/dev/null 2>&1; then GEN=(-G Ninja); fi
EXTRA=()
if [ -n "${FUZZ:-}" ]; then
  [ "$kind" = address ] || { echo "FUZZ=1 needs the address build" >&2; exit 2; }
  CXX_COMPILER=${CXX_COMPILER:-clang++}
  EXTRA+=(-DDETSLAM_FUZZ=ON)
fi
if [ -n "${CXX_COMPILER:-}" ]; then EXTRA+=(-DCMAKE_CXX_COMPILER="$CXX_COMPILER"); fi
if [ -n "${UNITY:-}" ]; then EXTRA+=(-DCMAKE_UNITY_BUILD=ON); fi
# -O2: Eigen inlined, as in Release (at -O1 the synthetic sequences the integration tests render
# took 10-20 times longer); -g1 keeps the reports' stacks readable.
cmake -S "$ROOT" -B "$BUILD_DIR" "${GEN[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1" -DDETSLAM_SANITIZE="$flags" \
  -DDETSLAM_BUILD_BENCH=OFF -DDETSLAM_ROS=OFF "${EXTRA[@]}" >/dev/null
start=$(date +%s)
if [ -n "${TARGETS:-}" ]; then
  # shellcheck disable=SC2086
  cmake --build "$BUILD_DIR" -j "$JOBS" --target $TARGETS
else
  cmake --build "$BUILD_DIR" -j "$JOBS"
fi
echo "[sanitize] $kind build: $(( $(date +%s) - start )) s"
if [ -n "${BUILD_ONLY:-}" ]; then exit 0; fi

supp="$ROOT/scripts/sanitizers"
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$supp/tsan.supp"
# OpenMP inside SuiteSparse (Ceres) in one thread under ThreadSanitizer, as OpenCV's loops are
# (tests/support/opencv_single_thread.cc): their pools are invisible to it.
if [ "$kind" = thread ]; then export OMP_NUM_THREADS=1; fi
start=$(date +%s)  # the tests' time, unit and integration together
# ctest with ARGS; under AddressSanitizer, tests that failed only because LeakSanitizer's own
# tracer crashed after they passed ("Tracer caught signal 11 ... LeakSanitizer has encountered a
# fatal error": no leak report, seen at exit on SynthLookalikeTest under load) are run once more,
# and that is said. Any other failure (a test assertion, an ASan or UBSan report, a leak found)
# fails at once.
run_ctest() {
  if ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" "$@"; then return 0; fi
  [ "$kind" = address ] || return 1
  local log="$BUILD_DIR/Testing/Temporary/LastTest.log"
  local failed tracer
  failed=$(grep -c '^Test Failed\.' "$log" || true)
  tracer=$(grep -c 'LeakSanitizer has encountered a fatal error' "$log" || true)
  if [ "$failed" -gt 0 ] && [ "$failed" -eq "$tracer" ] &&
     ! grep -qE 'ERROR: AddressSanitizer|runtime error:|detected memory leaks|\[  FAILED  \]' "$log"; then
    echo "[sanitize] $failed test(s) failed only by a LeakSanitizer tracer crash at exit; running them once more" >&2
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" --rerun-failed
    return
  fi
  return 1
}
if [ $# -eq 0 ]; then
  if [ "$kind" = address ]; then
    # Unit tests, and the integration tests that reach every module and command without the long
    # accuracy runs (those stay in the Release run of scripts/test.sh) and without the
    # interruption tests (run under ThreadSanitizer): the synthetic sequences the tests render are
    # 20-50 times slower to make under these sanitizers.
    run_ctest --timeout 900 -L unit
    set -- -R "IntegrationRunner|IntegrationFaults|IntegrationMapFile|IntegrationReport|IntegrationVocabCli|DataSlamFr2Desk.SeededSequentialRunsAreIdentical"
  else
    # Not the second-signal test: it quits with _exit while threads run, by design, which
    # ThreadSanitizer reports as a thread leak; nor the camera-rate stand-in's determinism test
    # (sequential runs: no thread of detslam's to check, 40 s under ThreadSanitizer).
    # The viewer's server and its live content: the runner's thread, the server's threads. The
    # map store's lock (tracking's access first).
    set -- -R "MapStore|BoundedQueue|StageThreads|ViewerServer|LiveViewer|IntegrationRunner|IntegrationInterrupt|DataSlamFr2Desk.(ThreadedRunner|MappingThread)" \
      -E "ASecondSignal|SimulatedCameraRateMasksAreDeterministic"
  fi
fi
run_ctest --timeout 1800 "$@"
echo "[sanitize] $kind tests: $(( $(date +%s) - start )) s"
