#!/usr/bin/env python3
"""Small helpers for bench/bench_slam.sh: read detslam run.json / eval JSON files and compute the
end drift of a trajectory (the last pose's position error after aligning the first poses only).

Usage:
  slam_metrics.py field FILE.json key.path        -> prints the value
  slam_metrics.py drift groundtruth.txt trajectory.txt -> prints 'drift_m path_m'
  slam_metrics.py kidnap run.json groundtruth.txt trajectory.txt FRAME
      -> prints 'frames_lost frame method error_m': after the jump at input frame FRAME, how many
         frames went by until one had a pose in trajectory.txt again (-1 -1 - -1 if none did), that
         frame's index, how it was tracked (motion, reference, relocalization, or
         new_map_merged_later: in a new map that later merged into the main one) and its position
         error (first poses aligned, as for the drift)
  slam_metrics.py loops run.json groundtruth.txt MAX_M
      -> prints 'true false': the run's loops (and merges) split by ground truth: false when the
         relative pose the loop asserts (run.json `candidate_from_keyframe`: its keyframe's camera
         in its candidate's camera frame) puts the keyframe's camera more than MAX_M from where
         ground truth has it in that frame. A true loop errs by the drift between the two views
         (centimetres); a loop that takes look-alike furnishings for the same ones errs by the
         distance between them (metres), however far apart or close the two cameras are.
  slam_metrics.py loop-errors run.json groundtruth.txt
      -> one line per loop: 'frame candidate_frame error_m' (error_m as for `loops`)
  slam_metrics.py nearest groundtruth.txt ROW
      -> prints 'distance_m angle_deg': how far ground-truth pose ROW (0-based row of the file) is
         from the closest of rows 0..ROW-1, closest by distance + angle / (30 deg per m)
"""
import json
import math
import sys


def get(path, dotted):
    with open(path) as f:
        v = json.load(f)
    for k in dotted.split("."):
        v = v[k]
    return v


def read_tum(path):
    out = []
    with open(path) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            v = [float(x) for x in s.replace(",", " ").split()]
            out.append(v[:8])
    return out


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def qrot(q, v):
    x, y, z, w = q
    p = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), (-x, -y, -z, w))
    return p[:3]


def qinv(q):
    return (-q[0], -q[1], -q[2], q[3])


def drift(gt_path, est_path):
    gt = read_tum(gt_path)
    est = read_tum(est_path)
    if not gt or not est:
        raise SystemExit("empty trajectory")

    def closest(t):
        return min(gt, key=lambda g: abs(g[0] - t))
    g0, e0 = closest(est[0][0]), est[0]
    g1, e1 = closest(est[-1][0]), est[-1]
    # world_gt_from_world_est = T_gt0 * T_est0^-1
    q = qmul(tuple(g0[4:8]), qinv(tuple(e0[4:8])))
    t0 = [g0[1 + i] - qrot(q, e0[1:4])[i] for i in range(3)]
    p = [qrot(q, e1[1:4])[i] + t0[i] for i in range(3)]
    d = math.dist(p, g1[1:4])
    length = 0.0
    prev = None
    for g in gt:
        if g[0] < est[0][0] - 0.02 or g[0] > est[-1][0] + 0.02:
            continue
        if prev is not None:
            length += math.dist(g[1:4], prev)
        prev = g[1:4]
    return d, length


def position_error_at(gt_path, est_path, stamp):
    gt = read_tum(gt_path)
    est = read_tum(est_path)

    def closest(rows, t):
        return min(rows, key=lambda r: abs(r[0] - t))
    g0, e0 = closest(gt, est[0][0]), est[0]
    q = qmul(tuple(g0[4:8]), qinv(tuple(e0[4:8])))
    t0 = [g0[1 + i] - qrot(q, e0[1:4])[i] for i in range(3)]
    e = closest(est, stamp)
    g = closest(gt, stamp)
    p = [qrot(q, e[1:4])[i] + t0[i] for i in range(3)]
    return math.dist(p, g[1:4])


def kidnap(run_json, gt_path, est_path, jump_frame):
    with open(run_json) as f:
        run = json.load(f)
    main = run.get("maps", {}).get("main", 0)
    for r in run["per_frame"]:
        # A pose in trajectory.txt: tracked, and in the main map at the end (several maps: a frame
        # of a new map counts once that map merged into the main one).
        if r["index"] >= jump_frame and r["tracked"] and r.get("final_map", main) == main:
            err = position_error_at(gt_path, est_path, r["stamp"])
            how = r["method"] if r.get("map", main) == main else "new_map_merged_later"
            return r["index"] - jump_frame, r["index"], how.replace(" ", "_"), err
    return -1, -1, "-", -1


def rotate_inverse(q, v):
    """Rotates v by the inverse of unit quaternion q = (x, y, z, w)."""
    x, y, z, w = -q[0], -q[1], -q[2], q[3]
    # v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx = y * v[2] - z * v[1]
    cy = z * v[0] - x * v[2]
    cz = x * v[1] - y * v[0]
    return (v[0] + 2 * (w * cx + y * cz - z * cy),
            v[1] + 2 * (w * cy + z * cx - x * cz),
            v[2] + 2 * (w * cz + x * cy - y * cx))


def loop_errors(run_json, gt_path):
    """Per loop of run.json: (frame, candidate_frame, error_m), error_m how far the loop's asserted
    relative pose puts the keyframe's camera from ground truth's (see `loops`)."""
    with open(run_json) as f:
        run = json.load(f)
    stamp = {r["index"]: r["stamp"] for r in run["per_frame"]}
    gt = read_tum(gt_path)

    def pose(t):
        return min(gt, key=lambda g: abs(g[0] - t))[1:8]

    out = []
    for loop in run["loops"]:
        kf, cand = pose(stamp[loop["frame"]]), pose(stamp[loop["candidate_frame"]])
        d = [kf[i] - cand[i] for i in range(3)]
        true_rel = rotate_inverse(cand[3:7], d)  # the keyframe's centre in the candidate's camera
        est_rel = loop["candidate_from_keyframe"][0:3]
        out.append((loop["frame"], loop["candidate_frame"], math.dist(true_rel, est_rel)))
    return out


def loops(run_json, gt_path, max_m):
    """Loops closed in a run, split by ground truth: (true, false)."""
    errors = [e for _, _, e in loop_errors(run_json, gt_path)]
    false_n = sum(1 for e in errors if e > max_m)
    return len(errors) - false_n, false_n


def nearest(gt_path, row):
    gt = read_tum(gt_path)
    if not 0 < row < len(gt):
        raise SystemExit(f"{gt_path}: row {row} out of range (1..{len(gt) - 1})")
    target = gt[row]
    best = None
    for g in gt[:row]:
        d = math.dist(g[1:4], target[1:4])
        dot = abs(sum(a * b for a, b in zip(g[4:8], target[4:8])))
        angle = math.degrees(2 * math.acos(min(1.0, dot)))
        score = d + angle / 30.0
        if best is None or score < best[0]:
            best = (score, d, angle)
    return best[1], best[2]


def main():
    if len(sys.argv) == 6 and sys.argv[1] == "kidnap":
        print("%d %d %s %.4f" % kidnap(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5])))
        return
    if len(sys.argv) == 4 and sys.argv[1] == "loop-errors":
        for frame, cand, err in loop_errors(sys.argv[2], sys.argv[3]):
            print("%d %d %.4f" % (frame, cand, err))
        sys.exit(0)
    if len(sys.argv) == 5 and sys.argv[1] == "loops":
        print("%d %d" % loops(sys.argv[2], sys.argv[3], float(sys.argv[4])))
        return
    if len(sys.argv) == 4 and sys.argv[1] == "nearest":
        print("%.4f %.2f" % nearest(sys.argv[2], int(sys.argv[3])))
        return 0
    if len(sys.argv) == 4 and sys.argv[1] == "field":
        v = get(sys.argv[2], sys.argv[3])
        print(f"{v:.6g}" if isinstance(v, float) else v)
    elif len(sys.argv) == 4 and sys.argv[1] == "drift":
        d, length = drift(sys.argv[2], sys.argv[3])
        print(f"{d:.6f} {length:.6f}")
    else:
        print(__doc__, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
