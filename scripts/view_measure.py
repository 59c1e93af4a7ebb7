#!/usr/bin/env python3
"""Interaction latency of a running `prtr view`, measured in headless chromium (tests/cdp.py):
for each size, a continuous drag of SECONDS across the image, then the page's own per-frame
log (window.prtrLog: request sent -> image decoded, split by the server's X-Prtr-Frame
timings into queue, render, overlay, encode and transfer). Prints median and 95th percentile
per part and the frames per second during the drag; saves a screenshot of the page.
Usage: view_measure.py URL [--mode decoupled] [--seconds 10] [--sizes 960x710,1280x948]
                       [--screenshot view.png]"""

import argparse
import functools
import base64
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import cdp  # noqa: E402

print = functools.partial(print, flush=True)  # progress while a long run goes on


def percentile(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(round(p / 100.0 * (len(v) - 1))))] if v else float("nan")


def measure(browser, url, mode, width, height, seconds):
    browser.call("Page.navigate", {"url": "%s?w=%d&h=%d&mode=%s" % (url, width, height, mode)})
    browser.wait_for("Number(document.getElementById('stat-frames').textContent) >= 1",
                     timeout=600, what="the first frame")
    time.sleep(1.0)
    rect = browser.rect("frame")
    y = rect[1] + rect[3] / 2
    browser.evaluate("window.prtrLog.length = 0")
    start = time.monotonic()
    browser.mouse("mousePressed", rect[0] + 10, y, buttons=1)
    x, step = rect[0] + 10, 4
    while time.monotonic() - start < seconds:  # a steady drag, ~60 events per second
        x += step
        if x > rect[0] + rect[2] - 10 or x < rect[0] + 10:
            step = -step
        browser.mouse("mouseMoved", x, y, buttons=1)
        time.sleep(1 / 60)
    browser.mouse("mouseReleased", x, y)
    drag_s = time.monotonic() - start
    time.sleep(2.0)
    log = browser.evaluate("window.prtrLog")
    during = [e for e in log if e["shown"] - log[0]["sent"] <= drag_s * 1000] if log else []
    return log, len(during) / drag_s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("url")
    ap.add_argument("--mode", default="decoupled")
    ap.add_argument("--seconds", type=float, default=10)
    ap.add_argument("--sizes", default="960x710,1280x948")
    ap.add_argument("--screenshot", default="")
    ap.add_argument("--profile", default="/tmp/prtr-view-measure-profile")
    a = ap.parse_args()
    browser = cdp.Browser("/usr/bin/chromium", a.profile, width=1700, height=1100)
    try:
        browser.open("about:blank")
        for size in a.sizes.split(","):
            w, h = (int(s) for s in size.split("x"))
            log, fps = measure(browser, a.url, a.mode, w, h, a.seconds)
            print("%s %d x %d: %d frames, %.2f FPS during a %.0f s drag" %
                  (a.mode, w, h, len(log), fps, a.seconds))
            for part in ("total", "queue", "render", "frame", "readback", "overlay", "encode",
                         "transfer"):
                values = [e[part] for e in log]
                print("  %-8s median %7.1f ms   p95 %7.1f ms" %
                      (part, percentile(values, 50), percentile(values, 95)))
        if a.screenshot:
            shot = browser.call("Page.captureScreenshot", {"format": "png"})["data"]
            with open(a.screenshot, "wb") as f:
                f.write(base64.b64decode(shot))
            print("screenshot: " + a.screenshot)
    finally:
        browser.close()


if __name__ == "__main__":
    main()
