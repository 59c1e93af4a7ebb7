#!/usr/bin/env python3
"""prtr view's HTTP/1.1 connection handling over raw sockets, 127.0.0.1 only, every read
bounded: 7 requests pipelined on one keep-alive connection are all answered, in the order
sent (/api/info with distinct queries, then frames of 7 different widths and other paths
whose answers differ); a request followed by shutdown(SHUT_WR) (as `nc -N` sends) gets its
whole answer, then the server closes, with and without `Connection: close`; several
pipelined requests and a half-close are all answered; and a slow client that has not
finished its request holds up neither a pipelined burst nor a plain request beside it.
Usage: view_http_test.py PRTR TMPDIR"""

import json
import os
import shutil
import socket
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import view_support as vs  # noqa: E402

check = vs.Checks()
TIMEOUT = 30  # seconds any one read may wait; a server that never answers fails, not hangs


def request(server, target, method="GET", extra=""):
    return ("%s %s HTTP/1.1\r\nHost: %s:%d\r\n%s\r\n" %
            (method, target, server.host, server.port, extra)).encode()


class Replies:
    """Reads HTTP/1.1 answers off one socket, framed by Content-Length."""

    def __init__(self, sock):
        self.sock = sock
        self.data = b""
        self.closed = False

    def _fill(self):
        chunk = self.sock.recv(65536)
        if not chunk:
            self.closed = True
        self.data += chunk
        return bool(chunk)

    def next(self, head_only=False):
        """(status, headers with lower-case names, body), or None when the server closed
        first or nothing came within TIMEOUT."""
        try:
            while b"\r\n\r\n" not in self.data:
                if not self._fill():
                    return None
            head, self.data = self.data.split(b"\r\n\r\n", 1)
            lines = head.decode("latin-1").split("\r\n")
            status = int(lines[0].split(" ")[1])
            headers = {}
            for line in lines[1:]:
                name, _, value = line.partition(":")
                headers[name.strip().lower()] = value.strip()
            length = 0 if head_only else int(headers.get("content-length", "0"))
            while len(self.data) < length:
                if not self._fill():
                    return None
            body, self.data = self.data[:length], self.data[length:]
            return status, headers, body
        except (OSError, ValueError, IndexError):
            return None

    def at_end(self):
        """Whether the server closed the connection after what was read (nothing else came)."""
        try:
            while not self.closed:
                if not self._fill():
                    break
        except OSError:
            return False
        return self.closed and self.data == b""


def connect(server):
    return socket.create_connection((server.host, server.port), timeout=TIMEOUT)


def check_pipelined_info(server):
    """7 GET /api/info on one socket in one write: 7 answers, each the whole JSON."""
    with connect(server) as s:
        s.sendall(b"".join(request(server, "/api/info?n=%d" % i) for i in range(7)))
        replies = Replies(s)
        answers = [replies.next() for _ in range(7)]
    ok = all(a is not None and a[0] == 200 and json.loads(a[2]).get("clusters") == 4
             for a in answers)
    check("7 pipelined GET /api/info: 7 answers, each the info JSON", ok,
          str([a and a[0] for a in answers]))


def check_pipelined_in_order(server):
    """7 pipelined requests whose answers differ: frames 33..39 pixels wide between other
    paths; each answer must be the one for the request in that position."""
    targets = ["/api/info", vs.frame_query(client="pipe", seq=1, w=33, h=24), "/nothing",
               vs.frame_query(client="pipe", seq=2, w=35, h=24), "/favicon.ico",
               vs.frame_query(client="pipe", seq=3, w=37, h=24), "/frame?w=oops"]
    expected = [(200, "info"), (200, (33, 24)), (404, None), (200, (35, 24)), (204, None),
                (200, (37, 24)), (400, "w")]
    with connect(server) as s:
        s.sendall(b"".join(request(server, t) for t in targets))
        replies = Replies(s)
        answers = [replies.next() for _ in targets]
    for i, (answer, (status, what)) in enumerate(zip(answers, expected)):
        if answer is None:
            check("pipelined request %d (%s) answered" % (i + 1, targets[i]), False)
            continue
        got, headers, body = answer
        if what == "info":
            ok = got == status and "probes" in json.loads(body)
        elif isinstance(what, tuple):
            ok = got == status and vs.jpeg_size(body) == what
        elif what is not None:
            ok = got == status and body.startswith(what.encode())
        else:
            ok = got == status
        check("pipelined request %d of 7 (%s): its own answer" % (i + 1, targets[i]), ok,
              "(%d %r)" % (got, body[:60]))


def check_half_close(server):
    for extra, name in [("", "keep-alive"), ("Connection: close\r\n", "Connection: close")]:
        with connect(server) as s:
            s.sendall(request(server, "/api/info", extra=extra))
            s.shutdown(socket.SHUT_WR)
            replies = Replies(s)
            answer = replies.next()
            ok = answer is not None and answer[0] == 200 and "probes" in json.loads(answer[2])
            check("half-closed request (%s): the whole answer" % name, ok, str(answer)[:120])
            check("half-closed request (%s): then the server closes" % name, replies.at_end())
    # Pipelined and then half-closed: a frame, a HEAD and the info, all answered, then closed.
    with connect(server) as s:
        s.sendall(request(server, vs.frame_query(client="hc", w=41, h=24)) +
                  request(server, "/api/info", method="HEAD") + request(server, "/api/info"))
        s.shutdown(socket.SHUT_WR)
        replies = Replies(s)
        frame = replies.next()
        head = replies.next(head_only=True)
        info = replies.next()
        check("pipelined + half-close: the frame",
              frame is not None and vs.jpeg_size(frame[2]) == (41, 24))
        check("pipelined + half-close: HEAD answered with the length and no body",
              head is not None and head[0] == 200 and int(head[1]["content-length"]) > 0)
        check("pipelined + half-close: the info after the HEAD",
              info is not None and "probes" in json.loads(info[2]))
        check("pipelined + half-close: then closed", replies.at_end())


def check_slow_client_beside_burst(server):
    """A client that has sent only part of its head (and is still connected) delays neither a
    pipelined burst on another connection nor a plain request; then it finishes and is
    answered too."""
    slow = connect(server)
    try:
        slow.sendall(b"GET /api/info HTTP/1.1\r\nHost: %s:%d\r\n" %
                     (server.host.encode(), server.port))
        with connect(server) as s:
            s.sendall(b"".join(request(server, vs.frame_query(client="burst", seq=i, w=30 + i,
                                                              h=20)) for i in range(7)))
            replies = Replies(s)
            sizes = [(lambda a: a and vs.jpeg_size(a[2]))(replies.next()) for _ in range(7)]
        check("a pipelined burst beside a slow client: 7 frames in order",
              sizes == [(30 + i, 20) for i in range(7)], str(sizes))
        status, _, _ = server.get("/api/info", timeout=TIMEOUT)
        check("a plain request beside a slow client: answered", status == 200)
        slow.setblocking(False)
        try:
            early = slow.recv(1)
        except BlockingIOError:
            early = b""
        check("the slow client is not answered before its head is complete", early == b"")
        slow.setblocking(True)
        slow.settimeout(TIMEOUT)
        slow.sendall(b"Connection: close\r\n\r\n")
        replies = Replies(slow)
        answer = replies.next()
        check("the slow client, once complete, is answered",
              answer is not None and answer[0] == 200, str(answer)[:80])
    finally:
        slow.close()


def main():
    prtr, tmp = sys.argv[1], sys.argv[2]
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    mesh, probe = vs.write_inputs(tmp)
    server = vs.ViewServer(prtr, [mesh, "--probe", probe, "--cache", os.path.join(tmp, "cache"),
                                  "--width", "64", "--height", "48"] + vs.SMALL_BAKE)
    try:
        check_pipelined_info(server)
        check_pipelined_in_order(server)
        check_half_close(server)
        check_slow_client_beside_burst(server)
    finally:
        code = server.stop()
    check("SIGTERM exits 0", code == 0, "(exit %s)" % code)
    print("view_http_test: %d passed, %d failed" % (check.passed, check.failed))
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
