#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A remote client steers its turtle over the protocol (`arc`, `drive`, `wheels`, issue 34 §3):
the results' distances along the arcs, the poses and headings against closed forms, a touch on a
straight `drive` at its contact, the numbers echoed as `args`, refusals naming the field, and the
input log that records them replaying to the same end; over TCP lines."""

import json
import math
import os
import subprocess
import tempfile

from harness import BIN, Server, check, main, world
from turtlegas_client import ServerError, World


def close(a, b, tol=1e-9):
    return abs(a - b) <= tol


def drive(w):
    t = w.claim("t1")
    w.resume()
    r = t.arc(100, -90)
    check(not r.touched and close(r.done, 50 * math.pi), "a left quarter of radius 100: %r" % r.reply)
    check(r.reply["args"] == {"degrees": -90.0, "radius": 100.0}, "the numbers echoed: %r" % r.reply)
    pos = r.reply["state"]["pos"]
    check(close(pos[0], 200) and close(pos[1], 250), "it ends at (200, 250): %r" % r.reply)
    check(close(math.remainder(t.heading, 360), 0, 1e-9), "heading 0: %r" % r.reply)
    r = t.wheels(30, 10, math.pi / 2)
    check(not r.touched and close(r.done, 10 * math.pi), "wheels 30 and 10 for pi/2 s: %r" % r.reply)
    pos = r.reply["state"]["pos"]
    check(close(pos[0], 220) and close(pos[1], 270), "it ends at (220, 270): %r" % r.reply)
    check(close(t.heading, 90), "heading 90: %r" % r.reply)
    r = t.drive(50, 0, 10)
    check(r.touched and r.touch.what == "target" and close(r.done, 70), "stopped by the wall after 70: %r" % r.reply)
    check(close(t.odometer, 60 * math.pi + 70), "the odometer counts along the arcs: %r" % r.reply)
    for bad, code, field in (({"type": "arc", "radius": -1, "degrees": 90}, "bad_value", "/radius"),
                             ({"type": "wheels", "left": 1, "right": 2}, "missing_field", "/seconds"),
                             ({"type": "drive", "v": 1, "omega": "x", "seconds": 1}, "wrong_type", "/omega")):
        try:
            t._command(dict(bad))
            check(False, "refused: %r" % bad)
        except ServerError as e:
            check(e.reply["code"] == code and e.reply.get("field") == field, "%r: %s at %s (got %r)" % (bad, code, field, e.reply))
    return t


def test_arcs_over_lines():
    with tempfile.TemporaryDirectory() as d:
        inputs = os.path.join(d, "inputs.jsonl")
        state = os.path.join(d, "state.json")
        with Server(world("arc_room.json"), "--paused", "--speed", "max", "--inputs-out", inputs) as s:
            w = World.connect("127.0.0.1", s.line_port)
            drive(w)
            check(s.stop() == 0, "stops on SIGINT")
        lines = [json.loads(line) for line in open(inputs)][1:]
        arcs = [x for x in lines if x.get("command") in ("arc", "drive", "wheels")]
        check([x["command"] for x in arcs] == ["arc", "wheels", "drive"], "the input log records them: %r" % lines)
        check(arcs[0]["radius"] == 100 and arcs[0]["degrees"] == -90, "with their numbers: %r" % arcs[0])
        # The replay ends where the turtle stopped against the wall.
        subprocess.run([BIN, "run", world("arc_room.json"), "--inputs", inputs, "--until", "60", "--state-out", state],
                       check=True, stdout=subprocess.DEVNULL)
        t1 = json.load(open(state))["turtles"][0]
        check(close(t1["pos"][0], 290) and close(t1["pos"][1], 270), "the replay ends at (290, 270): %r" % t1)


if __name__ == "__main__":
    main([test_arcs_over_lines])
