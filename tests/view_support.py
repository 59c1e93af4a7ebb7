"""Shared by prtr view's tests (Python 3 standard library only): small generated inputs (a UV
sphere OBJ, Radiance .hdr probes), a server started with --port 0 whose printed URL is the
real one, loopback HTTP with timeouts, and JPEG header parsing."""

import http.client
import json
import math
import os
import re
import signal
import subprocess
import threading
import time
import urllib.parse


def write_sphere_obj(path, segments=16, rings=8, radius=1.0):
    """A closed UV sphere (counter-clockwise seen from outside), written as OBJ."""
    verts = [(0.0, radius, 0.0)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            verts.append((radius * math.sin(theta) * math.cos(phi), radius * math.cos(theta),
                          -radius * math.sin(theta) * math.sin(phi)))
    verts.append((0.0, -radius, 0.0))
    bottom = len(verts)  # 1-based index of the south pole
    faces = []
    ring = lambda r, s: 2 + (r - 1) * segments + (s % segments)
    for s in range(segments):
        faces.append((1, ring(1, s), ring(1, s + 1)))
        faces.append((bottom, ring(rings - 1, s + 1), ring(rings - 1, s)))
    for r in range(1, rings - 1):
        for s in range(segments):
            a, b = ring(r, s), ring(r, s + 1)
            c, d = ring(r + 1, s), ring(r + 1, s + 1)
            faces += [(a, c, d), (a, d, b)]
    with open(path, "w") as f:
        for v in verts:
            f.write("v %.6f %.6f %.6f\n" % v)
        for t in faces:
            f.write("f %d %d %d\n" % t)


def _rgbe(r, g, b):
    m = max(r, g, b)
    if m < 1e-32:
        return bytes((0, 0, 0, 0))
    e = math.frexp(m)[1]
    scale = 256.0 / (2.0 ** e)
    return bytes((int(r * scale), int(g * scale), int(b * scale), e + 128))


def write_hdr(path, width, height, radiance):
    """A lat-long Radiance .hdr; radiance(u, v) -> (r, g, b) for u, v in [0, 1). Flat
    (uncompressed) scanlines, which every reader accepts."""
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(b"-Y %d +X %d\n" % (height, width))
        for y in range(height):
            f.write(b"".join(_rgbe(*radiance((x + 0.5) / width, (y + 0.5) / height))
                             for x in range(width)))


def sky(u, v):
    """Bright warm sky above, dark below, a brighter patch toward u = 0.25."""
    up = max(0.0, math.cos(math.pi * v))
    patch = 3.0 * math.exp(-((u - 0.25) ** 2 + (v - 0.3) ** 2) / 0.01)
    return (0.2 + 1.5 * up + patch, 0.2 + 1.2 * up + 0.5 * patch, 0.3 + 0.8 * up)


def sunset(u, v):
    glow = 4.0 * math.exp(-((u - 0.7) ** 2 + (v - 0.5) ** 2) / 0.02)
    return (0.1 + glow, 0.05 + 0.4 * glow, 0.2)


def write_inputs(tmp):
    """A sphere and a folder of two probes; returns (mesh, probe_a)."""
    os.makedirs(os.path.join(tmp, "probes"), exist_ok=True)
    mesh = os.path.join(tmp, "sphere.obj")
    write_sphere_obj(mesh)
    a = os.path.join(tmp, "probes", "a_sky.hdr")
    write_hdr(a, 64, 32, sky)
    write_hdr(os.path.join(tmp, "probes", "b_sunset.hdr"), 64, 32, sunset)
    with open(os.path.join(tmp, "probes", "notes.txt"), "w") as f:
        f.write("not a probe: the server must not list it\n")
    return mesh, a


SMALL_BAKE = ["--order", "3", "--samples", "32", "--bounces", "0", "--clusters", "4", "--pcs", "2"]


class ViewServer:
    """`prtr view ... --port 0` as a child; .url once it has printed it."""

    def __init__(self, prtr, args, timeout=120):
        self.proc = subprocess.Popen([prtr, "view"] + args + ["--port", "0", "-q"],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines = []
        self.url = None
        found = threading.Event()

        def read():
            for line in self.proc.stdout:
                self.lines.append(line)
                m = re.match(r"prtr view: (http://[0-9.]+:[0-9]+/)$", line.strip())
                if m and not self.url:
                    self.url = m.group(1)
                    found.set()
            found.set()

        self.reader = threading.Thread(target=read, daemon=True)
        self.reader.start()
        found.wait(timeout)
        if not self.url:
            self.proc.kill()
            raise RuntimeError("prtr view printed no URL: %s %s" %
                               ("".join(self.lines), self.proc.stderr.read()))
        parsed = urllib.parse.urlparse(self.url)
        self.host, self.port = parsed.hostname, parsed.port

    def get(self, path, timeout=60, method="GET"):
        """(status, headers dict with lower-case names, body bytes)."""
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        try:
            conn.request(method, path)
            r = conn.getresponse()
            return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
        finally:
            conn.close()

    def stop(self, sig=signal.SIGTERM, timeout=30):
        """Sends `sig`; the exit code (None when it had to be killed)."""
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            code = self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            code = None
        if code != 0:
            # A sanitizer's report or an exception's message is the only trace of why.
            tail = self.proc.stderr.read()[-6000:]
            print("prtr view exited %s; the end of its stderr:\n%s" % (code, tail))
        return code

    def rss_kib(self):
        with open("/proc/%d/status" % self.proc.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0


def frame_query(**params):
    return "/frame?" + urllib.parse.urlencode(params)


def jpeg_size(data):
    """(width, height) from a baseline/progressive JPEG's SOF marker, or None."""
    if data[:2] != b"\xff\xd8":
        return None
    i = 2
    while i + 9 < len(data):
        if data[i] != 0xFF:
            return None
        marker = data[i + 1]
        length = int.from_bytes(data[i + 2:i + 4], "big")
        if marker in (0xC0, 0xC1, 0xC2):
            return (int.from_bytes(data[i + 7:i + 9], "big"),
                    int.from_bytes(data[i + 5:i + 7], "big"))
        i += 2 + length
    return None


def frame_info(headers):
    return json.loads(headers["x-prtr-frame"])


class Checks:
    """Counts named checks; a failure prints its name and detail and the run goes on."""

    def __init__(self):
        self.passed = 0
        self.failed = 0

    def __call__(self, name, ok, detail=""):
        if ok:
            self.passed += 1
        else:
            self.failed += 1
            print("FAIL: %s %s" % (name, detail))
