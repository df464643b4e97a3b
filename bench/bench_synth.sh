#!/usr/bin/env bash
# Renders every synth preset in both realism modes (150 frames, seed 1, photo people if the shared
# cut-outs exist) and writes a markdown table of speed, texture and missing depth into
# docs/BENCHMARKS.md (section synth), beside the same measures on the real TUM frames in
# ../shared/data (build/bench/frame_stats measures both alike).
# Usage: bench/bench_synth.sh [path/to/detslam]   (default build/bin/detslam)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/build/bin/detslam}"
stats="${FRAME_STATS:-$(dirname "$(dirname "$bin")")/bench/frame_stats}"
frames="${FRAMES:-150}"
shared="${DETSLAM_SHARED:-$root/../shared}"
people_dir="$shared/data/people"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
[[ -x "$stats" ]] || { echo "missing $stats (build the frame_stats target)" >&2; exit 1; }
people_arg=()
people_note="procedural people"
if [[ -f "$people_dir/person_1.png" ]]; then
  people_arg=(--people "$people_dir")
  people_note="people textured with the TUM cut-outs in data/people"
fi
presets="static walking_xyz walking_static walking_rpy walking_halfsphere sitting_static loop loop_long roam"
row() {  # label frame_stats-json [synth stats json]
  python3 - "$@" <<'PY'
import json, sys
label, fs = sys.argv[1], json.loads(sys.argv[2])
s = json.load(open(sys.argv[3])) if len(sys.argv) > 3 else None
f, m = fs["fast20"], fs["missing_depth"]
speed = f"{s['render_fps']:.1f} | {s['total_fps']:.1f}" if s else "- | -"
cov = f"{100 * s['mean_people_coverage']:.1f}" if s else "-"
print(f"| {label} | {fs['frames']} | {speed} | {f['mean']:.0f} ({f['min']:.0f}-{f['max']:.0f}) | "
      f"{100 * m['mean']:.1f} ({100 * m['min']:.1f}-{100 * m['max']:.1f}) | {cov} |")
PY
}
{
  echo "\`detslam synth\`, 640x480, $frames frames per preset, seed 1, $people_note, $(nproc) threads,"
  echo "in both sensor models (\`--realism realistic\`, the default, and \`--realism easy\`)."
  echo "Render fps: ray casting + people + sensor effects; total fps adds PNG encoding and atomic"
  echo "writes (and the one-off scene texture build). FAST corners (cv::FAST threshold 20, non-max"
  echo "suppression) and missing depth (fraction of depth pixels that are 0) on every 5th frame, mean"
  echo "(min-max), measured by build/bench/frame_stats the same way on the real TUM RGB-D frames in"
  echo "../shared/data (first rows; real data, the rest synthetic). Coverage: mean fraction of pixels"
  echo "on people. Load average at start: $(cut -d' ' -f1-3 /proc/loadavg)."
  echo
  echo "| sequence | frames measured | render fps | total fps | FAST-20 corners | missing depth % | people coverage % |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
  for clip in rgbd_dataset_freiburg2_desk_subset50 rgbd_dataset_freiburg3_walking_xyz_1frame; do
    d="$shared/data/tum/$clip"
    if [[ -d "$d" ]]; then
      row "real: ${clip#rgbd_dataset_}" "$("$stats" "$d" 2>/dev/null)"
    else
      echo "| real: ${clip#rgbd_dataset_} (missing: $d) | - | - | - | - | - | - |"
    fi
  done
  for realism in realistic easy; do
    for p in $presets; do
      "$bin" synth --preset "$p" --seed 1 --frames "$frames" --realism "$realism" "${people_arg[@]}" \
        --out "$work/$p" --stats-json "$work/$p.json" >/dev/null 2>&1
      row "$p ($realism)" "$("$stats" --every 5 "$work/$p" 2>/dev/null)" "$work/$p.json"
      rm -rf "${work:?}/$p"
    done
  done
} | python3 "$here/update_section.py" synth "bench/bench_synth.sh"
