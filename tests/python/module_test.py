#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""turtlegas.World against the CLI (docs/python.md): the same world gives the same event log, the
same state and the same observables in process as `turtlegas run` writes; loader errors come as
turtlegas.WorldError with their JSON path; the engine runs without the GIL.

Run by ctest with the build tree's package on PYTHONPATH and TURTLEGAS set to the program."""

import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import numpy as np

import turtlegas

TURTLEGAS = os.environ.get("TURTLEGAS", "build/release/turtlegas")


def cli(*args):
    """Runs the program; returns its stdout."""
    done = subprocess.run([TURTLEGAS, *args], capture_output=True, text=True, timeout=300)
    if done.returncode != 0:
        raise AssertionError("turtlegas %s: exit %d\n%s" % (" ".join(args), done.returncode, done.stderr))
    return done.stdout


def periodic_gas(count=200, side=60.0, seed=3):
    return {"format": "turtlegas-world/1", "name": "periodic gas", "seed": seed,
            "arena": {"width": side, "height": side, "boundary": "periodic"},
            "gas": [{"count": count, "radius": 1, "mass": 1, "speed": 5,
                     "region": [[0, 0], [side, side]], "seed": seed}]}


class ModuleTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def write_world(self, world, name="world.json"):
        with open(self.path(name), "w") as f:
            json.dump(world, f)
        return self.path(name)

    def cli_run(self, world_file, until, *extra):
        events, state, stats = self.path("e.jsonl"), self.path("s.json"), self.path("stats.json")
        cli("run", world_file, "--until", str(until), "--events", events, "--state-out", state,
            "--stats-json", stats, *extra)
        with open(events, "rb") as f, open(state) as g, open(stats) as h:
            return f.read(), json.load(g), json.load(h)

    def test_gas_event_log_and_state_match_the_cli(self):
        for mode in ("exact", "step"):
            with self.subTest(mode=mode):
                log, state, stats = self.cli_run("worlds/gas.json", 3, "--mode", mode)
                w = turtlegas.World.load("worlds/gas.json", mode=mode)
                lines = ""
                for t in (0.5, 1.0, 2.25, 3.0):  # cut anywhere: the physics does not care
                    w.run(t)
                    lines += w.event_lines()
                self.assertGreater(log.count(b"\n"), 400)
                self.assertEqual(lines.encode(), log)
                self.assertEqual(w.time, 3.0)
                ids = w.ball_ids
                pos, vel = w.positions, w.velocities
                self.assertEqual(pos.shape, (len(state["balls"]), 2))
                for b in state["balls"]:
                    i = ids.index(b["id"])
                    self.assertEqual(list(pos[i]), b["pos"])
                    self.assertEqual(list(vel[i]), b["vel"])
                self.assertEqual(w.energy, stats["energy_end"])
                self.assertEqual(w.stats["collisions"], stats["collisions"])

    def test_energy_is_conserved_at_e_1(self):
        w = turtlegas.World.load(periodic_gas(count=400))
        m = np.asarray(w.masses)
        e0 = 0.5 * np.sum(m * np.sum(w.velocities ** 2, axis=1))
        self.assertAlmostEqual(w.energy / e0, 1.0, delta=1e-15)
        w.run(20.0)
        self.assertGreater(w.stats["ball_ball"], 10000)
        e1 = 0.5 * np.sum(m * np.sum(w.velocities ** 2, axis=1))
        self.assertLess(abs(e1 - e0) / e0, 1e-12)

    def test_events_three_ways(self):
        w = turtlegas.World.load("worlds/gas.json")
        w.run(0.5)
        a = w.events()
        self.assertEqual(len(w.events()), 0)  # consumed
        w2 = turtlegas.World.load("worlds/gas.json")
        w2.run(0.5)
        tuples = w2.event_tuples()
        w3 = turtlegas.World.load("worlds/gas.json")
        w3.run(0.5)
        lines = [json.loads(x) for x in w3.event_lines().splitlines()]
        self.assertGreater(len(a), 50)
        self.assertEqual(len(a), len(tuples))
        self.assertEqual(len(a), len(lines))
        for row, tup, line in zip(a, tuples, lines):
            self.assertEqual(row["t"], line["t"])
            self.assertEqual(tup.t, line["t"])
            self.assertEqual(row["kind"], line["kind"])
            self.assertEqual(tup.kind, line["kind"])
            self.assertEqual(row["a"], line["a"])
            self.assertEqual(tup.b, line.get("b", ""))
            self.assertEqual(row["b"], line.get("b", ""))
        self.assertTrue(np.all(np.diff(a["t"]) >= 0))

    def test_world_error_carries_the_path(self):
        bad = periodic_gas()
        bad["balls"] = [{"id": "x", "pos": [10, 10], "vel": [0, 0], "radius": -1}]
        with self.assertRaises(turtlegas.WorldError) as caught:
            turtlegas.World.load(bad)
        e = caught.exception
        self.assertIsInstance(e, ValueError)
        self.assertEqual(e.path, "/balls/0/radius")
        self.assertIn("radius", e.reason)
        self.assertIn("/balls/0/radius", str(e))
        # The same words as the CLI's for the same file.
        f = self.write_world(bad)
        done = subprocess.run([TURTLEGAS, "check", f], capture_output=True, text=True)
        self.assertEqual(done.returncode, 2)
        self.assertIn(f + ": " + e.path + ": " + e.reason, done.stderr)
        with self.assertRaises(turtlegas.WorldError) as caught:
            turtlegas.World.load(self.path("missing.json"))
        self.assertIn("no such file", str(caught.exception))
        with self.assertRaises(ValueError):
            turtlegas.World.load("worlds/gas.json", mode="fast")

    def test_state_arrays(self):
        w = turtlegas.World.load("worlds/gas.json")
        r1, r2 = w.radii, w.radii
        self.assertTrue(np.shares_memory(r1, r2))  # the module's own array, not a copy per call
        self.assertFalse(r1.flags.writeable)
        self.assertEqual(len(r1), len(w.ball_ids))
        i = w.ball_ids.index("heavy")
        self.assertEqual(r1[i], 24.0)
        self.assertEqual(w.masses[i], 20.0)
        self.assertTrue(np.all(w.charges == 0))
        self.assertTrue(np.all(w.alive))
        t = turtlegas.World.load("worlds/wall_follower.json")
        self.assertEqual(t.turtle_ids, ["righty", "lefty"])
        self.assertEqual(list(t.headings), [0.0, 270.0])
        self.assertEqual(t.turtle_positions.tolist(), [[250, 110], [60, 60]])

    def test_unwrapped_positions(self):
        # One ball alone, straight across the seams: unwrapped = start + v t exactly.
        world = {"format": "turtlegas-world/1", "arena": {"width": 50, "height": 40, "boundary": "periodic"},
                 "balls": [{"id": "b", "pos": [10, 10], "vel": [37, -23], "radius": 1}]}
        w = turtlegas.World.load(world)
        w.run(10.0)
        u = w.unwrapped[0]
        self.assertAlmostEqual(u[0], 10 + 370, delta=1e-9)
        self.assertAlmostEqual(u[1], 10 - 230, delta=1e-9)
        # A gas: each unwrapped position is its wrapped one plus whole arena images, and matches a
        # run read every 0.01 s and unwrapped here by nearest images.
        coarse = turtlegas.World.load(periodic_gas())
        fine = turtlegas.World.load(periodic_gas())
        last = fine.positions
        mine = last.copy()
        for k in range(1, 301):
            fine.run(k * 0.01)
            d = fine.positions - last
            d -= 60.0 * np.round(d / 60.0)
            mine += d
            last = fine.positions
        coarse.run(3.0)
        self.assertTrue(np.array_equal(coarse.positions, fine.positions))
        self.assertLess(np.max(np.abs(coarse.unwrapped - mine)), 1e-9)
        images = (coarse.unwrapped - coarse.positions) / 60.0
        self.assertLess(np.max(np.abs(images - np.round(images))), 1e-9)
        self.assertGreater(np.max(np.abs(images)), 0.5)  # some did cross
        walled = turtlegas.World.load("worlds/gas.json")
        self.assertTrue(np.array_equal(walled.unwrapped, walled.positions))

    def test_observe_matches_the_cli(self):
        f = self.write_world(periodic_gas(count=300))
        out = self.path("obs.json")
        cli("run", f, "--until", "4", "--observe", out, "--observe-from", "1", "--observe-samples", "10")
        with open(out) as g:
            expected = json.load(g)
        w = turtlegas.World.load(f)
        got = w.observe(until=4, start=1, samples=10)
        self.assertEqual(got, expected)
        self.assertEqual(w.time, 4.0)
        with self.assertRaises(ValueError):
            turtlegas.World.load("worlds/wall_follower.json").observe(until=1)

    def test_run_releases_the_gil(self):
        w = turtlegas.World.load(periodic_gas(count=2000, side=200))
        # The run must last far longer than the interpreter's switch interval (5 ms), on any
        # machine: a fixed simulated time finished inside a 50 ms sleep on a fast one. Time one
        # simulated second first, then ask for about half a second of wall time.
        t = time.perf_counter()
        w.run(1.0)
        per_unit = max(time.perf_counter() - t, 1e-6)
        until = w.time + min(max(0.5 / per_unit, 1.0), 10000.0)
        window = {}

        def work():
            window["t0"] = time.perf_counter()
            w.run(until)
            window["t1"] = time.perf_counter()

        # The main thread spins and marks each millisecond in which it ran. Held by C++ code, the
        # GIL would keep it out for the whole run but the edges (one switch interval each).
        ms = [0] * 20000
        start = time.perf_counter()
        worker = threading.Thread(target=work)
        worker.start()
        while worker.is_alive():
            k = int((time.perf_counter() - start) * 1000)
            if k < len(ms):
                ms[k] += 1
        worker.join()
        self.assertEqual(w.time, until)
        first = int((window["t0"] - start) * 1000) + 10
        last = int((window["t1"] - start) * 1000) - 10
        self.assertGreater(last - first, 100, "the run was too short to tell")
        ran = sum(1 for k in range(first, min(last, len(ms))) if ms[k] > 0)
        self.assertGreater(ran, 0.25 * (min(last, len(ms)) - first),
                           "the main thread barely ran while the world ran")

    def test_run_refuses_going_back(self):
        w = turtlegas.World.load("worlds/gas.json")
        w.run(1.0)
        with self.assertRaises(ValueError):
            w.run(0.5)
        w.advance(0.25)
        self.assertEqual(w.time, 1.25)


if __name__ == "__main__":
    unittest.main()
