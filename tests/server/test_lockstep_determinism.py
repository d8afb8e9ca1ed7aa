#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Lockstep determinism (issue 12, section 6): two remote turtles driven by the Python wall
follower give the same event log, byte for byte, as controllers/wall_follower.cpp run headless;
and the input log the server wrote replays headless (`run --inputs`) to the same log again."""

import os
import tempfile

from harness import ROOT, Server, check, main, run, world
from turtlegas_client import World
import importlib.util

spec = importlib.util.spec_from_file_location("wall_follower", os.path.join(ROOT, "clients", "python", "examples", "wall_follower.py"))
wf = importlib.util.module_from_spec(spec)
spec.loader.exec_module(wf)

UNTIL = 30


def test_python_lockstep_equals_cpp_headless():
    with tempfile.TemporaryDirectory() as d:
        cpp_log, served_log, replay_log, inputs = (os.path.join(d, n) for n in ("cpp.jsonl", "served.jsonl", "replay.jsonl", "inputs.jsonl"))
        run(["run", os.path.join(ROOT, "worlds", "wall_follower.json"), "--until", UNTIL, "--events", cpp_log])
        with Server(world("remote_followers.json"), "--speed", "max", "--paused", "--until", UNTIL,
                    "--events", served_log, "--inputs-out", inputs) as s:
            w = World.connect("127.0.0.1", s.line_port)
            righty, lefty = w.claim("righty"), w.claim("lefty")
            w.resume()
            errors = World.run_turtles({righty: lambda t: wf.wall_follower(t, right_hand=True),
                                        lefty: lambda t: wf.wall_follower(t, right_hand=False)})
            check(not errors, "turtle programs failed: %r" % errors)
            check(w.bye and w.bye["reason"] == "until", "the server says bye at --until: %r" % w.bye)
            check(s.wait(30) == 0, "serve exits 0 at --until: " + s.err())
            check(len(righty.touches) > 3 and len(lefty.touches) > 3, "both followers felt walls")
        cpp, served = open(cpp_log, "rb").read(), open(served_log, "rb").read()
        check(cpp.count(b"\n") > 20, "the C++ run logs touches")
        check(served == cpp, "the served lockstep log equals the C++ headless log (%d vs %d bytes)" % (len(served), len(cpp)))
        run(["run", world("remote_followers.json"), "--until", UNTIL, "--inputs", inputs, "--events", replay_log])
        check(open(replay_log, "rb").read() == served, "the input log replays headless to the same event log")
        # Without inputs the remote turtles stand still: a different log, so the test can fail.
        run(["run", world("remote_followers.json"), "--until", UNTIL, "--events", replay_log])
        check(open(replay_log, "rb").read() != served, "without the inputs the log differs")


if __name__ == "__main__":
    main([test_python_lockstep_equals_cpp_headless])
