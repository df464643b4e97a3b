#!/usr/bin/env bash
# What the live viewer costs a run. Per seed of the synthetic walking_xyz preset (people from the
# real TUM cut-outs, default dnn segmenter, sequential mode), three runs of the same frames:
#   off   no viewer
#   off2  no viewer again, last (two runs of the same frames: the machine's own run-to-run spread)
#   idle  --viewer, no page open
#   page  --viewer with a page open in headless Chromium for the whole run (started --paused, the
#         page connects, then Resume); the browser draws on the same 2 cores (software WebGL);
#         bench/viewer_browser.py holds it open (reads the page's counters 5 times a second) and on
#         the first seed saves the screenshot at half the frames as docs/viewer.png
# Reported per configuration (mean over seeds): processing time per frame (segmentation +
# extraction + tracking + mapping, from run.json's per-frame log), the viewer's own time in the
# tracking thread (its OnFrame: the frame's keypoints by fate, and map snapshots while a page is
# connected; printed by `detslam run`), frames per second of processing, and for off and idle the
# wall-clock frame rate of the whole run. The viewer has one setting (a map snapshot at most every
# 500 ms), not tuned on these seeds.
# Writes docs/BENCHMARKS.md (section viewer) and docs/viewer.png.
# Usage: bench/bench_viewer.sh [path/to/detslam]    env: SEEDS="201 202" FRAMES=300
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
bin="$(realpath "${1:-$root/build/bin/detslam}")"
seeds="${SEEDS:-201 202}"
frames="${FRAMES:-300}"
chromium="$(command -v chromium-headless-shell || command -v chromium || true)"
[[ -n "$chromium" ]] || { echo "no chromium-headless-shell (apt-get install chromium-headless-shell)" >&2; exit 1; }
source "$here/bench_lib.sh"  # shellcheck source=bench/bench_lib.sh
need_people_and_models
work="$(mktemp -d)"
browser_pid=""
cleanup() { [[ -n "$browser_pid" ]] && kill "$browser_pid" 2>/dev/null; rm -rf "$work"; }
trap cleanup EXIT
progress() { echo "[bench_viewer] $*" >&2; }

run() {  # seq config
  local seq=$1 config=$2 out="$work/$(basename "$1").$2"
  local args=(run --dataset "$seq" --out "$out" --seed 42 --no-progress --segmenter dnn --models "$models")
  case $config in
    off | off2) "$bin" "${args[@]}" >"$out.log" 2>&1 ;;
    idle) "$bin" "${args[@]}" --viewer >"$out.log" 2>&1 ;;
    page)
      "$bin" "${args[@]}" --viewer --paused >"$out.log" 2>&1 &
      local run_pid=$! url=""
      for _ in $(seq 600); do
        url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$out.log" | head -1 || true)
        [[ -n "$url" ]] && break
        sleep 0.1
      done
      [[ -n "$url" ]] || { cat "$out.log" >&2; exit 1; }
      local shot=()
      [[ "$seq" == "$first_seq" ]] && shot=(--shot-at $((frames / 2)) --shot "$work/viewer.png")
      python3 "$here/viewer_browser.py" "$chromium" "$url" "${shot[@]}" >"$work/browser.log" 2>&1 &
      browser_pid=$!
      local pages=0
      for _ in $(seq 300); do
        pages=$(curl -s "${url}api/counters" | python3 -c 'import json,sys; print(json.load(sys.stdin)["pages"])' || echo 0)
        [[ "$pages" -ge 1 ]] && break
        sleep 0.1
      done
      [[ "$pages" -ge 1 ]] || { echo "the page did not connect" >&2; exit 1; }
      curl -s -X POST -d resume "${url}api/control" >/dev/null
      wait "$run_pid"
      for _ in $(seq 50); do kill -0 "$browser_pid" 2>/dev/null || break; sleep 0.1; done  # it sees the end
      kill "$browser_pid" 2>/dev/null || true
      wait "$browser_pid" 2>/dev/null || true
      browser_pid=""
      ;;
  esac
  python3 - "$out" "$config" <<'PY'
import json, re, statistics, sys
out, config = sys.argv[1], sys.argv[2]
run = json.load(open(out + "/run.json"))
per = run["per_frame"]
total = [f["segmentation_ms"] + f["extraction_ms"] + f["tracking_ms"] + f["mapping_ms"] for f in per]
log = open(out + ".log").read()
m = re.search(r"viewer cost: ([0-9.]+) ms per frame in the tracking thread \(max ([0-9.]+)\), ([0-9]+) map snapshots of ([0-9.]+) ms", log)
viewer = [float(m.group(1)), float(m.group(2)), int(m.group(3)), float(m.group(4))] if m else [0, 0, 0, 0]
row = {"config": config, "frames": run["frames"], "tracked": run["frames_tracked"],
       "total_ms_mean": statistics.fmean(total), "total_ms_median": statistics.median(total),
       "viewer_ms_mean": viewer[0], "viewer_ms_max": viewer[1], "snapshots": viewer[2],
       "snapshot_ms": viewer[3], "wall_fps": run["frames"] / run["wall_s"] if config != "page" else None}
json.dump(row, open(out + ".row.json", "w"))
PY
}

first_seq="$work/walking_xyz_${seeds%% *}"
for seed in $seeds; do
  seq="$work/walking_xyz_$seed"
  progress "seed $seed: synthesising $frames frames"
  "$bin" synth --preset walking_xyz --seed "$seed" --frames "$frames" --people "$people" --out "$seq" >/dev/null 2>&1
  for config in off idle page off2; do
    progress "seed $seed: $config"
    run "$seq" "$config"
  done
done

python3 - "$work" "$seeds" "$frames" >"$work/section.md" <<'PY'
import glob, json, statistics, sys
work, seeds, frames = sys.argv[1], sys.argv[2].split(), sys.argv[3]
rows = [json.load(open(p)) for p in sorted(glob.glob(work + "/*.row.json"))]
names = {"off": "no viewer", "off2": "no viewer, repeated after the others", "idle": "--viewer, no page open", "page": "--viewer, page open in headless Chromium"}
print("What the live viewer (`detslam run --viewer`) costs a run: synthetic walking_xyz "
      f"(people from the real TUM cut-outs), seeds {', '.join(seeds)}, {frames} frames each, default "
      "dnn segmenter, sequential mode. Processing time per frame = segmentation + extraction + "
      "tracking + mapping (run.json per-frame log); viewer time = its own work in the tracking "
      "thread (keypoints by fate per frame; map snapshots, at most one per 500 ms, only while a "
      "page is connected). The page run is started paused and resumed once the page is connected, "
      "so its wall clock is not comparable (shown as -). All rows synthetic.\n")
print("| configuration | frames tracked | processing ms/frame (mean) | median | viewer ms/frame (mean) | viewer max ms | map snapshots (mean ms) | processing fps | wall-clock fps |")
print("|---|---|---|---|---|---|---|---|---|")
base = None
for config in ["off", "off2", "idle", "page"]:
    rs = [r for r in rows if r["config"] == config]
    if not rs:
        continue
    mean = lambda k: statistics.fmean(r[k] for r in rs)
    tracked = f'{sum(r["tracked"] for r in rs)}/{sum(r["frames"] for r in rs)}'
    per_frame = mean("total_ms_mean") + mean("viewer_ms_mean")
    fps = 1000.0 / per_frame
    if config == "off":
        base = per_frame
    wall = f'{mean("wall_fps"):.1f}' if rs[0]["wall_fps"] is not None else "-"
    snaps = f'{mean("snapshots"):.0f} ({mean("snapshot_ms"):.2f})'
    print(f'| {names[config]} | {tracked} | {mean("total_ms_mean"):.1f} | {mean("total_ms_median"):.1f} | '
          f'{mean("viewer_ms_mean"):.3f} | {max(r["viewer_ms_max"] for r in rs):.1f} | {snaps} | {fps:.1f} | {wall} |')
def per_frame(config):
    rs = [r for r in rows if r["config"] == config]
    return statistics.fmean(r["total_ms_mean"] + r["viewer_ms_mean"] for r in rs) if rs else None
def wall(config):
    rs = [r for r in rows if r["config"] == config and r["wall_fps"]]
    return statistics.fmean(r["wall_fps"] for r in rs) if rs else None
off, off2, idle, page = per_frame("off"), per_frame("off2"), per_frame("idle"), per_frame("page")
if off and off2:
    print(f"\nRun-to-run spread on this machine: the repeated run without a viewer differs from the first by "
          f"{100 * (off2 / off - 1):+.1f} % in processing time per frame and "
          f"{100 * (wall('off2') / wall('off') - 1):+.1f} % in wall-clock frame rate.")
if off and idle:
    v = statistics.fmean(r["viewer_ms_mean"] for r in rows if r["config"] == "idle")
    ref = (off + off2) / 2 if off2 else off
    ref_wall = (wall('off') + wall('off2')) / 2 if off2 else wall('off')
    print(f"No page open: the viewer's own time is {v:.3f} ms per frame ({100 * v / off:.2f} % of a "
          f"frame); processing time per frame {100 * (idle / ref - 1):+.1f} % and wall-clock frame rate "
          f"{100 * (wall('idle') / ref_wall - 1):+.1f} % against the mean of the two runs without a viewer.")
if off and page:
    print(f"Page open: processing time per frame {100 * (page / off - 1):+.1f} % (the browser's rendering "
          "shares the 2 cores; updates the page cannot take are dropped, never queued).")
PY
if [[ -f "$work/viewer.png" ]]; then
  cp "$work/viewer.png" "$root/docs/viewer.png.tmp" && mv "$root/docs/viewer.png.tmp" "$root/docs/viewer.png"
  progress "wrote $root/docs/viewer.png"
else
  progress "no screenshot was taken ($work/browser.log: $(tail -1 "$work/browser.log" 2>/dev/null))"
fi
python3 "$here/update_section.py" viewer "bench/bench_viewer.sh (SEEDS=\"$seeds\" FRAMES=$frames)" <"$work/section.md"
cat "$work/section.md"
