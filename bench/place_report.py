#!/usr/bin/env python3
"""Turns bench_place's JSON into the markdown of the `place` section and draws its plot.

Writes the markdown to stdout and the plot (relocalisation time against map size: median and p90
of the whole query, median of the bag-of-words candidates alone, the 5 ms target) to
docs/place_reloc_time.svg, a hand-made SVG (no plotting library needed).
bench/bench_place.sh calls it; it can also be run alone on a JSON file.
Usage: bench/place_report.py RESULT.json
"""
import html
import json
import math
import os
import sys

from update_section import write_atomically

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SVG_NAME = "place_reloc_time.svg"
TARGET_MS = 5.0       # median at 1000 keyframes
TARGET_RATIO = 1.5    # median(5000) / median(1000)


def by_size(result):
    return {s["keyframes"]: s for s in result["sizes"]}


def verdict(result, key="total_ms"):
    """(median at 1000, ratio 5000/1000, pass 1000, pass ratio) of the per-query times `key`
    (total_ms: each query's fastest run; total_ms_median_of_runs: its median run); None where
    not measured."""
    sizes = by_size(result)
    m1000 = sizes[1000][key]["median"] if 1000 in sizes else None
    m5000 = sizes[5000][key]["median"] if 5000 in sizes else None
    ratio = m5000 / m1000 if m1000 and m5000 is not None else None
    return (m1000, ratio, m1000 is not None and m1000 <= TARGET_MS,
            ratio is not None and ratio <= TARGET_RATIO)


def render_svg(result):
    sizes = sorted(by_size(result).items())
    xs = [n for n, _ in sizes]
    series = [
        ("median, whole query", "#1f5fbf", [s["total_ms"]["median"] for _, s in sizes], ""),
        ("p90, whole query", "#d0453a", [s["total_ms"]["p90"] for _, s in sizes], ""),
        ("median, candidates alone", "#3a9d4a", [s["candidates_ms"]["median"] for _, s in sizes],
         ""),
    ]
    width, height = 780, 450
    left, right, top, bottom = 70, 240, 80, 60
    pw, ph = width - left - right, height - top - bottom
    hi = max([TARGET_MS] + [v for *_, vals, _ in series for v in vals]) * 1.1
    step = 10 ** math.floor(math.log10(hi / 4))
    for m in (1, 2, 5, 10):
        if hi / (m * step) <= 8:
            step *= m
            break
    xmax = max(xs) * 1.04

    def x(v):
        return left + pw * v / xmax

    def y(v):
        return top + ph * (1 - v / hi)

    s = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
         f'font-family="sans-serif" font-size="12">',
         '<rect width="100%" height="100%" fill="white"/>',
         f'<text x="{left}" y="22" font-size="15" font-weight="bold">Relocalisation query time '
         'against map size (synthetic)</text>',
         f'<text x="{left}" y="40" fill="#555">Tracker::RelocalizeFrame, '
         f'{sizes[0][1]["queries"]} queries per size, single thread, fastest of '
         f'{result["settings"]["repeats"]} runs per query</text>']
    t = 0.0
    while t <= hi + 1e-9:
        s.append(f'<line x1="{left}" y1="{y(t):.1f}" x2="{left + pw}" y2="{y(t):.1f}" '
                 'stroke="#e5e5e5"/>')
        s.append(f'<text x="{left - 6}" y="{y(t) + 4:.1f}" text-anchor="end" fill="#555">'
                 f'{t:g}</text>')
        t += step
    last_label = -1e9
    for n in xs:
        s.append(f'<line x1="{x(n):.1f}" y1="{top}" x2="{x(n):.1f}" y2="{top + ph}" '
                 'stroke="#f0f0f0"/>')
        low = x(n) - last_label < 34  # crowded: this label one line lower
        s.append(f'<text x="{x(n):.1f}" y="{top + ph + (30 if low else 16)}" text-anchor="middle" '
                 f'fill="#555">{n}</text>')
        last_label = -1e9 if low else x(n)
    s.append(f'<line x1="{left}" y1="{top + ph}" x2="{left + pw}" y2="{top + ph}" stroke="#333"/>')
    s.append(f'<line x1="{left}" y1="{top}" x2="{left}" y2="{top + ph}" stroke="#333"/>')
    s.append(f'<text x="{left + pw / 2}" y="{height - 10}" text-anchor="middle">keyframes in the '
             'map</text>')
    s.append(f'<text x="18" y="{top + ph / 2}" text-anchor="middle" '
             f'transform="rotate(-90 18 {top + ph / 2})">milliseconds</text>')
    # Targets: 5 ms at 1000 keyframes, and 1.5 x the measured 1000 median at 5000.
    s.append(f'<line x1="{left}" y1="{y(TARGET_MS):.1f}" x2="{left + pw}" y2="{y(TARGET_MS):.1f}" '
             'stroke="#888" stroke-dasharray="6 4"/>')
    s.append(f'<text x="{left + pw + 6}" y="{y(TARGET_MS) + 4:.1f}" fill="#666">target: median '
             '&lt;= 5 ms at 1000</text>')
    m1000, _, _, _ = verdict(result)
    if m1000 is not None and 5000 in xs:
        s.append(f'<line x1="{x(1000):.1f}" y1="{y(m1000 * TARGET_RATIO):.1f}" x2="{x(5000):.1f}" '
                 f'y2="{y(m1000 * TARGET_RATIO):.1f}" stroke="#1f5fbf" stroke-dasharray="2 3"/>')
        s.append(f'<text x="{left + pw + 6}" y="{y(m1000 * TARGET_RATIO) + 4:.1f}" '
                 'fill="#1f5fbf">1.5 x median(1000)</text>')
    for i, (label, colour, vals, _) in enumerate(series):
        pts = " ".join(f"{x(n):.1f},{y(v):.1f}" for n, v in zip(xs, vals))
        s.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="2"/>')
        for n, v in zip(xs, vals):
            s.append(f'<circle cx="{x(n):.1f}" cy="{y(v):.1f}" r="3.5" fill="{colour}"/>')
        lx = left + 200 * i  # legend: one row between the subtitle and the plot
        s.append(f'<line x1="{lx}" y1="{top - 18}" x2="{lx + 22}" y2="{top - 18}" '
                 f'stroke="{colour}" stroke-width="2"/>')
        s.append(f'<text x="{lx + 28}" y="{top - 14}">{html.escape(label)}</text>')
    s.append("</svg>")
    return "\n".join(s) + "\n"


def fmt(v, digits=2):
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def markdown(result):
    st, b = result["settings"], result["build"]
    seqs = result["sequences"]
    seeds = sorted({q["seed"] for q in seqs})
    out = []
    out.append("Relocalisation query (issue \"place recognition\", first target): "
               "`Tracker::RelocalizeFrame` on a frame")
    out.append("whose tracking is lost, exactly what SLAM runs then: bag-of-words candidates from "
               "the map's keyframe")
    out.append("index (`RelocalizationCandidates`), matching within direct-index nodes, PnP "
               "RANSAC, pose optimisation and")
    out.append("projection search. Timed with std::chrono::steady_clock, one thread "
               f"(cv::setNumThreads(1)), each query run {st['repeats']} times;")
    out.append("a query's time is its fastest run (the one least disturbed by other processes "
               "on this shared host; the")
    out.append("median over queries of each query's median run is in its own column). "
               "A fresh Tracker per run (RANSAC seed "
               f"{st['seed']}); shipped vocabulary `{os.path.basename(st['vocabulary'])}`, "
               f"{st['orb_features']} ORB features per frame.")
    out.append("")
    out.append(f"**Synthetic maps** (synth/, rendered in memory, people off): {len(seqs)} "
               f"sequences, presets {', '.join(st['presets'])} cycling,")
    out.append(f"seeds {seeds[0]}-{seeds[-1]} (a seed gives the room other textures and the "
               f"camera path other phases); {st['keyframes_per_sequence']} keyframes per "
               f"sequence, one every {st['stride']} frames,")
    out.append("at the ground-truth pose; one landmark per keypoint with depth, back-projected "
               "with the ground-truth pose.")
    if st["covisibility"]:
        out.append("Covisibility: each keyframe shares the landmarks of the previous "
                   f"{st['covisible_keyframes']} keyframes of its sequence that `SearchByProjection` "
                   "finds in it at the")
        out.append("ground-truth pose (depth within 5 %); "
                   f"{b['shared_observations']} shared observations in the largest map.")
    else:
        out.append("Covisibility: none (every keyframe has its own landmarks; candidate groups "
                   "are single keyframes).")
    out.append("The map grows sequence by sequence and is measured at each size. **Queries**: "
               f"{st['queries_per_sequence']} frames from each of the")
    out.append(f"first {st['query_sequences']} sequences (those in the smallest map), each half-way "
               f"between two keyframes ({st['stride'] // 2} frames from both), the same queries "
               "at every size.")
    out.append("Success: RelocalizeFrame returned a pose (>= 50 inliers). Position error: camera "
               "centre against ground truth, successes only.")
    out.append(f"Map building took {b['seconds']:.0f} s (render {b['render_ms'] / 1000:.0f} s, "
               f"extraction {b['extract_ms'] / 1000:.0f} s, map insertion "
               f"{b['insert_ms'] / 1000:.0f} s).")
    out.append("")
    out.append("| map (synthetic) | keyframes | landmarks | queries | median ms | p90 ms | max ms | "
               "median ms, median run | candidates median ms | candidates (median) | success % | "
               "same room % | position error median cm |")
    out.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n, s in sorted(by_size(result).items()):
        t = s["total_ms"]
        succ = s["successes"]
        out.append(f"| synthetic, {n} keyframes | {n} | {s['landmarks']} | {s['queries']} | "
                   f"{fmt(t['median'])} | {fmt(t['p90'])} | {fmt(t['max'])} | "
                   f"{fmt(s['total_ms_median_of_runs']['median'])} | "
                   f"{fmt(s['candidates_ms']['median'])} | {s['candidates']['median']:.0f} | "
                   f"{100 * s['success_rate']:.1f} | "
                   f"{fmt(100 * s['same_room'] / succ if succ else None, 1)} | "
                   f"{fmt(s['position_error_cm']['median'])} |")
    out.append("")
    out.append("Same room: successes relocalised against a keyframe of the query's own room "
               "(seed).")
    out.append("")
    out.append("Inverted-index work per query (medians, counted outside the timing): entries on "
               "the lists of the query's words,")
    out.append("which `KeyFrameDatabase::Query` visits one by one, and keyframes sharing at least "
               "one word with the query.")
    out.append("")
    out.append("| map (synthetic) | words in a query | index entries visited | keyframes sharing a "
               "word | candidates median ms |")
    out.append("|---|---:|---:|---:|---:|")
    for n, s in sorted(by_size(result).items()):
        out.append(f"| synthetic, {n} keyframes | {s['query_words']['median']:.0f} | "
                   f"{s['index_entries']['median']:.0f} | "
                   f"{s['keyframes_sharing_a_word']['median']:.0f} | "
                   f"{fmt(s['candidates_ms']['median'])} |")
    def judged(value, ok):
        return "not measured" if value is None else ("PASS" if ok else "FAIL")

    out.append("")
    out.append("| target | per query | measured | result |")
    out.append("|---|---|---:|---|")
    for key, label in (("total_ms", "fastest run"), ("total_ms_median_of_runs", "median run")):
        m1000, ratio, ok1, ok2 = verdict(result, key)
        out.append(f"| median <= {TARGET_MS:g} ms at 1000 keyframes (synthetic) | {label} | "
                   f"{fmt(m1000)} ms | {judged(m1000, ok1)} |")
        out.append(f"| median(5000) / median(1000) <= {TARGET_RATIO:g} (synthetic) | {label} | "
                   f"{fmt(ratio)} | {judged(ratio, ok2)} |")
    out.append("")
    out.append(f"![relocalisation time against map size]({SVG_NAME})")
    return "\n".join(out) + "\n"


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1]) as f:
        result = json.load(f)
    write_atomically(os.path.join(ROOT, "docs", SVG_NAME), render_svg(result))
    sys.stdout.write(markdown(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
