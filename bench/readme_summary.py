#!/usr/bin/env python3
"""Writes the README's benchmark summary table from the measured tables in docs/BENCHMARKS.md.

The numbers come only from the sections the benchmark commands wrote (slam, dynamic, atlas-cover,
atlas-files, dense, realtime, realtime-tracking, realtime-long); this script
condenses them (per preset: seeds, frames tracked, ATE ratio to the static twin) and names the
sections and their dates. The benchmark commands call it at the end; it can also be run alone.
Usage: bench/readme_summary.py
"""
import os
import re
import statistics
import sys

from update_section import replace_marked_block, write_atomically

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def section(text, name):
    m = re.search(rf"<!-- BEGIN {name} -->\n(.*?)<!-- END {name} -->", text, re.S)
    return m.group(1) if m else None


def stamp_date(body):
    m = re.search(r"on (\d{4}-\d{2}-\d{2} \d{2}:\d{2}); .*?commit ([0-9a-f]+[^._]*)", body)
    return f"{m.group(1)}, commit {m.group(2).strip()}" if m else "unknown date"


def tables(body):
    """Every markdown table of a section as a list of dicts keyed by the header cells."""
    out, lines = [], body.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and lines[i + 1].startswith("|---"):
            head = [c.strip() for c in lines[i].strip("|").split("|")]
            rows, i = [], i + 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(dict(zip(head, (c.strip() for c in lines[i].strip("|").split("|")))))
                i += 1
            out.append(rows)
        else:
            i += 1
    return out


def table_with(body, column):
    """The first table of a section that has `column`, as tables() gives it (empty if none)."""
    return next((t for t in tables(body) if t and column in t[0]), [])


def number(cell):
    m = re.match(r"[-0-9.]+", cell)
    return float(m.group(0)) if m else float("nan")


def sensor_model(body):
    """The generator's sensor model a section was measured with, from its stamp (sections written
    before `REALISM` was recorded used the easy one)."""
    m = re.search(r"REALISM=(\w+)", body)
    return m.group(1) if m else "easy"


def summary(bench_text):
    rows = []
    slam = section(bench_text, "slam")
    if slam:
        # The run tables (the depth-weighting table has one ATE column per setting instead).
        run_tables = [t for t in tables(slam) if t and "ATE RMSE mm" in t[0]]
        for table in run_tables:
            for r in table:
                seq = r.get("sequence", "")
                if seq.startswith("fr2/desk"):
                    rows.append(("SLAM core, real TUM fr2/desk (50 frames)", f"{r['tracked']} tracked",
                                 f"ATE RMSE {r['ATE RMSE mm']} mm (ORB-SLAM3: 7.0-8.1 mm)"))
        static = [r for t in run_tables for r in t if r.get("sequence", "").startswith("static")]
        if static:
            ates = [number(r["ATE RMSE mm"]) for r in static]
            tracked = "all frames tracked" if all(r["tracked"].split("/")[0] == r["tracked"].split("/")[1] for r in static) else "NOT all tracked"
            over = re.search(r"Over the (\d+) evaluation seeds: ATE RMSE (.+?) mm", slam)
            seeds = re.search(r"preset \(.*?\), evaluation seeds ([0-9 ]+)", slam)
            if over:
                rows.append((f"SLAM core, synthetic static (evaluation seeds {seeds.group(1).strip() if seeds else '?'})",
                             tracked, f"ATE RMSE {over.group(2)} mm (mean +- sd)"))
            else:
                rows.append((f"SLAM core, synthetic static ({len(static)} seeds)", tracked,
                             f"ATE RMSE {min(ates):.1f}-{max(ates):.1f} mm"))
        loops = {r["sequence"]: r for t in run_tables for r in t if r.get("sequence", "").startswith("loop")}
        drift = dict(re.findall(r"End drift, loop closing (on|off): ([0-9.]+ cm over a [0-9.]+ m path \([0-9.]+ %\))", slam))
        for name, r in loops.items():
            mode = "on" if "closing on" in name else "off"
            rows.append((f"SLAM core, synthetic loop, loop closing {mode}", f"{r['tracked']} tracked",
                         f"ATE RMSE {r['ATE RMSE mm']} mm; end drift {drift.get(mode, '?')}"))
    dyn = section(bench_text, "dynamic")
    if dyn:
        main = table_with(dyn, "ratio")
        sensor = f"synthetic, {sensor_model(dyn)} sensor"
        by_preset = {}
        for r in main:
            by_preset.setdefault(r["preset"], []).append(r)
        for preset, rs in by_preset.items():
            ratios = [number(r["ratio"]) for r in rs]
            all_tracked = all(r["with filter (dnn)"].split("(")[1].rstrip(")").split("/")[0] ==
                              r["with filter (dnn)"].split("(")[1].rstrip(")").split("/")[1] for r in rs)
            met = sum(1 for r in rs if r["target met"] == "yes")
            none = [number(r["without filter"]) for r in rs]
            seeds = ", ".join(r["seed"] for r in rs)
            rows.append((f"Det-SLAM filter (dnn), {preset} ({sensor}, seeds {seeds})",
                         f"{'all frames tracked' if all_tracked else 'NOT all tracked'}, target met {met}/{len(rs)} seeds",
                         f"ATE / static twin {statistics.mean(ratios):.2f} (max {max(ratios):.2f}); "
                         f"without filter {min(none):.1f}-{max(none):.1f} mm"))
    # The every-k table: its own section since it runs on one sequence (older files: in dynamic).
    dyn_k = section(bench_text, "dynamic-k") or dyn
    if dyn_k:
        sensor = f"synthetic, {sensor_model(dyn_k)} sensor"
        k_seed = re.search(r"K_SEED=(\d+)", dyn_k)
        k_seed = k_seed.group(1) if k_seed else "1"
        ks = next((t for t in tables(dyn_k) if t and "k" in t[0] and "fps (threaded, live dnn)" in t[0]), [])
        for r in ks:
            k = r["k"]
            if k.isdigit():
                what = (f"dnn segmenter (YOLOX-nano + Yolo-Fastest-xl on every 2nd segmented frame), "
                        f"segment every {k} frame(s)")
            elif "YOLOX only" in k:
                what = f"YOLOX-nano alone, segment every {k.split()[0]} frame(s)"
            else:  # "1 (second detector every frame)"
                what = f"YOLOX-nano + Yolo-Fastest-xl both on every frame, segment every {k.split()[0]} frame(s)"
            fps = re.match(r"([0-9.]+)(?: \(([0-9.]+-[0-9.]+)\))?", r["fps (threaded, live dnn)"])
            fps_text = f"{fps.group(1)} fps" + (f" (runs: {fps.group(2)})" if fps.group(2) else "")
            live = r.get("live run's own ATE mm (tracked)")
            accuracy = (f"ATE of the live run itself {live} mm" if live else
                        f"ATE {r['ATE mm (tracked)']} mm (replayed masks)")
            rows.append((f"Live threaded pipeline, {what}", fps_text,
                         f"{accuracy} (walking_xyz seed {k_seed}, {sensor})"))
    cover = section(bench_text, "atlas-cover")
    if cover:
        # The over-the-seeds table of the covered-lens benchmark, by position (its header repeats
        # "worst"): mode, posed % mean, worst, ATE mean, sd, worst, ratio mean, worst.
        lines_c = cover.splitlines()
        start = next((i for i, l in enumerate(lines_c) if l.startswith("| sequence, mode")), None)
        i = start + 2 if start is not None else len(lines_c)
        while i < len(lines_c) and lines_c[i].startswith("|"):
            c = [x.strip() for x in lines_c[i].strip("|").split("|")]
            i += 1
            if c[0].startswith("uncovered"):
                continue
            rows.append((f"Covered lens 2 s (roam, synthetic, 3 seeds): {c[0]}",
                         f"{c[1]} % of not-black frames in trajectory.txt (worst {c[2]} %)",
                         f"ATE RMSE {c[3]} mm (worst {c[5]}); {c[6]}x the uncovered run's "
                         f"(worst {c[7]}x)"))
    files = section(bench_text, "atlas-files")
    if files:
        for r in table_with(files, "ATE / SLAM run of that path"):
            if "--load-map" in r["run"]:
                rows.append((f"Map file (static, synthetic): {r['run']}",
                             f"{r['frames tracked']} tracked, {r['keyframes added']} keyframes added",
                             f"ATE RMSE {r['ATE RMSE mm']} mm, {r['ATE / SLAM run of that path']}x the SLAM run's"))
    dense = section(bench_text, "dense")
    if dense:
        for r in table_with(dense, "on people, filter %"):
            rows.append((f"Dense static map (synthetic {r['preset']}, 3 evaluation seeds)",
                         f"{r['points (k)'].split()[0]}k points, completeness {r['completeness %'].split()[0]} %",
                         f"on people {r['on people, filter %']} % (no filter, no carving: "
                         f"{r['on people, no filter, no carving %'].split()[0]} %); median distance to the "
                         f"scene {r['median distance mm']} mm"))
    realtime = section(bench_text, "realtime")
    if realtime:
        # Since 2026-12-07 each sequence's figures are the mean over several live runs
        # (LIVE_REPEATS); the older one-run sections read the same way.
        m = re.search(r"Over the (\d+) sequences(?:' means)? \(mean, sd, worst(?: sequence)?\): processed "
                      r"([0-9.]+) fps \(sd [0-9.]+, "
                      r"worst ([0-9.]+)\); dropped ([0-9.]+) % \(sd [0-9.]+, worst ([0-9.]+)\); latency p99 "
                      r"([0-9.]+) ms \(sd [0-9.]+, worst ([0-9.]+)\); ATE ratio ([0-9.]+) \(sd [0-9.]+, "
                      r"worst ([0-9.]+)\); processed frames without a pose(?: in all (\d+) runs)?: (\d+)", realtime)
        if m:
            n, fps, fps_w, drop, drop_w, p99, p99_w, ratio, ratio_w, runs, untracked = m.groups()
            runs_text = f", {int(runs) // int(n)} live runs each, their mean" if runs else ""
            rows.append((f"Camera rate (`--realtime`, asynchronous dnn segmentation; synthetic walking "
                         f"presets, {n} sequences of evaluation seeds{runs_text})",
                         f"{fps} fps processed (worst {fps_w}), {drop} % dropped (worst {drop_w} %), "
                         f"latency p99 {p99} ms (worst {p99_w}); {untracked} processed frames without a pose",
                         f"live ATE {ratio}x the offline run's (worst {ratio_w}x)"))
    tracking = section(bench_text, "realtime-tracking")
    if tracking:
        for r in table_with(tracking, "segmenter"):
            if r["segmenter"] == "none":
                rows.append(("Tracking + extraction per frame (real TUM fr2/desk clip, sequential, no segmenter)",
                             f"{r['frames tracked']} tracked",
                             f"{r['extraction + tracking ms: mean']} ms median (worst run {r['worst']} ms; "
                             "ORB-SLAM3: 13-22 ms as the issue quotes it)"))
    long_run = section(bench_text, "realtime-long")
    if long_run:
        runs = table_with(long_run, "frames offered")
        cost = {r["per frame"]: r for r in table_with(long_run, "last / first")}
        stall = re.search(r"no tracking stall longer than 2 frame periods while a loop is corrected: "
                          r"(met|MISSED) \(([^)]*)\)", long_run)
        growth = re.search(r"Growth per 1000 keyframes: ([0-9.]+) MiB", long_run)
        if runs and "tracking ms, median" in cost:
            r, c = runs[0], cost["tracking ms, median"]
            rows.append((f"Long camera-rate run ({r['frames offered']} synthetic frames, loop_long lap repeated)",
                         f"{r['processed frames tracked']} tracked, {r['dropped']} dropped",
                         f"ATE {r['ATE mm']} mm; tracking {c['first 10 %']} -> {c['last 10 %']} ms median "
                         f"(first / last 10 %: {c['last / first']}x)"
                         + (f"; memory {growth.group(1)} MiB per 1000 keyframes" if growth else "")
                         + (f"; loop correction stall {stall.group(2)}" if stall else "")))
    lines = ["| benchmark | frames | accuracy |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    sources = []
    for name in ("slam", "dynamic", "dynamic-k", "atlas-cover", "atlas-files", "dense", "realtime",
                 "realtime-tracking", "realtime-long"):
        body = section(bench_text, name)
        if body:
            sources.append(f"`{name}` ({stamp_date(body)})")
    # The synthetic generator's sensor model each section was measured with (sections written
    # before `REALISM` was recorded used the easy one).
    sensors = {}
    for name in ("slam", "dynamic", "dynamic-k", "atlas-cover", "atlas-files", "dense", "realtime",
                 "realtime-long"):
        body = section(bench_text, name)
        if body:
            sensors.setdefault(sensor_model(body), []).append(f"`{name}`")
    sensor_text = "; ".join(f"{k} sensor: {', '.join(v)}" for k, v in sorted(sensors.items(), reverse=True))
    head = (f"_Condensed by `bench/readme_summary.py` from docs/BENCHMARKS.md sections "
            f"{', '.join(sources) or '(none yet)'}; details, machine and settings there. Synthetic "
            f"rows by the generator's sensor model (`detslam synth --realism`): {sensor_text}._\n\n")
    return head + "\n".join(lines) + "\n"


def main():
    with open(os.path.join(ROOT, "docs", "BENCHMARKS.md")) as f:
        bench = f.read()
    readme_path = os.path.join(ROOT, "README.md")
    with open(readme_path) as f:
        readme = f.read()
    if "<!-- BEGIN summary -->" not in readme or "<!-- END summary -->" not in readme:
        print(f"{readme_path}: no '<!-- BEGIN summary -->' ... '<!-- END summary -->' markers", file=sys.stderr)
        return 1
    write_atomically(readme_path, replace_marked_block(readme, "summary", summary(bench)))
    print(f"updated the benchmark summary of {readme_path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
