#!/usr/bin/env python3
"""Lists a TUM-format sequence's frames again and again with later timestamps (soak runs).

Usage: repeat_sequence.py SEQ_DIR PERIOD_S FRAMES

Rewrites SEQ_DIR/rgb.txt, depth.txt and groundtruth.txt in place: repetition r of every line has
its timestamp increased by r * PERIOD_S (the duration of one pass, e.g. a closed camera circuit),
the image paths unchanged, until rgb.txt lists FRAMES frames; depth and ground truth are cut at
the last colour stamp (+ one period of a frame).
"""
import os
import sys

seq, period, frames = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])


def read(name):
    path = os.path.join(seq, name)
    lines = open(path).read().splitlines()
    head = [l for l in lines if l.startswith("#")]
    data = [l.split() for l in lines if l.strip() and not l.startswith("#")]
    return path, head, data


def repeated(data, count=None, until=None):
    out, r = [], 0
    while True:
        for row in data:
            stamp = float(row[0]) + r * period
            if (count is not None and len(out) == count) or (until is not None and stamp > until):
                return out
            out.append([f"{stamp:.6f}"] + row[1:])
        r += 1


rgb_path, rgb_head, rgb = read("rgb.txt")
span = float(rgb[-1][0]) - float(rgb[0][0])
if not 0 < span < period:
    sys.exit(f"{rgb_path}: frames span {span} s, not less than one period of {period} s")
rgb_out = repeated(rgb, count=frames)
last = float(rgb_out[-1][0]) + period / len(rgb)
for name in ("rgb.txt", "depth.txt", "groundtruth.txt"):
    path, head, data = read(name)
    rows = rgb_out if name == "rgb.txt" else repeated(data, until=last)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(head + [" ".join(r) for r in rows]) + "\n")
    os.replace(tmp, path)
print(f"[repeat] {seq}: {len(rgb_out)} frames, {len(rgb_out) / len(rgb):.1f} passes of {period} s")
