#!/usr/bin/env bash
# Several maps and map files benchmark (issue: several maps, map files, localisation mode).
# Sequential mode (deterministic), seed 42, shipped vocabulary; every row is a synthetic sequence
# from `detslam synth`. Measures:
#  A. covered lens: the `roam` preset with `--cover 8:2` (black colour and no depth for 2 s while
#     the camera turns towards the back of the room, which it has never seen; it comes back to the
#     start at ~24 s), ROAM_SEEDS (evaluation seeds: the preset was written and the rules chosen on
#     seeds 1 and 2): frames that are not black with a pose in trajectory.txt and the ATE, against
#     the same sequence without the cover, and with new maps off (Atlas.NewMapWhenLost=0: stay
#     lost until relocalisation, the behaviour before several maps); default segmenter (dnn);
#  B. map files: the static preset (MAP_FRAMES frames), a map saved after the SLAM run of path 1
#     (seed 101) and loaded with --localization on the same sequence and on path 2 (seed 111 with
#     --scene-seed 101: another camera path through the same room): frames tracked, ATE against the
#     SLAM run of that sequence, keyframes added; and two sessions: the map of path 1 loaded and
#     extended with path 2 (no --localization): maps left, ATE of path 2 against mapping it alone;
#  C. loading a map made from BIG_FRAMES frames (loop_long preset: a 9 x 5 m circuit in a large
#     office, --segmenter none): load time (a timing: run it on a quiet machine);
#  D. false merges: the `lookalike` preset (two parts of a long room with the same textures in
#     other layouts) with `--cover 18:12`, which hides the passage between them: the new map starts
#     in the second part, where every place looks like one of the first map's; each merge is checked
#     against ground truth (false: the relative pose it asserts between its two keyframes puts the
#     camera more than 0.5 m from where ground truth has it),
#     and so is the first pose after the cover, LOOKALIKE_SEEDS (evaluation seeds; the cover was
#     chosen on the tuning seeds 1-3: with 20:7 the camera still saw the passage wall the first map
#     had seen and relocalised in it), ground-truth masks;
# and writes the tables into docs/BENCHMARKS.md (sections atlas-cover, atlas-files, atlas-load,
# atlas-false-merges: one per part) via bench/update_section.py.
# Usage: bench/bench_atlas.sh [path/to/detslam]
#   (env: ROAM_SEEDS="101 102 103", MAP_FRAMES=500, BIG_FRAMES=3000,
#    LOOKALIKE_SEEDS="101 102 103", PARTS="A B C D")
set -euo pipefail
# The synthetic sensor model (`detslam synth --realism`): realistic, the generator's default;
# REALISM=easy gives the first generator's sequences.
export realism="${REALISM:-realistic}"
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="${1:-$root/build/bin/detslam}"
roam_seeds="${ROAM_SEEDS:-101 102 103}"
map_frames="${MAP_FRAMES:-500}"
big_frames="${BIG_FRAMES:-3000}"
lookalike_seeds="${LOOKALIKE_SEEDS:-101 102 103}"
parts="${PARTS:-A B C D}"
settings_line="bench/bench_atlas.sh (ROAM_SEEDS=\"$roam_seeds\" MAP_FRAMES=$map_frames BIG_FRAMES=$big_frames LOOKALIKE_SEEDS=\"$lookalike_seeds\" REALISM=$realism)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
bench_name=bench_atlas
# shellcheck source=bench/bench_lib.sh
source "$here/bench_lib.sh"

out="$work/section_a.md"
if want A; then
: >"$work/cover.tsv"
{
  echo "Sequential mode (deterministic), seed 42, shipped vocabulary, default segmenter (dnn). All"
  echo "rows are synthetic (\`detslam synth --preset roam\`, 900 frames, one person behind the desk)."
  echo
  echo "### A. Covered lens: \`roam\` with \`--cover 8:2\` (frames 240-299 black, no depth), evaluation seeds $roam_seeds"
  echo
  echo "While the lens is covered the camera turns from the table towards the back of the room, which"
  echo "it has never seen; it comes back to the start at about 24 s (frame 720). Columns: frames that"
  echo "are not black with a pose in trajectory.txt (the main map; other maps would go to"
  echo "trajectory_map<N>.txt), maps started, merges (at frame), maps left at the end, ATE of"
  echo "trajectory.txt. Target: at least 95% of the frames that are not black posed, ATE at most 1.5x"
  echo "that of the same sequence without the cover."
  echo
  echo "| seed | sequence | mode | not-black frames posed in trajectory.txt | maps started | merged at frame | maps left | ATE RMSE mm | ATE / uncovered |"
  echo "|---|---|---|---:|---:|---|---:|---:|---:|"
} >"$out"
for s in $roam_seeds; do
  progress "A: roam seed $s"
  "$bin" synth --realism "$realism" --preset roam --seed "$s" --out "$work/roam_$s" >/dev/null 2>&1
  "$bin" synth --realism "$realism" --preset roam --seed "$s" --cover 8:2 --out "$work/cover_$s" >/dev/null 2>&1
  run_eval "$work/roam_$s" "$work/roam_${s}_run"
  run_eval "$work/cover_$s" "$work/cover_${s}_run"
  run_eval "$work/cover_$s" "$work/cover_${s}_old" --set Atlas.NewMapWhenLost=0
  plain=$(m field "$work/roam_${s}_run/eval.json" ate.rmse)
  for v in "roam_${s}_run|uncovered|several maps (default)|0" "cover_${s}_run|covered 8:2|several maps (default)|60" \
           "cover_${s}_old|covered 8:2|one map, stay lost (Atlas.NewMapWhenLost=0)|60"; do
    IFS='|' read -r o seqname mode black <<<"$v"
    read -r posed notblack started merges left < <(python3 - "$work/$o/run.json" "$black" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
black = int(sys.argv[2])
maps = j["maps"]
merges = ", ".join(str(x["frame"]) for x in maps["merges"]) or "-"
print(j["frames_in_main_map"], j["frames"] - black, maps["started"], merges.replace(" ", ""), maps["left"])
PY
)
    ate=$(m field "$work/$o/eval.json" ate.rmse)
    ratio=$(python3 -c "print(f'{float($ate)/float($plain):.2f}')")
    pct=$(python3 -c "print(f'{100*$posed/$notblack:.1f}')")
    echo "| $s | $seqname | $mode | $posed/$notblack ($pct%) | $started | $merges | $left | $(mm "$ate") | $ratio |" >>"$out"
    printf '%s\t%s\t%s\t%s\n' "$mode|$seqname" "$pct" "$(mm "$ate")" "$ratio" >>"$work/cover.tsv"
  done
done
{
  echo
  echo "Over the seeds (mean, sd, worst):"
  echo
  echo "| sequence, mode | not-black frames posed %: mean | worst | ATE RMSE mm: mean | sd | worst | ATE / uncovered: mean | worst |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|"
  python3 - "$work/cover.tsv" <<'PY'
import statistics as st, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
for key in dict.fromkeys(r[0] for r in rows):
    r = [x for x in rows if x[0] == key]
    pct = [float(x[1]) for x in r]; ate = [float(x[2]) for x in r]; ratio = [float(x[3]) for x in r]
    sd = st.stdev(ate) if len(ate) > 1 else 0.0
    mode, seq = key.split("|")
    print(f"| {seq}, {mode} | {st.mean(pct):.1f} | {min(pct):.1f} | {st.mean(ate):.1f} | {sd:.1f} | "
          f"{max(ate):.1f} | {st.mean(ratio):.2f} | {max(ratio):.2f} |")
PY
  echo
} >>"$out"
publish atlas-cover "$out"
fi

out="$work/section_b.md"
if want B; then
progress "B: map files (static, $map_frames frames)"
"$bin" synth --realism "$realism" --preset static --seed 101 --frames "$map_frames" --out "$work/path1" >/dev/null 2>&1
"$bin" synth --realism "$realism" --preset static --seed 111 --scene-seed 101 --frames "$map_frames" --out "$work/path2" >/dev/null 2>&1
run_eval "$work/path1" "$work/slam1" --save-map "$work/path1.dslmap"
run_eval "$work/path2" "$work/slam2"
run_eval "$work/path1" "$work/loc1" --load-map "$work/path1.dslmap" --localization
run_eval "$work/path2" "$work/loc2" --load-map "$work/path1.dslmap" --localization
run_eval "$work/path2" "$work/session2" --load-map "$work/path1.dslmap"
{
  echo "### B. Map files and localisation mode: \`static\` preset, $map_frames frames"
  echo
  echo "Path 1: seed 101; path 2: seed 111 with \`--scene-seed 101\` (another camera path through the same"
  echo "room, with its own people). The map is saved after the SLAM run of path 1 (\`--save-map\`)."
  echo "Targets: localisation tracks every frame with ATE at most 1.1x the SLAM run's and adds no"
  echo "keyframe; a second session extends the map into one map (one trajectory frame) with ATE of"
  echo "path 2 no worse than mapping it alone."
  echo
  echo "| run | frames tracked | in trajectory.txt | keyframes added | maps left | ATE RMSE mm | ATE / SLAM run of that path |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
  for v in "slam1|path 1, SLAM (saves the map)|slam1" "slam2|path 2, SLAM alone|slam2" \
           "loc1|path 1, --load-map --localization|slam1" "loc2|path 2, --load-map --localization|slam2" \
           "session2|path 2, --load-map (second session, mapping on)|slam2"; do
    IFS='|' read -r o name ref <<<"$v"
    read -r tracked main added left < <(python3 - "$work/$o/run.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
loaded = j.get("loaded_map", {}).get("keyframes", 0)
print(f"{j['frames_tracked']}/{j['frames']}", j["frames_in_main_map"], j["keyframes"] - loaded, j["maps"]["left"])
PY
)
    ate=$(m field "$work/$o/eval.json" ate.rmse)
    echo "| $name | $tracked | $main | $added | $left | $(mm "$ate") | $(python3 -c "print(f'{float($ate)/float($(m field "$work/$ref/eval.json" ate.rmse)):.2f}')") |"
  done
  echo
  echo "Save -> load -> save byte identity is checked by the integration test IntegrationMapFile."
  echo
} >"$out"
publish atlas-files "$out"
fi

out="$work/section_c.md"
if want C; then
progress "C: loading a $big_frames-frame map (loop_long)"
"$bin" synth --realism "$realism" --preset loop_long --seed 1 --frames "$big_frames" --out "$work/big" >/dev/null 2>&1
"$bin" run --dataset "$work/big" --out "$work/big_run" --seed 42 --no-progress --segmenter none \
  --save-map "$work/big.dslmap" >"$work/big_run.log" 2>&1 || { cat "$work/big_run.log"; exit 1; }
"$bin" synth --realism "$realism" --preset loop_long --seed 1 --frames 30 --out "$work/short" >/dev/null 2>&1
for i in 1 2 3; do
  run_eval "$work/short" "$work/big_load_$i" --segmenter none --load-map "$work/big.dslmap" --localization
done
{
  echo "### C. Loading a map made from $big_frames frames (\`loop_long\`, seed 1, --segmenter none)"
  echo
  echo "The map of a $big_frames-frame run (a 9 x 5 m circuit in a 12.6 x 8.4 m office, one and a half"
  echo "laps), loaded three times by \`detslam run --load-map --localization\` on its first 30 frames."
  echo
  python3 - "$work/big.dslmap" "$work"/big_load_*/run.json <<'PY'
import json, os, sys
runs = [json.load(open(p))["loaded_map"] for p in sys.argv[2:]]
ms = sorted(r["load_ms"] for r in runs)
j = runs[0]
print(f"{j['keyframes']} keyframes, {j['map_points']} map points, {os.path.getsize(sys.argv[1]) / 2**20:.1f} MiB: "
      f"loaded (read, checked, restored, place index rebuilt) in **{ms[len(ms) // 2]:.0f} ms** "
      f"(median of {len(ms)}; {ms[0]:.0f}-{ms[-1]:.0f} ms; target: under 1 s).")
PY
  echo
} >"$out"
publish atlas-load "$out"
fi

out="$work/section_d.md"
if want D; then
{
  echo "### D. False merges: \`lookalike\` with \`--cover 18:12\` (frames 540-899 black, no depth), evaluation seeds $lookalike_seeds"
  echo
  echo "The camera explores the first part of a long room, then, while the lens is covered, walks"
  echo "through the passage into the second part, whose furnishings have the first part's textures in"
  echo "another layout (every item moved by a different step and resized). After the cover it sees"
  echo "nothing the first map holds (about 1.2 m of wall between the two views), so a new map must"
  echo "start and no merge or relocalisation into the first map is true: each merge (run.json"
  echo "\`loops\` with \`merge\`) is checked against ground truth, false when the relative pose it"
  echo "asserts between its two keyframes puts the camera more than 0.5 m from where ground truth has"
  echo "it (the two parts are 6.8 m apart), and the first pose"
  echo "in trajectory.txt after the cover, if any, by its position error (the trajectory anchored at"
  echo "its first pose). Ground-truth masks as segmenter. Target: no false merge or relocalisation;"
  echo "the second part's frames stay in trajectory_map1.txt."
  echo
  echo "| seed | frames not black | posed (all maps) | in trajectory.txt | maps started | merge candidates examined / passed rigid RANSAC / verified | merges | of which false (ground truth) | first pose in trajectory.txt after the cover | maps left | ATE RMSE mm (trajectory.txt) |"
  echo "|---:|---:|---:|---:|---:|---|---:|---:|---|---:|---:|"
} >"$out"
false_merges=0
for s in $lookalike_seeds; do
  progress "D: lookalike seed $s"
  "$bin" synth --realism "$realism" --preset lookalike --seed "$s" --cover 18:12 --out "$work/la_$s" >/dev/null 2>&1
  o="$work/la_${s}_run"
  run_eval "$work/la_$s" "$o" --segmenter gt
  read -r true_merges false_n < <(m loops "$o/run.json" "$work/la_$s/groundtruth.txt" 0.5)
  false_merges=$((false_merges + false_n))
  read -r _ after how err < <(m kidnap "$o/run.json" "$work/la_$s/groundtruth.txt" "$o/trajectory.txt" 900)
  first="none (stays in map 1)"
  [[ $after -ge 0 ]] && first="frame $after ($how), $(mm "$err") mm off"
  python3 - "$o/run.json" "$s" "$false_n" "$first" "$(mm "$(m field "$o/eval.json" ate.rmse)")" >>"$out" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
maps, ld = j["maps"], j["loop_detection"]
merges = sum(1 for l in j["loops"] if l["merge"])
print(f"| {sys.argv[2]} | {j['frames'] - 360} | {j['frames_tracked']} | {j['frames_in_main_map']} | "
      f"{maps['started']} | {ld['candidates']} / {ld['rigid_ransac']} / {ld['verified']} | {merges} | "
      f"{sys.argv[3]} | {sys.argv[4]} | {maps['left']} | {sys.argv[5]} |")
PY
done
{
  echo
  echo "False merges over the seeds: $false_merges. (Loop candidates count those of both maps: within"
  echo "the second map too, where no loop is true either.)"
  echo
} >>"$out"
publish atlas-false-merges "$out"
fi
python3 "$here/readme_summary.py"
