#!/usr/bin/env python3
"""Runs one command under a watchdog and samples its memory (bench/bench_reliability.sh part K).

Usage: soak_monitor.py PREFIX WATCHDOG_S -- COMMAND...

The command's output goes to PREFIX.log. Twice a second the monitor reads the process's resident
memory (/proc/PID/status VmRSS) and the newest `[run] k/N frames, K keyframes, P map points`
progress line, and appends `seconds frame keyframes map_points rss_mib` to PREFIX.samples.tsv. If
no frame was finished for WATCHDOG_S seconds the run is taken to be hung: the threads' stacks are
written to PREFIX.stacks (gdb, when installed), the process is killed and the monitor exits 3.
Otherwise it exits with the command's status. PREFIX.peak gets the peak resident memory (MiB, from
the kernel's accounting of the finished child).
"""
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

prefix, watchdog = sys.argv[1], float(sys.argv[2])
cmd = sys.argv[sys.argv.index("--") + 1:]
progress = re.compile(rb"\[run\] (\d+)/\d+ frames, (-?\d+) keyframes, (-?\d+) map points")

log = open(prefix + ".log", "wb")
proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
t0 = time.time()
last_frame, last_change = -1, t0
hung = False
with open(prefix + ".samples.tsv", "w") as samples:
    samples.write("seconds\tframe\tkeyframes\tmap_points\trss_mib\n")
    while proc.poll() is None:
        time.sleep(0.5)
        try:
            status = open(f"/proc/{proc.pid}/status").read()
            rss = int(re.search(r"VmRSS:\s+(\d+) kB", status).group(1)) / 1024.0
        except (OSError, AttributeError):
            continue  # exiting
        with open(prefix + ".log", "rb") as f:
            f.seek(max(0, os.path.getsize(prefix + ".log") - 4096))
            found = progress.findall(f.read())
        now = time.time()
        if found:
            frame, kfs, points = (int(x) for x in found[-1])
            if frame != last_frame:
                last_frame, last_change = frame, now
            samples.write(f"{now - t0:.1f}\t{frame}\t{kfs}\t{points}\t{rss:.1f}\n")
            samples.flush()
        if now - last_change > watchdog:
            hung = True
            if shutil.which("gdb"):
                with open(prefix + ".stacks", "w") as stacks:
                    subprocess.call(["gdb", "-p", str(proc.pid), "-batch", "-ex",
                                     "thread apply all bt"], stdout=stacks,
                                    stderr=subprocess.STDOUT, timeout=120)
            proc.send_signal(signal.SIGKILL)
            break
rc = proc.wait()
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
with open(prefix + ".peak", "w") as f:
    f.write(f"{peak:.1f}\n")
print(f"[soak] exit {rc}, {time.time() - t0:.0f} s, peak {peak:.0f} MiB"
      + (f", HUNG: no frame finished for {watchdog:.0f} s" if hung else ""))
sys.exit(3 if hung else rc)
