#!/usr/bin/env python3
"""Fault cases for docs/RELIABILITY.md (bench/bench_reliability.sh part X).

Usage: fault_cases.py DETSLAM WORK_DIR [SEGMENTER]

Writes one synthetic static sequence with `detslam synth`, then for each case damages a copy of it
(or the command line, or the disk), runs the `detslam` command a user would run, and checks the
behaviour decided for that case (README "Faults"): the frame skipped and listed in run.json, or a
clear error naming the file before any output is written, or the previous outputs left whole.
Prints a Markdown table, one row per case, whose last column says whether the decided behaviour
was observed; exits 1 if any case was not. Needs only the Python standard library.
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import time
import zlib

BIN, WORK = sys.argv[1], sys.argv[2]
SEGMENTER = sys.argv[3] if len(sys.argv) > 3 else "dnn"
FRAMES = 90


def write_png(path, width, height, bit_depth, channels, value):
    """A PNG of one constant value (8 or 16 bits per sample, 1 or 3 channels)."""
    color_type = {1: 0, 3: 2}[channels]
    sample = value.to_bytes(bit_depth // 8, "big")
    row = b"\x00" + sample * (width * channels)
    raw = row * height

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
                chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def frame_files(seq):
    """(rgb path, depth path) per frame, from rgb.txt and depth.txt (same count in synth output)."""
    def listed(name):
        out = []
        with open(os.path.join(seq, name)) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    out.append(os.path.join(seq, line.split()[1]))
        return out
    return list(zip(listed("rgb.txt"), listed("depth.txt")))


def edit_list_line(seq, name, edit):
    """Rewrites the data lines of a list file with edit(lines) -> lines."""
    path = os.path.join(seq, name)
    with open(path) as f:
        lines = f.readlines()
    comments = [l for l in lines if l.startswith("#")]
    data = [l for l in lines if not l.startswith("#")]
    with open(path, "w") as f:
        f.writelines(comments + edit(data))


def run(args, log, limit=None, env_prefix=""):
    """Runs detslam with args; returns (exit status, seconds, log text)."""
    cmd = " ".join([BIN] + ["'" + a + "'" for a in args])
    if limit is not None:
        cmd = f"ulimit -f {limit}; {cmd}"
    t0 = time.time()
    with open(log, "w") as f:
        rc = subprocess.call(["bash", "-c", env_prefix + cmd], stdout=f, stderr=subprocess.STDOUT,
                             timeout=900)
    return rc, time.time() - t0, open(log, errors="replace").read()


def run_json(out):
    path = os.path.join(out, "run.json")
    return json.load(open(path)) if os.path.exists(path) else None


def first_line(text, *keys):
    """The first line holding keys[0], else the first holding keys[1], ...; without the log's
    time stamp."""
    for k in keys:
        for line in text.splitlines():
            if k in line:
                return re.sub(r"^\[[0-9-]+ [0-9:.]+\] ", "", line.strip())
    return ""


def short(text, n=150):
    text = text.replace(WORK + "/", "").replace("|", "\\|")
    return text if len(text) <= n else text[:n - 3] + "..."


base = os.path.join(WORK, "base")
subprocess.check_call([BIN, "synth", "--preset", "static", "--seed", "2", "--no-people", "--frames",
                       str(FRAMES), "--out", base], stdout=subprocess.DEVNULL)
FILES = frame_files(base)
rows = []
failures = 0


def case(name, damage, decided):
    """Runs one case. damage(seq, files, out) damages the copy `seq` and returns the setup (extra
    arguments, a whole command line, a runner, a file size limit, ...); decided(rc, log, run_json,
    files, out, setup) -> (as decided?, the decided behaviour in words)."""
    global failures
    key = str(len(rows) + 1)
    seq = os.path.join(WORK, "seq" + key)
    shutil.copytree(base, seq)
    out = os.path.join(WORK, "out" + key)
    files = frame_files(seq)
    setup = damage(seq, files, out)
    args = ["run", "--dataset", seq, "--out", out, "--segmenter", SEGMENTER, "--no-progress"]
    args += setup.get("extra", [])
    if "args" in setup:
        args = setup["args"]
    rc, secs, log = (setup["runner"](args, out) if "runner" in setup
                     else run(args, out + ".log", setup.get("limit")))
    j = run_json(out)
    ok, behaviour = decided(rc, log, j, files, out, setup)
    failures += 0 if ok else 1
    frames = "-"
    if j is not None and not setup.get("stale_json"):
        frames = f"{len(j.get('skipped_frames', []))} / {j['frames_tracked']} / {j['frames']}"
    message = first_line(log, "error:", "skipped", "warning")
    rows.append(f"| {name} | {behaviour} | {rc} | {secs:.1f} | {frames} | `{short(message)}` | "
                f"{'yes' if ok else 'NO'} |")


def skipped_ok(expect_frames):
    def check(rc, log, j, files, out, setup):
        listed = [s["frame"] for s in (j or {}).get("skipped_frames", [])]
        tracked = (j or {}).get("frames_tracked", -1)
        traj = os.path.join(out, "trajectory.txt")
        lines = (sum(1 for l in open(traj) if l.strip() and not l.startswith("#"))
                 if os.path.exists(traj) else -1)
        ok = (rc == 0 and listed == expect_frames and tracked == FRAMES - len(expect_frames) and
              lines == tracked)
        return ok, (f"skipped with a warning, listed in run.json (frames {expect_frames}); every "
                    f"other frame tracked")
    return check


def error_ok(*must_name):
    def check(rc, log, j, files, out, setup):
        err = first_line(log, "error:")
        ok = (rc != 0 and err != "" and all(n in err for n in must_name) and
              not os.path.exists(os.path.join(out, "trajectory.txt")) and "[run]" not in log)
        return ok, "stops before the first frame with an error naming the file; no outputs"
    return check


def truncate(path):
    data = open(path, "rb").read()
    open(path, "wb").write(data[:len(data) // 2])


case("colour PNG truncated to half (frame 20)",
     lambda seq, f, out: truncate(f[20][0]) or {},
     skipped_ok([20]))
case("depth PNG 8-bit instead of 16-bit (frame 30)",
     lambda seq, f, out: write_png(f[30][1], 640, 480, 8, 1, 9) or {},
     skipped_ok([30]))
case("depth PNG 320x240 instead of 640x480 (frame 40)",
     lambda seq, f, out: write_png(f[40][1], 320, 240, 16, 1, 9000) or {},
     skipped_ok([40]))


def delete_during_run(seq, files, out):
    target = files[70][0]

    def runner(args, out_dir):
        log = out_dir + ".log"
        t0 = time.time()
        with open(log, "w") as f:
            p = subprocess.Popen([BIN] + args, stdout=f, stderr=subprocess.STDOUT)
            # The map is initialised on the first frame: the file list was checked by then.
            while p.poll() is None and "initialised with" not in open(log, errors="replace").read():
                time.sleep(0.005)
            if os.path.exists(target):
                os.remove(target)
            rc = p.wait(timeout=900)
        return rc, time.time() - t0, open(log, errors="replace").read()
    return {"runner": runner}


case("colour file deleted while the run goes on (frame 70, once frame 0 is tracked)", delete_during_run,
     skipped_ok([70]))
case("a listed colour file missing before the run (frame 3)",
     lambda seq, f, out: os.remove(f[3][0]) or {},
     error_ok("rgb.txt:", os.path.basename(FILES[3][0])))
case("duplicated timestamp in rgb.txt (line of frame 11 = frame 10)",
     lambda seq, f, out: edit_list_line(
         seq, "rgb.txt",
         lambda d: d[:11] + [d[10].split()[0] + " " + d[11].split()[1] + "\n"] + d[12:]) or {},
     error_ok("rgb.txt:"))
case("unsorted timestamps in depth.txt (frames 10 and 11 swapped)",
     lambda seq, f, out: edit_list_line(
         seq, "depth.txt", lambda d: d[:10] + [d[11], d[10]] + d[12:]) or {},
     error_ok("depth.txt:"))


def blank(seq, files, out, frames, which, bit_depth, channels, value):
    for k in frames:
        write_png(files[k][which], 640, 480, bit_depth, channels, value)
    return {}


def processed_ok(bad, recover_from):
    def check(rc, log, j, files, out, setup):
        if j is None:
            return False, "no run.json"
        per = j["per_frame"]
        later = all(per[k]["tracked"] for k in range(recover_from, FRAMES))
        ok = rc == 0 and not j.get("skipped_frames") and later and j["frames"] == FRAMES
        return ok, (f"processed (a pose only where the frame allows one); tracking goes on: "
                    f"frames {recover_from}-{FRAMES - 1} all tracked")
    return check


case("black colour images (frames 30-39)",
     lambda seq, f, out: blank(seq, f, out, range(30, 40), 0, 8, 3, 0),
     processed_ok(range(30, 40), 60))
case("saturated (white) colour images (frames 30-39)",
     lambda seq, f, out: blank(seq, f, out, range(30, 40), 0, 8, 3, 255),
     processed_ok(range(30, 40), 60))
case("depth images with no valid pixel (frames 30-39)",
     lambda seq, f, out: blank(seq, f, out, range(30, 40), 1, 16, 1, 0),
     processed_ok(range(30, 40), 60))
case("every depth image unreadable (8-bit colour)",
     lambda seq, f, out: [write_png(d, 640, 480, 8, 3, 7) for _, d in f] and {},
     lambda rc, log, j, files, out, setup: (
         rc != 0 and "no frame of" in log and not os.path.exists(os.path.join(out, "trajectory.txt")),
         "stops with an error (no frame could be read); no outputs"))


def gt_value(seq, files, out, text):
    path = os.path.join(seq, "groundtruth.txt")
    lines = open(path).readlines()
    idx = [i for i, l in enumerate(lines) if not l.startswith("#")][5]
    parts = lines[idx].split()
    parts[1] = text
    lines[idx] = " ".join(parts) + "\n"
    open(path, "w").writelines(lines)
    gt_line = idx + 1
    # `detslam eval` of the clean run's trajectory against the damaged ground truth.
    clean = os.path.join(WORK, "clean_run")
    if not os.path.exists(clean):
        subprocess.call([BIN, "run", "--dataset", base, "--out", clean, "--segmenter", "none",
                         "--no-progress"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return {"args": ["eval", "--gt", path, "--est", os.path.join(clean, "trajectory.txt")],
            "gt_line": gt_line, "stale_json": True}


def eval_error_ok(rc, log, j, files, out, setup):
    err = first_line(log, "error:")
    ok = rc != 0 and f"groundtruth.txt:{setup['gt_line']}" in err
    return ok, "`detslam eval` stops with an error naming the file and line"


case("NaN position in groundtruth.txt (`detslam eval`)",
     lambda seq, f, out: gt_value(seq, f, out, "nan"), eval_error_ok)
case("position of 10^12 m in groundtruth.txt (`detslam eval`)",
     lambda seq, f, out: gt_value(seq, f, out, "1e12"), eval_error_ok)


def under_file(seq, files, out, save_map):
    os.makedirs(out + "_dir", exist_ok=True)
    blocker = os.path.join(out + "_dir", "a_file")
    open(blocker, "w").write("not a folder\n")
    if save_map:
        return {"extra": ["--save-map", os.path.join(blocker, "m.dslmap")]}
    return {"args": ["run", "--dataset", seq, "--out", os.path.join(blocker, "out"), "--segmenter",
                     SEGMENTER, "--no-progress"]}


def unwritable_ok(word):
    def check(rc, log, j, files, out, setup):
        err = first_line(log, "error:")
        ok = rc != 0 and word in err and "a_file" in err and "[run]" not in log
        return ok, "stops before the first frame with an error naming the path"
    return check


case("output folder cannot be created (a file is in its path)",
     lambda seq, f, out: under_file(seq, f, out, False), unwritable_ok("output folder"))
case("--save-map folder cannot be created",
     lambda seq, f, out: under_file(seq, f, out, True), unwritable_ok("--save-map"))


def disk_full(seq, files, out):
    # A whole first run, then a second one into the same folder under a 16 KiB file size limit
    # (a full disk): run.json no longer fits.
    subprocess.check_call([BIN, "run", "--dataset", seq, "--out", out, "--segmenter", SEGMENTER,
                           "--no-progress"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    before = open(os.path.join(out, "run.json"), "rb").read()
    return {"limit": 16, "extra": ["--max-frames", "40"], "before": before, "stale_json": True}


def disk_full_ok(rc, log, j, files, out, setup):
    after = open(os.path.join(out, "run.json"), "rb").read()
    traj = [l for l in open(os.path.join(out, "trajectory.txt")) if l.strip() and l[0] != "#"]
    ok = (rc != 0 and "disk full?" in log and "run.json" in first_line(log, "error:") and
          after == setup["before"] and len(traj) in (40, FRAMES))
    return ok, ("stops with an error naming the file; the previous run.json whole, "
                "trajectory.txt whole (old or new)")


case("disk full while the outputs are written (ulimit -f 16 KiB, second run)", disk_full,
     disk_full_ok)


def bad_settings(seq, files, out):
    path = os.path.join(seq, "broken.yaml")
    open(path, "w").write("%YAML:1.0\nCamera.fx: 517.3\nCamera.fy: [unclosed\nCamera.cx: 318.6\n")
    return {"extra": ["--config", path]}


case("settings YAML with a syntax error (--config)", bad_settings, error_ok("broken.yaml"))


def bad_map(seq, files, out):
    path = os.path.join(WORK, "whole.dslmap")
    if not os.path.exists(path):
        subprocess.check_call([BIN, "run", "--dataset", base, "--out", os.path.join(WORK, "map_run"),
                               "--segmenter", "none", "--no-progress", "--save-map", path],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    cut = os.path.join(WORK, "cut.dslmap")
    data = open(path, "rb").read()
    open(cut, "wb").write(data[:len(data) * 2 // 3])
    return {"extra": ["--load-map", cut]}


case("map file truncated to 2/3 (--load-map)", bad_map, error_ok("cut.dslmap"))

print(f"`detslam` on a synthetic `static` sequence of {FRAMES} frames (seed 2, no people; "
      f"segmenter {SEGMENTER}), one fault per row. Frames: skipped (listed in run.json) / tracked /"
      f" total. The message is the first error or warning line the command printed.")
print()
print("| fault | decided behaviour | exit | seconds | frames | message | as decided |")
print("|---|---|---:|---:|---|---|---|")
print("\n".join(rows))
print()
sys.exit(1 if failures else 0)
