#!/usr/bin/env python3
"""Summarises the soak run of bench/bench_reliability.sh part K (Markdown on stdout) and draws
docs/reliability_soak.svg (resident memory and atlas size against the frame).

Usage: soak_report.py PREFIX RUN_DIR ATE_M MONITOR_EXIT FRAMES
  PREFIX: soak_monitor.py's prefix (PREFIX.samples.tsv, PREFIX.peak)
  RUN_DIR: the run's output folder (run.json)
Memory counts as bounded when the resident memory at the last frame is at most 1.25x that at half
the run (the outputs written after the last frame make a one-off peak, reported apart): over the second half of a sequence that keeps going round the same room the map should not
grow, since keyframes that add nothing are culled.
"""
import json
import os
import sys

from frame_panels import FramePanels
from update_section import write_atomically

prefix, run_dir, ate, monitor_rc, frames = sys.argv[1:6]
frames = int(frames)
rows = []
for line in open(prefix + ".samples.tsv").read().splitlines()[1:]:
    s, f, k, p, r = line.split("\t")
    rows.append((float(s), int(f), int(k), int(p), float(r)))
peak = float(open(prefix + ".peak").read())
run = json.load(open(os.path.join(run_dir, "run.json"))) if os.path.exists(
    os.path.join(run_dir, "run.json")) else None


def at(fraction):
    """The first sample at or after fraction of the frames."""
    want = fraction * frames
    return next((r for r in rows if r[1] >= want), rows[-1] if rows else None)


# The last sample before the last frame was done: after it the outputs are written (run.json of
# every frame built in memory), a one-off peak reported apart.
half = at(0.5)
end = next((r for r in reversed(rows) if r[1] < frames), rows[-1] if rows else None)
bounded = bool(half and end and end[4] <= 1.25 * half[4])
finished = monitor_rc == "0" and run is not None and run["frames"] == frames
print("| result | frames processed | tracked | wall s | fps | ATE m | keyframes at 10% / 50% / end "
      "| map points at end | RSS MiB at 10% / 50% / last frame | peak RSS MiB (outputs written "
      "included) | memory bounded (last frame <= 1.25x half) |")
print("|---|---:|---:|---:|---:|---:|---|---:|---|---:|---|")
if run is None:
    print(f"| FAILED (monitor exit {monitor_rc}) | - | - | - | - | - | - | - | - | {peak:.0f} | - |")
else:
    p10 = at(0.1)
    tracked = run["frames_tracked"] / max(run["frames"], 1)
    result = "finished, no hang" if finished else f"FAILED (monitor exit {monitor_rc})"
    print(f"| {result} | {run['frames']} | {100 * tracked:.1f}% | {run['wall_s']:.0f} | "
          f"{run['frames'] / max(run['wall_s'], 1e-9):.1f} | {ate} | {p10[2]} / {half[2]} / "
          f"{run['keyframes']} | {run['map_points']} | {p10[4]:.0f} / {half[4]:.0f} / {end[4]:.0f}"
          f" | {peak:.0f} | {'yes' if bounded else 'NO'} |")

# The figure: two panels sharing the frame axis.
W, H, L, R, T, GAP, PH = 760, 440, 70, 70, 30, 50, 150
x_max = max(frames, 1)
panels = FramePanels(W, L, R, PH, x_max)


svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
       f'font-family="sans-serif">', f'<rect width="{W}" height="{H}" fill="white"/>',
       f'<text x="{W / 2}" y="18" text-anchor="middle" font-size="13">Soak run: {frames} synthetic '
       f'frames (loop preset, threaded, people); resident memory and atlas size</text>']
# One point per progress line (every 100 frames): the last sample taken at that frame.
plotted = list({r[1]: r for r in rows}.values())
if rows:
    rss_max = max(r[4] for r in rows) * 1.1
    kf_max = max(r[2] for r in rows) * 1.1
    pt_max = max(r[3] for r in rows) * 1.1
    top1, top2 = T + 10, T + 10 + PH + GAP
    svg += panels.axes(top1, rss_max, "RSS MiB", "#c0392b")
    svg.append(panels.line([(r[1], r[4]) for r in plotted], rss_max, top1, "#c0392b"))
    svg += panels.axes(top2, kf_max, "keyframes", "#2166ac")
    svg.append(panels.line([(r[1], r[2]) for r in plotted], kf_max, top2, "#2166ac"))
    svg.append(panels.line([(r[1], r[3] * kf_max / pt_max) for r in plotted], kf_max, top2, "#1a9850"))
    svg.append(f'<text x="{W - R + 6}" y="{top2 + 12}" font-size="11" fill="#1a9850">points</text>')
    svg.append(f'<text x="{W - R + 6}" y="{top2 + 26}" font-size="11" fill="#1a9850">'
               f'(max {pt_max / 1.1:.0f})</text>')
    for k in range(0, 6):
        f = x_max * k / 5
        x = panels.x(f)
        svg.append(f'<text x="{x:.1f}" y="{top2 + PH + 16}" text-anchor="middle" '
                   f'font-size="11">{f:.0f}</text>')
    svg.append(f'<text x="{W / 2}" y="{top2 + PH + 34}" text-anchor="middle" font-size="12">'
               f'frame</text>')
svg.append("</svg>")
here = os.path.dirname(os.path.abspath(__file__))
write_atomically(os.path.join(os.path.dirname(here), "docs", "reliability_soak.svg"),
                 "\n".join(svg) + "\n")
print()
print("![Soak run: resident memory and atlas size against the frame](reliability_soak.svg)")
print()
