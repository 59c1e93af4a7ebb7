#!/usr/bin/env python3
"""prtr view end to end in a real browser: headless Debian chromium driven over the DevTools
protocol (tests/cdp.py). Opens the page on a generated sphere at 320 x 237, waits for the
first frame and checks it is not blank, drags across it and checks the image and the
environment angle in the statistics change, switches to multipass with one cluster per pass
and checks passes and overdraw update, toggles the overdraw overlay and checks the image
changes, changes the clusters in the page (compressed in the background) and checks the passes
follow, opens a second tab with its own state (the first keeps its view), and saves a
screenshot (view_browser.png in TMPDIR). Exit 77 (skip) only when
/usr/bin/chromium is absent.
Usage: view_browser_test.py PRTR TMPDIR"""

import base64
import os
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cdp  # noqa: E402
import view_support as vs  # noqa: E402

CHROMIUM = "/usr/bin/chromium"

# The displayed image's size, spread and a hash of its pixels, read back through a canvas.
# The page may have just given the image a newer frame's URL (the still view's 2 x 2 refinement
# follows the first frame by itself), and until that decodes naturalWidth is 0: wait for it.
PIXELS = """(async () => {
  const img = document.getElementById('frame');
  for (let i = 0; i < 100 && !(img.complete && img.naturalWidth); ++i)
    await img.decode().catch(() => new Promise((r) => setTimeout(r, 50)));
  if (!img.naturalWidth) return null;
  const c = document.createElement('canvas');
  c.width = img.naturalWidth; c.height = img.naturalHeight;
  const g = c.getContext('2d'); g.drawImage(img, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  let s = 0, s2 = 0, h = 0;
  for (let i = 0; i < d.length; i += 4) {
    const v = (d[i] + d[i + 1] + d[i + 2]) / 3; s += v; s2 += v * v;
    h = (Math.imul(h, 31) + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
  }
  const n = d.length / 4, m = s / n;
  return {w: c.width, h: c.height, mean: m, std: Math.sqrt(Math.max(0, s2 / n - m * m)), hash: h};
})()"""

check = vs.Checks()


def text(browser, element):
    return browser.evaluate("document.getElementById('%s').textContent" % element)


def frames(browser):
    return int(text(browser, "stat-frames"))


def settle(browser, after, what):
    """Waits for a frame newer than `after` and for the page to have nothing in flight."""
    browser.wait_for("Number(document.getElementById('stat-frames').textContent) > %d" % after,
                     what=what)
    time.sleep(0.3)  # a request the last input queued
    n = frames(browser)
    time.sleep(0.5)
    while frames(browser) != n:
        n = frames(browser)
        time.sleep(0.5)


def set_control(browser, element, value):
    browser.evaluate("(() => { const e = document.getElementById('%s'); e.value = '%s';"
                     " e.dispatchEvent(new Event('change')); })()" % (element, value))


def check_second_tab(browser, server):
    """A second tab has its own state: its frames do not change the first tab's view."""
    first_tab = browser.session
    browser.open(server.url + "?w=160&h=118&mode=cpu")
    browser.wait_for("Number(document.getElementById('stat-frames').textContent) >= 1",
                     timeout=60, what="the second tab's first frame")
    check("second tab: its own mode", text(browser, "stat-mode") == "cpu" and
          text(browser, "stat-passes") == "1", text(browser, "stat-mode"))
    second_env = text(browser, "stat-env")
    browser.session = first_tab
    n = frames(browser)
    browser.evaluate("document.getElementById('reset').click()")
    settle(browser, n, "a frame of the first tab after the second rendered")
    check("first tab keeps its mode and passes", text(browser, "stat-mode").startswith("multipass")
          and text(browser, "stat-passes") == "4", text(browser, "stat-mode"))
    check("second tab's angle is its own", second_env.startswith("yaw 0.0°"), second_env)


def check_compression(browser):
    """Clusters chosen in the page: compressed in the background through the cache, the old
    compression shown until the new one is ready, then the passes follow (multipass at one
    cluster per pass: one pass per cluster); back to the launch's 4 at once (kept)."""
    set_control(browser, "clusters", "2")
    browser.wait_for("document.getElementById('stat-clusters').textContent === '2'",
                     timeout=60, what="the 2-cluster compression")
    browser.wait_for("document.getElementById('stat-passes').textContent === '2'",
                     what="2 passes")
    check("compression: 2 clusters shown, 2 passes, Average SE of the launch's hidden",
          text(browser, "stat-se") == "-", text(browser, "stat-se"))
    check("compression: no progress left on screen",
          text(browser, "compress-status") == "", text(browser, "compress-status"))
    set_control(browser, "clusters", "4")
    browser.wait_for("document.getElementById('stat-passes').textContent === '4'",
                     what="back to 4 passes")
    check("compression: the launch's back, with its Average SE",
          text(browser, "stat-clusters") == "4" and text(browser, "stat-se") != "-")


def check_order(browser):
    """Another SH order chosen in the page: baked and compressed in the background, shown
    when ready (the launch's order 3 until then), and back to the launch's at once (kept)."""
    set_control(browser, "order", "2")
    browser.wait_for("document.getElementById('stat-order').textContent === '2'",
                     timeout=90, what="the order-2 bake and compression")
    check("order: 2 shown with the launch's clusters and no progress left",
          text(browser, "stat-clusters") == "4" and text(browser, "compress-status") == "",
          "%s / %s" % (text(browser, "stat-clusters"), text(browser, "compress-status")))
    set_control(browser, "order", "3")
    browser.wait_for("document.getElementById('stat-order').textContent === '3'",
                     what="back to order 3")
    check("order: the launch's back, with its Average SE", text(browser, "stat-se") != "-",
          text(browser, "stat-se"))


def check_refusals(browser, cx, cy):
    """A refused setting does not poison the tab: the field goes back to the value in use,
    the reason shows beside it, and the next drag renders."""
    for field, bad in [("budget", "1"), ("budget", "-5000000"), ("cpp", "9999")]:
        before = browser.evaluate("document.getElementById('%s').value" % field)
        set_control(browser, field, bad)
        browser.wait_for("document.getElementById('refused-%s').textContent !== '' || "
                         "document.getElementById('%s').value !== '%s'" % (field, field, bad),
                         what="the page's answer to %s=%s" % (field, bad))
        time.sleep(0.5)
        value = browser.evaluate("document.getElementById('%s').value" % field)
        reason = text(browser, "refused-" + field)
        # -5000000 is no budget at all: the field shows the 0 in use and nothing is refused.
        check("%s=%s: the field shows the value in use (%s)" % (field, bad, before),
              value == (before if bad != "-5000000" else "0"), "%r" % value)
        if bad != "-5000000":
            check("%s=%s: the reason is shown beside it" % (field, bad), reason != "", reason)
        n = frames(browser)
        browser.drag(cx - 30, cy, 60, 0)
        settle(browser, n, "a frame after a refused %s" % field)
        check("%s=%s: the next drag renders" % (field, bad),
              text(browser, "stat-error") == "", text(browser, "stat-error"))


def key(browser, name, shift=False):
    browser.evaluate("window.dispatchEvent(new KeyboardEvent('keydown', {key: '%s', shiftKey: %s}))"
                     % (name, "true" if shift else "false"))


def check_keys_and_autorotate(browser):
    """Arrow keys turn the environment (shift: the camera); auto-rotation keeps frames coming
    without input, and space stops it."""
    env0, cam0 = text(browser, "stat-env"), text(browser, "stat-cam")
    n = frames(browser)
    key(browser, "ArrowRight")
    settle(browser, n, "a frame after ArrowRight")
    env1 = text(browser, "stat-env")
    check("ArrowRight turns the environment", env1 != env0 and text(browser, "stat-cam") == cam0,
          "%r -> %r" % (env0, env1))
    n = frames(browser)
    key(browser, "ArrowRight", shift=True)
    settle(browser, n, "a frame after shift-ArrowRight")
    check("shift-ArrowRight orbits the camera", text(browser, "stat-cam") != cam0 and
          text(browser, "stat-env") == env1, text(browser, "stat-cam"))
    n = frames(browser)
    key(browser, " ")
    time.sleep(2.0)
    turning = frames(browser) - n
    check("auto-rotate keeps frames coming without input", turning >= 3, str(turning))
    check("auto-rotate turns the environment", text(browser, "stat-env") != env1)
    key(browser, " ")
    time.sleep(0.5)
    n = frames(browser)
    time.sleep(1.0)
    check("space stops auto-rotation", frames(browser) - n <= 1, str(frames(browser) - n))


def check_fit_window(browser):
    """"fit the window": the frame fills what the panel leaves, at the device pixel ratio."""
    n = frames(browser)
    set_control(browser, "size", "window")
    settle(browser, n, "a frame that fits the window")
    box = browser.evaluate("(() => { const i = document.getElementById('frame');"
                           " const r = i.getBoundingClientRect(); const d = devicePixelRatio;"
                           " return [i.naturalWidth, i.naturalHeight, Math.round(r.width * d),"
                           " Math.round(r.height * d), innerWidth, innerHeight]; })()")
    check("fit the window: the frame is rendered at its displayed size",
          box[0] == box[2] and box[1] == box[3] and box[0] > 320, str(box))
    panel = browser.evaluate("document.getElementById('panel').getBoundingClientRect().bottom")
    check("the panel fits the window's height", panel <= box[5] + 1, "%s of %s" % (panel, box[5]))
    n = frames(browser)
    set_control(browser, "size", "320x237")
    settle(browser, n, "a 320 x 237 frame again")


def run(browser, server, tmp):
    browser.open(server.url + "?w=320&h=237")
    browser.wait_for("Number(document.getElementById('stat-frames').textContent) >= 1",
                     timeout=60, what="the first frame")
    first = browser.evaluate(PIXELS)
    check("first frame is 320 x 237", first and (first["w"], first["h"]) == (320, 237), str(first))
    check("first frame is not blank", first and first["std"] > 5, str(first))
    check("statistics: renderer shown", "llvmpipe" in text(browser, "stat-gl"))
    check("statistics: clusters, PCs, order",
          [text(browser, e) for e in ("stat-clusters", "stat-pcs", "stat-order")] == ["4", "2", "3"])
    browser.wait_for("document.getElementById('stat-aa').textContent === '2 × 2'",
                     what="the still view anti-aliased")
    check("the still view is refined to 2 x 2 samples", text(browser, "stat-aa") == "2 × 2")
    env0 = text(browser, "stat-env")

    rect = browser.rect("frame")
    cx, cy = rect[0] + rect[2] / 2, rect[1] + rect[3] / 2
    n = frames(browser)
    browser.drag(cx - 60, cy, 120, 20)
    settle(browser, n, "a frame after the drag")
    dragged = browser.evaluate(PIXELS)
    env1 = text(browser, "stat-env")
    check("drag changes the frame", dragged["hash"] != first["hash"], str(dragged))
    check("drag changes the environment angle", env1 != env0, "%r -> %r" % (env0, env1))
    check("drag left the camera alone", text(browser, "stat-cam").startswith("yaw 0.0°"))

    n = frames(browser)
    browser.drag(cx, cy, -80, 0, modifiers=8)  # shift: orbit the camera
    settle(browser, n, "a frame after the shift-drag")
    check("shift-drag orbits the camera", not text(browser, "stat-cam").startswith("yaw 0.0°"),
          text(browser, "stat-cam"))
    check("shift-drag keeps the environment", text(browser, "stat-env") == env1)

    n = frames(browser)
    set_control(browser, "cpp", "1")
    set_control(browser, "mode", "multipass")
    browser.wait_for("document.getElementById('stat-passes').textContent === '4'",
                     what="4 passes")
    settle(browser, n, "a multipass frame")
    check("multipass: mode shown", text(browser, "stat-mode").startswith("multipass"))
    overdraw = float(text(browser, "stat-overdraw"))
    check("multipass: overdraw above 1", overdraw > 1.0, str(overdraw))
    plain = browser.evaluate(PIXELS)

    n = frames(browser)
    browser.evaluate("document.getElementById('overlay-overdraw').click()")
    settle(browser, n, "a frame with the overlay")
    overlaid = browser.evaluate(PIXELS)
    check("overdraw overlay changes the frame", overlaid["hash"] != plain["hash"])
    check("no error shown", text(browser, "stat-error") == "", text(browser, "stat-error"))
    n = frames(browser)
    browser.evaluate("document.getElementById('overlay-difference').click()")
    settle(browser, n, "a frame of the difference view")
    shown = text(browser, "stat-difference")
    check("difference view: the overlay switches and the RMS is shown",
          not browser.evaluate("document.getElementById('overlay-overdraw').checked") and
          shown.startswith("RMS "), shown)
    check("difference view changes the frame", browser.evaluate(PIXELS)["hash"] != overlaid["hash"])
    browser.evaluate("document.getElementById('overlay-difference').click()")
    check_compression(browser)
    check_order(browser)
    check_refusals(browser, cx, cy)
    check_keys_and_autorotate(browser)
    check_fit_window(browser)
    check_second_tab(browser, server)
    shot = browser.call("Page.captureScreenshot", {"format": "png"})["data"]
    path = os.path.join(tmp, "view_browser.png")
    with open(path, "wb") as f:
        f.write(base64.b64decode(shot))
    print("screenshot: " + path)


def main():
    if not os.path.exists(CHROMIUM):
        print("SKIP: %s is absent (apt-get install chromium); the browser test needs it" % CHROMIUM)
        return 77
    prtr, tmp = sys.argv[1], sys.argv[2]
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    mesh, probe = vs.write_inputs(tmp)
    started = time.monotonic()
    browser = cdp.Browser(CHROMIUM, os.path.join(tmp, "profile"))
    server = None
    try:
        server = vs.ViewServer(prtr, [mesh, "--probe", probe, "--cache", os.path.join(tmp, "cache")]
                               + vs.SMALL_BAKE)
        run(browser, server, tmp)
    except cdp.CdpError as e:
        check("browser session", False, str(e))
    finally:
        browser.close()
        code = server.stop() if server else None
    check("server exits 0 on SIGTERM", code == 0, str(code))
    print("view_browser_test: %d passed, %d failed in %.1f s" %
          (check.passed, check.failed, time.monotonic() - started))
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
