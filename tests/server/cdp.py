# SPDX-License-Identifier: MIT
"""Headless Chromium driven over the DevTools protocol through a pipe (--remote-debugging-pipe),
Python standard library only: for the viewer's browser test and bench/viewer_bench.py.

Chromium reads NUL-terminated JSON commands on its fd 3 and writes replies and events on fd 4.
Every wait is bounded."""

import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import time

CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "chrome")


def find_chromium():
    """The browser's path, or None (then the caller skips, saying so)."""
    env = os.environ.get("CHROMIUM")
    if env:
        return env if os.path.exists(env) else shutil.which(env)
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


class CdpError(RuntimeError):
    pass


class Browser:
    def __init__(self, path, width=1280, height=960, timeout=60.0):
        self.profile = tempfile.mkdtemp(prefix="tg-chromium-")
        cmd_r, self._cmd_w = os.pipe()   # we write commands, Chromium reads fd 3
        self._ev_r, ev_w = os.pipe()     # Chromium writes fd 4, we read
        args = [path, "--headless", "--remote-debugging-pipe", "--no-sandbox", "--disable-gpu",
                "--no-first-run", "--no-default-browser-check", "--disable-extensions",
                "--disable-background-networking", "--disable-renderer-backgrounding",
                "--disable-background-timer-throttling", "--disable-backgrounding-occluded-windows",
                "--force-device-scale-factor=1", "--hide-scrollbars", "--mute-audio",
                "--user-data-dir=" + self.profile, "--window-size=%d,%d" % (width, height), "about:blank"]

        def child():
            # Through fds >= 10 first: the pipe's own numbers may be 3 or 4.
            a, b = fcntl.fcntl(cmd_r, fcntl.F_DUPFD, 10), fcntl.fcntl(ev_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.stderr = tempfile.TemporaryFile()
        self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=self.stderr,
                                     preexec_fn=child, close_fds=False)
        os.close(cmd_r)
        os.close(ev_w)
        self._buf = b""
        self._next = 1
        self.events = []
        self.session = None
        self.timeout = timeout
        # The browser answers its first command once it is up.
        self.call("Browser.getVersion", timeout=timeout, session=False)

    def err(self):
        self.stderr.seek(0)
        return self.stderr.read().decode(errors="replace")[-3000:]

    def _read_message(self, deadline):
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise CdpError("no answer from Chromium in time; its stderr: " + self.err())
            r, _, _ = select.select([self._ev_r], [], [], left)
            if r:
                chunk = os.read(self._ev_r, 1 << 20)
                if not chunk:
                    raise CdpError("Chromium closed its pipe (exit %s); its stderr: %s" % (self.proc.poll(), self.err()))
                self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def call(self, method, params=None, timeout=None, session=True):
        mid = self._next
        self._next += 1
        m = {"id": mid, "method": method, "params": params or {}}
        if session and self.session:
            m["sessionId"] = self.session
        os.write(self._cmd_w, json.dumps(m).encode() + b"\0")
        deadline = time.monotonic() + (timeout or self.timeout)
        while True:
            r = self._read_message(deadline)
            if r.get("id") == mid:
                if "error" in r:
                    raise CdpError("%s: %s" % (method, r["error"]))
                return r.get("result", {})
            self.events.append(r)

    def open(self, url, width=1280, height=960):
        """A new page at url, attached; later calls go to it."""
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=False)
        self.session = self.call("Target.attachToTarget", {"targetId": target["targetId"], "flatten": True},
                                 session=False)["sessionId"]
        self.call("Page.enable")
        self.call("Runtime.enable")
        self.call("Emulation.setDeviceMetricsOverride", {"width": width, "height": height, "deviceScaleFactor": 1,
                                                           "mobile": False})
        self.call("Page.navigate", {"url": url})

    def eval(self, expression, timeout=None):
        """The value of a JavaScript expression in the page (promises awaited)."""
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                      timeout=timeout)
        if "exceptionDetails" in r:
            raise CdpError("%s: %s" % (expression[:80], r["exceptionDetails"].get("exception", {}).get("description",
                                                                                                     r["exceptionDetails"])))
        return r["result"].get("value")

    def wait_for(self, expression, timeout=30.0, what=None):
        """Polls a JavaScript expression until it is truthy; its value."""
        deadline = time.monotonic() + timeout
        last = None
        while time.monotonic() < deadline:
            try:
                last = self.eval(expression)
            except CdpError as e:
                last = str(e)
            if last and not isinstance(last, str):
                return last
            time.sleep(0.1)
        raise AssertionError("%s: not true within %s s (last: %r)" % (what or expression, timeout, last))

    def screenshot(self, path):
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))
        return path

    def close(self):
        try:
            if self.proc.poll() is None:
                try:
                    self.call("Browser.close", timeout=5, session=False)
                except Exception:
                    pass
                try:
                    self.proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    self.proc.kill()
                    self.proc.wait()
        finally:
            for fd in (self._cmd_w, self._ev_r):
                try:
                    os.close(fd)
                except OSError:
                    pass
            shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
