#!/usr/bin/env python3
"""prtr view on a surface light field (.slfc), over loopback and in a real browser. A tiny
light field (a generated sphere, 64 x 64 texels, 8 x 4 directions, 2 samples, 4 clusters x 2
terms: seconds) is made with prtr slf and served with --port 0. Over HTTP: /api/info says
kind "slf" with its clusters, k, texels and directions and only the baked probe; a frame is a
JPEG of the asked size drawn in one pass; an orbited camera is another frame; a turned
environment, another probe, an overlay, another compression or a PRT rendering path is 400
with a one-line reason. In headless chromium (tests/cdp.py): the page shows a frame that is
not blank, a drag (no modifier) changes it and the camera angle, not the environment; the
environment, probe, mode, overlay and compression controls are hidden and disabled; the
about box names the surface light field and its figures. Exit 77 (skip) when
/usr/bin/chromium is absent and the loopback checks passed.
Usage: view_slf_browser_test.py PRTR TMPDIR"""

import base64
import json
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cdp  # noqa: E402
import view_support as vs  # noqa: E402
from view_browser_test import CHROMIUM, PIXELS, frames, settle, text  # noqa: E402

check = vs.Checks()


def make_slfc(prtr, tmp):
    mesh, probe = vs.write_inputs(tmp)
    slfc = os.path.join(tmp, "sphere.slfc")
    r = subprocess.run([prtr, "slf", mesh, "--probe", probe, "--samples", "64x64",
                        "--directions", "8x4", "--spp", "2", "--bounces", "0", "--clusters", "4",
                        "--pcs", "2", "-o", slfc, "--no-cache", "-q"],
                       capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise RuntimeError("prtr slf failed (%d): %s" % (r.returncode, r.stderr))
    return slfc, probe


def check_loopback(server):
    status, _, body = server.get("/api/info")
    info = json.loads(body) if status == 200 else {}
    check("info: kind slf", info.get("kind") == "slf", str(info))
    check("info: 4 clusters, k = 2, 8 x 4 = 32 directions",
          (info.get("clusters"), info.get("components"), info.get("directions")) == (4, 2, 32),
          str(info))
    check("info: the default direction space, reflected",
          info.get("direction_space") == "reflected", str(info))
    check("info: texels in the 64 x 64 atlas",
          0 < info.get("texels", 0) <= 64 * 64 and info.get("atlas_width") == 64, str(info))
    check("info: only the baked probe", info.get("probes") == ["a_sky.hdr"], str(info))

    status, headers, first = server.get(vs.frame_query(w=160, h=120))
    check("frame: 200, a 160 x 120 JPEG", status == 200 and vs.jpeg_size(first) == (160, 120),
          "(%d %s)" % (status, first[:80]))
    if status == 200:
        f = vs.frame_info(headers)
        check("frame: one pass, the file's clusters and k",
              (f["passes"], f["clusters"], f["pcs"]) == (1, 4, 2), str(f))
    status, _, turned = server.get(vs.frame_query(w=160, h=120, cam_yaw=90, zoom=1.5))
    check("an orbited camera is another frame", status == 200 and turned != first, str(status))

    refused = [(dict(env_yaw=30), "the lighting is baked into sphere.slfc; orbit the camera"),
               (dict(env_pitch=-10), "orbit the camera instead"),
               (dict(probe=1), "probe="),
               (dict(overlay="clusters"), "overlay=clusters"),
               (dict(overlay="difference"), "overlay="),
               (dict(clusters=8), "clusters="),
               (dict(order=4), "order="),
               (dict(mode="multipass"), "mode=multipass"),
               (dict(budget=64), "budget=64")]
    for params, reason in refused:
        status, _, body = server.get(vs.frame_query(w=64, h=48, **params))
        line = body.decode(errors="replace").rstrip("\n")
        check("%s: 400 with its reason on one line" % params,
              status == 400 and reason in line and "\n" not in line, "(%d %r)" % (status, line))


def check_page(browser, server, tmp):
    browser.open(server.url + "?w=320&h=237")
    browser.wait_for("Number(document.getElementById('stat-frames').textContent) >= 1",
                     timeout=60, what="the first frame")
    first = browser.evaluate(PIXELS)
    check("first frame is 320 x 237 and not blank",
          first and (first["w"], first["h"]) == (320, 237) and first["std"] > 5, str(first))
    about = text(browser, "about")
    check("about: a surface light field with its k, clusters, texels and directions",
          "surface light field" in about and "k = 2" in about and "4 clusters" in about and
          "texels" in about and "32 reflected directions" in about, about)
    check("about box shown", browser.evaluate(
        "document.getElementById('about').offsetParent !== null"))
    for control in ["drag-env", "autorotate", "probe", "mode", "strategy", "budget", "cpp",
                    "clusters", "pcs", "order", "overlay-overdraw", "overlay-clusters",
                    "overlay-difference"]:
        usable = browser.evaluate("(() => { const e = document.getElementById('%s');"
                                  " return !e.disabled || e.offsetParent !== null; })()" % control)
        check("%s: hidden and disabled" % control, usable is False, str(usable))
    check("environment statistics hidden", browser.evaluate(
        "document.getElementById('stat-env').offsetParent === null"))

    # Wait for the still view's refinement, so that the drag's frame is compared with a still.
    browser.wait_for("document.getElementById('stat-aa').textContent === '2 × 2'",
                     what="the still view anti-aliased")
    still = browser.evaluate(PIXELS)
    rect = browser.rect("frame")
    cx, cy = rect[0] + rect[2] / 2, rect[1] + rect[3] / 2
    n = frames(browser)
    browser.drag(cx - 60, cy, 120, 20)
    settle(browser, n, "a frame after the drag")
    dragged = browser.evaluate(PIXELS)
    cam = text(browser, "stat-cam")
    check("drag changes the frame", dragged["hash"] != still["hash"], str(dragged))
    check("drag orbits the camera", not cam.startswith("yaw 0.0°"), cam)
    check("no request refused", text(browser, "stat-error") == "", text(browser, "stat-error"))
    n = frames(browser)
    browser.evaluate("window.dispatchEvent(new KeyboardEvent('keydown', {key: 'ArrowRight'}))")
    settle(browser, n, "a frame after ArrowRight")
    check("ArrowRight orbits the camera", text(browser, "stat-cam") != cam and
          text(browser, "stat-error") == "", text(browser, "stat-cam"))
    shot = browser.call("Page.captureScreenshot", {"format": "png"})["data"]
    path = os.path.join(tmp, "view_slf_browser.png")
    with open(path, "wb") as f:
        f.write(base64.b64decode(shot))
    print("screenshot: " + path)


def main():
    prtr, tmp = sys.argv[1], sys.argv[2]
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    started = time.monotonic()
    slfc, probe = make_slfc(prtr, tmp)
    print("made %s in %.1f s" % (slfc, time.monotonic() - started))
    server = vs.ViewServer(prtr, [slfc, "--probe", probe])
    browser = None
    skipped = False
    try:
        check_loopback(server)
        if os.path.exists(CHROMIUM):
            browser = cdp.Browser(CHROMIUM, os.path.join(tmp, "profile"))
            check_page(browser, server, tmp)
        else:
            skipped = True
            print("SKIP: %s is absent (apt-get install chromium); the page was not opened" %
                  CHROMIUM)
    except cdp.CdpError as e:
        check("browser session", False, str(e))
    finally:
        if browser:
            browser.close()
        code = server.stop()
    check("server exits 0 on SIGTERM", code == 0, str(code))
    print("view_slf_browser_test: %d passed, %d failed in %.1f s" %
          (check.passed, check.failed, time.monotonic() - started))
    if check.failed:
        return 1
    return 77 if skipped else 0


if __name__ == "__main__":
    sys.exit(main())
