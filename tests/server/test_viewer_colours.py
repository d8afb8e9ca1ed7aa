#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The viewer draws the world file's colours (issue 34 §2): headless Chromium loads the page of
`turtlegas serve` of a still world whose wall, ball and turtle have a "colour" key
(tests/server/worlds/viewer_colours.json), and a ball and a turtle that have none. The pixels at
those bodies are checked: red wall, #00c0c0 ball, magenta turtle; the uncoloured ball in a speed
colour and the uncoloured turtle in the viewer's own second colour (#f28e2b), as before.

Skips (exit 77, with the reason) only when no Chromium is installed."""

import os
import sys
import tempfile
import time
import json

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from harness import Server, check, world  # noqa: E402
import cdp  # noqa: E402


def near(rgb, want, tol=30):
    return all(abs(a - b) <= tol for a, b in zip(rgb, want))


def test():
    chromium = cdp.find_chromium()
    if not chromium:
        print("SKIP: no Chromium found (chromium, chromium-browser, google-chrome); scripts/install-deps.sh installs Debian's")
        sys.exit(77)
    shot_dir = os.environ.get("TURTLEGAS_SCREENSHOT_DIR", tempfile.gettempdir())
    with Server(world("viewer_colours.json"), "--speed", "1") as server, cdp.Browser(chromium, 1000, 800) as b:
        b.open("http://127.0.0.1:%d/" % server.http_port, 1000, 800)
        b.wait_for("window.turtlegasViewer && turtlegasViewer.state.t > 0.3 && turtlegasViewer.state.turtles.length === 2 && "
                   "turtlegasViewer.state.balls.n === 2", 30, "the viewer has the world")
        time.sleep(0.5)
        colours = b.eval("turtlegasViewer.state.world.colours")
        check(colours == {"w1": "#ff0000", "b1": "#00c0c0", "t1": "#ff00ff"}, "the world message's colours: %r" % colours)
        b.screenshot(os.path.join(shot_dir, "turtlegas_viewer_colours.png"))

        def pixels(points):
            js = """((pts) => { const p = turtlegasViewer.panels.get('arena'), M = p.matrix, g = p.canvas.getContext('2d');
              return pts.map(([x, y]) => { const X = M.a * x + M.c * y + M.e, Y = M.b * x + M.d * y + M.f;
                return Array.from(g.getImageData(Math.round(X), Math.round(Y), 1, 1).data.slice(0, 3)); }); })(%s)"""
            return [tuple(c) for c in b.eval(js % json.dumps(points))]
        # The wall: a line of 2.5 px; one of the pixels across it is red.
        across = pixels([(150, 250 + e) for e in (-0.6, -0.3, 0, 0.3, 0.6)])
        check(any(near(rgb, (255, 0, 0), 40) for rgb in across), "the wall w1 is red (got %s); screenshot in %s" % (across, shot_dir))
        # Bodies: pixels inside, clear of the heading line (which runs from the centre up, heading 0).
        got = pixels([(300, 100), (310, 95), (185, 140), (215, 140), (100, 100), (190, 55)])
        check(near(got[0], (0, 0xc0, 0xc0)) and near(got[1], (0, 0xc0, 0xc0)), "ball b1 is #00c0c0 (got %s)" % got[:2])
        check(near(got[2], (255, 0, 255)) and near(got[3], (255, 0, 255)), "turtle t1 is magenta (got %s)" % got[2:4])
        check(not near(got[4], (0, 0xc0, 0xc0)) and not near(got[4], (0xf8, 0xf8, 0xf4), 10),
              "ball b2, uncoloured, keeps its speed's colour (got %s)" % (got[4],))
        check(near(got[5], (0xf2, 0x8e, 0x2b)), "turtle t2, uncoloured, keeps the viewer's second colour (got %s)" % (got[5],))
        print("ok   viewer colours: the world file's wall, ball and turtle colours drawn; screenshot in %s" % shot_dir)


if __name__ == "__main__":
    test()
