#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A remote client drives a turtle into a wall and gets the touch interrupt with the right
sensors, bearing, what and contact time (issue 12, section 6), over TCP lines and WebSocket."""

from harness import Server, check, main, world
from turtlegas_client import World


def drive(w):
    r_t = w.welcome["world"]["turtles"][0]["radius"]
    t = w.claim("t1")
    w.resume()
    # East from x = 100 into the wall at x = 300: the disc touches when its centre is r short of it.
    r = t.forward(1000)
    check(r.touched, "forward into the wall is cut short: %r" % r.reply)
    d = 200 - r_t
    check(abs(r.done - d) < 1e-9, "done = 200 - radius = %r (got %r)" % (d, r.done))
    check(abs(r.touch.t - d / 50.0) < 1e-9, "contact time = d / speed = %r (got %r)" % (d / 50.0, r.touch.t))
    check(r.touch.sensors == ["front"] and r.touch.bits == 1, "the front sensor fired: %r" % r.touch)
    check(abs(r.touch.bearing) < 1e-9 or abs(r.touch.bearing - 360) < 1e-9, "bearing 0: %r" % r.touch.bearing)
    check(r.touch.what == "target" and r.touch.kind == "wall", "touched the wall 'target': %r" % r.touch)
    check(len(t.touches) == 1 and t.touches[0].t == r.touch.t, "one touch interrupt, before the result: %r" % t.touches)
    check(r.t >= r.touch.t and r.t - r.touch.t < w.welcome["world"]["dt"] + 1e-12, "the result comes at the next boundary")
    # Right 90 (now facing south), then down into the arena's bottom wall: contact at y = r.
    turned = t.right(90)
    check(abs(turned.done - 90) < 1e-9 and abs(turned.state["heading"] - 180) < 1e-9, "turned to 180: %r" % turned.reply)
    r2 = t.forward(1000)
    d2 = 150 - r_t
    check(r2.touched and r2.touch.what == "arena-bottom", "touched the arena's bottom: %r" % r2.reply)
    check(abs(r2.touch.t - (turned.t + d2 / 50.0)) < 1e-9,
          "contact time = start + d / speed = %r (got %r)" % (turned.t + d2 / 50.0, r2.touch.t))
    check(r2.touch.front, "front again")
    # Touches while standing still are delivered before the next result; back off the wall.
    b = t.back(10)
    check(not b.touched and abs(b.done - 10) < 1e-9, "back 10: %r" % b.reply)
    check(abs(b.state["odometer"] - (d + d2 + 10)) < 1e-9, "odometer adds up: %r" % b.state)


def test_touch_over_lines():
    with Server(world("wall_touch.json"), "--paused", "--speed", "max") as s:
        drive(World.connect("127.0.0.1", s.line_port))
        check(s.stop() == 0, "stops on SIGINT")


def test_touch_over_websocket():
    with Server(world("wall_touch.json"), "--paused", "--speed", "max") as s:
        drive(World.connect_ws("127.0.0.1", s.http_port))
        check(s.stop() == 0, "stops on SIGINT")


if __name__ == "__main__":
    main([test_touch_over_lines, test_touch_over_websocket])
