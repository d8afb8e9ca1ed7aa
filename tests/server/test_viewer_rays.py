#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The viewer draws range sensors' rays (issue 34, section 1): headless Chromium loads the page of
`turtlegas serve` of a world whose turtle stands still and reads a front ray and a ring of four
every 0.5 s. The rays' pixels are checked against the closed forms of what they hit (the same
geometry as worlds/tests/senses_closed_form.json): drawn from the turtle's centre to the hit, a dot
at the hit, nothing past it, and a miss drawn faint to the sensor's range.

Skips (exit 77, with the reason) only when no Chromium is installed."""

import json
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from harness import Server, check, world  # noqa: E402
import cdp  # noqa: E402

BACKGROUND = (0xf8, 0xf8, 0xf4)


def near(rgb, want, tol=45):
    return all(abs(a - b) <= tol for a, b in zip(rgb, want))


def ray_ish(rgb):
    """The ray's colour, maybe blended half with the background by antialiasing: far redder than
    green, which nothing else on the page is (background, walls, the blue and orange turtles, the
    blue still ball)."""
    return rgb[0] - rgb[1] > 50 and rgb[2] - rgb[1] > 15


def test():
    chromium = cdp.find_chromium()
    if not chromium:
        print("SKIP: no Chromium found (chromium, chromium-browser, google-chrome); scripts/install-deps.sh installs Debian's")
        sys.exit(77)
    shot_dir = os.environ.get("TURTLEGAS_SCREENSHOT_DIR", tempfile.gettempdir())
    with Server(world("viewer_rays.json"), "--speed", "1") as server, cdp.Browser(chromium, 1000, 800) as b:
        b.open("http://127.0.0.1:%d/" % server.http_port, 1000, 800)
        b.wait_for("window.turtlegasViewer && turtlegasViewer.state.t > 0.7 && "
                   "turtlegasViewer.state.turtles.length === 2 && turtlegasViewer.state.turtles[0].readings.size === 2",
                   30, "the viewer has t1's front and ring readings")
        b.eval("document.getElementById('pause').click()")
        b.wait_for("turtlegasViewer.state.paused", 10, "pause reaches the page")
        time.sleep(0.5)
        readings = b.eval("(() => { const r = turtlegasViewer.state.turtles[0].readings;"
                          " return Object.fromEntries([...r].map(([k, v]) => [k, {range: v.range, hit: v.hit}])); })()")
        check(readings["front"] == {"range": [96], "hit": ["b1"]}, "front reading: %r" % readings["front"])
        check(readings["ring"] == {"range": [96, 100, 100, None], "hit": ["b1", "t2", "arena-left", None]},
              "ring reading: %r" % readings["ring"])
        b.screenshot(os.path.join(shot_dir, "turtlegas_viewer_rays.png"))
        # World points -> canvas pixels through the panel's own matrix (the whole arena).
        def pixels(points):
            js = """((pts) => { const p = turtlegasViewer.panels.get('arena'), M = p.matrix, g = p.canvas.getContext('2d');
              return pts.map(([x, y]) => { const X = M.a * x + M.c * y + M.e, Y = M.b * x + M.d * y + M.f;
                return Array.from(g.getImageData(Math.round(X), Math.round(Y), 1, 1).data.slice(0, 3)); }); })(%s)"""
            return [tuple(c) for c in b.eval(js % json.dumps(points))]
        # On the rays, between the turtle's edge and the hit: the ray's colour. Ahead: to b1's surface
        # at x = 196; below: to t2's at y = 50; behind: to the arena's left wall.
        on = [(130, 150), (160, 150), (185, 150), (100, 120), (100, 70), (70, 150), (30, 150), (196, 150)]
        for p in on:
            # The pixel on the line and its neighbours across it (a 2 px line falls between pixels).
            across = [(p[0], p[1] + e) for e in (-0.5, 0, 0.5)] if p[1] == 150 else [(p[0] + e, p[1]) for e in (-0.5, 0, 0.5)]
            got = pixels(across)
            check(any(ray_ish(rgb) for rgb in got), "the ray through %s is drawn (got %s); screenshot in %s" % (p, got, shot_dir))
        # Off the rays: background. Beside them, and past the front ray's hit (b1 is at 200 +- 5,
        # so beyond x = 210 the front ray does not go on).
        off = [(160, 160), (160, 140), (110, 100), (90, 70), (260, 150), (320, 150)]
        got = pixels(off)
        for p, rgb in zip(off, got):
            check(near(rgb, BACKGROUND, 20), "nothing drawn at %s, off the rays and past their hits (got %s); screenshot in %s"
                  % (p, rgb, shot_dir))
        # Above: the ring's ray that hit nothing within 120, faint and dashed: somewhere along it,
        # neither the background nor the full ray colour.
        up = pixels([(100, 150 + d) for d in range(15, 118)])
        faint = [rgb for rgb in up if not near(rgb, BACKGROUND, 8) and not near(rgb, (0xd6, 0x33, 0x6c), 30)]
        check(len(faint) > 20, "the miss above is drawn faint to the range (%d faint pixels)" % len(faint))
        check(near(pixels([(100, 150 + 140)])[0], BACKGROUND, 20), "nothing past the miss's range of 120")
        print("ok   viewer rays: front and ring readings drawn to their closed-form hits; screenshot in %s" % shot_dir)


if __name__ == "__main__":
    test()
