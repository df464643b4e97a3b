#!/usr/bin/env bash
# Quick start: installs what is missing (Debian 12), builds detslam in Release, generates a
# synthetic dynamic RGB-D sequence (people walking through an office, with ground truth) and its
# static twin, runs SLAM on both, evaluates them like the TUM tools, writes an HTML report of each
# run and prints where everything is.
# Usage: scripts/demo.sh [FRAMES]   (default 300; outputs in demo_out/)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
FRAMES=${1:-300}
OUT="$ROOT/demo_out"
BUILD_DIR=${BUILD_DIR:-"$ROOT/build"}
"$ROOT/scripts/install_deps.sh"
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  GEN=(); command -v ninja >/dev/null 2>&1 && GEN=(-G Ninja)
  cmake -S "$ROOT" -B "$BUILD_DIR" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$BUILD_DIR" -j "$(nproc)" --target detslam
DETSLAM="$BUILD_DIR/bin/detslam"
SHARED="$ROOT/../shared"
PEOPLE=()
if [ -d "$SHARED/data/people" ]; then PEOPLE=(--people "$SHARED/data/people"); fi
# The Det-SLAM filter with the real detector when the models are there, else with the
# generator's ground-truth masks (an oracle segmenter, so the demo runs without ../shared).
FILTER=gt
if [ -f "$SHARED/models/yolox_nano/yolox_nano.onnx" ]; then FILTER=dnn; fi
mkdir -p "$OUT"
echo "== 1/3 synthetic sequences: walking_xyz ($FRAMES frames, people walking) and its static twin"
"$DETSLAM" synth --preset walking_xyz --seed 1 --frames "$FRAMES" "${PEOPLE[@]}" --out "$OUT/walking_xyz"
"$DETSLAM" synth --preset walking_xyz --seed 1 --frames "$FRAMES" --no-people --out "$OUT/walking_xyz_static_twin"
run() {  # name dataset segmenter [run options]
  echo "== 2/3 SLAM: $1"
  "$DETSLAM" run --dataset "$OUT/$2" --segmenter "$3" --threaded --out "$OUT/$1" "${@:4}"
  echo "== 3/3 evaluation: $1 (TUM conventions: 0.02 s association, SE(3) alignment, RPE over 1 s)"
  "$DETSLAM" eval --gt "$OUT/$2/groundtruth.txt" --est "$OUT/$1/trajectory.txt" --frames "$OUT/$2" \
    --json "$OUT/$1/eval.json" --plot "$OUT/$1/eval.svg"
  "$DETSLAM" report --run "$OUT/$1"
}
run static_twin walking_xyz_static_twin none
run people_no_filter walking_xyz none
run people_detslam_$FILTER walking_xyz "$FILTER" --dense-map "$OUT/people_detslam_$FILTER/dense_map.ply"
echo
echo "Summary:"
for r in static_twin people_no_filter "people_detslam_$FILTER"; do
  python3 -c "import json,sys; e=json.load(open(sys.argv[2])); print(f'  {sys.argv[1]:<26} ATE RMSE {e[\"ate\"][\"rmse\"]*1000:7.1f} mm, tracked {e[\"coverage\"][\"fraction\"]*100:5.1f} %')" "$r" "$OUT/$r/eval.json"
done
echo "Outputs under $OUT/: <run>/trajectory.txt (TUM), keyframes.txt, map.ply, run.json,"
echo "eval.json, eval.svg (trajectory and error plots) and report.html (the run with its plots;"
echo "open it in a browser); people_detslam_$FILTER/dense_map.ply is the dense static map with the"
echo "people removed (open it in MeshLab or CloudCompare)."
echo "Look at a run in the browser: $DETSLAM view $OUT/people_detslam_$FILTER (Ctrl-C to quit), or"
echo "watch one live: $DETSLAM run --dataset $OUT/walking_xyz --segmenter $FILTER --out $OUT/live --viewer"
