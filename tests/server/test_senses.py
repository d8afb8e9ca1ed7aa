#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A remote client reads its turtle's range sensors over the protocol (`sense`, issue 34) and its
line camera (`camera`: each pixel's colour, the background past the range): the
distances and ids against closed forms, no simulated time taken, the readings after a stroke, an
unknown sensor refused with bad_value, and the sense events in the event log; over TCP lines and
WebSocket."""

import json
import math
import os
import tempfile

from harness import Server, check, main, world
from turtlegas_client import ServerError, World


def drive(w):
    t = w.claim("t1")
    check([(x["name"], x["bearings"], x["range"]) for x in t.senses] ==
          [("front", [0], 500), ("ring", [0, 90, 180, 270], 160), ("eye", [-40, 0, 40], 180)],
          "the claimed reply lists the range sensors: %r" % t.senses)
    check([x.get("camera", False) for x in t.senses] == [False, False, True], "and marks the camera: %r" % t.senses)
    w.resume()
    front = t.sense("front")
    check(len(front) == 1, "one ray: %r" % front)
    check(front[0].what == "target" and front[0].kind == "wall", "the front ray meets the wall: %r" % front)
    check(abs(front[0].distance - 200) < 1e-9, "at 300 - 100 = 200: %r" % front)
    ring = t.sense("ring")
    check([r.bearing for r in ring] == [0, 90, 180, 270], "the ring's bearings: %r" % ring)
    check(not ring[0].hit and math.isinf(ring[0].distance), "nothing within 160 ahead: %r" % ring[0])
    check([r.what for r in ring[1:]] == ["arena-bottom", "arena-left", "arena-top"], "the arena's walls: %r" % ring)
    check([r.distance for r in ring[1:]] == [150, 100, 150], "at 150, 100, 150: %r" % ring)
    moved = t.forward(50)
    check(not moved.touched and abs(moved.done - 50) < 1e-9, "forward 50: %r" % moved.reply)
    after = t.sense("front")
    check(abs(after[0].distance - 150) < 1e-9, "then the wall is 150 away: %r" % after)
    try:
        t.sense("nope")
        check(False, "an unknown sensor is refused")
    except ServerError as e:
        check(e.reply["code"] == "bad_value" and "front, ring" in e.reply["message"], "bad_value naming the senses: %r" % e.reply)
    again = t.sense("front")
    check(abs(again[0].distance - 150) < 1e-9, "the turtle still senses after a refusal: %r" % again)
    # The camera, 150 from the target now: the middle pixel sees it red, the others the background.
    eye = t.camera("eye")
    check([p.bearing for p in eye] == [-40, 0, 40], "the pixels' bearings: %r" % eye)
    check([p.colour for p in eye] == ["#ffffff", "#ff0000", "#ffffff"], "white, red, white: %r" % eye)
    check(eye[1].what == "target" and abs(eye[1].distance - 150) < 1e-9, "the target at 150: %r" % eye)
    check(not eye[0].hit and math.isinf(eye[0].distance) and eye[0].what is None, "nothing within 180: %r" % eye[0])
    check(t.sense("front")[0].colour is None, "a range sensor's readings have no colour")
    try:
        t.camera("ring")
        check(False, "a range sensor is no camera")
    except ServerError as e:
        check(e.reply["code"] == "bad_value" and "its cameras: eye" in e.reply["message"], "bad_value naming the cameras: %r" % e.reply)
    return t


def test_senses_over_lines():
    with tempfile.TemporaryDirectory() as d:
        events = os.path.join(d, "events.jsonl")
        with Server(world("sense_room.json"), "--paused", "--speed", "max", "--events", events) as s:
            drive(World.connect("127.0.0.1", s.line_port))
            check(s.stop() == 0, "stops on SIGINT")
        senses = [json.loads(line) for line in open(events) if '"sense"' in line]
        senses = [e for e in senses if e["kind"] == "sense"]
        check(len(senses) == 6, "six readings logged: %r" % senses)
        check(senses[4]["sensor"] == "eye" and senses[4]["colour"] == ["#ffffff", "#ff0000", "#ffffff"] and
              senses[4]["hit"] == [None, "target", None], "the camera's reading with its colours: %r" % senses[4])
        check("colour" not in senses[5], "a range sensor's has none: %r" % senses[5])
        check(senses[0]["a"] == "t1" and senses[0]["sensor"] == "front" and senses[0]["hit"] == ["target"],
              "the first names the turtle, the sensor and what it hit: %r" % senses[0])
        check(senses[1]["range"] == [None, 150, 100, 150], "null past the range: %r" % senses[1])
        check(senses[0]["t"] == senses[1]["t"], "a reading takes no time: %r" % senses[:2])


def test_senses_over_websocket():
    with Server(world("sense_room.json"), "--paused", "--speed", "max") as s:
        drive(World.connect_ws("127.0.0.1", s.http_port))
        check(s.stop() == 0, "stops on SIGINT")


if __name__ == "__main__":
    main([test_senses_over_lines, test_senses_over_websocket])
