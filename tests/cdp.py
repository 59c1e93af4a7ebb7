"""A minimal Chrome DevTools Protocol client over --remote-debugging-pipe (Python 3 standard
library only): chromium reads commands from fd 3 and writes replies and events to fd 4, each
message JSON followed by a NUL byte. One page target, attached with a flat session."""

import fcntl
import json
import os
import queue
import subprocess
import threading
import time


class CdpError(RuntimeError):
    pass


class Browser:
    def __init__(self, chromium, user_data_dir, width=1400, height=950):
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()

        def place_pipes():  # in the child, before exec: the pipes become fds 3 and 4
            r = fcntl.fcntl(to_child_r, fcntl.F_DUPFD, 10)
            w = fcntl.fcntl(from_child_w, fcntl.F_DUPFD, 10)
            os.dup2(r, 3)
            os.dup2(w, 4)

        # Root in a container needs --no-sandbox; there is no GPU.
        args = [chromium, "--headless=new", "--no-sandbox", "--disable-gpu",
                "--remote-debugging-pipe", "--user-data-dir=" + user_data_dir,
                "--no-first-run", "--no-default-browser-check", "--disable-extensions",
                "--disable-dev-shm-usage", "--mute-audio", "--hide-scrollbars",
                "--window-size=%d,%d" % (width, height), "about:blank"]
        self.proc = subprocess.Popen(args, preexec_fn=place_pipes, close_fds=False,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_child_r)
        os.close(from_child_w)
        self._next_id = 0
        self._replies = {}
        self._cond = threading.Condition()
        self.events = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        self.session = None

    def _read(self):
        buffer = b""
        while True:
            try:
                chunk = os.read(self._from_child, 1 << 16)
            except OSError:
                chunk = b""
            if not chunk:
                with self._cond:
                    self._replies[None] = "closed"
                    self._cond.notify_all()
                return
            buffer += chunk
            while b"\0" in buffer:
                raw, buffer = buffer.split(b"\0", 1)
                msg = json.loads(raw)
                if "id" in msg:
                    with self._cond:
                        self._replies[msg["id"]] = msg
                        self._cond.notify_all()
                else:
                    self.events.put(msg)

    def call(self, method, params=None, session=True, timeout=30):
        with self._cond:
            self._next_id += 1
            mid = self._next_id
        msg = {"id": mid, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        os.write(self._to_child, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        with self._cond:
            while mid not in self._replies:
                if None in self._replies:
                    raise CdpError("chromium closed the pipe during " + method)
                left = deadline - time.monotonic()
                if left <= 0:
                    raise CdpError("no reply to %s within %d s" % (method, timeout))
                self._cond.wait(left)
            reply = self._replies.pop(mid)
        if "error" in reply:
            raise CdpError("%s: %s" % (method, reply["error"]))
        return reply.get("result", {})

    def open(self, url):
        target = self.call("Target.createTarget", {"url": url}, session=False)["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True},
                                 session=False)["sessionId"]
        return self.session  # assign .session to switch between opened pages

    def evaluate(self, expression, timeout=30):
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                                "awaitPromise": True}, timeout=timeout)
        if "exceptionDetails" in result:
            raise CdpError("JS exception: %s" % result["exceptionDetails"])
        return result.get("result", {}).get("value")

    def wait_for(self, expression, timeout=30, what=None):
        """Polls `expression` until it is truthy; returns its value."""
        deadline = time.monotonic() + timeout
        while True:
            try:
                value = self.evaluate(expression)
            except CdpError:  # the page is still loading: its elements do not exist yet
                value = None
            if value:
                return value
            if time.monotonic() > deadline:
                raise CdpError("timed out after %d s waiting for %s" % (timeout, what or expression))
            time.sleep(0.05)

    def mouse(self, kind, x, y, buttons=0, modifiers=0):
        params = {"type": kind, "x": x, "y": y, "button": "left" if kind != "mouseMoved" else
                  ("left" if buttons else "none"), "buttons": buttons, "modifiers": modifiers}
        if kind != "mouseMoved":
            params["clickCount"] = 1
        self.call("Input.dispatchMouseEvent", params)

    def rect(self, element_id):
        """The element's [x, y, width, height] in CSS pixels."""
        return self.evaluate("(() => { const r = document.getElementById(%r)"
                             ".getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })()"
                             % element_id)

    def drag(self, x0, y0, dx, dy, steps=10, modifiers=0, pause=0.0):
        self.mouse("mousePressed", x0, y0, buttons=1, modifiers=modifiers)
        for i in range(1, steps + 1):
            self.mouse("mouseMoved", x0 + dx * i / steps, y0 + dy * i / steps, buttons=1,
                       modifiers=modifiers)
            if pause:
                time.sleep(pause)
        self.mouse("mouseReleased", x0 + dx, y0 + dy, buttons=0, modifiers=modifiers)

    def close(self):
        try:
            self.call("Browser.close", session=False, timeout=5)
        except CdpError:
            pass
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_child, self._from_child):
            try:
                os.close(fd)
            except OSError:
                pass
