#!/usr/bin/env python3
"""Markdown for docs/BENCHMARKS.md section dense, from bench_dense.sh's per-sequence JSON files
(written by build/bench/dense_eval). Usage: dense_report.py ROWS_DIR PRESETS EVAL_SEEDS TUNE_SEEDS FRAMES"""
import json
import os
import statistics
import sys

rows_dir, presets, eval_seeds, tune_seeds, frames = sys.argv[1:6]
presets, eval_seeds, tune_seeds = presets.split(), eval_seeds.split(), tune_seeds.split()


def load(kind, preset, seed):
    path = os.path.join(rows_dir, f"{kind}_{preset}_{seed}.json")
    with open(path) as f:
        return json.load(f)


def msw(values, scale=1.0, fmt="{:.2f}", worst=max):
    v = [x * scale for x in values]
    sd = statistics.stdev(v) if len(v) > 1 else 0.0
    return f"{fmt.format(statistics.mean(v))} ± {fmt.format(sd)} ({fmt.format(worst(v))})"


print(f"Synthetic sequences only ({frames} frames each, people from the real TUM cut-outs, default dnn")
print("segmenter): the full TUM dynamic sequences are not available on this machine. Evaluation seeds")
print(f"{', '.join(eval_seeds)}; each cell is mean ± sd (worst) over them. The dense map is the live run's")
print("own (`detslam run --dense-map`, keyframes fused at their final poses without the pixels the")
print("Det-SLAM stage removed, free-space carving on); the no-filter columns are `detslam densify")
print("--keep-dynamic` of the same run (every pixel fused), with carving on and off. Clouds are moved")
print("into the scene's frame by the rigid motion that best maps the run's poses (trajectory.txt,")
print("orientations and positions) onto the ground truth's.")
print()
print("- *on people*: points within 10 cm of a person's rendered surface in any frame **and** more than")
print("  3 cm from every static surface (people smeared into the map). Target: under 1 %.")
print("- *within 10 cm of a person*: the same without the second condition; it also counts correct")
print("  static points the people came within 10 cm of (the floor under their feet, desks and walls")
print("  they pass), so it is not zero even for a perfect static map.")
print("- *median distance*: of all points to the nearest static surface (target at most 1 cm);")
print("  *completeness*: share of the static surface samples the keyframes saw (1 cm grid, 0.3-4 m)")
print("  with a point within 2 cm.")
print()
print("| preset | points (k) | on people, filter % | on people, no filter % | on people, no filter, no carving % | within 10 cm of a person, filter / no filter % | median distance mm | completeness % | fusion s (keyframes) | memory MB |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
all_ok = True
for p in presets:
    r = [load("eval", p, s) for s in eval_seeds]
    c = lambda name, key: [x["clouds"][name][key] for x in r]
    smear = c("filter", "smear_fraction")
    med = c("filter", "static_median_m")
    all_ok &= max(smear) < 0.01 and max(med) <= 0.01
    kf = statistics.mean(x["dense"]["keyframes_fused"] for x in r)
    print(f"| {p} | {msw(c('filter', 'points'), 1e-3, '{:.0f}')} | {msw(smear, 100)} | "
          f"{msw(c('nofilter', 'smear_fraction'), 100)} | {msw(c('nofilter_nocarve', 'smear_fraction'), 100)} | "
          f"{statistics.mean(c('filter', 'near_person_fraction')) * 100:.1f} / "
          f"{statistics.mean(c('nofilter', 'near_person_fraction')) * 100:.1f} | "
          f"{msw(med, 1e3, '{:.1f}')} | {msw(c('filter', 'completeness'), 100, '{:.1f}', min)} | "
          f"{statistics.mean(x['dense']['fusion_s'] for x in r):.1f} ({kf:.0f}) | "
          f"{statistics.mean(x['dense']['memory_mb'] for x in r):.0f} |")
print()
print(f"Targets (on people under 1 % and median distance at most 1 cm on every evaluation seed): "
      f"{'met' if all_ok else 'NOT met'}.")
print()
print("With the filter but without carving (`--no-carve`), on people %: " + ", ".join(
    f"{p} {msw([load('eval', p, s)['clouds']['filter_nocarve']['smear_fraction'] for s in eval_seeds], 100)}"
    for p in presets) + ".")
print()
print(f"Tuning (walking_xyz, tuning seeds {', '.join(tune_seeds)}; the default min weight 2 was chosen on")
print("seed 1): a surface needs this many keyframe observations to be written.")
print()
print("| seed | min weight | points (k) | on people % | median distance mm | completeness % |")
print("|---:|---:|---:|---:|---:|---:|")
for s in tune_seeds:
    r = load("tune", "walking_xyz", s)
    for name, w in (("w1", 1), ("filter", 2), ("w3", 3)):
        x = r["clouds"][name]
        print(f"| {s} | {w} | {x['points'] / 1e3:.0f} | {x['smear_fraction'] * 100:.2f} | "
              f"{x['static_median_m'] * 1e3:.1f} | {x['completeness'] * 100:.1f} |")
