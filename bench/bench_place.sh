#!/usr/bin/env bash
# Place-recognition benchmark (issue "place recognition", first target: a relocalisation query at
# most 5 ms median with a 1000-keyframe map, at most 1.5x that at 5000). Builds synthetic keyframe
# maps of SIZES keyframes (rendered in memory, no disk), times Tracker::RelocalizeFrame and the
# bag-of-words candidates alone on the same queries at every size, and writes the table, the
# PASS/FAIL lines and the plot docs/place_reloc_time.svg into docs/BENCHMARKS.md (section place)
# via bench/update_section.py. About 10 minutes on 2 cores with the defaults; progress on stderr.
# Usage: bench/bench_place.sh [path/to/bench_place]   (default build/bench/bench_place)
#   (env: SIZES=250,500,1000,2000,5000 STRIDE=8 KF_PER_SEQ=50 QUERIES_PER_SEQ=30 REPEATS=5
#         COVISIBILITY=1 JSON=path to keep the raw results)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/build/bench/bench_place}"
sizes="${SIZES:-250,500,1000,2000,5000}"
stride="${STRIDE:-8}"
kf_per_seq="${KF_PER_SEQ:-50}"
queries="${QUERIES_PER_SEQ:-30}"
repeats="${REPEATS:-5}"
covis="${COVISIBILITY:-1}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
json="${JSON:-$work/place.json}"
args=(--json "$json" --sizes "$sizes" --stride "$stride" --keyframes-per-sequence "$kf_per_seq"
      --queries-per-sequence "$queries" --repeats "$repeats")
[[ $covis == 0 ]] && args+=(--no-covisibility)
load_start="$(cut -d' ' -f1-3 /proc/loadavg)"
"$bin" "${args[@]}"
{
  python3 "$here/place_report.py" "$json"
  echo
  echo "Load average at start: $load_start (times rise when other jobs share the cores)."
} >"$work/section.md"
python3 "$here/update_section.py" place \
  "bench/bench_place.sh (SIZES=$sizes STRIDE=$stride KF_PER_SEQ=$kf_per_seq QUERIES_PER_SEQ=$queries REPEATS=$repeats COVISIBILITY=$covis)" \
  <"$work/section.md"
cat "$work/section.md"
