#!/usr/bin/env python3
"""Keeps a detslam viewer page open in headless Chromium for bench/bench_viewer.sh.

Drives Chromium over its DevTools pipe (--remote-debugging-pipe: file descriptors 3 and 4,
JSON messages ending in a NUL byte), standard library only. With --shot-at N --shot FILE it
saves a screenshot of the page once the page's counters show N frames done (the README's figure
of the live viewer). Runs until the page says the run has finished or the process is killed.

Usage: viewer_browser.py CHROMIUM URL [--shot-at N --shot FILE] [--size 1400x760]
"""
import argparse
import base64
import fcntl
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time


class Browser:
    def __init__(self, chromium, width, height):
        self.profile = tempfile.mkdtemp(prefix="detslam_bench_chromium_")
        to_r, to_w = os.pipe()      # us -> browser (its fd 3)
        from_r, from_w = os.pipe()  # browser -> us (its fd 4)
        # The child's ends above fd 4 first, so that moving them to 3 and 4 cannot overwrite one.
        high = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (to_r, from_w)]
        os.close(to_r)
        os.close(from_w)
        to_r, from_w = high

        def child_fds():
            os.dup2(to_r, 3)
            os.dup2(from_w, 4)

        self.proc = subprocess.Popen(
            [chromium, "--headless", "--no-sandbox", "--enable-unsafe-swiftshader",
             "--use-angle=swiftshader", "--remote-debugging-pipe", "--no-first-run",
             "--disable-dev-shm-usage", f"--user-data-dir={self.profile}",
             f"--window-size={width},{height}", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, preexec_fn=child_fds,
            pass_fds=(3, 4))
        os.close(to_r)
        os.close(from_w)
        self.out = os.fdopen(to_w, "wb", buffering=0)
        self.inp = os.fdopen(from_r, "rb", buffering=0)
        self.buffer = b""
        self.next_id = 0
        self.session = None

    def call(self, method, params=None, in_page=True):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if in_page and self.session:
            msg["sessionId"] = self.session
        self.out.write(json.dumps(msg).encode() + b"\0")
        while True:
            while b"\0" not in self.buffer:
                chunk = self.inp.read(65536)
                if not chunk:
                    raise RuntimeError("the browser closed its DevTools pipe")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def open(self, url, width, height):
        target = self.call("Target.createTarget", {"url": url, "width": width, "height": height}, False)
        self.session = self.call("Target.attachToTarget",
                                 {"targetId": target["targetId"], "flatten": True}, False)["sessionId"]
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})

    def evaluate(self, expression):
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True})
        return r.get("result", {}).get("value")

    def close(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        shutil.rmtree(self.profile, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("chromium")
    ap.add_argument("url")
    ap.add_argument("--shot-at", type=int, default=-1)
    ap.add_argument("--shot")
    ap.add_argument("--size", default="1400x760")
    a = ap.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # closes the browser on the way out
    width, height = (int(v) for v in a.size.split("x"))
    browser = Browser(a.chromium, width, height)
    try:
        browser.open(a.url, width, height)
        shot_taken = a.shot_at < 0 or not a.shot
        while True:
            done = browser.evaluate(
                "typeof page === 'object' && page.counters ? page.counters.frames_done : -1")
            finished = browser.evaluate("typeof page === 'object' && !!page.finished")
            if not shot_taken and done is not None and done >= a.shot_at:
                time.sleep(0.5)  # the frame image and the 3-D view draw on the next animation frames
                png = base64.b64decode(browser.call("Page.captureScreenshot", {"format": "png"})["data"])
                tmp = a.shot + ".tmp"
                with open(tmp, "wb") as f:
                    f.write(png)
                os.replace(tmp, a.shot)
                print(f"screenshot at frame {done}: {a.shot}", file=sys.stderr)
                shot_taken = True
            if finished:
                return 0
            time.sleep(0.2)
    except RuntimeError as e:
        print(f"viewer_browser: {e}", file=sys.stderr)
        return 1
    finally:
        browser.close()


if __name__ == "__main__":
    sys.exit(main())
