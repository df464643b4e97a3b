#!/usr/bin/env python3
"""Replaces one named section of docs/BENCHMARKS.md (or docs/RELIABILITY.md) with markdown read
from stdin.

Benchmark commands pipe their own output here, so every number in those files was written by the
command that measured it. The section is stamped with the machine, the date and the command.
Usage: some_benchmark | bench/update_section.py NAME "command line that produced it" [RELIABILITY]
"""
import datetime
import os
import platform
import re
import subprocess
import sys


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    mem = ""
    try:
        with open("/proc/meminfo") as f:
            kb = int(f.readline().split()[1])
            mem = f", {kb / 1024 / 1024:.0f} GiB RAM"
    except (OSError, ValueError, IndexError):
        pass
    return f"{cpu}, {os.cpu_count()} cores{mem}, {platform.system()} {platform.release()}"


def commit() -> str:
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                             cwd=os.path.dirname(os.path.abspath(__file__)), check=True)
        status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                                capture_output=True, text=True, check=True,
                                cwd=os.path.dirname(os.path.abspath(__file__))).stdout
        # The benchmark file, the README summary and the plots the benchmarks draw (docs/*.svg)
        # do not make the measured code dirty.
        dirty = [l for l in status.splitlines()
                 if l.strip() and not l.endswith(DOCS_AND_README)
                 and not (l[3:].startswith("docs/") and l.endswith(".svg"))]
        return out.stdout.strip() + (" (uncommitted changes)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


DOCS = {  # name -> (file under docs/, its title and opening line)
    "BENCHMARKS": ("BENCHMARKS.md", "# Benchmarks"),
    "RELIABILITY": ("RELIABILITY.md", "# Reliability"),
}
DOCS_AND_README = tuple("docs/" + f for f, _ in DOCS.values()) + ("README.md",)


def replace_marked_block(text: str, name: str, content: str) -> str:
    """`text` with the block between <!-- BEGIN name --> and <!-- END name --> replaced by
    `content` (appended at the end when the markers are missing)."""
    begin, end = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    block = f"{begin}\n{content}{end}"
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if pattern.search(text):
        return pattern.sub(lambda _: block, text)
    return text.rstrip() + "\n\n" + block + "\n"


def write_atomically(path: str, text: str) -> None:
    """Writes `text` to a temporary file beside `path`, then renames it over `path`."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def main() -> int:
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    name, command = sys.argv[1], sys.argv[2]
    doc = sys.argv[3] if len(sys.argv) > 3 else "BENCHMARKS"
    if doc not in DOCS:
        print(f"unknown document {doc!r} (one of {', '.join(DOCS)})", file=sys.stderr)
        return 2
    filename, title = DOCS[doc]
    if not re.fullmatch(r"[a-z0-9_-]+", name):
        print(f"bad section name {name!r}", file=sys.stderr)
        return 2
    body = sys.stdin.read().rstrip() + "\n"
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    path = os.path.join(root, "docs", filename)
    text = ""
    if os.path.exists(path):
        with open(path) as f:
            text = f.read()
    if not text.startswith(title):
        text = (f"{title}\n\nEvery section below is written by the command named in it "
                "(never by hand); rerun that command to refresh it.\n")
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    stamp = (f"_Written by `{command}` on {datetime.datetime.now().strftime('%Y-%m-%d %H:%M')}; "
             f"machine: {machine()}; load average when written {load}; commit {commit()}._\n\n")
    write_atomically(path, replace_marked_block(text, name, f"{stamp}{body}"))
    print(f"updated section '{name}' of {path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
