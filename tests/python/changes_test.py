#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Changes while a world runs, from Python (docs/python.md, "Changes while it runs"): spawn, remove,
teleport and add_wall. In a world with turtles they are the world server's own world changes (those
of the protocol), made at the next control boundary: the event log equals `turtlegas run --inputs`
of an input log that makes the same changes at the same steps. Without turtles they are the
engine's, made at once, and logged with the same event kinds.

Run by ctest with the build tree's package on PYTHONPATH and TURTLEGAS set to the program."""

import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

import turtlegas

TURTLEGAS = os.environ.get("TURTLEGAS", "build/release/turtlegas")

BOX = {"format": "turtlegas-world/1", "name": "box", "seed": 2,
       "arena": {"width": 100, "height": 100, "boundary": "walls"},
       "balls": [{"id": "a", "pos": [20, 50], "vel": [10, 0], "radius": 2},
                 {"id": "b", "pos": [80, 20], "vel": [0, 5], "radius": 2}]}


class WithTurtlesTest(unittest.TestCase):
    """The world server's changes, checked against the CLI replaying the same changes."""

    def test_same_log_as_an_input_log_replay(self):
        world_file = "worlds/wall_follower.json"
        w = turtlegas.World.load(world_file)
        dt = w.dt
        steps = []  # (step the change is made at, input-log line body)
        w.run(30 * dt)
        w.spawn_ball("b9", (450, 50), vel=(-20, 15), radius=4, mass=2)
        steps.append((31, {"spawn": {"ball": {"id": "b9", "pos": [450, 50], "vel": [-20, 15], "radius": 4, "mass": 2}}}))
        w.add_wall("w9", (420, 150), (480, 150))
        steps.append((31, {"add_wall": {"id": "w9", "from": [420, 150], "to": [480, 150]}}))
        w.run(90 * dt)
        w.teleport("b9", (440, 60), vel=(5, -25))
        steps.append((91, {"teleport": {"id": "b9", "pos": [440, 60], "vel": [5, -25]}}))
        w.teleport("lefty", (100, 330), heading=45)
        steps.append((91, {"teleport": {"id": "lefty", "pos": [100, 330], "heading": 45}}))
        w.run(150 * dt)
        w.spawn_turtle("t9", (450, 230), heading=270, controller="square", params={"side": 20})
        steps.append((151, {"spawn": {"turtle": {"id": "t9", "pos": [450, 230], "heading": 270, "radius": 10,
                                                 "speed": 30, "turn_rate": 90, "controller": "square",
                                                 "params": {"side": 20}}}}))
        w.run(400 * dt)
        w.remove("b9")
        steps.append((401, {"remove": "b9"}))
        w.run(20.0)
        got = w.event_lines()
        for kind in ("spawn", "wall-added", "teleport", "remove"):
            self.assertIn('"kind": "%s"' % kind, got)
        self.assertNotIn("b9", w.ball_ids[:0])
        self.assertFalse(w.alive[w.ball_ids.index("b9")])
        self.assertIn("t9", w.turtle_ids)
        with tempfile.TemporaryDirectory() as tmp:
            inputs, events = os.path.join(tmp, "in.jsonl"), os.path.join(tmp, "e.jsonl")
            with open(world_file) as f:
                name = json.load(f)["name"]
            with open(inputs, "w") as f:
                f.write(json.dumps({"format": "turtlegas-inputs/1", "world": name, "dt": dt}) + "\n")
                for step, body in steps:
                    f.write(json.dumps(dict(step=step, **body)) + "\n")
            done = subprocess.run([TURTLEGAS, "run", world_file, "--until", "20", "--inputs", inputs, "--events", events],
                                  capture_output=True, text=True, timeout=120)
            self.assertEqual(done.returncode, 0, done.stderr)
            with open(events) as f:
                expected = f.read()
        self.assertEqual(got, expected)

    def test_refused_at_once_when_it_can_be_seen(self):
        w = turtlegas.World.load("worlds/wall_follower.json")
        with self.assertRaises(ValueError) as caught:
            w.spawn_ball("x", (250, 110), radius=5)  # on righty
        self.assertIn("turtle 'righty'", str(caught.exception))
        with self.assertRaises(ValueError):
            w.spawn_ball("righty", (450, 50))  # a taken id
        with self.assertRaises(ValueError):
            w.remove("nobody")
        with self.assertRaises(ValueError):
            w.teleport("righty", (60, 60), heading=0)  # onto lefty

    def test_refused_at_the_boundary_is_raised_after_the_run(self):
        w = turtlegas.World.load("worlds/wall_follower.json")
        w.add_wall("w9", (450, 300), (450, 300))  # zero length: only the engine sees it
        w.spawn_ball("b9", (450, 50), vel=(0, 0), radius=4)
        with self.assertRaises(ValueError):
            w.run(1.0)
        self.assertEqual(w.time, 1.0)
        self.assertIn("b9", w.ball_ids)  # the other change was made
        w.run(2.0)  # and the world runs on


class BareTest(unittest.TestCase):
    """The engine's own changes, at once, in a world without turtles."""

    def test_spawn_remove_teleport_add_wall(self):
        w = turtlegas.World.load(BOX)
        w.run(1.0)
        w.spawn_ball("c", (50, 80), vel=(0, 10), radius=3, mass=2)
        i = w.ball_ids.index("c")
        self.assertEqual(w.radii[i], 3)
        self.assertEqual(w.masses[i], 2)
        self.assertEqual(w.charges[i], 0)
        w.run(1.5)
        self.assertEqual(w.positions[i].tolist(), [50, 85])
        w.add_wall("lid", (40, 90), (60, 90))
        w.run(2.0)  # c hits the lid at y = 87 (radius 3) at t = 1.7
        ev = [e for e in w.event_tuples() if e.kind != "ball-wall" or e.b == "lid"]
        kinds = [(e.kind, e.a, e.b) for e in ev]
        self.assertIn(("spawn", "c", "ball"), kinds)
        self.assertIn(("wall-added", "lid", ""), kinds)
        hits = [e for e in ev if e.kind == "ball-wall" and e.a == "c"]
        self.assertEqual(len(hits), 1)
        self.assertAlmostEqual(hits[0].t, 1.7, delta=1e-12)
        self.assertAlmostEqual(w.velocities[i][1], -10, delta=1e-12)
        w.teleport("a", (50, 20), vel=(0, -1))
        self.assertEqual(w.positions[w.ball_ids.index("a")].tolist(), [50, 20])
        w.remove("b")
        self.assertFalse(w.alive[w.ball_ids.index("b")])
        kinds = [(e.kind, e.a, e.b) for e in w.event_tuples()]
        self.assertEqual(kinds, [("teleport", "a", "ball"), ("remove", "b", "ball")])
        e0 = w.energy
        w.run(10.0)
        self.assertAlmostEqual(w.energy, e0, delta=1e-9 * e0)

    def test_refusals_name_the_obstacle(self):
        w = turtlegas.World.load(BOX)
        with self.assertRaises(ValueError) as caught:
            w.spawn_ball("c", (21, 50), radius=2)
        self.assertIn("ball 'a'", str(caught.exception))
        with self.assertRaises(ValueError):
            w.spawn_ball("a", (50, 50))
        with self.assertRaises(ValueError):
            w.spawn_turtle("t", (50, 50))  # no turtle lists in this engine
        with self.assertRaises(ValueError):
            w.teleport("a", (80, 21))  # onto b
        self.assertEqual(w.positions[0].tolist(), [20, 50])  # nothing changed


if __name__ == "__main__":
    unittest.main()
