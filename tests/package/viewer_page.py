# SPDX-License-Identifier: MIT
"""An installed `turtlegas serve` serves the installed viewer page (share/turtlegas/web beside
bin/turtlegas), not the source tree's: the test marks the installed index.html and looks for the
mark in GET /."""

import re
import selectors
import subprocess
import time
import urllib.request
from pathlib import Path


def check_installed_viewer(turtlegas, web, world, fail):
    web = Path(web)
    for name in ("index.html", "viewer.js", "protocol.js", "geometry.js", "panels.js", "draw.js", "viewer.css"):
        if not (web / name).is_file():
            fail("the viewer's " + name + " is not installed in " + str(web))
    mark = "<!-- installed copy: viewer_page.py -->"
    index = web / "index.html"
    index.write_text(index.read_text() + mark + "\n")
    proc = subprocess.Popen([str(turtlegas), "serve", str(world), "--port", "0", "--paused"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        sel = selectors.DefaultSelector()
        sel.register(proc.stdout, selectors.EVENT_READ)
        deadline, out = time.monotonic() + 30, b""
        while b"\n" not in out and time.monotonic() < deadline and sel.select(deadline - time.monotonic()):
            chunk = proc.stdout.read1(4096)
            if not chunk:
                break
            out += chunk
        m = re.search(rb"http://127\.0\.0\.1:(\d+)/", out)
        if not m:
            fail("the installed turtlegas serve did not start: " + repr(out))
        base = "http://127.0.0.1:%d/" % int(m.group(1))
        page = urllib.request.urlopen(base, timeout=30).read().decode()
        if mark not in page:
            fail("the installed turtlegas serve does not serve the installed viewer page (" + str(web) + ")")
        script = urllib.request.urlopen(base + "viewer.js", timeout=30).read()
        if script != (web / "viewer.js").read_bytes():
            fail("GET /viewer.js is not the installed viewer.js")
    finally:
        proc.terminate()
        proc.wait(timeout=30)
