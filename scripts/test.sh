#!/usr/bin/env bash
# Builds detslam (Release) and runs every test: unit, integration and data (real clips in
# ../shared). Extra arguments go to ctest, e.g. scripts/test.sh -L unit
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-"$ROOT/build"}
"$ROOT/scripts/build.sh"
cd "$BUILD_DIR"
ctest --output-on-failure -j "$(nproc)" --timeout 900 "$@"
