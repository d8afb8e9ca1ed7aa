#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Views on a served world (issue 13, sections 1 and 5): a program's Display changes reach the
frames, a client's view messages reach every other client's frames and the event log, and a served
run with views logs exactly what `turtlegas run` logs of the same world (views included)."""

import json
import os
import queue
import tempfile
import time

from harness import ROOT, Server, check, main, run
from turtlegas_client import World

TAG = os.path.join(ROOT, "worlds", "tag_views.json")
UNTIL = 12


def frames_until(w, pred, timeout, what):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            f = w.frames.get(timeout=max(0.05, deadline - time.monotonic()))
        except queue.Empty:
            continue
        if pred(f):
            return f
    check(False, "%s: not within %s s" % (what, timeout))


def ids(views):
    return [v["id"] for v in views]


def test_program_and_client_views_reach_frames_and_log():
    with tempfile.TemporaryDirectory() as d:
        headless, served = os.path.join(d, "headless.jsonl"), os.path.join(d, "served.jsonl")
        run(["run", TAG, "--until", UNTIL, "--events", headless])
        with Server(TAG, "--speed", "8", "--paused", "--until", UNTIL, "--events", served) as s:
            watcher = World.connect("127.0.0.1", s.line_port)
            check(ids(watcher.welcome["world"]["views"]) == ["room", "t3-ahead"], "the world file's views in the welcome: %r" % watcher.welcome["world"]["views"])
            watcher.subscribe(rate=30, events=["view", "tag"])
            snap = frames_until(watcher, lambda f: f["type"] == "snapshot", 10, "the snapshot")
            check(ids(snap["views"]) == ["room", "t3-ahead"], "the snapshot's views: %r" % snap["views"])
            check(snap["views"][1]["rotate"] is True and snap["views"][1]["follow"] == "t3", "t3-ahead as the file says")
            # Another client opens a view; the watcher's frames carry it.
            other = World.connect_ws("127.0.0.1", s.http_port)
            other.view_open({"id": "corner", "center": [60, 60], "size": [120, 120], "title": "a corner"})
            f = frames_until(watcher, lambda f: f["type"] == "frame" and "views" in f, 10, "a frame with the client's view")
            check(ids(f["views"]) == ["room", "t3-ahead", "corner"], "client's view in the frames: %r" % ids(f["views"]))
            # The program: t1 (tag_camera, "it" from the start) opens t1-it at t = 0 and closes it
            # once it has tagged someone.
            watcher.resume()
            f = frames_until(watcher, lambda f: f["type"] == "frame" and "views" in f and "t1-it" in ids(f["views"]), 20,
                             "a frame with t1's own view")
            v = [v for v in f["views"] if v["id"] == "t1-it"][0]
            check(v["follow"] == "t1" and v["title"] == "t1 is it", "t1-it follows t1: %r" % v)
            f = frames_until(watcher, lambda f: f["type"] == "frame" and "views" in f and "t1-it" not in ids(f["views"]), 30,
                             "a frame after t1 closed its view")
            check(s.wait(120) == 0, "serve ends at --until: " + s.err()[-2000:])
        lines = [json.loads(x) for x in open(served)]
        views = [e for e in lines if e["kind"] == "view"]
        check([(e["a"], e["op"], e.get("by")) for e in views] == [("corner", "open", None), ("t1-it", "open", "t1"), ("t1-it", "close", "t1")],
              "the served log's view events: %r" % views)
        check(views[0]["t"] == 0 and views[0]["view"]["center"] == [60, 60], "the client's view, logged at t = 0 (paused): %r" % views[0])
        # Everything else is what the headless run logs (its views are the program's only).
        a = [x for x in open(headless)]
        b = [x for x in open(served) if '"a": "corner"' not in x]
        check(len(a) > 20 and a == b, "the served log equals the headless one but for the client's view (%d vs %d lines)" % (len(b), len(a)))


if __name__ == "__main__":
    main([test_program_and_client_views_reach_frames_and_log])
