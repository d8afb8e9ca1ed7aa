# SPDX-License-Identifier: MIT
"""The C++ controllers' twins, written as Python programs (docs/python.md, "Python controllers").

Each reads like its C++ original in controllers/*.cpp and, given the same world, produces the same
event log byte for byte (tests/python/controllers_test.py compares them with `turtlegas run
--events`). Parameters take the C++ declarations' defaults.

    world = turtlegas.World.load("worlds/tag.json", programs={"t1": turtlegas.controllers.tag_chaser})
"""

import math

__all__ = ["wall_follower", "braitenberg", "tag_chaser", "tag_evader", "tag_random", "by_name"]


def wall_follower(t, p):
    """Keep a wall on one side (params.hand "right" (default) or "left"); controllers/wall_follower.cpp."""
    right_hand = p.get("hand", "right") != "left"
    hop = p.get("hop", 20.0)
    probe = p.get("probe", 12.0)
    back_off = p.get("back_off", 3.0)

    def towards_wall(deg):
        return t.right(deg) if right_hand else t.left(deg)

    def away_from_wall(deg):
        return t.left(deg) if right_hand else t.right(deg)

    # Find a wall first: straight ahead until something is touched, then put it on our hand's side.
    while not (yield t.forward(1000)).touched:
        yield t.right(90 * t.uniform())
    yield t.back(back_off)
    yield away_from_wall(90)
    while True:
        if (yield t.forward(hop)).touched:
            # Inside corner (or an obstacle): turn away from the wall.
            yield t.back(back_off)
            yield away_from_wall(90)
            continue
        # Probe sideways for the wall.
        yield towards_wall(90)
        if (yield t.forward(probe)).touched:
            yield t.back(back_off)
            yield away_from_wall(90)
        # No touch: the wall turned away (an outside corner); keep the new heading and go on.


def braitenberg(t, p):
    """Wander on an infrared ring without touching (Braitenberg's explorer); controllers/braitenberg.cpp."""
    sensor = p.get("sensor", "ir")
    clearance = p.get("clearance", 0.0)
    gain = p.get("gain", 60.0)
    max_turn = p.get("turn", 30.0)
    # One stroke a control step at most: the ring is read again before the next.
    stroke = min(p.get("step", 1e9), t.speed * t.dt)
    ring = yield t.scan(sensor)
    half_gap = 180.0 / float(len(ring))
    needed = (t.radius + stroke) / math.cos(half_gap * math.pi / 180.0)
    threshold = max(clearance, needed * (1.0 + 1e-9))
    while True:
        front = left = right = math.inf
        for r in ring:
            b = math.remainder(r.bearing, 360.0)  # (-180, 180]: negative on the left
            if math.fabs(b) <= 90.0 + half_gap:
                front = min(front, r.distance)
            if 0.0 < b < 180.0:
                right = min(right, r.distance)
            if -180.0 < b < 0.0:
                left = min(left, r.distance)
        if front >= threshold:
            # Steer away from the nearer side, by how much nearer it is (in proximity, 1/distance).
            pull = gain * t.radius * (1.0 / left - 1.0 / right)
            turn = min(max(pull, -max_turn), max_turn) + (2.0 * t.uniform() - 1.0) * 0.1 * max_turn
            if math.fabs(turn) > 1e-9:
                yield t.right(turn)
            ring = yield t.scan(sensor)  # the turn changed what lies ahead
            clear = all(not (math.fabs(math.remainder(r.bearing, 360.0)) <= 90.0 + half_gap and r.distance < threshold)
                        for r in ring)
            if clear:
                yield t.forward(stroke)
        elif right > left:
            yield t.right(max_turn)
        else:
            yield t.left(max_turn)
        ring = yield t.scan(sensor)


# The tag players' shared moves (controllers/tag_common.hpp).
def _shortest_turn(degrees):
    """An angle in degrees folded into [-180, 180): the shortest turn to it, for right()."""
    a = math.fmod(degrees + 180.0, 360.0)
    if a < 0.0:
        a += 360.0
    return a - 180.0


def _turn_away(t, bearing, spread):
    yield t.right(_shortest_turn(bearing + 180.0 + (2.0 * t.uniform() - 1.0) * spread))


def _after_sweep(t, moved, back_off):
    if moved.touched:
        if moved.touch.kind != "turtle":
            yield t.back(back_off)
        yield from _turn_away(t, moved.touch.bearing, 70.0)
    else:
        yield t.right((2.0 * t.uniform() - 1.0) * 90.0)


def _flee_touch(t, still, flee):
    if still.touched and still.touch.kind == "turtle" and not t.it:
        yield from _turn_away(t, still.touch.bearing, 30.0)
        yield t.forward(flee)


def tag_chaser(t, p):
    """Tag: when it, sweep and lunge at the last tagger; else keep still; controllers/tag_chaser.cpp."""
    leg = p.get("leg", 400.0)
    lunge = p.get("lunge", 80.0)
    no_tag_back = p.get("no_tag_back", 2.0)
    back_off = p.get("back_off", 5.0)
    flee = p.get("flee", 60.0)
    # The last turtle that touched us, and where: a tag's message follows its touch at the same
    # control step, so the tagger's bearing is known when the message says we are "it".
    state = {"last_turtle_touch": None, "pending": None}

    def on_touch(touch):
        if touch.kind == "turtle":
            state["last_turtle_touch"] = touch

    def on_message(m):
        if m.kind != "tag" or not m.data.get("it", False):
            return
        by = m.data.get("by", "")
        last = state["last_turtle_touch"]
        if last is not None and last.what == by:
            state["pending"] = (last.bearing, m.t + no_tag_back)

    t.on_touch(on_touch)
    t.on_message(on_message)
    while True:
        if t.it:
            if state["pending"] is not None:
                bearing, after = state["pending"]
                state["pending"] = None
                yield t.right(_shortest_turn(bearing))
                if t.time < after:
                    yield t.wait(after - t.time + 0.05)
                if not t.it:
                    continue
                yield t.forward(lunge)
                continue
            moved = yield t.forward(leg * (0.5 + t.uniform()))
            yield from _after_sweep(t, moved, back_off)
        else:
            state["pending"] = None
            still = yield t.wait(1.0)
            yield from _flee_touch(t, still, flee)


def tag_evader(t, p):
    """Tag: when not it, follow walls and flee touches; controllers/tag_evader.cpp."""
    reach = p.get("reach", 40.0)
    curve = p.get("curve", 20.0)
    back_off = p.get("back_off", 5.0)
    flee = p.get("flee", 120.0)
    leg = p.get("leg", 500.0)
    while True:
        if t.it:
            moved = yield t.forward(leg)
            if moved.touched:
                yield t.back(back_off)
                yield from _turn_away(t, moved.touch.bearing, 60.0)
            continue
        moved = yield t.forward(reach)
        if not moved.touched:
            yield t.right(curve)  # nothing within reach: lean back towards the wall
        elif moved.touch.kind == "turtle":
            if t.it:
                continue  # that was a tag: play "it" from the next turn of the loop
            yield from _turn_away(t, moved.touch.bearing, 20.0)
            yield t.forward(flee)
        else:
            yield t.back(back_off)
            yield t.left(90 if moved.touch.front else 30)


def tag_random(t, p):
    """Tag: random legs whatever the role, a baseline; controllers/tag_random.cpp."""
    leg = p.get("leg", 300.0)
    back_off = p.get("back_off", 5.0)
    while True:
        if (yield t.forward(leg * t.uniform())).touched:
            yield t.back(back_off)
        yield t.right((2.0 * t.uniform() - 1.0) * 180.0)


by_name = {"wall_follower": wall_follower, "braitenberg": braitenberg, "tag_chaser": tag_chaser,
           "tag_evader": tag_evader, "tag_random": tag_random}
