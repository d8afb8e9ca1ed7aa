#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The replay viewer in a real browser (issue 32, section 2): `turtlegas replay R.tgrec` of a
recording whose only view follows a turtle, loaded in headless Chromium, checked by its pixels and
its clock:

- the REPLAY mark is shown (its red badge, read from a screenshot) and the end time is written;
- the whole room gets a panel of its own (the recording's one view is a follow camera);
- the panels use the window (before: one panel took a third of its width and 44 % of its height);
- turtles are drawn in their own colours, as `render` draws them (formats/look.hpp);
- dragging the timeline seeks: the clock goes where the knob was let go, and the turtles are drawn
  where the server's world has them there;
- reverse plays backwards: the clock goes down, and the turtles are drawn where they were.

Skips (exit 77, with the reason) only when no Chromium is installed."""

import json
import math
import os
import subprocess
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from harness import BIN, Server, check, world  # noqa: E402
import cdp  # noqa: E402
from png import png_pixels  # noqa: E402

WORLD = world("replay_follow.json")
UNTIL = 8.0
COLOUR = {"t0": (0x4e, 0x79, 0xa7), "t1": (0xf2, 0x8e, 0x2b)}
MARK = (0xb3, 0x26, 0x1e)
WIDTH, HEIGHT = 1280, 800


def near(rgb, want, tol=40):
    return all(abs(a - b) <= tol for a, b in zip(rgb, want))


def api_state(server):
    with urllib.request.urlopen("http://127.0.0.1:%d/api/state" % server.http_port, timeout=10) as r:
        return json.loads(r.read())


class Page:
    def __init__(self, b):
        self.b = b

    def rect(self, selector):
        return self.b.eval("(() => { const e = document.querySelector(%s); if (!e) return null;"
                           " const r = e.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()"
                           % json.dumps(selector))

    def clock(self):
        return self.b.eval("(() => { const s = turtlegasViewer.state; return {t: s.t, paused: s.paused, frames: s.framesIn,"
                           " replay: s.replay, status: document.getElementById('status').textContent,"
                           " time: document.getElementById('replay-time').textContent}; })()")

    def turtle_pixels(self, view_id, server_state):
        """The canvas colour at each turtle's body (half a radius behind its heading), where the
        server's world has the turtle, mapped through the panel's own view (the whole arena)."""
        js = """(([view, pts]) => {
          const c = document.querySelector('canvas[data-view=' + JSON.stringify(view) + ']');
          const p = turtlegasViewer.panels.get(view), M = p.matrix, g = c.getContext('2d');
          return pts.map(([x, y]) => { const X = M.a * x + M.c * y + M.e, Y = M.b * x + M.d * y + M.f;
            return Array.from(g.getImageData(Math.floor(X), Math.floor(Y), 1, 1).data.slice(0, 3)); });
        })(%s)"""
        pts, ids = [], []
        for t in server_state["turtles"]:
            h = math.radians(t["heading"])
            r = t.get("radius", 10)
            pts.append([t["pos"][0] - 0.5 * r * math.sin(h), t["pos"][1] - 0.5 * r * math.cos(h)])
            ids.append(t["id"])
        got = self.b.eval(js % json.dumps([view_id, pts]))
        return {i: tuple(c) for i, c in zip(ids, got)}

    def settle(self):
        """A frame drawn after the clock stopped."""
        n = self.clock()["frames"]
        self.b.wait_for("turtlegasViewer.state.framesIn > %d" % n, 20, "frames keep coming")
        time.sleep(0.4)


def mouse(b, kind, xy):
    b.call("Input.dispatchMouseEvent", {"type": kind, "x": xy[0], "y": xy[1], "button": "left",
                                        "buttons": 1 if kind != "mouseReleased" else 0, "clickCount": 1})


def check_turtles_drawn(page, server, what, shot_dir):
    st = api_state(server)
    got = page.turtle_pixels("arena", st)
    for tid, rgb in got.items():
        check(near(rgb, COLOUR[tid]), "%s: %s is drawn in its colour %s where the world has it at t=%s (got %s); screenshots in %s"
              % (what, tid, COLOUR[tid], st["t"], rgb, shot_dir))
    return st


def test():
    chromium = cdp.find_chromium()
    if not chromium:
        print("SKIP: no Chromium found (chromium, chromium-browser, google-chrome); scripts/install-deps.sh installs Debian's")
        sys.exit(77)
    shot_dir = os.environ.get("TURTLEGAS_SCREENSHOT_DIR", tempfile.gettempdir())
    tmp = tempfile.mkdtemp(prefix="turtlegas_replay_viewer_")
    rec = os.path.join(tmp, "follow.tgrec")
    subprocess.run([BIN, "run", WORLD, "--until", str(UNTIL), "--record", rec], check=True, capture_output=True, timeout=120)
    with Server(rec, "--paused", command="replay") as server, cdp.Browser(chromium, WIDTH, HEIGHT) as b:
        b.open("http://127.0.0.1:%d/" % server.http_port, WIDTH, HEIGHT)
        page = Page(b)
        b.wait_for("window.turtlegasViewer && turtlegasViewer.state.framesIn > 3 && turtlegasViewer.state.replay &&"
                   " document.querySelectorAll('canvas[data-view]').length === 2", 30,
                   "the replay shows the follow view and a whole-room panel")
        page.settle()
        c = page.clock()
        check(c["replay"]["end"] == UNTIL, "the status carries the recording's end: %r" % c["replay"])
        check(c["time"] == "0.00 / %.2f s" % UNTIL, "the end time is shown beside the timeline: %r" % c["time"])
        shot = os.path.join(shot_dir, "turtlegas_replay_start.png")
        b.screenshot(shot)

        # The REPLAY mark: its badge's pixels are its red.
        w, h, rows = png_pixels(open(shot, "rb").read())
        px = lambda x, y: rows[y][x]  # noqa: E731
        m = page.rect("#replay-mark")
        check(m and m[2] > 20 and m[3] > 8, "the REPLAY mark is laid out: %r" % m)
        red = sum(near(px(int(m[0] + m[2] * fx), int(m[1] + m[3] * fy)), MARK, 30)
                  for fx in (0.05, 0.5, 0.95) for fy in (0.15, 0.85))
        check(red >= 5, "the REPLAY mark is drawn red (%d of 6 probes); screenshot %s" % (red, shot))
        check(b.eval("document.title").startswith("REPLAY"), "the page's title says REPLAY: %r" % b.eval("document.title"))

        # The panels use the window: two panels side by side filling the page under the bar.
        box = page.rect("#panels")
        arena, chase = page.rect("section[data-view=arena]"), page.rect("section[data-view=chase]")
        area = (arena[2] * arena[3] + chase[2] * chase[3]) / (box[2] * box[3])
        check(area > 0.85, "the two panels fill the page: %.0f %% of %r (arena %r, chase %r)" % (100 * area, box, arena, chase))
        canvas = page.rect("canvas[data-view=arena]")
        check(canvas[2] > 0.4 * WIDTH or canvas[3] > 0.6 * box[3],
              "the whole room is drawn large: canvas %r in a %dx%d window" % (canvas, WIDTH, HEIGHT))

        # Turtles in their own colours where the world has them (t = 0).
        check_turtles_drawn(page, server, "at the start", shot_dir)

        # Drag the timeline's knob from the left to three quarters along: a seek there.
        tl = page.rect("#timeline")
        y = tl[1] + tl[3] / 2
        mouse(b, "mousePressed", (tl[0] + 4, y))
        for k in range(1, 9):
            mouse(b, "mouseMoved", (tl[0] + 4 + k * (0.75 * tl[2] - 4) / 8, y))
        mouse(b, "mouseReleased", (tl[0] + 0.75 * tl[2], y))
        want = b.eval("Number(document.getElementById('timeline').value)")
        check(0.6 * UNTIL < want < 0.9 * UNTIL, "the knob was let go three quarters along: %r" % want)
        b.wait_for("Math.abs(turtlegasViewer.state.t - %r) < 1e-9 && turtlegasViewer.state.paused" % want, 30,
                   "the replay's clock goes to the knob (%r)" % want)
        st = api_state(server)
        check(abs(st["t"] - want) < 1e-9, "the server's world is at the knob: %r vs %r" % (st["t"], want))
        page.settle()
        c = page.clock()
        check(c["time"] == "%.2f / %.2f s" % (want, UNTIL), "the time beside the timeline: %r" % c["time"])
        b.screenshot(os.path.join(shot_dir, "turtlegas_replay_seeked.png"))
        check_turtles_drawn(page, server, "after the seek", shot_dir)

        # Reverse: the clock goes down (and the turtles are drawn where they were then).
        b.eval("document.getElementById('reverse').click()")
        b.wait_for("!turtlegasViewer.state.paused && turtlegasViewer.state.replay.reverse", 10, "reverse plays")
        b.wait_for("turtlegasViewer.state.t < %r" % (want - 1.0), 30, "the clock goes back from %r" % want)
        check("REVERSE" in page.clock()["status"], "the status line says REVERSE: %r" % page.clock()["status"])
        b.eval("document.getElementById('pause').click()")
        b.wait_for("turtlegasViewer.state.paused", 10, "pause reaches the page")
        page.settle()
        st = check_turtles_drawn(page, server, "after reverse", shot_dir)
        check(st["t"] < want - 1.0, "the server's world went back: %r" % st["t"])
        b.screenshot(os.path.join(shot_dir, "turtlegas_replay_reversed.png"))
        print("ok   replay viewer: REPLAY mark, whole-room panel, panels %.0f %% of the page, seek to %.2f s by the "
              "timeline, reverse to %.2f s; screenshots in %s" % (100 * area, want, st["t"], shot_dir))


if __name__ == "__main__":
    test()
