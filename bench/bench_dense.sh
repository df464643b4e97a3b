#!/usr/bin/env bash
# Dense static map benchmark on the synthetic walking presets (people textured with the real TUM
# cut-outs so that the real detector fires on them). Per preset and seed: generate the sequence,
# segment it with the default dnn segmenter (`detslam segment`, replayed as masks:DIR: the same
# as --segmenter dnn since 2026-12-05, see bench_dynamic.sh; sections written before used masks
# that lost overlaps), run `detslam run --dense-map` (the live run's own dense map,
# what a user gets), then `detslam densify` of the same run without the masks (--keep-dynamic)
# and without free-space carving (--no-carve), and score every cloud against the generator's truth
# with build/bench/dense_eval (synth/dense_truth.h).
# Held-out protocol: the dense defaults (voxel 1 cm, truncation 4 cm, min weight 2, carving on)
# were chosen on tuning seed 1 of walking_xyz; the published table holds evaluation seeds
# (EVAL_SEEDS) nothing was chosen on, as mean, sd and worst over seeds. The tuning table shows the
# min-weight choice on the tuning seeds (TUNE_SEEDS). Seeds 101-103 were the evaluation seeds of
# the first run and were looked at to diagnose its one miss (README, dense map), so they are no
# longer held out.
# Writes docs/BENCHMARKS.md (section dense) and docs/dense_map.png (the first evaluation seed of
# walking_xyz with the filter and without it, no carving).
# Usage: bench/bench_dense.sh [path/to/detslam]
#   env: PRESETS="walking_xyz walking_static walking_rpy walking_halfsphere" EVAL_SEEDS="201 202 203"
#        TUNE_SEEDS="1 2 3" FRAMES=300 JOBS=2
set -euo pipefail
# The synthetic sensor model (`detslam synth --realism`): realistic, the generator's default;
# REALISM=easy gives the first generator's sequences.
export realism="${REALISM:-realistic}"
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="$(realpath "${1:-$root/build/bin/detslam}")"
evaluator="$(dirname "$(dirname "$bin")")/bench/dense_eval"
presets="${PRESETS:-walking_xyz walking_static walking_rpy walking_halfsphere}"
eval_seeds="${EVAL_SEEDS:-201 202 203}"
tune_seeds="${TUNE_SEEDS:-1 2 3}"
frames="${FRAMES:-300}"
jobs="${JOBS:-2}"
[[ -x "$evaluator" ]] || { echo "missing $evaluator (build the bench targets)" >&2; exit 1; }
source "$here/bench_lib.sh"  # shellcheck source=bench/bench_lib.sh
need_people_and_models
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/rows" "$work/fig"
export bin evaluator models people frames work

# One (kind, preset, seed) job: kind "eval" or "tune". Writes $work/rows/<kind>_<preset>_<seed>.json.
job() {
  local kind=$1 preset=$2 seed=$3 seq="$work/${2}_$3"
  "$bin" synth --realism "$realism" --preset "$preset" --seed "$seed" --frames "$frames" --people "$people" --out "$seq" >/dev/null 2>&1
  "$bin" segment --dataset "$seq" --models "$models" --out "$seq.masks" >"$seq.segment.log" 2>&1
  "$bin" run --dataset "$seq" --out "$seq.run" --seed 42 --no-progress --segmenter "masks:$seq.masks" \
    --dense-map "$seq.run/dense_map.ply" >"$seq.run.log" 2>&1 || { cat "$seq.run.log" >&2; return 1; }
  local clouds=("filter=$seq.run/dense_map.ply")
  densify() { "$bin" densify "$seq.run" --no-progress --out "$seq.run/$1.ply" "${@:2}" >>"$seq.densify.log" 2>&1; }
  if [[ $kind == eval ]]; then
    densify nofilter --keep-dynamic
    densify filter_nocarve --no-carve
    densify nofilter_nocarve --keep-dynamic --no-carve
    clouds+=("nofilter_nocarve=$seq.run/nofilter_nocarve.ply" "nofilter=$seq.run/nofilter.ply"
             "filter_nocarve=$seq.run/filter_nocarve.ply")
  else
    densify w1 --dense-min-weight 1
    densify w3 --dense-min-weight 3
    clouds+=("w1=$seq.run/w1.ply" "w3=$seq.run/w3.ply")
  fi
  local figure=()  # the README figure: the first two clouds of one evaluation sequence
  [[ $kind == eval && $preset == walking_xyz && $seed == "$eval_first" ]] && figure=(--figure "$work/fig/dense_map.png")
  "$evaluator" --preset "$preset" --seed "$seed" --frames "$frames" --people "$people" --run "$seq.run" \
    --json "$work/rows/${kind}_${preset}_$seed.json" "${figure[@]}" "${clouds[@]}" 2>"$seq.eval.log" ||
    { cat "$seq.eval.log" >&2; return 1; }
  python3 - "$seq.run/run.json" "$work/rows/${kind}_${preset}_$seed.json" <<'PY'
import json, sys
run = json.load(open(sys.argv[1])); path = sys.argv[2]; e = json.load(open(path))
e["dense"] = run["dense_map"]; e["tracked"] = run["frames_tracked"]; e["frames"] = run["frames"]
json.dump(e, open(path, "w"), indent=1)
PY
  rm -rf "$seq" "$seq.masks" "$seq.run"
}
export -f job
eval_first="${eval_seeds%% *}"
export eval_first

list=()
for preset in $presets; do for seed in $eval_seeds; do list+=("eval $preset $seed"); done; done
for seed in $tune_seeds; do list+=("tune walking_xyz $seed"); done
echo "[bench_dense] ${#list[@]} sequences, $jobs at a time" >&2
printf '%s\n' "${list[@]}" | xargs -P "$jobs" -L 1 bash -c 'job "$0" "$1" "$2" && echo "[bench_dense] done $0 $1 seed $2" >&2'

python3 "$here/dense_report.py" "$work/rows" "$presets" "$eval_seeds" "$tune_seeds" "$frames" >"$work/section.md"
python3 "$here/update_section.py" dense "bench/bench_dense.sh (PRESETS=\"$presets\" EVAL_SEEDS=\"$eval_seeds\" TUNE_SEEDS=\"$tune_seeds\" FRAMES=$frames JOBS=$jobs REALISM=$realism)" <"$work/section.md"
cat "$work/section.md"
if [[ -f "$work/fig/dense_map.png" ]]; then
  cp "$work/fig/dense_map.png" "$root/docs/dense_map.png.tmp" && mv "$root/docs/dense_map.png.tmp" "$root/docs/dense_map.png"
  echo "wrote $root/docs/dense_map.png" >&2
fi
python3 "$here/readme_summary.py"
