#!/usr/bin/env python3
"""A bounded load test of prtr view, on 127.0.0.1 only: CLIENTS threads request frames as fast
as they are answered (each its own client id, changing angles, modes and sizes) for SECONDS,
while another thread sends a burst of malformed requests and garbage. Passes when every
valid request got a JPEG, every malformed one a 400/404, the server's RSS over the second
half stayed within a bound of the first half's, and SIGTERM exits 0.
Usage: view_load_test.py PRTR TMPDIR [--seconds S] [--clients N] [-- extra prtr view flags]
(default: a generated sphere; pass MESH --probe PROBE ... after -- for another input)."""

import argparse
import http.client
import os
import random
import shutil
import socket
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import view_support as vs  # noqa: E402

MODES = ["decoupled", "singlepass", "cpu", "multipass"]
SIZES = [(64, 48), (160, 118), (320, 237)]


def client_loop(server, cid, deadline, stats, lock, seed):
    rng = random.Random(seed)
    conn = http.client.HTTPConnection(server.host, server.port, timeout=120)
    seq = 0
    while time.monotonic() < deadline:
        seq += 1
        w, h = rng.choice(SIZES)
        query = vs.frame_query(client="load%d" % cid, seq=seq, w=w, h=h,
                               env_yaw=round(rng.uniform(-180, 180), 2),
                               cam_yaw=round(rng.uniform(-180, 180), 2), mode=rng.choice(MODES),
                               overlay=rng.choice(["none", "none", "overdraw", "clusters"]))
        try:
            conn.request("GET", query)
            r = conn.getresponse()
            body = r.read()
            ok = r.status == 200 and body[:2] == b"\xff\xd8" and vs.jpeg_size(body) == (w, h)
        except (OSError, http.client.HTTPException) as e:
            ok, body = False, repr(e).encode()
            conn.close()
            conn = http.client.HTTPConnection(server.host, server.port, timeout=120)
        with lock:
            stats["valid"] += 1
            stats["answered"] += ok
            if not ok and len(stats["errors"]) < 5:
                stats["errors"].append(body[:200])
    conn.close()


def malformed_burst(server, stats, lock, count):
    bad = ["/frame?w=nan", "/frame?env_yaw=inf", "/frame?mode=x", "/frame?budget=-3",
           "/frame?w=99999&h=99999", "/frame?probe=../../etc/passwd", "/frame?zz=1",
           "/nothing", "/../etc/passwd"]
    for i in range(count):
        path = bad[i % len(bad)]
        try:
            status, _, _ = server.get(path, timeout=30)
            ok = status in (400, 404)
        except OSError:
            ok = False
        if i % 20 == 0:  # and raw garbage now and then
            try:
                with socket.create_connection((server.host, server.port), timeout=5) as s:
                    s.sendall(b"\x00\xff GET nonsense\r\n\r\n")
                    s.recv(1024)
            except OSError:
                pass
        with lock:
            stats["malformed"] += 1
            stats["refused"] += ok


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("prtr")
    parser.add_argument("tmp")
    parser.add_argument("--seconds", type=float, default=20)
    parser.add_argument("--clients", type=int, default=4)
    parser.add_argument("view_args", nargs="*")
    a = parser.parse_args()
    shutil.rmtree(a.tmp, ignore_errors=True)
    os.makedirs(a.tmp)
    if a.view_args:
        args = a.view_args
    else:
        mesh, probe = vs.write_inputs(a.tmp)
        args = [mesh, "--probe", probe, "--cache", os.path.join(a.tmp, "cache")] + vs.SMALL_BAKE
    server = vs.ViewServer(a.prtr, args, timeout=1800)
    stats = {"valid": 0, "answered": 0, "malformed": 0, "refused": 0, "errors": []}
    lock = threading.Lock()
    start = time.monotonic()
    deadline = start + a.seconds
    threads = [threading.Thread(target=client_loop, args=(server, c, deadline, stats, lock, c))
               for c in range(a.clients)]
    threads.append(threading.Thread(target=malformed_burst, args=(server, stats, lock, 300)))
    for t in threads:
        t.start()
    rss = []  # (seconds since start, KiB)
    while any(t.is_alive() for t in threads):
        rss.append((time.monotonic() - start, server.rss_kib()))
        time.sleep(0.25)
    for t in threads:
        t.join()
    code = server.stop()
    half = a.seconds / 2
    first = max([k for t, k in rss if t < half] or [0])
    second = max([k for t, k in rss if t >= half] or [0])
    # Renderers and probes are cached up to fixed counts, so after the first half has built
    # them the peak should not climb: allow allocator noise, not growth.
    bound = first * 1.10 + 16 * 1024
    print("view_load_test: %d clients, %.0f s: %d/%d valid requests answered (%.1f/s), "
          "%d/%d malformed refused, RSS peak %d MiB (first half) -> %d MiB (second), exit %s"
          % (a.clients, a.seconds, stats["answered"], stats["valid"],
             stats["valid"] / a.seconds, stats["refused"], stats["malformed"], first // 1024,
             second // 1024, code))
    failures = []
    if stats["valid"] == 0 or stats["answered"] != stats["valid"]:
        failures.append("valid requests unanswered: %s" % stats["errors"])
    if stats["refused"] != stats["malformed"]:
        failures.append("malformed requests not refused with 400/404")
    if "ASAN_OPTIONS" in os.environ:  # scripts/sanitize.sh: freed memory waits in quarantine
        print("note: RSS bound not enforced under AddressSanitizer (its quarantine grows)")
    elif second > bound:
        failures.append("RSS grew beyond %d MiB" % (bound // 1024))
    if code != 0:
        failures.append("exit code %s after SIGTERM" % code)
    for f in failures:
        print("FAIL: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
