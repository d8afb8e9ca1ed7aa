#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A client never ends a world, nor waits on itself (issue 32 section 1), with the shipped Python
client over TCP lines and over the WebSocket:
- in lockstep, add_wall, spawn, teleport and remove sent between a claimed turtle's commands are
  answered at the boundary the world waits at (they used to wait for the next boundary, which
  waited for that turtle's command: a deadlock until --lockstep-timeout released the claims);
  the input log marks them and replays headless to the same event log;
- one connection that claims two turtles and drives one of them: the lockstep timeout releases
  its claims, and the command in flight is answered with the error (it used to wait for ever)."""

import os
import tempfile
import threading
import time

from harness import Server, check, main, run, world
from turtlegas_client import Closed, ServerError, World

TRANSPORTS = (("lines", lambda s: World.connect("127.0.0.1", s.line_port)),
              ("websocket", lambda s: World.connect_ws("127.0.0.1", s.http_port)))
UNTIL = 6


def timed(what, f):
    t0 = time.monotonic()
    r = f()
    took = time.monotonic() - t0
    check(took < 3.0, "%s answered while the world waits for the turtle's command (%.2f s)" % (what, took))
    return r


def changes_between_commands(name, connect):
    with tempfile.TemporaryDirectory() as d:
        served, replay, inputs = (os.path.join(d, n) for n in ("served.jsonl", "replay.jsonl", "inputs.jsonl"))
        with Server(world("remote_followers.json"), "--speed", "max", "--paused", "--until", UNTIL, "--lockstep-timeout", 8,
                    "--events", served, "--inputs-out", inputs) as s:
            w = connect(s)
            t = w.claim("righty")
            w.resume()
            t.forward(20)
            # The obvious way: the world now waits for righty's next command.
            r = timed("add_wall", lambda: w.add_wall("fence", (20, 380), (120, 380)))
            check(r["type"] == "ok", "%s: the wall: %r" % (name, r))
            r = timed("spawn", lambda: w.spawn(ball={"id": "b-new", "pos": [100, 300], "vel": [20, 0], "radius": 4}))
            check(r["type"] == "ok" and r["kind"] == "ball", "%s: the ball: %r" % (name, r))
            r = timed("teleport", lambda: w.teleport("b-new", (120, 300), vel=(0, -30)))
            check(r["type"] == "ok", "%s: teleported: %r" % (name, r))
            r = timed("spawn", lambda: w.spawn(turtle={"id": "t-new", "pos": [440, 40], "heading": 270}))
            check(r["type"] == "ok" and r["kind"] == "turtle", "%s: a turtle: %r" % (name, r))
            r = timed("remove", lambda: w.remove("t-new"))
            check(r["type"] == "ok", "%s: removed: %r" % (name, r))
            res = t.right(90)  # still claimed: no timeout released it
            check(res.reply["type"] == "result", "%s: righty turns: %r" % (name, res.reply))
            try:
                for _ in range(200):
                    res = t.forward(30)
                    if res.touched:
                        t.left(90)
            except Closed:
                pass
            check(s.wait(30) == 0, "%s: serve exits at --until" % name)
        text = open(inputs).read()
        check(text.count('"waiting": "righty"') >= 5, "%s: the input log marks the changes made while waiting:\n%s" % (name, text[:800]))
        log = open(served, "rb").read()
        check(b'"wall-added"' in log and b'"spawn"' in log and b'"remove"' in log, "%s: the event log has the changes" % name)
        run(["run", world("remote_followers.json"), "--until", UNTIL, "--inputs", inputs, "--events", replay])
        check(open(replay, "rb").read() == log, "%s: the input log replays headless to the same event log" % name)


def timeout_answers_the_command_in_flight(name, connect):
    with Server(world("remote_followers.json"), "--speed", "max", "--paused", "--lockstep-timeout", 1) as s:
        w = connect(s)
        a = w.claim("righty")
        w.claim("lefty")  # claimed and never driven: the world waits for it at the next boundary
        w.resume()
        got = {}

        def drive():
            try:
                got["r"] = a.forward(1000)
            except ServerError as e:
                got["e"] = e.reply

        th = threading.Thread(target=drive, daemon=True)
        th.start()
        th.join(timeout=20)
        check(not th.is_alive(), "%s: the command in flight is answered after the timeout" % name)
        e = got.get("e")
        check(e and e["code"] == "lockstep_timeout" and "lefty" in e["message"], "%s: with the timeout's error: %r" % (name, got))
        v = connect(s)
        check(v.status["ended"] is None, "%s: the world goes on: %r" % (name, v.status))
        v.claim("lefty")  # released
        check(s.stop() == 0, "%s: stops cleanly" % name)


def test_changes_between_commands():
    for name, connect in TRANSPORTS:
        changes_between_commands(name, connect)


def test_timeout_answers_the_command_in_flight():
    for name, connect in TRANSPORTS:
        timeout_answers_the_command_in_flight(name, connect)


if __name__ == "__main__":
    main([test_changes_between_commands, test_timeout_answers_the_command_in_flight])
