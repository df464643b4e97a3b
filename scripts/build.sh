#!/usr/bin/env bash
# Configures and builds detslam in Release into build/ (override with BUILD_DIR). UNITY=1 on the
# first configure makes a unity build (several sources per compiler run: about half the time from
# scratch, as in CI; slower to rebuild after a one-file change).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-"$ROOT/build"}
JOBS=${JOBS:-$(nproc)}
"$ROOT/scripts/install_deps.sh"
GEN=()
if command -v ninja >/dev/null 2>&1; then GEN=(-G Ninja); fi
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  if [ -n "${UNITY:-}" ]; then GEN+=(-DCMAKE_UNITY_BUILD=ON); fi
  cmake -S "$ROOT" -B "$BUILD_DIR" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
elif [ $# -gt 0 ]; then
  cmake -S "$ROOT" -B "$BUILD_DIR" "$@"
fi
cmake --build "$BUILD_DIR" -j "$JOBS"
