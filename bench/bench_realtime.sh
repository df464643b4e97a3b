#!/usr/bin/env bash
# Camera-rate benchmark (issue: real time on two CPU cores). Every row is a synthetic sequence from
# `detslam synth` (people from the real TUM cut-outs in ../shared), default dnn segmenter, seed 42.
# Per walking preset and evaluation seed (SEEDS; nothing in the camera-rate mode was chosen on any
# seed), runs of the same frames:
#   offline   sequential, every frame segmented (the accuracy reference; deterministic)
#   threaded  `detslam run --threaded`, every frame taken and segmented, no camera: the offline
#             run's own spread when the mapping thread runs beside tracking (THREADED_REPEATS runs,
#             default 2; 0 leaves them out). A sequential run maps each keyframe before the next
#             frame, so its local mapping is always idle and it makes more keyframes than
#             any threaded run; which frames become keyframes moves a sequence's ATE both ways
#             (threaded 0.83-1.18x the sequential run on tuning seeds 1-3 of walking_xyz and
#             walking_halfsphere)
#   live      `detslam run --realtime`: frames offered at their timestamps (30 fps), dropped when
#             the pipeline is busy; threaded with the mapping and loop-closing threads;
#             asynchronous segmentation. LIVE_REPEATS runs (default 3): a live run depends on the
#             scheduler, and one run's ATE and latency tail spread widely, so each sequence's
#             figures are the mean over its runs, with the worst single run beside it
#   sync      the same with --sync-segmentation (each frame taken is segmented before extraction:
#             the previous design, for comparison)
# and reports, from the live run's own outputs (run.json and its trajectory, not a replay): frames
# processed per second, frames dropped, latency from a frame's arrival to its pose (median, 99th
# percentile), frames processed that were tracked, and its ATE against the offline run's. The
# issue's targets are checked and printed as met or missed. Timings: run it on a quiet machine.
# Writes docs/BENCHMARKS.md (section realtime).
# Part `tracking`: tracking + extraction per frame on the real fr2/desk clip in ../shared
# (sequential, segmenter none and dnn, REPEATS runs each) against ORB-SLAM3's figure in the issue;
# writes section realtime-tracking.
# Part `long` (only when named in PARTS): a LONG_FRAMES-frame camera-rate run (default 20000 = 11
# min at 30 Hz) of one lap of the synthetic `loop_long` preset (evaluation seed LONG_SEED, 1920
# frames = 64 s, the circuit closes exactly) listed again and again (bench/repeat_sequence.py),
# default dnn segmenter, under bench/soak_monitor.py (memory twice a second, watchdog); frames read
# on time (--camera-preload-mb 0, so that the memory is the pipeline's). bench/long_run_report.py
# checks the issue's long-run targets (tracking time of the last 10 % against the first 10 %,
# memory per 1000 keyframes, tracking stalls while loops are corrected) and draws
# docs/realtime_long.svg; writes section realtime-long.
# Usage: bench/bench_realtime.sh [path/to/detslam]
#   (env: PRESETS="walking_xyz walking_static walking_rpy walking_halfsphere", SEEDS="101 102 103",
#    FRAMES=300, PARTS="live tracking", LIVE_REPEATS=3, THREADED_REPEATS=2, REPEATS=5, LONG_FRAMES=20000,
#    LONG_SEED=101)
set -euo pipefail
# The synthetic sensor model (`detslam synth --realism`): realistic, the generator's default;
# REALISM=easy gives the first generator's sequences.
export realism="${REALISM:-realistic}"
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="$(realpath "${1:-$root/build/bin/detslam}")"
presets="${PRESETS:-walking_xyz walking_static walking_rpy walking_halfsphere}"
seeds="${SEEDS:-101 102 103}"
frames="${FRAMES:-300}"
parts="${PARTS:-live tracking}"
live_repeats="${LIVE_REPEATS:-3}"
threaded_repeats="${THREADED_REPEATS:-2}"
long_frames="${LONG_FRAMES:-20000}"
long_seed="${LONG_SEED:-101}"
settings_line="bench/bench_realtime.sh (PRESETS=\"$presets\" SEEDS=\"$seeds\" FRAMES=$frames PARTS=\"$parts\" LIVE_REPEATS=$live_repeats THREADED_REPEATS=$threaded_repeats$([[ " $parts " != *" long "* ]] || echo " LONG_FRAMES=$long_frames LONG_SEED=$long_seed") REALISM=$realism)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
bench_name=bench_realtime
# shellcheck source=bench/bench_lib.sh
source "$here/bench_lib.sh"
need_people_and_models

if want live; then
rows="$work/rows.jsonl"
: >"$rows"
for preset in $presets; do
  for seed in $seeds; do
    seq="$work/${preset}_$seed"
    progress "$preset seed $seed: synthesising $frames frames"
    "$bin" synth --realism "$realism" --preset "$preset" --seed "$seed" --frames "$frames" --people "$people" --out "$seq" >/dev/null 2>&1
    progress "$preset seed $seed: offline (sequential)"
    run_eval "$seq" "$seq.offline" --segmenter dnn --models "$models"
    for rep in $(seq 1 "$threaded_repeats"); do
      progress "$preset seed $seed: offline threaded (--threaded, every frame), run $rep of $threaded_repeats"
      run_eval "$seq" "$seq.threaded$rep" --segmenter dnn --models "$models" --threaded
    done
    for rep in $(seq 1 "$live_repeats"); do
      progress "$preset seed $seed: live (--realtime), run $rep of $live_repeats"
      run_eval "$seq" "$seq.live$rep" --segmenter dnn --models "$models" --realtime
    done
    progress "$preset seed $seed: live (--realtime --sync-segmentation)"
    run_eval "$seq" "$seq.sync" --segmenter dnn --models "$models" --realtime --sync-segmentation
    python3 - "$seq" "$preset" "$seed" "$live_repeats" "$threaded_repeats" >>"$rows" <<'PY'
import json, sys
seq, preset, seed, repeats, threaded_repeats = sys.argv[1:6]
ate = lambda p: json.load(open(p + "/eval.json"))["ate"]["rmse"]
def made(p):  # keyframes made over the run, and those the map kept (culling removes the others)
    j = json.load(open(p + "/run.json"))
    return f'{sum(bool(f.get("keyframe")) for f in j["per_frame"])} ({j["keyframes"]})'
runs = []  # one per live run, in run order
for k in range(1, int(repeats) + 1):
    live = json.load(open(f"{seq}.live{k}/run.json"))
    t = live["realtime"]
    runs.append({"offered": t["offered"], "dropped": t["dropped"],
                 "processed": live["frames"], "tracked": live["frames_tracked"],
                 "fps": t["processed_fps"], "lat_median": t["latency_ms"]["median"],
                 "lat_p99": t["latency_ms"]["p99"], "ate_live": ate(f"{seq}.live{k}"),
                 "segmented": t["frames_segmented"],
                 "age_median": t["mask_age_frames"]["median"], "age_max": t["mask_age_frames"]["max"],
                 "deferred": t["keyframes_deferred"], "keyframes": live["keyframes"],
                 "burst": t.get("keyframes_mapped_in_burst", -1)})
print(json.dumps({"preset": preset, "seed": int(seed), "runs": runs,
                  "ate_offline": ate(seq + ".offline"),
                  "offline_keyframes": made(seq + ".offline"),
                  "threaded": [{"ate": ate(f"{seq}.threaded{k}"), "keyframes": made(f"{seq}.threaded{k}")}
                               for k in range(1, int(threaded_repeats) + 1)],
                  "sync_fps": json.load(open(seq + ".sync/run.json"))["realtime"]["processed_fps"],
                  "ate_sync": ate(seq + ".sync")}))
PY
  done
done

carry_growth="$(setting_default Segmentation.CarryGrowth)"
export carry_growth
python3 - "$rows" "$seeds" "$frames" >"$work/section.md" <<'PY'
import json, os, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
seeds, frames = sys.argv[2], sys.argv[3]
print(f"`detslam run --realtime` on synthetic walking sequences (people from the real TUM cut-outs; all "
      f"rows synthetic, `detslam synth --realism {os.environ['realism']}`), evaluation seeds {seeds.replace(' ', ', ')}, {frames} frames at 30 fps each, "
      "default dnn segmenter (offline: YOLOX input 416, Segmentation.InputSize; camera rate: 256 (320 in runs before 2026-12-05 12:20), "
      "Segmentation.CameraRateInputSize, chosen on the tuning seeds 1-3: fresher masks; one OpenCV thread "
      "at camera rate, Segmentation.CameraRateOpenCvThreads, chosen on the same seeds; see the README), "
      "threaded with the mapping and loop-closing threads (loop closing in its own thread since commit 7cfabb5). The camera offers each frame at its "
      "timestamp and holds one; a frame the pipeline has not taken when the next arrives is dropped. "
      "As a camera delivers decoded images, the frames are decoded from their PNG files before the "
      "camera starts (up to 2 GiB; all of these). Segmentation is asynchronous: the segmentation thread "
      "takes the newest frame whenever it is free, and every frame uses the newest masks carried to it "
      "by optical flow (mask age = input frames since the frame they were segmented on), grown by "
      f"{os.environ['carry_growth']} px per frame of age (Segmentation.CarryGrowth; 2 in runs of this section before 2026-12-07 13:00); a frame whose "
      "masks are more than Segmentation.KeyFrameMaxMaskAge = 6 frames old makes no keyframe (chosen on "
      "walking_xyz tuning seeds 1-3 of the easy generator: mean live ATE 2.70 / 2.65 / 2.64 mm with 4 / 6 / 8, equal within the "
      "run-to-run spread, 3 clearly worse for lack of keyframes; 6 keeps the staleness bound at 0.2 s). The "
      "first frame waits for its own masks and is tracked; the frames that arrived before them are "
      "dropped, not queued behind it (Segmentation.CameraRateFirstFrameWaits; runs of this section "
      "before 2026-12-05 11:00 queued them). The mask-free part of a frame's extraction runs in a "
      "helper thread while its masks are carried (Segmentation.CameraRateParallelExtraction; runs of "
      "this section before 2026-12-07 02:00 did it after). The "
      "segmentation and local-mapping threads run at nice 5, so that the frames' path gets the cores "
      "first (on the same tuning seeds: 23.5 -> 26.3 fps, 20 -> 11 % dropped, p99 127 -> 100 ms, ATE "
      "unchanged within the spread; nice 10 for segmentation only or for both did no better). Before each frame it "
      "takes, the segmentation thread waits (at most 100 ms) while the cores were more than 95 % busy over the "
      "last 100 ms (Segmentation.CameraRateMaxBusy; runs of this section before 2026-12-07 22:00 did not wait): "
      "with both cores kept busy the host of this virtual machine stops a core for about 100 ms now and then "
      "(docs/STATUS.md). Figures come from "
      "the live run's own run.json and trajectory: processed fps = frames processed over the time from "
      "the camera's start to the last processed frame's pose (runs of this section before 2026-12-04 "
      "22:00 counted on to the end of the mapping and segmentation threads' work after it); the live ATE is over the frames it processed; ATE "
      "ratio = live ATE over the ATE of the offline sequential run of the same sequence, which processes "
      "and segments every frame. Keyframes: made in the live run (deferred: frames whose keyframe waited "
      "for fresher masks; burst: mapped without fusion or bundle adjustment because more keyframes "
      "waited, as ORB-SLAM3's local mapping does). Columns `sync`: the same camera-rate run with "
      "--sync-segmentation (each frame taken is segmented before extraction). Columns `threaded`: "
      "`detslam run --threaded` on the same frames, every frame taken and segmented, no camera and no "
      "frame dropped (the offline run with the mapping thread beside tracking; THREADED_REPEATS runs): "
      "a sequential run maps each keyframe before the next frame, so its local mapping is always idle "
      "and, by ORB-SLAM3's keyframe rule, it makes more keyframes than any threaded run (made, and in brackets kept after culling); "
      "which frames become keyframes moves a sequence's ATE both ways, so these runs show how far an "
      "offline run with threads lies from the sequential one before any camera-rate effect. "
      "The frame-rate target "
      "reads the issue's \"at least 30 fps processed (at most 2 % of frames dropped)\" as processed fps "
      "at least 98 % of the camera's 30 fps: frames offered at 30 fps give 30.0 processed fps only "
      "when not one frame is dropped.\n")
n_runs = len(rows[0]["runs"])
mean = statistics.fmean
for r in rows:  # per sequence: the mean over its live runs and the worst single run
    for run in r["runs"]:
        run["drop_pct"] = 100 * run["dropped"] / run["offered"]
        run["ratio"] = run["ate_live"] / r["ate_offline"]
    r["m"] = {k: mean(run[k] for run in r["runs"]) for k in
              ("fps", "drop_pct", "lat_median", "lat_p99", "ate_live", "ratio", "segmented",
               "age_median", "keyframes", "deferred", "burst")}
    th = r.get("threaded", [])
    r["th_ratio"] = [t["ate"] / r["ate_offline"] for t in th]
    # The offline runs together: the sequential one and the threaded ones, every frame segmented.
    offline_all = [r["ate_offline"]] + [t["ate"] for t in th]
    r["ate_offline_all"] = mean(offline_all)
    r["ratio_all"] = r["m"]["ate_live"] / r["ate_offline_all"]
    r["worst"] = {"fps": min(run["fps"] for run in r["runs"]),
                  "drop_pct": max(run["drop_pct"] for run in r["runs"]),
                  "lat_p99": max(run["lat_p99"] for run in r["runs"]),
                  "ate_live": max(run["ate_live"] for run in r["runs"]),
                  "ratio": max(run["ratio"] for run in r["runs"]),
                  "age_max": max(run["age_max"] for run in r["runs"])}
print(f"Each sequence ran live {n_runs} times (LIVE_REPEATS): a live run depends on the scheduler, and "
      "one run's ATE and latency tail spread widely between runs of the same frames. Each row gives the "
      "mean over its live runs and, in brackets, the worst single run; the targets are checked on each "
      "sequence's mean (what a user gets on average) and the worst single run is printed beside each. "
      "Runs of this section before 2026-12-07 06:00 made one live run per sequence.\n")
print("| preset | seed | processed fps | dropped % | latency median ms | latency p99 ms | frames segmented | mask age median / max | keyframes (deferred, burst) | processed frames tracked | ATE live mm | ATE offline mm | ATE ratio | sync fps | sync ATE ratio | threaded ATE mm (runs) | threaded ATE ratio (runs) | keyframes made (kept), offline / threaded |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    m, w = r["m"], r["worst"]
    tracked = sum(run["tracked"] for run in r["runs"])
    processed = sum(run["processed"] for run in r["runs"])
    print(f'| {r["preset"]} | {r["seed"]} | {m["fps"]:.1f} ({w["fps"]:.1f}) | {m["drop_pct"]:.1f} ({w["drop_pct"]:.1f}) | '
          f'{m["lat_median"]:.0f} | {m["lat_p99"]:.0f} ({w["lat_p99"]:.0f}) | {m["segmented"]:.0f} | '
          f'{m["age_median"]:.1f} / {w["age_max"]:.0f} | {m["keyframes"]:.0f} ({m["deferred"]:.0f}, {m["burst"]:.0f}) | '
          f'{tracked}/{processed} | {1000 * m["ate_live"]:.1f} ({1000 * w["ate_live"]:.1f}) | {1000 * r["ate_offline"]:.1f} | '
          f'{m["ratio"]:.2f} ({w["ratio"]:.2f}) | {r["sync_fps"]:.1f} | {r["ate_sync"] / r["ate_offline"]:.2f} | '
          + (" / ".join(f'{1000 * t["ate"]:.1f}' for t in r["threaded"]) + " | "
             + " / ".join(f"{x:.2f}" for x in r["th_ratio"]) + " | "
             + f'{r["offline_keyframes"]} / ' + " / ".join(str(t["keyframes"]) for t in r["threaded"]) + " |"
             if r.get("threaded") else "- | - | - |"))
def agg(key):
    v = [key(r) for r in rows]
    return statistics.fmean(v), (statistics.pstdev(v) if len(v) > 1 else 0.0), v
all_runs = [run for r in rows for run in r["runs"]]
fps_m, fps_sd, fps = agg(lambda r: r["m"]["fps"])
drop_m, drop_sd, drop = agg(lambda r: r["m"]["drop_pct"])
p99_m, p99_sd, p99 = agg(lambda r: r["m"]["lat_p99"])
ratio_m, ratio_sd, ratio = agg(lambda r: r["m"]["ratio"])
sfps_m, sfps_sd, sfps = agg(lambda r: r["sync_fps"])
sratio_m, sratio_sd, sratio = agg(lambda r: r["ate_sync"] / r["ate_offline"])
untracked = sum(run["processed"] - run["tracked"] for run in all_runs)
print(f"\nOver the {len(rows)} sequences' means (mean, sd, worst sequence): processed {fps_m:.1f} fps (sd {fps_sd:.1f}, "
      f"worst {min(fps):.1f}); dropped {drop_m:.1f} % (sd {drop_sd:.1f}, worst {max(drop):.1f}); latency p99 "
      f"{p99_m:.0f} ms (sd {p99_sd:.0f}, worst {max(p99):.0f}); ATE ratio {ratio_m:.2f} (sd {ratio_sd:.2f}, "
      f"worst {max(ratio):.2f}); processed frames without a pose in all {len(all_runs)} runs: {untracked}. "
      f"With --sync-segmentation (one run per sequence): "
      f"{sfps_m:.1f} fps (worst {min(sfps):.1f}), ATE ratio {sratio_m:.2f} (worst {max(sratio):.2f}).", end="")
th_all = [x for r in rows for x in r["th_ratio"]]
if th_all:
    th_seq = [statistics.fmean(r["th_ratio"]) for r in rows if r["th_ratio"]]
    print(f" Offline threaded runs ({len(th_all)}, every frame segmented, no camera): ATE ratio to the "
          f"sequential run {statistics.fmean(th_all):.2f} mean (sd {statistics.pstdev(th_all):.2f}, range "
          f"{min(th_all):.2f}-{max(th_all):.2f}; worst sequence's mean {max(th_seq):.2f}), "
          f"{sum(abs(x - 1) > 0.10 for x in th_all)} of {len(th_all)} more than 10 % off it.", end="")
print("\n")
def target(name, ok, detail):
    print(f"- {name}: {'met' if ok else 'MISSED'} ({detail})")
def single(key, ok, worst):
    v = [key(run) for run in all_runs]
    return f"single runs: {sum(ok(x) for x in v)} of {len(v)} within, worst {worst(v)}"
print("Targets of the issue, on each sequence's mean over its live runs:")
target("at least 30 fps processed (98 % of the camera's 30 fps: 29.4)", min(fps) >= 29.4,
       f"worst sequence {min(fps):.1f}; " + single(lambda x: x["fps"], lambda x: x >= 29.4, lambda v: f"{min(v):.1f}"))
target("at most 2 % of frames dropped", max(drop) <= 2,
       f"worst sequence {max(drop):.1f} %; " + single(lambda x: x["drop_pct"], lambda x: x <= 2, lambda v: f"{max(v):.1f} %"))
target("pose latency p99 at most 60 ms", max(p99) <= 60,
       f"worst sequence {max(p99):.0f} ms; " + single(lambda x: x["lat_p99"], lambda x: x <= 60, lambda v: f"{max(v):.0f} ms"))
target("live ATE within 10 % of the offline run's", max(ratio) <= 1.10,
       f"worst sequence {max(ratio):.2f}; " + single(lambda x: x["ratio"], lambda x: x <= 1.10, lambda v: f"{max(v):.2f}"))
target("every processed frame tracked (every run)", untracked == 0, f"{untracked} without a pose")
if th_all:
    ra = [r["ratio_all"] for r in rows]
    print("\nThe ATE target read against all offline runs of a sequence (the mean of the sequential run and "
          "the threaded ones, every frame segmented), so that the reference is not one draw of the "
          "keyframe choice: live ATE within 10 % of it: "
          f"{'met' if max(ra) <= 1.10 else 'MISSED'} (mean {statistics.fmean(ra):.2f}, worst sequence "
          f"{max(ra):.2f}, {sum(x <= 1.10 for x in ra)} of {len(ra)} sequences within). The issue's "
          "reading above (the sequential run) stays the target.")
PY
publish realtime "$work/section.md"
fi

if want tracking; then
  # Tracking + extraction per frame on the real fr2/desk clip (../shared, 50 frames), sequential,
  # against the figure the issue gives for ORB-SLAM3 on this clip and machine kind.
  desk="${DETSLAM_SHARED:-$root/../shared}/data/tum/rgbd_dataset_freiburg2_desk_subset50"
  [[ -f "$desk/rgb.txt" ]] || { echo "missing $desk (the fr2/desk clip)" >&2; exit 1; }
  repeats="${REPEATS:-5}"
  trows="$work/tracking.jsonl"
  : >"$trows"
  for seg in none dnn; do
    for r in $(seq 1 "$repeats"); do
      progress "fr2/desk, segmenter $seg, run $r of $repeats"
      extra=(--segmenter "$seg")
      [[ $seg == dnn ]] && extra+=(--models "$models")
      run_eval "$desk" "$work/desk_${seg}_$r" "${extra[@]}"
      python3 - "$work/desk_${seg}_$r" "$seg" >>"$trows" <<'PY'
import json, statistics, sys
out, seg = sys.argv[1:3]
j = json.load(open(out + "/run.json"))
f = [x for x in j["per_frame"] if x.get("tracked")]
print(json.dumps({"segmenter": seg,
                  "ext": statistics.median(x["extraction_ms"] for x in f),
                  "trk": statistics.median(x["tracking_ms"] for x in f),
                  "sum": statistics.median(x["extraction_ms"] + x["tracking_ms"] for x in f),
                  "frames": len(j["per_frame"]), "tracked": len(f),
                  "ate": json.load(open(out + "/eval.json"))["ate"]["rmse"]}))
PY
    done
  done
  python3 - "$trows" "$repeats" >"$work/tracking.md" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
print(f"Tracking and extraction per frame on the real TUM fr2/desk clip in ../shared (50 frames, "
      f"640x480), sequential mode, {sys.argv[2]} runs each, one row per segmenter setting: `none` is "
      "the RGB-D core alone (what ORB-SLAM3 does); `dnn` adds the Det-SLAM stage's work inside "
      "extraction (masks rasterised, pre-mask, keypoint labels; the detector itself runs before "
      "extraction and is not counted). Extraction includes the bag-of-words words of the frame. "
      "Per run: the median over tracked frames of extraction + tracking ms; the table gives mean, "
      "sd and worst (largest) over runs. Compared with 13-22 ms, the median ORB-SLAM3 tracking time "
      "per frame on this clip and machine kind as the issue states it (ORB-SLAM3 could not be built "
      "here: not measured by this project).\n")
print("| segmenter | extraction ms (median) | tracking ms (median) | extraction + tracking ms: mean | sd | worst | frames tracked | ATE mm |")
print("|---|---|---|---|---|---|---|---|")
for seg in ("none", "dnn"):
    rs = [r for r in rows if r["segmenter"] == seg]
    s = [r["sum"] for r in rs]
    sd = statistics.pstdev(s) if len(s) > 1 else 0.0
    print(f'| {seg} | {statistics.fmean(r["ext"] for r in rs):.1f} | {statistics.fmean(r["trk"] for r in rs):.1f} | '
          f'{statistics.fmean(s):.1f} | {sd:.1f} | {max(s):.1f} | {rs[0]["tracked"]}/{rs[0]["frames"]} | '
          f'{1000 * statistics.fmean(r["ate"] for r in rs):.1f} |')
worst = max(r["sum"] for r in rows if r["segmenter"] == "none")
print(f"\n- target, tracking + extraction at most ORB-SLAM3's 13-22 ms: "
      f"{'met' if worst <= 22 else 'MISSED'} (worst run {worst:.1f} ms against the upper end, 22 ms"
      f"{'; within the lower end, 13 ms' if worst <= 13 else ''})")
PY
  publish realtime-tracking "$work/tracking.md"
fi

if want long; then
  seq="$work/long_seq"
  progress "long: synthesising one loop_long lap (1920 frames, seed $long_seed)"
  "$bin" synth --realism "$realism" --preset loop_long --seed "$long_seed" --frames 1920 --people "$people" --out "$seq" >/dev/null 2>&1
  python3 "$here/repeat_sequence.py" "$seq" 64.0 "$long_frames" >&2
  progress "long: camera-rate run of $long_frames frames ($((long_frames / 30)) s; watchdog 120 s)"
  set +e
  python3 "$here/soak_monitor.py" "$work/long" 120 -- "$bin" run --dataset "$seq" \
    --out "$work/long_run" --seed 42 --realtime --camera-preload-mb 0 --models "$models" >&2
  long_rc=$?
  set -e
  ate="-"
  if [ -f "$work/long_run/trajectory.txt" ]; then
    "$bin" eval --gt "$seq/groundtruth.txt" --est "$work/long_run/trajectory.txt" \
      --json "$work/long_eval.json" >/dev/null 2>&1 &&
      cross_check "$work/long_eval.json" &&
      ate=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["ate"]["rmse"])' \
        "$work/long_eval.json")
  fi
  {
    echo "\`detslam run --realtime\` (default dnn segmenter, threaded with the mapping and loop-closing threads) on $long_frames"
    echo "synthetic frames at 30 Hz ($((long_frames / 1800)) min $(((long_frames % 1800) / 30)) s): one lap of the \`loop_long\` preset"
    echo "(evaluation seed $long_seed; an ellipse of 9.0 x 5.2 m in the large office, 1920 frames = 64 s, the circuit"
    echo "closes exactly; people walk about) listed again and again with later timestamps"
    echo "(bench/repeat_sequence.py), so the camera goes round the same room $(( (long_frames + 1919) / 1920 )) times"
    echo "(the people jump where a lap starts again). The frames are read and decoded on time"
    echo "(--camera-preload-mb 0), so the memory is the pipeline's; that costs CPU time a live camera does"
    echo "not. Every figure comes from the run's own run.json; memory from bench/soak_monitor.py (a run"
    echo "counts as hung when no frame finishes for 120 s). The map stops growing once the room is mapped"
    echo "(keyframes that add nothing are culled): the growth test covers a map of the size in the table."
    echo
    python3 "$here/long_run_report.py" "$work/long" "$work/long_run" "$ate" "$long_rc" "$long_frames"
  } >"$work/long.md"
  publish realtime-long "$work/long.md"
fi

python3 "$here/readme_summary.py"
