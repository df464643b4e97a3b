# Helpers shared by the whole-sequence benchmarks (sourced, not run). The sourcing script sets
# here (bench/), bin (the detslam binary), parts, settings_line, work and bench_name first.
want() { [[ " $parts " == *" $1 "* ]]; }
publish() {  # section file
  python3 "$here/update_section.py" "$1" "$settings_line" <"$2"
  cat "$2"
}
m() { python3 "$here/slam_metrics.py" "$@"; }
mm() { python3 -c "print(f'{float($1)*1000:.1f}')"; }
progress() { echo "[$bench_name] $*" >&2; }
# setting_default KEY: the default value of a settings key in $bin (`detslam settings --list`).
setting_default() { "$bin" settings --list | awk -v key="$1" '$1 == key { print $4 }'; }
# cross_check EVAL_JSON: the same ATE and RPE recomputed by the independent
# tools/tum_eval_reference.py; a disagreement above 1e-6 m stops the benchmark (the result is
# deleted too, so that a caller in a background job cannot read it either).
cross_check() {
  python3 "$here/cross_check_eval.py" "$1" ||
    { echo "[bench] cross-check failed: $1" >&2; rm -f "$1"; exit 1; }
}

run_eval() {  # dataset_dir out_dir [run options...]: sequential run, seed 42, then eval.json
  local ds=$1 o=$2
  shift 2
  "$bin" run --dataset "$ds" --out "$o" --seed 42 --no-progress "$@" >"$o.log" 2>&1 ||
    { cat "$o.log"; exit 1; }
  "$bin" eval --gt "$ds/groundtruth.txt" --est "$o/trajectory.txt" --frames "$ds" \
    --json "$o/eval.json" >/dev/null
  cross_check "$o/eval.json"
}

# The real people cut-outs and the models from ../shared ($DETSLAM_SHARED overrides): sets people
# and models (needs root), or exits naming what is missing.
need_people_and_models() {
  local shared="${DETSLAM_SHARED:-$root/../shared}"
  people="$shared/data/people"
  models="$shared/models"
  [[ -f "$people/person_1.png" ]] || { echo "missing $people (the people cut-outs)" >&2; exit 1; }
  [[ -f "$models/yolox_nano/yolox_nano.onnx" ]] || { echo "missing models in $models" >&2; exit 1; }
}
