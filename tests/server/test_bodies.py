#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""spawn, teleport and remove over the protocol (docs/protocol.md, "World changes"): applied at a
boundary, refused with the reason (what the body would overlap, by how much), bad entries and
ids answered at once, a turtle claimed by another connection left alone; a spawned remote turtle
is claimed and driven into a wall (touch and contact time); the served event log replays headless
from the input log to the same bytes, in both modes."""

import json
import os
import tempfile
import threading

from harness import Server, check, main, run, world
from turtlegas_client import World

UNTIL = 12
_next = [1000]


def change(w, message, steps=1):
    """Sends `message` with an id of its own, then `step` (so that the next boundary comes), and
    returns the reply to the message (an ok, or an error, as sent)."""
    _next[0] += 1
    m = dict(message)
    m["id"] = _next[0]
    w.send(m)
    if steps:
        w.step(steps)
    while True:
        n = w.notices.get(timeout=30)
        if n.get("id") == m["id"]:
            return n


def settle(w, step):
    """Until the world has paused after boundary `step` (its status says so)."""
    while not (w.status and w.status.get("paused") and w.status["step"] >= step):
        w.notices.get(timeout=30)


def code(reply):
    return reply.get("code") if reply["type"] == "error" else "ok"


def session(a, b, mode):
    # A ball where nothing is.
    r = change(a, {"type": "spawn", "ball": {"id": "b-new", "pos": [200, 200], "vel": [0, -30], "radius": 4}})
    check(code(r) == "ok" and r["kind"] == "ball" and r["index"] == 2 and r["body"] == "b-new", "spawned: %r" % r)
    # On b2 (at rest at (300, 250), radius 5): refused, naming b2 and the depth 5 + 4 - 2 = 7.
    r = change(a, {"type": "spawn", "ball": {"id": "b-on", "pos": [302, 250], "radius": 4}})
    check(code(r) == "refused" and "'b2' by 7" in r["message"], "an overlapping spawn is refused with the reason: %r" % r)
    r = change(a, {"type": "spawn", "ball": {"id": "b-out", "pos": [450, 150], "radius": 4}})
    check(code(r) == "refused" and "sticks out" in r["message"], "outside the arena: %r" % r)
    r = change(a, {"type": "spawn", "turtle": {"id": "t-wall", "pos": [200, 5]}})
    check(code(r) == "refused" and "'arena-bottom'" in r["message"], "into a wall: %r" % r)
    # Answered at once (no boundary needed): bad entries and ids.
    for msg, want, field in (({"type": "spawn", "ball": {"id": "x", "pos": [50, 50], "radius": -1}}, "bad_value", "/ball/radius"),
                             ({"type": "spawn", "ball": {"id": "x", "pos": [50, 50], "radius": 2, "category": "ghost"}}, "bad_value", "/ball/category"),
                             ({"type": "spawn", "ball": {"id": "x", "pos": [50, 50], "radius": 2, "colour": 1}}, "bad_value", "/ball/colour"),
                             ({"type": "spawn", "turtle": {"id": "x", "pos": [50, 50], "controller": "nobody"}}, "bad_value", "/turtle/controller"),
                             ({"type": "spawn"}, "missing_field", "/ball"),
                             ({"type": "remove", "body": "zzz"}, "unknown_body", "/body"),
                             ({"type": "remove"}, "missing_field", "/body"),
                             ({"type": "teleport", "body": "b1", "pos": [1, "a"]}, "wrong_type", "/pos"),
                             ({"type": "teleport", "body": "b1", "pos": [100, 100], "heading": 3}, "bad_value", "/heading")):
        r = change(a, msg, steps=0)
        check(code(r) == want and r.get("field") == field, "%r: %s at %s (got %r)" % (msg, want, field, r))
    r = change(a, {"type": "spawn", "ball": {"id": "b1", "pos": [50, 250], "radius": 2}})
    check(code(r) == "refused" and "taken" in r["message"], "a taken id: %r" % r)
    # A remote turtle (no controller given), claimed by the other connection.
    r = change(a, {"type": "spawn", "turtle": {"id": "t-new", "pos": [300, 100], "heading": 0, "speed": 30}})
    check(code(r) == "ok" and r["kind"] == "turtle" and r["index"] == 2, "spawned a turtle: %r" % r)
    # Claimed only once the step that spawned it has ended: a claim that lands during that
    # boundary makes the world wait there for t-new's command (lockstep), and the teleport below
    # would then wait for a boundary that never comes (the lockstep timeout ends the world).
    settle(a, r["status"]["step"])
    t = b.claim("t-new")
    r = change(a, {"type": "remove", "body": "t-new"}, steps=0)
    check(code(r) == "claimed", "removing another connection's turtle is refused: %r" % r)
    r = change(a, {"type": "teleport", "body": "t-new", "pos": [300, 150]}, steps=0)
    check(code(r) == "claimed", "so is moving it: %r" % r)
    # Its owner moves it to face the right wall: 90 units to go at 30/s. The world waits for
    # t-new's command at that boundary (lockstep), so the drive starts there.
    got = {}
    th = threading.Thread(target=lambda: got.setdefault("r", change(b, {"type": "teleport", "body": "t-new", "pos": [300, 150], "heading": 90})))
    th.start()
    th.join(timeout=30)
    r = got["r"]
    check(code(r) == "ok", "teleported: %r" % r)
    t0 = r["status"]["t"]
    a.resume()
    res = t.forward(1000)
    check(res.touched and res.touch.what == "arena-right" and res.touch.sensors == ["front"], "into the wall: %r" % res.reply)
    check(abs(res.done - 90) < 1e-9, "done 90: %r" % res.done)
    check(abs(res.touch.t - (t0 + 3.0)) < 1e-9, "contact at t0 + 90 / 30 = %r (got %r)" % (t0 + 3.0, res.touch.t))
    a.pause()  # (answered at once while the world waits for t-new's next command)
    b.release("t-new")
    r = change(a, {"type": "teleport", "body": "b-new", "pos": [100, 250], "vel": [10, 10]})
    check(code(r) == "ok", "a ball teleported: %r" % r)
    r = change(a, {"type": "teleport", "body": "b-new", "pos": [302, 250]})
    check(code(r) == "refused" and "'b2'" in r["message"], "not onto b2: %r" % r)
    r = change(a, {"type": "remove", "body": "t2"})
    check(code(r) == "ok", "a turtle with a program removed (its coroutine ends): %r" % r)
    r = change(a, {"type": "remove", "body": "b-new"})
    check(code(r) == "ok", "a ball removed: %r" % r)
    r = change(a, {"type": "remove", "body": "b-new"}, steps=0)
    check(code(r) == "unknown_body", "it is gone: %r" % r)
    r = change(a, {"type": "spawn", "ball": {"id": "b-new", "pos": [100, 250], "radius": 2}})
    check(code(r) == "refused" and "taken" in r["message"], "its id is not reused: %r" % r)
    r = change(a, {"type": "spawn", "ball": {"id": "b-3", "pos": [100, 250], "radius": 2}})
    check(code(r) == "ok" and r["index"] == 3, "the next spawn takes the next index: %r" % r)
    snap = a.snapshot()
    check(snap["balls"]["ids"] == ["b1", "b2", "b-new", "b-3"] and 2 in snap["balls"]["dead"], "the snapshot: %r" % snap["balls"])
    check([x["id"] for x in snap["turtles"]] == ["t1", "t2", "t-new"], "turtles: %r" % snap["turtles"])


def served_and_replayed(mode):
    with tempfile.TemporaryDirectory() as d:
        served, replay, inputs = (os.path.join(d, n) for n in ("served.jsonl", "replay.jsonl", "inputs.jsonl"))
        with Server(world("bodies_room.json"), "--paused", "--speed", "max", "--mode", mode, "--until", UNTIL,
                    "--events", served, "--inputs-out", inputs) as s:
            a = World.connect("127.0.0.1", s.line_port)
            b = World.connect_ws("127.0.0.1", s.http_port)
            session(a, b, mode)
            a.resume()
            check(s.wait(60) == 0, "serve exits 0 at --until: " + s.err())
        text = open(inputs).read()
        for key in ('"spawn": {"ball"', '"spawn": {"turtle"', '"teleport"', '"remove": "t2"'):
            check(key in text, "the input log has %s" % key)
        log = open(served, "rb").read()
        kinds = [json.loads(line)["kind"] for line in log.decode().splitlines()]
        check(kinds.count("spawn") == 3 and kinds.count("remove") == 2 and kinds.count("teleport") == 2,
              "the event log has the changes: %r" % sorted(set(kinds)))
        run(["run", world("bodies_room.json"), "--until", UNTIL, "--mode", mode, "--inputs", inputs, "--events", replay])
        check(open(replay, "rb").read() == log, "%s: the input log replays headless to the same event log" % mode)


def mirror_and_removed(mode):
    """A spawned `mirror` turtle runs its program reflected; a removed turtle cannot be claimed
    (or taken over); the run replays headless from its input log."""
    with tempfile.TemporaryDirectory() as d:
        served, replay, inputs = (os.path.join(d, n) for n in ("served.jsonl", "replay.jsonl", "inputs.jsonl"))
        with Server(world("bodies_room.json"), "--paused", "--speed", "max", "--mode", mode, "--until", UNTIL,
                    "--events", served, "--inputs-out", inputs) as s:
            a = World.connect("127.0.0.1", s.line_port)
            # The mirror image (about x = 200) of "turn right 90, forward 50": left 90, then 50 west.
            mirror = {"of": "script", "params": {"commands": [["right", 90], ["forward", 50]]}, "through": [200, 0]}
            r = change(a, {"type": "spawn", "turtle": {"id": "t-m", "pos": [300, 150], "heading": 0, "speed": 50,
                                                       "turn_rate": 180, "controller": "mirror", "params": mirror}})
            check(code(r) == "ok" and r["kind"] == "turtle" and r["index"] == 2, "a mirror turtle spawned: %r" % r)
            bad = dict(mirror, of="nobody")
            r = change(a, {"type": "spawn", "turtle": {"id": "t-bad", "pos": [300, 80], "controller": "mirror", "params": bad}})
            check(code(r) in ("bad_value", "refused") and "nobody" in r["message"], "a mirror of nothing is refused: %r" % r)
            r = change(a, {"type": "remove", "body": "t1"})
            check(code(r) == "ok", "the remote turtle t1 removed: %r" % r)
            r = change(a, {"type": "remove", "body": "t2"})
            check(code(r) == "ok", "t2 (a program) removed: %r" % r)
            for msg in ({"type": "claim", "turtle": "t1"}, {"type": "claim", "turtle": "t2", "takeover": True}):
                r = change(a, msg, steps=0)
                check(code(r) == "unknown_turtle" and "removed" in r["message"] and r.get("field") == "/turtle",
                      "a removed turtle cannot be claimed: %r -> %r" % (msg, r))
            r = change(a, {"type": "forward", "turtle": "t1", "amount": 10}, steps=0)
            check(code(r) == "unknown_turtle", "nor driven: %r" % r)
            a.step(60)  # 3 s: the turn (0.5 s) and the 50 units (1 s) are done
            while a.status is None or not a.status.get("paused") or a.status["t"] < 3:
                a.notices.get(timeout=30)
            snap = a.snapshot()
            tm = [x for x in snap["turtles"] if x["id"] == "t-m"][0]
            check(abs(tm["pos"][0] - 250) < 1e-9 and abs(tm["pos"][1] - 150) < 1e-9 and abs(tm["heading"] - 270) < 1e-9,
                  "the mirror turned left and drove west to (250, 150): %r" % tm)
            gone = {x["id"]: x["gone"] for x in snap["turtles"]}
            check(gone == {"t1": True, "t2": True, "t-m": False}, "the removed turtles are gone: %r" % gone)
            # A pen-down turtle teleported: its trail breaks (null) rather than joining the two places.
            pen = {"of": "script", "params": {"commands": [["forward", 20], ["wait", 100]]}}
            r = change(a, {"type": "spawn", "turtle": {"id": "t-pen", "pos": [100, 220], "heading": 90, "speed": 40,
                                                       "pen": "down", "controller": "mirror", "params": pen}})
            check(code(r) == "ok", "a pen-down turtle spawned: %r" % r)
            r = change(a, {"type": "teleport", "body": "t-pen", "pos": [100, 100]}, steps=3)
            check(code(r) == "ok", "teleported: %r" % r)
            trail = [x for x in a.snapshot()["turtles"] if x["id"] == "t-pen"][0]["trail"]
            check(None in trail, "the trail has a break: %r" % trail)
            k = trail.index(None)
            check(trail[k - 1][0] > 100 and trail[k - 1][1] == 220 and trail[k + 1] == [100, 100] and None not in trail[k + 1:],
                  "the stroke ends where it was, the next starts at (100, 100): %r" % trail)
            a.resume()
            check(s.wait(60) == 0, "serve exits 0 at --until: " + s.err())
        run(["run", world("bodies_room.json"), "--until", UNTIL, "--mode", mode, "--inputs", inputs, "--events", replay])
        check(open(replay, "rb").read() == open(served, "rb").read(), "%s: the mirror spawn replays headless" % mode)


def test_mirror_and_removed():
    mirror_and_removed("exact")


def test_bodies_exact():
    served_and_replayed("exact")


def test_bodies_step():
    served_and_replayed("step")


if __name__ == "__main__":
    main([test_bodies_exact, test_bodies_step, test_mirror_and_removed])
