#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Lockstep determinism (issue 12, section 6): two remote turtles driven by the Python wall
follower give the same event log, byte for byte, as controllers/wall_follower.cpp run headless;
and the input log the server wrote replays headless (`run --inputs`) to the same log again."""

import os
import queue
import subprocess
import tempfile
import threading
import time

from harness import BIN, ROOT, Server, check, main, run, world
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


def wait_paused(w, seconds=30):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if w.status and w.status["paused"]:
            return
        try:
            n = w.notices.get(timeout=1)
            if n.get("type") == "status":
                w.status = n["status"]
        except queue.Empty:
            pass
    check(False, "the world paused")


def test_takeover_and_add_wall_replay():
    """A takeover of a C++ turtle and an added wall are inputs too: the log replays headless."""
    src = os.path.join(ROOT, "worlds", "wall_follower.json")
    with tempfile.TemporaryDirectory() as d:
        served, replay, inputs, plain = (os.path.join(d, n) for n in ("served.jsonl", "replay.jsonl", "inputs.jsonl", "plain.jsonl"))
        with Server(src, "--speed", "max", "--paused", "--until", 20, "--events", served, "--inputs-out", inputs) as s:
            w = World.connect("127.0.0.1", s.line_port)
            w.step(40)
            wait_paused(w)
            claim = {}
            th = threading.Thread(target=lambda: claim.setdefault("t", w.claim("righty", takeover=True)))
            th.start()  # answered at the next boundary
            time.sleep(0.2)
            w.step(1)
            th.join(timeout=30)
            righty = claim["t"]
            pending = threading.Thread(target=lambda: claim.setdefault(
                "wall", w.request({"type": "add_wall", "wall": {"id": "fence", "from": [20, 380], "to": [120, 380]}})))
            pending.start()
            w.resume()
            World.run_turtles({righty: lambda t: wf.wall_follower(t, right_hand=False)})
            pending.join(timeout=30)
            check(claim.get("wall", {}).get("type") == "ok", "the wall was added: %r" % claim.get("wall"))
            check(s.wait(30) == 0, "serve exits at --until")
        text = open(inputs).read()
        check('"takeover": "righty"' in text and '"add_wall"' in text, "the input log has the takeover and the wall")
        log = open(served, "rb").read()
        check(b'"takeover"' in log and b'"wall-added"' in log, "the event log has them too")
        run(["run", src, "--until", 20, "--inputs", inputs, "--events", replay])
        check(open(replay, "rb").read() == log, "the input log replays headless to the same event log")
        run(["run", src, "--until", 20, "--events", plain])
        check(open(plain, "rb").read() != log, "and differs from the run without it")


def test_bad_input_logs_are_bad_input():
    with tempfile.TemporaryDirectory() as d:
        bad = os.path.join(d, "bad.jsonl")
        for text, words in (("", "empty"), ('{"format": "other"}\n', "/format"),
                            ('{"format": "turtlegas-inputs/1"}\n{"step": 0, "turtle": "nobody", "command": "forward", "amount": 1}\n', "nobody"),
                            ('{"format": "turtlegas-inputs/1"}\n{"step": 0, "turtle": "righty", "command": "fly"}\n', "/command"),
                            ('{"format": "turtlegas-inputs/1"}\nnot json\n', "bad.jsonl:2")):
            open(bad, "w").write(text)
            r = subprocess.run([BIN, "run", world("remote_followers.json"), "--until", "1", "--inputs", bad],
                               capture_output=True, text=True, timeout=60)
            check(r.returncode == 2 and words in r.stderr and "bad.jsonl" in r.stderr,
                  "exit 2 naming the file and the problem (%s): %d %s" % (words, r.returncode, r.stderr))


def test_step_sent_during_a_step():
    """A `step` handled while a step runs (here: the world waits inside it for a claimed turtle's
    command) runs its steps from that boundary; it used to be swallowed by the running step (the
    world paused one boundary later instead of `steps`, and a change waiting for that boundary
    never came)."""
    with Server(world("remote_followers.json"), "--speed", "max", "--paused") as s:
        w = World.connect("127.0.0.1", s.line_port)
        t = w.claim("righty")
        k = w.welcome["status"]["step"]
        w.step(1)        # from boundary k, where the world waits for righty's command, to k + 1
        r = t.yield_()   # taken at k, ends at k + 1: the world waits there again, inside the step
        check(r.step == k + 1, "the yield ended at k + 1: %r" % r.reply)
        w.step(2)        # handled during that wait, at boundary k + 1: two steps from there
        # Each yield ends at the next boundary; the world pauses after a boundary once righty's
        # next command is in. Sent without waiting for a result that a paused world never gives.
        steps, paused = [], None
        for n in range(1, 10):
            w.send({"type": "yield", "turtle": "righty", "id": 5000 + n})
            while paused is None:
                m = w.notices.get(timeout=10)
                if m.get("id") == 5000 + n:
                    steps.append(m["step"])
                    break
                if m["type"] == "status" and m["status"]["paused"]:
                    paused = m["status"]["step"]
            if paused is not None:
                break
        check(paused == k + 3, "paused at boundary %d + 3 (got %r; yields ended at %r)" % (k, paused, steps))
        check(steps == [k + 2, k + 3], "one yield a boundary: %r" % steps)


if __name__ == "__main__":
    main([test_python_lockstep_equals_cpp_headless, test_takeover_and_add_wall_replay, test_bad_input_logs_are_bad_input,
          test_step_sent_during_a_step])
