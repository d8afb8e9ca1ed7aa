#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Python programs (turtlegas.programs, turtlegas.controllers) against their C++ twins: the same
world run with the Python wall follower, tag players and Braitenberg vehicle gives an event log
byte-identical to `turtlegas run --events` with the C++ controllers; and the program protocol
(results, touches, messages, readings, faults, exceptions) behaves as docs/python.md says.

Run by ctest with the build tree's package on PYTHONPATH and TURTLEGAS set to the program."""

import json
import math
import os
import subprocess
import tempfile
import unittest

import turtlegas
from turtlegas import controllers

TURTLEGAS = os.environ.get("TURTLEGAS", "build/release/turtlegas")


def cli_events(world_file, until, mode):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "e.jsonl")
        done = subprocess.run([TURTLEGAS, "run", world_file, "--until", str(until), "--mode", mode, "--events", out],
                              capture_output=True, text=True, timeout=300)
        if done.returncode != 0:
            raise AssertionError(done.stderr)
        with open(out, "rb") as f:
            return f.read()


def python_events(world_file, until, mode, chunk=None):
    """The world with every turtle's controller replaced by its Python twin."""
    with open(world_file) as f:
        spec = json.load(f)
    programs = {t["id"]: controllers.by_name[t["controller"]] for t in spec["turtles"]}
    w = turtlegas.World.load(world_file, mode=mode, programs=programs)
    lines = ""
    t = 0.0
    while t < until:
        t = min(until, t + (chunk or until))
        w.run(t)
        lines += w.event_lines()
    return lines.encode(), w


class TwinsTest(unittest.TestCase):
    def twin(self, world_file, until, mode, chunk=None, must_have=()):
        expected = cli_events(world_file, until, mode)
        got, w = python_events(world_file, until, mode, chunk)
        for kind in must_have:
            self.assertIn(b'"kind": "%s"' % kind.encode(), expected)
        if got != expected:
            e, g = expected.splitlines(), got.splitlines()
            first = next((k for k in range(min(len(e), len(g))) if e[k] != g[k]), min(len(e), len(g)))
            self.fail("%s (%s): the logs part at line %d of %d/%d:\n C++:    %s\n Python: %s" % (
                world_file, mode, first + 1, len(e), len(g), e[first] if first < len(e) else "(end)",
                g[first] if first < len(g) else "(end)"))
        return w

    def test_wall_follower(self):
        for mode in ("exact", "step"):
            with self.subTest(mode=mode):
                self.twin("worlds/wall_follower.json", 120, mode, chunk=7.3, must_have=("touch", "turtle-wall"))

    def test_tag_players(self):
        for mode in ("exact", "step"):
            with self.subTest(mode=mode):
                self.twin("worlds/tag.json", 90, mode, must_have=("touch", "tag", "turtle-turtle"))

    def test_braitenberg(self):
        self.twin("worlds/tests/braitenberg_no_touch.json", 120, "exact", chunk=10, must_have=("sense",))

    def test_braitenberg_with_a_noisy_ring(self):
        # The noise and the program's uniform() draw from one stream, in C++ and in Python alike.
        with open("worlds/tests/braitenberg_no_touch.json") as f:
            world = json.load(f)
        world.pop("expect")
        world["turtles"][0]["senses"][0]["noise"] = {"sd": 2.0, "dropout": 0.1}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "noisy.json")
            with open(path, "w") as f:
                json.dump(world, f)
            w = self.twin(path, 60, "exact", must_have=("sense",))
        self.assertEqual(w.time, 60.0)


class ThreadsTest(unittest.TestCase):
    def test_worlds_with_programs_in_threads(self):
        # Runs of worlds with turtles take turns (one simulation thread at a time, fiber.hpp);
        # each gives the log it gives alone.
        import threading
        alone, _ = python_events("worlds/tag.json", 30, "exact")
        worlds = [turtlegas.World.load("worlds/tag.json", programs={"t5": controllers.tag_random, "t1": controllers.tag_chaser,
                                                                     "t2": controllers.tag_chaser, "t3": controllers.tag_evader,
                                                                     "t4": controllers.tag_evader}) for _ in range(3)]
        threads = [threading.Thread(target=w.run, args=(30,)) for w in worlds]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for w in worlds:
            self.assertEqual(w.time, 30.0)
            self.assertEqual(w.event_lines().encode(), alone)


class ProtocolTest(unittest.TestCase):
    ROOM = {"format": "turtlegas-world/1", "seed": 4, "arena": {"width": 200, "height": 200, "boundary": "walls"},
            "turtles": [{"id": "t", "pos": [100, 100], "heading": 90, "speed": 50, "turn_rate": 180,
                         "senses": [{"name": "ir", "ring": 4, "range": 500}]}]}

    def test_results_touches_and_readings(self):
        seen = {}

        def program(t, p):
            seen["params"] = p
            r = yield t.forward(30)
            seen["free"] = r
            seen["heading0"] = t.heading
            touches = []
            t.on_touch(touches.append)
            r = yield t.forward(1000)  # into the east wall
            seen["hit"] = r
            seen["touches"] = list(touches)
            seen["time"] = t.time
            seen["ring"] = yield t.scan("ir")
            seen["front"] = yield t.range("ir")
            yield t.left(90)
            seen["heading1"] = t.heading
            seen["odometer"] = t.odometer

        w = turtlegas.World.load(self.ROOM, programs={"t": program})
        w.run(60)
        self.assertEqual(seen["params"], {})
        self.assertFalse(seen["free"].touched)
        self.assertEqual(seen["free"].done, 30)
        hit = seen["hit"]
        self.assertTrue(hit.touched)
        self.assertTrue(hit.touch.front)
        self.assertEqual(hit.touch.what, "arena-right")
        self.assertEqual(hit.touch.kind, "wall")
        self.assertAlmostEqual(hit.done, 200 - 10 - 130, delta=1e-9)
        self.assertEqual(seen["touches"], [hit.touch])  # the handler saw it before the result
        self.assertEqual(len(seen["ring"]), 4)
        self.assertAlmostEqual(seen["ring"][0].distance, 10, delta=1e-9)  # the wall, ahead
        self.assertEqual(seen["front"], seen["ring"][0])
        self.assertAlmostEqual(seen["ring"][2].distance, 190, delta=1e-9)  # the west wall, behind
        self.assertEqual(seen["heading0"], 90.0)
        self.assertEqual(seen["heading1"], 0.0)
        self.assertAlmostEqual(seen["odometer"], 90, delta=1e-9)
        self.assertAlmostEqual(w.turtle_positions[0][0], 190, delta=1e-9)
        kinds = [e.kind for e in w.event_tuples()]
        self.assertEqual(kinds.count("touch"), 1)
        self.assertEqual(kinds.count("sense"), 2)

    def test_camera(self):
        # Two pixels over 20 degrees (bearings -5 and 5) see a red ball of radius 5 whose centre is
        # 50 ahead: b - sqrt(r^2 - c^2) with b = 50 cos 5deg, c = 50 sin 5deg; a range sensor's
        # readings have no colour.
        room = {"format": "turtlegas-world/1", "arena": {"width": 200, "height": 200, "boundary": "walls"},
                "balls": [{"id": "b", "pos": [150, 100], "radius": 5, "colour": "Red"}],
                "turtles": [{"id": "t", "pos": [100, 100], "heading": 90,
                             "senses": [{"name": "eye", "camera": {"pixels": 2, "fov": 20, "range": 500}},
                                        {"name": "ir", "range": 500}]}]}
        seen = {}

        def program(t, p):
            seen["eye"] = yield t.camera("eye")
            seen["ir"] = yield t.scan("ir")

        w = turtlegas.World.load(room, programs={"t": program})
        w.run(1)
        a = math.radians(5)
        expected = 50 * math.cos(a) - math.sqrt(25 - (50 * math.sin(a)) ** 2)
        self.assertEqual([r.bearing for r in seen["eye"]], [-5, 5])
        for r in seen["eye"]:
            self.assertEqual((r.what, r.kind, r.colour), ("b", "ball", "#ff0000"))
            self.assertAlmostEqual(r.distance, expected, delta=1e-12)
        self.assertEqual(seen["ir"][0].colour, "")
        self.assertAlmostEqual(seen["ir"][0].distance, 45, delta=1e-12)

    def test_arcs_drive_and_wheels(self):
        seen = {}

        def program(t, p):
            seen["axle"] = t.axle
            seen["arc"] = yield t.arc(50, -90)  # from (100, 100) heading 90: a left quarter about (100, 150)
            seen["heading"] = t.heading
            seen["wheels"] = yield t.wheels(40, 20, 1)  # 30 units/s turning 1 rad/s clockwise
            seen["drive"] = yield t.drive(50, 0, 10)  # straight on into the north wall
            seen["odometer"] = t.odometer

        w = turtlegas.World.load(self.ROOM, programs={"t": program})
        w.run(30)
        self.assertEqual(seen["axle"], 20.0)  # twice the default radius
        self.assertAlmostEqual(seen["arc"].done, 25 * math.pi, delta=1e-9)
        self.assertAlmostEqual(seen["heading"], 0.0, delta=1e-9)
        self.assertAlmostEqual(seen["wheels"].done, 30, delta=1e-9)
        self.assertTrue(seen["drive"].touched)
        self.assertEqual(seen["drive"].touch.what, "arena-top")
        self.assertAlmostEqual(seen["odometer"], 25 * math.pi + 30 + seen["drive"].done, delta=1e-9)
        # After the wheels: heading 1 rad, 30 units from the circle's centre (180, 150) along (-cos 1, sin 1).
        x = 180 - 30 * math.cos(1) + (190 - (150 + 30 * math.sin(1))) * math.tan(1)
        self.assertAlmostEqual(w.turtle_positions[0][0], x, delta=1e-9)
        self.assertAlmostEqual(w.turtle_positions[0][1], 190, delta=1e-9)

    def test_a_program_that_raises_stops_its_turtle_not_the_world(self):
        def program(t, p):
            yield t.forward(10)
            raise KeyError("boom")

        w = turtlegas.World.load(self.ROOM, programs={"t": program})
        with self.assertRaises(KeyError):
            w.run(5)
        self.assertEqual(w.time, 5.0)
        x = w.turtle_positions[0][0]
        w.run(10)  # the world runs on; the turtle stands still
        self.assertEqual(w.turtle_positions[0][0], x)

    def test_programs_must_yield_commands(self):
        def not_a_generator(t, p):
            return 3

        w = turtlegas.World.load(self.ROOM, programs={"t": not_a_generator})
        with self.assertRaises(TypeError):  # when its program starts, at the first boundary
            w.run(1)

        def yields_junk(t, p):
            yield 10

        w = turtlegas.World.load(self.ROOM, programs={"t": yields_junk})
        with self.assertRaises(TypeError):
            w.run(1)
        with self.assertRaises(ValueError):
            turtlegas.World.load(self.ROOM, programs={"nobody": yields_junk})

    def test_a_wall_pen_without_builder_faults_as_in_cpp(self):
        def program(t, p):
            yield t.pen_down("wall")
            yield t.forward(10)

        w = turtlegas.World.load(self.ROOM, programs={"t": program})
        w.run(2)
        faults = [e for e in w.event_tuples() if e.kind == "fault"]
        self.assertEqual(len(faults), 1)
        self.assertIn("builder", faults[0].message)


if __name__ == "__main__":
    unittest.main()
