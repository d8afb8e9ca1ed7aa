#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`turtlegas serve --record` (issue 13, section 3; docs/recording.md, "Recording a served run"):
the recording of a served run, with a remote turtle driven by a client, bodies spawned, removed and
teleported, a wall added and a view opened by a client, replays; its keyframes and the replay's
states at random times equal a fresh `turtlegas run --until t --inputs` of the same world with the
served run's input log, to the byte; its event lines are the served `--events`; the client's view
is in the replay. A served run stopped by SIGINT leaves a whole recording. In a replay, views a
client opened survive a seek backwards (which rebuilds the world).

Seeded randomness (the seed is printed on failure); every wait is bounded."""

import json
import os
import random
import signal
import tempfile
import threading
import time
import urllib.request

from harness import Server, check, main, run, world
from turtlegas_client import World

SEED = int(os.environ.get("RECORD_TEST_SEED", "20261202"))
UNTIL = 12
ROOM = world("bodies_room.json")


def fresh_state(t, mode, inputs):
    return run(["run", ROOM, "--until", repr(t), "--mode", mode, "--inputs", inputs, "--state-out", "-"]).stdout


def get_state(server):
    with urllib.request.urlopen("http://127.0.0.1:%d/api/state" % server.http_port, timeout=60) as r:
        return r.read().decode()


def lines_of(path):
    return open(path, "rb").read().decode().splitlines()


def applied(a, message):
    """Sends a world change and steps the paused world until the change's boundary answers it."""
    got = {}
    th = threading.Thread(target=lambda: got.setdefault("r", a.request(message, timeout=60)))
    th.start()
    while th.is_alive():
        a.step()
        th.join(0.05)
    check(got.get("r", {}).get("type") == "ok", "%r applied: %r" % (message, got.get("r")))
    return got["r"]


def session(a, b):
    """Every kind of input a served world takes: spawns, a wall, a remote turtle's commands,
    teleports, removals."""
    applied(a, {"type": "spawn", "ball": {"id": "b-new", "pos": [200, 200], "vel": [0, -30], "radius": 4}})
    applied(a, {"type": "add_wall", "wall": {"id": "w-new", "from": [20, 120], "to": [120, 120]}})
    t = b.claim("t1")
    a.resume()
    res = t.forward(60)
    check(abs(res.done - 60) < 1e-9 or res.touched, "t1 drove: %r" % res.reply)
    t.left(90)
    t.forward(30)
    a.pause()  # answered while the world waits for t1's next command (lockstep)
    b.release("t1")
    applied(a, {"type": "teleport", "body": "b-new", "pos": [100, 250], "vel": [10, 10]})
    applied(a, {"type": "remove", "body": "t2"})
    applied(a, {"type": "spawn", "ball": {"id": "b-3", "pos": [330, 120], "vel": [-20, 5], "radius": 3}})
    applied(a, {"type": "remove", "body": "b-new"})


def served_run(d, mode):
    served, inputs, rec = (os.path.join(d, n) for n in ("served.jsonl", "inputs.jsonl", "r.tgrec"))
    with Server(ROOM, "--paused", "--speed", "max", "--mode", mode, "--until", UNTIL, "--events", served,
                "--inputs-out", inputs, "--record", rec, "--keyframe-seconds", "1") as s:
        a = World.connect("127.0.0.1", s.line_port)
        b = World.connect_ws("127.0.0.1", s.http_port)
        a.view_open({"id": "cam", "follow": "t1", "size": [120, 90], "title": "t1 seen by a client"})
        session(a, b)
        a.view_open({"id": "corner", "center": [60, 60], "size": [120, 120]})
        a.resume()
        check(s.wait(120) == 0, "serve exits 0 at --until: " + s.err()[-2000:])
    return served, inputs, rec


def check_recording(served, inputs, rec, mode, rng):
    text = lines_of(rec)
    header = json.loads(text[0])
    check(header["format"] == "turtlegas-recording/1" and header["command"] == "serve" and header["until"] == UNTIL,
          "the header: %r" % {k: header[k] for k in header if k != "world"})
    check(text[-1].startswith('{"end_of_recording":'), "a clean end: %r" % text[-1][:80])
    index = json.loads(text[-2])
    check(index["stopped"] == "" and index["end"] == UNTIL, "the index: end %r, stopped %r" % (index["end"], index["stopped"]))
    # The event lines are the served run's --events, byte for byte.
    events = [x for x in text if x.startswith('{"t":')]
    check(events == lines_of(served), "the recording's events are the served log (%d vs %d lines)" % (len(events), len(lines_of(served))))
    # The inputs are the input log's (its header aside), in order, with the client's views among them.
    taken = [x for x in text if x.startswith('{"step":')]
    for key in ('"command": "forward"', '"command": "left"', '"spawn": {"ball"', '"add_wall"', '"teleport"', '"remove": "t2"'):
        check(any(key in x for x in taken), "the recording's inputs have %s" % key)
    check([x for x in taken if '"view": {"op"' not in x] == lines_of(inputs)[1:], "the recording's inputs are the input log's")
    views = [json.loads(x) for x in taken if '"view": {"op"' in x]
    check([(v["view"]["op"], v["view"]["view"]["id"]) for v in views] == [("open", "cam"), ("open", "corner")],
          "the client's views among the inputs: %r" % views)
    # Keyframes: every simulated second, bit-exact against fresh runs with the input log.
    keys = [json.loads(x) for x in text if x.startswith('{"keyframe":')]
    check([k["t"] for k in keys] == list(range(0, UNTIL + 1)), "keyframes at 0, 1, ..., %d: %r" % (UNTIL, [k["t"] for k in keys]))
    for k in [keys[0], keys[-1]] + rng.sample(keys[1:-1], 3):
        want = json.loads(fresh_state(k["t"], mode, inputs))
        check(k["state"] == want, "%s: the keyframe at t=%r equals a fresh run with --inputs (seed %d)" % (mode, k["t"], SEED))


def check_replay(rec, inputs, mode, rng):
    server = Server(rec, "--paused", command="replay")
    try:
        w = World.connect(port=server.line_port, timeout=60)
        check("replay" in w.welcome["capabilities"], "a replay: %r" % w.welcome["capabilities"])
        times = sorted(rng.uniform(0, UNTIL) for _ in range(5))
        for t in [times[4], times[0], times[3], times[1], times[2]]:  # forward and back
            r = w.request({"type": "seek", "t": t}, timeout=120)
            check(r["status"]["t"] == t, "seeked: %r" % r)
            got, want = get_state(server), fresh_state(t, mode, inputs)
            check(got == want, "%s: the replay's state at t=%r equals a fresh run with --inputs (seed %d)" % (mode, t, SEED))
            # The recorded client's views are the replay's from t = 0 on (opened while paused at 0).
            snap = w.request({"type": "snapshot"}, timeout=60)
            ids = [v["id"] for v in snap["views"]]
            check("cam" in ids, "the served client's view 'cam' in the replay at t=%r: %r" % (t, ids))
        # A view this replay's client opens survives a seek backwards (the world is rebuilt).
        w.request({"type": "seek", "t": 9.0}, timeout=120)
        w.request({"type": "view_open", "view": {"id": "mine", "follow": "t1", "size": [50, 50], "rotate": True}})
        w.request({"type": "view_change", "view": {"id": "mine", "size": [70, 60]}})
        w.request({"type": "seek", "t": 2.0}, timeout=120)
        snap = w.request({"type": "snapshot"}, timeout=60)
        mine = [v for v in snap["views"] if v["id"] == "mine"]
        check(len(mine) == 1 and mine[0]["size"] == [70, 60] and mine[0]["rotate"] is True and mine[0]["follow"] == "t1",
              "the replay client's view after a seek back: %r" % snap["views"])
        check(get_state(server) == fresh_state(2.0, mode, inputs), "and the state is still the fresh run's")
        w.request({"type": "view_close", "view": "mine"})
        w.request({"type": "seek", "t": 1.0}, timeout=120)
        snap = w.request({"type": "snapshot"}, timeout=60)
        check("mine" not in [v["id"] for v in snap["views"]], "a closed view stays closed after a seek back: %r" % snap["views"])
        w.close()
    finally:
        server.stop()


def test_served_recording_exact():
    rng = random.Random(SEED)
    with tempfile.TemporaryDirectory() as d:
        served, inputs, rec = served_run(d, "exact")
        check_recording(served, inputs, rec, "exact", rng)
        check_replay(rec, inputs, "exact", rng)


def test_served_recording_step():
    rng = random.Random(SEED + 1)
    with tempfile.TemporaryDirectory() as d:
        served, inputs, rec = served_run(d, "step")
        check_recording(served, inputs, rec, "step", rng)


def test_signal_closes_the_recording():
    with tempfile.TemporaryDirectory() as d:
        rec, inputs = os.path.join(d, "r.tgrec"), os.path.join(d, "inputs.jsonl")
        with Server(ROOM, "--speed", "20", "--record", rec, "--inputs-out", inputs, "--keyframe-seconds", "0.5") as s:
            w = World.connect("127.0.0.1", s.line_port)
            deadline = time.monotonic() + 60
            while w.request({"type": "ping"})["t"] < 2.0 and time.monotonic() < deadline:
                time.sleep(0.25)
            check(s.stop(signal.SIGTERM) == 0, "serve ends cleanly on SIGTERM: " + s.err()[-2000:])
        text = lines_of(rec)
        check(text[-1].startswith('{"end_of_recording":'), "the recording is whole after SIGTERM: %r" % text[-1][:80])
        index = json.loads(text[-2])
        check(index["stopped"] == "signal" and index["end"] >= 2.0, "the index says why: %r" % {k: index[k] for k in ("end", "stopped")})
        last = json.loads([x for x in text if x.startswith('{"keyframe":')][-1])
        check(last["t"] == index["end"], "the last keyframe is at the end")
        check(last["state"] == json.loads(fresh_state(last["t"], "exact", inputs)), "and equals a fresh run there")
        r = run(["render", rec, "--at", repr(index["end"]), "--out", os.path.join(d, "end.svg")])
        check("incomplete" not in r.stderr, "the recording reads without a warning: " + r.stderr)


if __name__ == "__main__":
    main([test_served_recording_exact, test_served_recording_step, test_signal_closes_the_recording])
