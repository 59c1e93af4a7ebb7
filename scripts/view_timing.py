#!/usr/bin/env python3
"""End-to-end frame timing of a running `prtr view`, without a browser (the GPU hosts have
none): FRAMES sequential frame requests at one size while the camera turns, each timed from
the request to the last byte of its JPEG, split by the server's X-Prtr-Frame header into
queue, render (GL work and read-back), encode (JPEG) and the rest (tone mapping, HTTP and
transfer over loopback). Prints a Markdown table of medians and 90th percentiles and the frames per second.
Loopback only; every request has a timeout.
Usage: view_timing.py URL [--frames 60] [--size 1280x948] [--mode decoupled] [--wait 300]"""

import argparse
import json
import sys
import time
import urllib.error
import urllib.request


def percentile(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(round(p / 100.0 * (len(v) - 1))))] if v else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("url")
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--size", default="1280x948")
    ap.add_argument("--mode", default="decoupled")
    ap.add_argument("--wait", type=float, default=300, help="seconds to wait for the server")
    a = ap.parse_args()
    if not a.url.startswith(("http://127.0.0.1:", "http://localhost:")):
        sys.exit("view_timing: loopback URLs only")
    width, height = (int(x) for x in a.size.split("x"))
    base = a.url.rstrip("/")
    start = time.monotonic()
    while True:  # the server bakes and compresses before it listens
        try:
            urllib.request.urlopen(base + "/api/info", timeout=10).read()
            break
        except (urllib.error.URLError, ConnectionError, OSError):
            if time.monotonic() - start > a.wait:
                sys.exit("view_timing: no server at %s after %.0f s" % (base, a.wait))
            time.sleep(0.5)
    rows = []
    first = time.monotonic()
    for i in range(a.frames + 1):  # frame 0 warms up and is not counted
        query = "w=%d&h=%d&mode=%s&client=timing&seq=%d&cam_yaw=%d" % (
            width, height, a.mode, i + 1, (i * 7) % 360)
        t0 = time.monotonic()
        with urllib.request.urlopen(base + "/frame?" + query, timeout=60) as r:
            body = r.read()
            frame = json.loads(r.headers["X-Prtr-Frame"])
        wall = (time.monotonic() - t0) * 1000.0
        if i == 0:
            first = time.monotonic()
            continue
        # render_ms holds any set-up, the frame and the read-back.
        server = sum(frame[k] for k in ("queue_ms", "render_ms", "overlay_ms", "encode_ms"))
        rows.append({"wall": wall, "queue": frame["queue_ms"], "render": frame["render_ms"],
                     "encode": frame["encode_ms"], "rest": max(0.0, wall - server),
                     "bytes": len(body)})
    seconds = time.monotonic() - first
    print("view %s, %s, %d frames: %.1f frames/s end to end" % (a.size, a.mode, len(rows),
                                                                 len(rows) / seconds))
    print()
    print("| part | median ms | 90th percentile ms | share of the median frame |")
    print("| --- | ---: | ---: | ---: |")
    total = percentile([r["wall"] for r in rows], 50)
    for key, label in (("render", "render (GL, readback)"), ("encode", "JPEG encode"),
                       ("queue", "queue"), ("rest", "the rest: tone map, HTTP, transfer"),
                       ("wall", "whole frame")):
        v = [r[key] for r in rows]
        print("| %s | %.2f | %.2f | %.0f %% |" % (label, percentile(v, 50), percentile(v, 90),
                                                100.0 * percentile(v, 50) / total))
    print()
    print("JPEG bytes: median %d" % percentile([r["bytes"] for r in rows], 50))


if __name__ == "__main__":
    main()
