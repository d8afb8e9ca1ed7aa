#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Viewers never change a run (issue 12, section 6): 20 viewers subscribed at different rates,
formats and event kinds, some reading slowly, watch 20 s of a 10^3-ball gas; the served event
log equals `turtlegas run`'s byte for byte."""

import os
import queue
import random
import tempfile
import threading
import time

from harness import Server, check, main, run, world
from turtlegas_client import World

UNTIL = 20


def viewer(s, k, counts):
    rng = random.Random(k)  # seeded: the viewers' pattern is the same every run
    ws = k % 2 == 1
    w = World.connect_ws("127.0.0.1", s.http_port) if ws else World.connect("127.0.0.1", s.line_port)
    rate = [1, 2, 5, 10, 15, 24, 30, 60, 90, 120][k % 10]
    events = ["all", [], ["ball-wall"], ["ball-ball", "ball-wall"]][k % 4]
    fmt = "binary" if ws and k % 4 == 1 else "json"
    w.subscribe(rate=rate, events=events, fmt=fmt, velocities=k % 3 != 0)
    n = 0
    slow = k % 5 == 0
    while True:
        try:
            w.frames.get(timeout=1)
        except queue.Empty:
            if w.closed:
                break
            continue
        n += 1
        if slow:
            time.sleep(rng.uniform(0.05, 0.3))
    counts[k] = n


def test_twenty_viewers_leave_the_log_alone():
    with tempfile.TemporaryDirectory() as d:
        headless, served = os.path.join(d, "headless.jsonl"), os.path.join(d, "served.jsonl")
        run(["run", world("gas_1000.json"), "--until", UNTIL, "--events", headless])
        with Server(world("gas_1000.json"), "--speed", "4", "--paused", "--until", UNTIL, "--events", served) as s:
            counts = {}
            threads = [threading.Thread(target=viewer, args=(s, k, counts), daemon=True) for k in range(20)]
            for th in threads:
                th.start()
            time.sleep(1.0)
            World.connect("127.0.0.1", s.line_port).resume()
            check(s.wait(240) == 0, "serve ends at --until: " + s.err()[-2000:])
            for th in threads:
                th.join(timeout=60)
            print("frames per viewer: %r" % [counts.get(k) for k in range(20)])
            check(len(counts) == 20 and all(c > 1 for c in counts.values()), "every viewer got frames: %r" % counts)
        a, b = open(headless, "rb").read(), open(served, "rb").read()
        check(a.count(b"\n") > 1000, "the gas collides (%d events)" % a.count(b"\n"))
        check(a == b, "the served log equals the headless one (%d vs %d bytes)" % (len(b), len(a)))


if __name__ == "__main__":
    main([test_twenty_viewers_leave_the_log_alone])
