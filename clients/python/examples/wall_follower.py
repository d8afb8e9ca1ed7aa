#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The wall follower of controllers/wall_follower.cpp, driven over the network.

    turtlegas serve tests/server/worlds/remote_followers.json --port 0 --speed max --paused
    python3 clients/python/examples/wall_follower.py --port LINE_PORT --turtle righty:right --turtle lefty:left

Each turtle runs in a thread of its own; the script resumes the world once every turtle is
claimed and ends when the server stops (--until, or Ctrl-C on the server). With the same
commands at the same steps as the C++ program (the server in lockstep), the event log is the
same bit for bit (tests/server/test_lockstep_determinism.py).
"""

import argparse
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from turtlegas_client import World  # noqa: E402


def wall_follower(t, right_hand=True, hop=20.0, probe=12.0, back_off=3.0):
    """controllers/wall_follower.cpp, line for line."""
    towards_wall = t.right if right_hand else t.left
    away_from_wall = t.left if right_hand else t.right
    # Find a wall first. (The C++ program turns by 90 * uniform() from its seeded generator when
    # nothing is touched; this stand-in is not seeded alike, so the logs agree only where the
    # first forward touches, as in the shipped worlds.)
    while not t.forward(1000).touched:
        t.right(90 * random.random())
    t.back(back_off)
    away_from_wall(90)
    while True:
        if t.forward(hop).touched:
            t.back(back_off)
            away_from_wall(90)
            continue
        towards_wall(90)
        if t.forward(probe).touched:
            t.back(back_off)
            away_from_wall(90)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, required=True, help="the server's TCP-lines port")
    ap.add_argument("--token")
    ap.add_argument("--turtle", action="append", required=True, help="ID[:right|left], repeatable")
    ap.add_argument("--no-resume", action="store_true", help="do not resume the world once claimed")
    a = ap.parse_args()
    world = World.connect(a.host, a.port, token=a.token)
    programs = {}
    for spec in a.turtle:
        tid, _, hand = spec.partition(":")
        t = world.claim(tid)
        programs[t] = (lambda right: lambda turtle: wall_follower(turtle, right_hand=right))(hand != "left")
    if not a.no_resume:
        world.resume()
    errors = World.run_turtles(programs)
    for tid, e in errors.items():
        print("turtle %s: %r" % (tid, e), file=sys.stderr)
    commands = sum(len(t.touches) for t in programs)
    print("done: %s; touches %d" % (world.bye.get("reason") if world.bye else "closed", commands))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
