#!/usr/bin/env python3
"""Cross-checks one `detslam eval` result against the independent tools/tum_eval_reference.py.

Every benchmark evaluates its runs through bench_lib.sh's eval_checked, which calls this after
`detslam eval`: the reference re-reads the same ground truth and estimate files and recomputes
ATE RMSE and the translational RPE RMSE; a difference above 1e-6 m stops the benchmark.
Usage: cross_check_eval.py EVAL_JSON   (the reference runs under /usr/bin/python3, which has numpy)
Prints nothing on agreement; appends "max_abs_diff_m" lines to $CROSS_CHECK_LOG when set.
"""
import json
import os
import subprocess
import sys

TOLERANCE_M = 1e-6


def main() -> int:
    path = sys.argv[1]
    e = json.load(open(path))
    gt, est = e["inputs"]["groundtruth"], e["inputs"]["estimate"]
    o = e["options"]
    if o.get("scale"):
        return 0  # the reference aligns without scale only; Sim(3) runs are not cross-checked
    tool = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools",
                        "tum_eval_reference.py")
    cmd = ["/usr/bin/python3", tool, gt, est, "--max_difference", repr(o["max_difference_s"]),
           "--offset", repr(o["offset_s"]), "--delta", repr(o["rpe_delta"]),
           "--delta_unit", "f" if o["rpe_unit"] in ("f", "frames") else "s"]
    ref = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    pairs = [("ATE RMSE", e["ate"]["rmse"], ref["ate"]["rmse"])]
    if "trans_m" in ref["rpe"] and e["rpe"].get("trans_m"):
        pairs.append(("RPE translation RMSE", e["rpe"]["trans_m"]["rmse"], ref["rpe"]["trans_m"]["rmse"]))
    worst = max(abs(a - b) for _, a, b in pairs)
    log = os.environ.get("CROSS_CHECK_LOG")
    if log:
        with open(log, "a") as f:
            f.write(f"{worst:.3e} {path}\n")
    bad = [(name, a, b) for name, a, b in pairs if abs(a - b) > TOLERANCE_M]
    for name, a, b in bad:
        print(f"cross-check FAILED for {path}: {name} detslam {a:.9f} m, "
              f"tools/tum_eval_reference.py {b:.9f} m (|diff| > {TOLERANCE_M} m)", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
