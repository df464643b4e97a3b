#!/usr/bin/env python3
"""Draws docs/dynamic_ratio.svg from the `dynamic` section of docs/BENCHMARKS.md.

One row per walking sequence: the ATE of the run with the Det-SLAM filter divided by the ATE of
its static twin (the issue-4 target is <= 1.25, drawn as a dashed line), green where the target is
met and red where it is not; a hollow diamond marks the same ratio with ground-truth masks, and a
whisker spans the ratios of the spread table (the same runs with a perturbed, people-unrelated
setting) where the benchmark measured one. Every number comes from the tables the benchmark wrote.
bench/bench_dynamic.sh calls it at the end; it can also be run alone.
Usage: bench/plot_dynamic.py
"""
import html
import os
import sys

from readme_summary import ROOT, number, section, stamp_date, tables
from update_section import write_atomically

TARGET = 1.25


def rows_from(dyn):
    """(label, ratio, met, gt_ratio, (lo, hi) or None) per sequence, in table order."""
    ts = tables(dyn)
    main = next((t for t in ts if t and "ratio" in t[0] and "target met" in t[0]), [])
    ablation = next((t for t in ts if t and "gt masks" in t[0]), [])
    spread = next((t for t in ts if t and any(k.startswith("ratio ") for k in t[0])), [])
    gt = {(r["preset"], r["seed"]): number(r["gt masks"]) / number(r["static twin"]) for r in ablation}
    whisker = {}
    for r in spread:
        key = next(k for k in r if k.startswith("ratio "))
        values = [float(v) for v in r[key].split("/")]
        whisker[(r["preset"], r["seed"])] = (min(values), max(values))
    out = []
    for r in main:
        key = (r["preset"], r["seed"])
        out.append((f"{r['preset']} {r['seed']}", number(r["ratio"]), r["target met"] == "yes",
                    gt.get(key), whisker.get(key)))
    return out


def render(rows, subtitle):
    left, right, top, row_h = 170, 50, 58, 22
    width = 760
    plot_w = width - left - right
    height = top + row_h * len(rows) + 48
    hi = max([TARGET * 1.2] + [r[1] for r in rows] + [w[1] for *_, w in rows if w] +
             [g for *_, g, _ in rows if g])
    hi = min(hi, 4.0)

    def x(v):
        return left + plot_w * min(v, hi) / hi

    s = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
         f'font-family="sans-serif" font-size="12">',
         '<rect width="100%" height="100%" fill="white"/>',
         f'<text x="{left}" y="20" font-size="15" font-weight="bold">ATE with the Det-SLAM filter / '
         'ATE of the static twin</text>',
         f'<text x="{left}" y="38" fill="#555">{html.escape(subtitle)}</text>']
    tick = 0.0
    while tick <= hi + 1e-9:
        s.append(f'<line x1="{x(tick):.1f}" y1="{top - 6}" x2="{x(tick):.1f}" '
                 f'y2="{top + row_h * len(rows)}" stroke="#e5e5e5"/>')
        s.append(f'<text x="{x(tick):.1f}" y="{top + row_h * len(rows) + 16}" text-anchor="middle" '
                 f'fill="#555">{tick:g}</text>')
        tick += 0.25
    for i, (label, ratio, met, gt, whisk) in enumerate(rows):
        y = top + i * row_h
        mid = y + row_h / 2
        colour = "#3a9d4a" if met else "#d0453a"
        s.append(f'<text x="{left - 8}" y="{mid + 4:.1f}" text-anchor="end">{html.escape(label)}</text>')
        s.append(f'<rect x="{left}" y="{y + 4}" width="{x(ratio) - left:.1f}" height="{row_h - 8}" '
                 f'fill="{colour}" opacity="0.85"/>')
        s.append(f'<text x="{left + plot_w + 8}" y="{mid + 4:.1f}" fill="{colour}">{ratio:.2f}</text>')
        if whisk:
            s.append(f'<line x1="{x(whisk[0]):.1f}" y1="{mid:.1f}" x2="{x(whisk[1]):.1f}" y2="{mid:.1f}" '
                     'stroke="black" stroke-width="1.5"/>')
            for v in whisk:
                s.append(f'<line x1="{x(v):.1f}" y1="{mid - 5:.1f}" x2="{x(v):.1f}" y2="{mid + 5:.1f}" '
                         'stroke="black" stroke-width="1.5"/>')
        if gt is not None:
            d = 5
            s.append(f'<polygon points="{x(gt):.1f},{mid - d:.1f} {x(gt) + d:.1f},{mid:.1f} '
                     f'{x(gt):.1f},{mid + d:.1f} {x(gt) - d:.1f},{mid:.1f}" fill="white" stroke="#1f4e9c" '
                     'stroke-width="1.5"/>')
    s.append(f'<line x1="{x(TARGET):.1f}" y1="{top - 8}" x2="{x(TARGET):.1f}" y2="{top + row_h * len(rows)}" '
             'stroke="black" stroke-dasharray="5,4"/>')
    s.append(f'<text x="{x(TARGET) + 4:.1f}" y="{top - 10}" fill="black">target {TARGET}</text>')
    ly = top + row_h * len(rows) + 36
    s.append(f'<rect x="{left}" y="{ly - 9}" width="12" height="10" fill="#3a9d4a"/>'
             f'<text x="{left + 16}" y="{ly}">target met</text>'
             f'<rect x="{left + 100}" y="{ly - 9}" width="12" height="10" fill="#d0453a"/>'
             f'<text x="{left + 116}" y="{ly}">missed</text>'
             f'<polygon points="{left + 200},{ly - 9} {left + 205},{ly - 4} {left + 200},{ly + 1} '
             f'{left + 195},{ly - 4}" fill="white" stroke="#1f4e9c" stroke-width="1.5"/>'
             f'<text x="{left + 210}" y="{ly}">ground-truth masks</text>'
             f'<line x1="{left + 345}" y1="{ly - 4}" x2="{left + 375}" y2="{ly - 4}" stroke="black" '
             f'stroke-width="1.5"/><text x="{left + 380}" y="{ly}">spread (perturbed setting)</text>')
    s.append("</svg>")
    return "\n".join(s) + "\n"


def main():
    with open(os.path.join(ROOT, "docs", "BENCHMARKS.md")) as f:
        dyn = section(f.read(), "dynamic")
    rows = rows_from(dyn) if dyn else []
    if not rows:
        print("docs/BENCHMARKS.md: no dynamic section with a ratio table; run bench/bench_dynamic.sh",
              file=sys.stderr)
        return 1
    path = os.path.join(ROOT, "docs", "dynamic_ratio.svg")
    write_atomically(path, render(rows, f"bench/bench_dynamic.sh, {stamp_date(dyn)}"))
    print(f"wrote {path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
