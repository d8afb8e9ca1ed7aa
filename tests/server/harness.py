# SPDX-License-Identifier: MIT
"""Starts `turtlegas serve` on loopback port 0 for the server's tests and reads its ports.

The binary comes from $TURTLEGAS (ctest sets it); every wait is bounded."""

import os
import re
import selectors
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
BIN = os.environ.get("TURTLEGAS", os.path.join(ROOT, "build", "release", "turtlegas"))
WORLDS = os.path.join(ROOT, "tests", "server", "worlds")


def world(name):
    return os.path.join(WORLDS, name)


class Server:
    def __init__(self, world_file, *args, start_timeout=30.0, command="serve"):
        self.stderr = tempfile.TemporaryFile()
        cmd = [BIN, command, world_file, "--port", "0", *map(str, args)]
        self.cmd = cmd
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.stderr)
        lines = []
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        deadline = time.monotonic() + start_timeout
        buf = b""
        while len(lines) < 2:
            left = deadline - time.monotonic()
            if left <= 0 or self.proc.poll() is not None and not sel.select(0):
                self.kill()
                raise AssertionError("server did not start: %s\nstderr: %s" % (cmd, self.err()))
            if sel.select(left):
                chunk = os.read(self.proc.stdout.fileno(), 4096)
                if not chunk:
                    continue
                buf += chunk
                while b"\n" in buf:
                    line, buf = buf.split(b"\n", 1)
                    lines.append(line.decode())
        sel.close()
        self.http_port = int(re.search(r"listening on http://127\.0\.0\.1:(\d+)/", lines[0]).group(1))
        self.line_port = int(re.search(r"lines on tcp://127\.0\.0\.1:(\d+)", lines[1]).group(1))

    def err(self):
        self.stderr.seek(0)
        return self.stderr.read().decode(errors="replace")

    def alive(self):
        return self.proc.poll() is None

    def stop(self, sig=signal.SIGINT, timeout=30.0):
        if self.alive():
            self.proc.send_signal(sig)
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise AssertionError("server did not stop within %s s after signal %s" % (timeout, sig))

    def wait(self, timeout=60.0):
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise AssertionError("server did not end within %s s" % timeout)

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.kill()
        return False


def check(cond, message):
    if not cond:
        raise AssertionError(message)


def run(cmd, **kw):
    r = subprocess.run([BIN, *map(str, cmd)], capture_output=True, text=True, timeout=300, **kw)
    check(r.returncode == 0, "turtlegas %s failed (%d): %s" % (cmd, r.returncode, r.stderr))
    return r


def main(tests):
    """Runs each test function, prints its name; exit 1 on the first failure."""
    for t in tests:
        start = time.monotonic()
        t()
        print("ok   %s (%.1f s)" % (t.__name__, time.monotonic() - start), flush=True)
