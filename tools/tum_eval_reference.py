#!/usr/bin/env python3
"""Independent reference for `detslam eval`: TUM RGB-D benchmark ATE and fixed-delta RPE.

Written from the documented semantics of the TUM tools (associate.py, evaluate_ate.py,
evaluate_rpe.py --fixed_delta); it shares no code with them or with detslam. Stamps are parsed
exactly into integer nanoseconds so that association never depends on float rounding.

  ATE: greedy one-to-one association of |t_gt - (t_est + offset)| < max_difference, closest
       pairs first (ties: smaller gt stamp, then smaller est stamp); closed-form rigid alignment
       of the estimated positions to the ground-truth positions (SVD with reflection fix, no
       scale); per-pair error |gt - aligned est|.
  RPE: for each estimate index i, j = estimate whose stamp (unit s) or index (unit f) is closest
       to key_i + delta (ties: earlier); drop the pair when j is the last index; ground truth is
       the closest stamp to t_est + offset, rejected beyond 2 x the median gt interval;
       E = inv(inv(Pe_j) Pe_i) inv(Pg_j) Pg_i; trans = |t(E)|, rot = arccos((tr R - 1) / 2) in deg.

Prints one JSON object. Needs Python 3 and numpy.
Usage: tum_eval_reference.py GT EST [--max_difference 0.02] [--offset 0] [--delta 1]
       [--delta_unit s|f]
"""
import argparse
import bisect
import json
import sys
from decimal import Decimal

import numpy as np


def read_poses(path):
    """Returns a sorted list of (stamp_ns, 4x4 world_from_cam) from a TUM trajectory file."""
    poses = {}
    with open(path) as f:
        for line in f:
            text = line.replace(",", " ").replace("\t", " ").strip()
            if not text or text.startswith("#"):
                continue
            fields = text.split()
            stamp = int((Decimal(fields[0]) * 1000000000).to_integral_value())
            v = [float(x) for x in fields[1:8]]
            q = np.array(v[3:7])  # qx qy qz qw
            q = q / np.linalg.norm(q)
            x, y, z, w = q
            rot = np.array([
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            m = np.eye(4)
            m[:3, :3] = rot
            m[:3, 3] = v[0:3]
            poses[stamp] = m
    return sorted(poses.items())


def greedy_associate(gt_stamps, est_stamps, max_diff_ns, offset_ns):
    candidates = []
    for a in gt_stamps:
        for b in est_stamps:
            d = abs(a - (b + offset_ns))
            if d < max_diff_ns:
                candidates.append((d, a, b))
    candidates.sort()
    used_a, used_b, out = set(), set(), []
    for _, a, b in candidates:
        if a in used_a or b in used_b:
            continue
        used_a.add(a)
        used_b.add(b)
        out.append((a, b))
    out.sort()
    return out


def rigid_fit(src, dst):
    """R, t minimising sum |dst - (R src + t)|^2; src, dst are 3xN."""
    mu_s = src.mean(axis=1, keepdims=True)
    mu_d = dst.mean(axis=1, keepdims=True)
    cov = (dst - mu_d) @ (src - mu_s).T
    u, _, vt = np.linalg.svd(cov)
    fix = np.diag([1.0, 1.0, np.sign(np.linalg.det(u) * np.linalg.det(vt))])
    r = u @ fix @ vt
    return r, mu_d - r @ mu_s


def stats(values):
    v = np.asarray(values, dtype=float)
    return {"count": int(v.size), "rmse": float(np.sqrt(np.mean(v * v))),
            "mean": float(np.mean(v)), "median": float(np.median(v)),
            "std": float(np.std(v)), "min": float(np.min(v)), "max": float(np.max(v))}


def closest(sorted_keys, key):
    k = bisect.bisect_left(sorted_keys, key)
    if k == 0:
        return 0
    if k == len(sorted_keys):
        return len(sorted_keys) - 1
    return k - 1 if key - sorted_keys[k - 1] <= sorted_keys[k] - key else k


def ate(gt, est, max_diff_ns, offset_ns):
    gt_map, est_map = dict(gt), dict(est)
    pairs = greedy_associate([s for s, _ in gt], [s for s, _ in est], max_diff_ns, offset_ns)
    if len(pairs) < 3:
        raise SystemExit("fewer than 3 associated pairs")
    g = np.array([gt_map[a][:3, 3] for a, _ in pairs]).T
    e = np.array([est_map[b][:3, 3] for _, b in pairs]).T
    r, t = rigid_fit(e, g)
    err = np.sqrt(np.sum((r @ e + t - g) ** 2, axis=0))
    out = stats(err)
    out["pairs"] = len(pairs)
    return out


def rpe(gt, est, delta, unit, offset_ns):
    gt_stamps = [s for s, _ in gt]
    est_stamps = [s for s, _ in est]
    n = len(est)
    max_gt_ns = 2.0 * float(np.median(np.diff(np.array(gt_stamps, dtype=np.int64))))
    trans, rot = [], []
    for i in range(n):
        if unit == "s":
            j = closest(est_stamps, est_stamps[i] + int(round(delta * 1e9)))
        else:
            j = min(i + int(round(delta)), n - 1)
        if j == n - 1:
            continue
        gi = closest(gt_stamps, est_stamps[i] + offset_ns)
        gj = closest(gt_stamps, est_stamps[j] + offset_ns)
        if (abs(gt_stamps[gi] - (est_stamps[i] + offset_ns)) > max_gt_ns or
                abs(gt_stamps[gj] - (est_stamps[j] + offset_ns)) > max_gt_ns):
            continue
        est_ji = np.linalg.inv(est[j][1]) @ est[i][1]
        gt_ji = np.linalg.inv(gt[gj][1]) @ gt[gi][1]
        err = np.linalg.inv(est_ji) @ gt_ji
        trans.append(float(np.linalg.norm(err[:3, 3])))
        c = (np.trace(err[:3, :3]) - 1.0) / 2.0
        rot.append(float(np.degrees(np.arccos(min(1.0, max(-1.0, c))))))
    out = {"pairs": len(trans)}
    if trans:
        out["trans_m"] = stats(trans)
        out["rot_deg"] = stats(rot)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gt")
    parser.add_argument("est")
    parser.add_argument("--max_difference", type=float, default=0.02)
    parser.add_argument("--offset", type=float, default=0.0)
    parser.add_argument("--delta", type=float, default=1.0)
    parser.add_argument("--delta_unit", choices=["s", "f"], default="s")
    args = parser.parse_args()
    gt = read_poses(args.gt)
    est = read_poses(args.est)
    offset_ns = int(round(args.offset * 1e9))
    result = {"ate": ate(gt, est, args.max_difference * 1e9, offset_ns),
              "rpe": rpe(gt, est, args.delta, args.delta_unit, offset_ns)}
    json.dump(result, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
