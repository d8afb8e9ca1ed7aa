#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The viewer in a real browser (issue 13, section 5): headless Chromium loads the page of a real
`turtlegas serve` on loopback, waits for frames, and the pixels of the canvases are checked against
the world's geometry, computed here independently of the viewer (turtle/view.hpp's formulas):

- the fixed view: the walls and the turtles are where the world puts them, and nothing is drawn
  where the world has nothing;
- the follow view: after the turtle has moved, it is at the view's centre;
- the turned view: the turtle is at its offset with its heading up, and a wall turned with it;
- pause: pressing the page's pause button stops the sim clock (the server's and the page's).

Skips (exit 77, with the reason) only when no Chromium is installed (scripts/install-deps.sh
installs Debian's). A screenshot of the page is written to $TURTLEGAS_SCREENSHOT_DIR (default: the
system's temporary directory) for a person to look at."""

import json
import math
import os
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from harness import Server, check, world  # noqa: E402
import cdp  # noqa: E402

ROOM = world("browser_room.json")
BACKGROUND = (0xf8, 0xf8, 0xf4)
# Each turtle in its own colour, as `render` draws it (formats/look.hpp, Tableau 10 by index); t1,
# the remote one, has a purple outline, its body in its colour.
TURTLE_COLOUR = {"t1": (0x4e, 0x79, 0xa7), "t2": (0xf2, 0x8e, 0x2b)}
WALL = (0x22, 0x22, 0x22)


def view_transform(view, pose):
    """(centre, right, up) of a view, pose = (x, y, heading degrees) of the followed turtle."""
    if not view.get("follow"):
        return view["center"], (1.0, 0.0), (0.0, 1.0)
    x, y, h = pose
    off = view.get("offset", [0, 0])
    if view.get("rotate"):
        s, c = math.sin(math.radians(h)), math.cos(math.radians(h))
        up, right = (s, c), (c, -s)
        return (x + off[0] * right[0] + off[1] * up[0], y + off[0] * right[1] + off[1] * up[1]), right, up
    return (x + off[0], y + off[1]), (1.0, 0.0), (0.0, 1.0)


def to_pixel(view, pose, p, width, height):
    (cx, cy), right, up = view_transform(view, pose)
    dx, dy = p[0] - cx, p[1] - cy
    vx, vy = dx * right[0] + dy * right[1], dx * up[0] + dy * up[1]
    return (vx / view["size"][0] + 0.5) * width, (0.5 - vy / view["size"][1]) * height


def near(rgb, want, tol=40):
    return all(abs(a - b) <= tol for a, b in zip(rgb, want))


class Page:
    def __init__(self, browser):
        self.b = browser

    def canvas(self, view_id):
        """(width, height) of a view's canvas."""
        return tuple(self.b.eval("(() => { const c = document.querySelector('canvas[data-view=%s]');"
                                 " return c ? [c.width, c.height] : null; })()" % json.dumps(view_id)))

    def pixels(self, view_id, points):
        """The RGB of each canvas pixel (x, y) of a view, read from the canvas itself."""
        js = ("(() => { const c = document.querySelector('canvas[data-view=%s]'); const g = c.getContext('2d');"
              " return %s.map(([x, y]) => Array.from(g.getImageData(Math.floor(x), Math.floor(y), 1, 1).data.slice(0, 3))); })()"
              % (json.dumps(view_id), json.dumps([[x, y] for x, y in points])))
        return [tuple(p) for p in self.b.eval(js)]

    def state(self):
        return self.b.eval("(() => { const s = turtlegasViewer.state; return {t: s.t, paused: s.paused, frames: s.framesIn,"
                           " turtles: s.turtles.map((t) => [t.id, t.x, t.y, t.heading, t.radius]),"
                           " views: s.views, status: document.getElementById('status').textContent}; })()")

    def frames_after(self, n, timeout=20):
        self.b.wait_for("turtlegasViewer.state.framesIn > %d" % n, timeout, "frames keep coming")


def api_state(server):
    with urllib.request.urlopen("http://127.0.0.1:%d/api/state" % server.http_port, timeout=10) as r:
        return json.loads(r.read())


def check_room(page, views, st, shot_dir):
    """The fixed view: walls and turtles at their places, background elsewhere."""
    room = views["room"]
    w, h = page.canvas("room")
    check(abs(w / h - 400 / 300) < 0.02, "the room's canvas has the view's aspect: %sx%s" % (w, h))
    pose = None
    probes, want = [], []
    # Along each wall: dark; 10 units to either side: background.
    for (a, b) in (((40, 60), (160, 60)), ((340, 180), (340, 280)), ((170, 100), (170, 200))):
        for s in (0.25, 0.5, 0.75):
            p = (a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]))
            probes.append(to_pixel(room, pose, p, w, h))
            want.append(("wall", p))
            n = (0, 10) if a[1] == b[1] else (10, 0)
            for sign in (1, -1):
                q = (p[0] + sign * n[0], p[1] + sign * n[1])
                probes.append(to_pixel(room, pose, q, w, h))
                want.append(("background", q))
    # Each turtle: its body half a radius behind its heading (the heading line is white).
    for tid, x, y, hd, r in st["turtles"]:
        q = (x - 0.5 * r * math.sin(math.radians(hd)), y - 0.5 * r * math.cos(math.radians(hd)))
        probes.append(to_pixel(room, pose, q, w, h))
        want.append(("turtle " + tid, q))
    # The arena's walls: the boundary at x = 0 and y = 300, halfway along.
    for p in ((0, 150), (200, 300)):
        probes.append(to_pixel(room, pose, p, w, h))
        want.append(("arena wall", p))
    got = page.pixels("room", probes)
    for (what, p), px, rgb in zip(want, probes, got):
        colour = BACKGROUND if what == "background" else \
            TURTLE_COLOUR[what.split()[1]] if what.startswith("turtle") else WALL
        check(near(rgb, colour), "room view: %s at world %s (pixel %.0f,%.0f) is %s, expected about %s; screenshot in %s"
              % (what, p, px[0], px[1], rgb, colour, shot_dir))


def turtle_pose(st, tid):
    for t in st["turtles"]:
        if t[0] == tid:
            return t[1], t[2], t[3], t[4]
    raise AssertionError("no turtle " + tid)


def check_follow(page, views, st, shot_dir):
    x, y, hd, r = turtle_pose(st, "t2")
    for vid in ("chase", "turned"):
        v = views[vid]
        w, h = page.canvas(vid)
        check(abs(w / h - v["size"][0] / v["size"][1]) < 0.02, "%s: the canvas has the view's aspect" % vid)
        behind = (x - 0.5 * r * math.sin(math.radians(hd)), y - 0.5 * r * math.cos(math.radians(hd)))
        ahead = (x + 0.6 * r * math.sin(math.radians(hd)), y + 0.6 * r * math.cos(math.radians(hd)))
        pb, pa = to_pixel(v, (x, y, hd), behind, w, h), to_pixel(v, (x, y, hd), ahead, w, h)
        if vid == "chase":  # centred on the turtle
            centre = to_pixel(v, (x, y, hd), (x, y), w, h)
            check(abs(centre[0] - w / 2) < 1e-6 and abs(centre[1] - h / 2) < 1e-6, "the geometry centres the turtle")
        else:  # 20 units below the centre, heading straight up
            check(abs(pb[0] - w / 2) < 1.0 and pb[1] > h / 2 and pa[1] < pb[1], "the turned view's geometry: %s %s" % (pb, pa))
        got = page.pixels(vid, [pb, pa, (2, 2)])
        check(near(got[0], TURTLE_COLOUR["t2"]), "%s: the followed turtle at pixel %.0f,%.0f (got %s); screenshot in %s" % (vid, pb[0], pb[1], got[0], shot_dir))
        check(near(got[1], (255, 255, 255), 60), "%s: its heading line ahead of it at %.0f,%.0f (got %s)" % (vid, pa[0], pa[1], got[1]))
        check(near(got[2], BACKGROUND) or near(got[2], WALL), "%s: the corner is drawn (got %s)" % (vid, got[2]))
    # The turned view shows a wall turned with the turtle: the arena's nearest walls, probed at the
    # points of the view where the geometry puts them (if any is in sight).
    v = views["turned"]
    w, h = page.canvas("turned")
    hits = []
    for (a, b) in (((0, 0), (400, 0)), ((400, 0), (400, 300)), ((400, 300), (0, 300)), ((0, 300), (0, 0)),
                   ((40, 60), (160, 60)), ((340, 180), (340, 280)), ((170, 100), (170, 200))):
        for k in range(1, 40):
            s = k / 40
            p = (a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]))
            px = to_pixel(v, (x, y, hd), p, w, h)
            if 6 < px[0] < w - 6 and 6 < px[1] < h - 6 and math.hypot(p[0] - x, p[1] - y) > 2 * r:
                hits.append(px)
    if hits:
        got = page.pixels("turned", hits[:12])
        dark = sum(1 for rgb in got if near(rgb, WALL, 60))
        check(dark >= len(got) * 0.8, "turned view: walls where the turned geometry puts them (%d of %d dark: %s)" % (dark, len(got), got))
    return len(hits)


def test():
    chromium = cdp.find_chromium()
    if not chromium:
        print("SKIP: no Chromium found (chromium, chromium-browser, google-chrome); scripts/install-deps.sh installs Debian's")
        sys.exit(77)
    shot_dir = os.environ.get("TURTLEGAS_SCREENSHOT_DIR", tempfile.gettempdir())
    with Server(ROOM, "--paused", "--speed", "4") as server, cdp.Browser(chromium) as b:
        b.open("http://127.0.0.1:%d/" % server.http_port, 1280, 960)
        page = Page(b)
        b.wait_for("window.turtlegasViewer && turtlegasViewer.state.framesIn > 3 && document.querySelectorAll('canvas[data-view]').length === 3",
                   30, "the viewer shows the three views of the world")
        st = page.state()
        views = {v["id"]: v for v in st["views"]}
        check(set(views) == {"room", "chase", "turned"}, "the world's views: %s" % sorted(views))
        check(st["paused"], "the world starts paused")
        time.sleep(0.3)  # a frame drawn after the state above (the world is paused: nothing moves)
        b.screenshot(os.path.join(shot_dir, "turtlegas_viewer_paused.png"))
        start = turtle_pose(page.state(), "t2")
        check_room(page, views, page.state(), shot_dir)
        seen_start = check_follow(page, views, page.state(), shot_dir)
        check(seen_start > 0, "the rail is in the turned view at the start")

        # Resume: t2 drives its square; the follow views keep it at their centre.
        b.eval("document.getElementById('resume').click()")
        b.wait_for("turtlegasViewer.state.t > 3 && !turtlegasViewer.state.paused", 30, "the sim clock runs after resume")
        b.eval("document.getElementById('pause').click()")
        b.wait_for("turtlegasViewer.state.paused", 10, "pause reaches the page")
        n = page.state()["frames"]
        page.frames_after(n + 2)
        time.sleep(0.3)
        st = page.state()
        moved = turtle_pose(st, "t2")
        check(math.hypot(moved[0] - start[0], moved[1] - start[1]) > 20 or abs(moved[2] - start[2]) > 30,
              "t2 moved: %s -> %s" % (start, moved))
        b.screenshot(os.path.join(shot_dir, "turtlegas_viewer_moved.png"))
        seen = check_follow(page, views, st, shot_dir)
        check_room(page, views, st, shot_dir)

        # Pause stops the sim clock: the server's and the page's stay where they are.
        t0, s0 = st["t"], api_state(server)["t"]
        time.sleep(1.5)
        page.frames_after(page.state()["frames"] + 3)
        st = page.state()
        check(st["t"] == t0 and api_state(server)["t"] == s0, "paused: the clock stays at %s (page %s, server %s)" % (t0, st["t"], api_state(server)["t"]))
        check("PAUSED" in st["status"] and "t=%.2f" % t0 in st["status"], "the status line says paused at t: %r" % st["status"])

        # Clicking a turtle opens a view that follows it; dragging a rectangle, a fixed view of it.
        rect = b.eval("(() => { const r = document.querySelector('canvas[data-view=\"room\"]').getBoundingClientRect();"
                      " return [r.left, r.top, r.width, r.height]; })()")
        w, h = page.canvas("room")
        x1, y1 = turtle_pose(st, "t1")[:2]

        def page_xy(p):
            px, py = to_pixel(views["room"], None, p, w, h)
            return rect[0] + px * rect[2] / w, rect[1] + py * rect[3] / h

        def mouse(kind, xy):
            b.call("Input.dispatchMouseEvent", {"type": kind, "x": xy[0], "y": xy[1], "button": "left",
                                                "buttons": 1 if kind != "mouseReleased" else 0, "clickCount": 1})

        at = page_xy((x1, y1))
        mouse("mousePressed", at)
        mouse("mouseReleased", at)
        b.wait_for("turtlegasViewer.state.views.some((v) => v.follow === 't1' && !v.rotate) && "
                   "document.querySelector('canvas[data-view=\"t1-follow\"]') !== null", 10, "a click on t1 opens a view following it")
        # The panels share the window anew with the fourth view: read the room's place again.
        time.sleep(0.3)
        rect = b.eval("(() => { const r = document.querySelector('canvas[data-view=\"room\"]').getBoundingClientRect();"
                      " return [r.left, r.top, r.width, r.height]; })()")
        w, h = page.canvas("room")
        a, z = page_xy((220, 40)), page_xy((300, 100))
        mouse("mousePressed", a)
        for k in range(1, 6):
            mouse("mouseMoved", (a[0] + k * (z[0] - a[0]) / 5, a[1] + k * (z[1] - a[1]) / 5))
        mouse("mouseReleased", z)
        box = b.wait_for("turtlegasViewer.state.views.find((v) => v.id === 'box')", 10, "a drag opens a fixed view")
        check(abs(box["center"][0] - 260) < 3 and abs(box["center"][1] - 70) < 3 and abs(box["size"][0] - 80) < 3
              and abs(box["size"][1] - 60) < 3, "the dragged view covers the rectangle: %r" % box)
        time.sleep(0.5)
        b.screenshot(os.path.join(shot_dir, "turtlegas_viewer_opened.png"))
        print("ok   browser: fixed, follow and turned views match the geometry (%d wall probes in the turned view); "
              "pause holds t=%.2f; screenshots in %s" % (seen_start + seen, t0, shot_dir))


if __name__ == "__main__":
    test()
