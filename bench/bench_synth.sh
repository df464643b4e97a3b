#!/usr/bin/env bash
# Renders every synth preset (150 frames, seed 1, photo people if the shared cut-outs exist) and
# writes a markdown table of speed and content statistics into docs/BENCHMARKS.md (section synth).
# Usage: bench/bench_synth.sh [path/to/detslam]   (default build/bin/detslam)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/build/bin/detslam}"
frames="${FRAMES:-150}"
people_dir="${DETSLAM_SHARED:-$root/../shared}/data/people"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
people_arg=()
people_note="procedural people"
if [[ -f "$people_dir/person_1.png" ]]; then
  people_arg=(--people "$people_dir")
  people_note="people textured with the TUM cut-outs in data/people"
fi
presets="static walking_xyz walking_static walking_rpy walking_halfsphere sitting_static loop"
{
  echo "\`detslam synth\`, 640x480, $frames frames per preset, seed 1, $people_note, $(nproc) threads."
  echo "Render fps: ray casting + people + sensor noise; total fps adds PNG encoding and atomic"
  echo "writes (and the one-off scene texture build). FAST corners: cv::FAST threshold 20 with"
  echo "non-max suppression on every 5th frame. Coverage: mean fraction of pixels on people."
  echo "Load average at start: $(cut -d' ' -f1-3 /proc/loadavg) (fps drop when other jobs share the cores)."
  echo
  echo "| preset | frames | render fps | total fps | mean FAST-20 corners | mean people coverage % |"
  echo "|---|---:|---:|---:|---:|---:|"
  for p in $presets; do
    "$bin" synth --preset "$p" --seed 1 --frames "$frames" "${people_arg[@]}" \
      --out "$work/$p" --stats-json "$work/$p.json" >/dev/null 2>&1
    python3 - "$work/$p.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"| {s['preset']} | {s['frames']} | {s['render_fps']:.1f} | {s['total_fps']:.1f} | "
      f"{s['mean_fast20_corners']:.0f} | {100 * s['mean_people_coverage']:.1f} |")
PY
    rm -rf "${work:?}/$p"
  done
} | python3 "$here/update_section.py" synth "bench/bench_synth.sh"
