#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Recording, replay and render (issue 13, sections 3 and 4; docs/recording.md).

- a recording's event lines are the --events log byte for byte, and recording changes nothing;
- its keyframes hold the state of a fresh `run --until t --state-out`, to the bit;
- `turtlegas replay` seeks (forward and back) to 5 random times and its state (GET /api/state,
  and the snapshot message) is a fresh run's to the bit;
- a cut recording and a SIGKILLed run (its R.partial) load up to their last keyframe, with a warning;
- `render` PNG pixels match the scene's geometry; --frames writes fps (T1 - T0) + 1 frames.

Seeded randomness (the seed is printed on failure); every wait is bounded."""

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "server"))
import harness  # noqa: E402
from png import png_pixels  # noqa: E402
from turtlegas_client import World  # noqa: E402

BIN = harness.BIN
SEED = int(os.environ.get("RECORD_TEST_SEED", "20261202"))
TMP = tempfile.mkdtemp(prefix="turtlegas-record-test-")


def run(*args, ok=(0,), timeout=300):
    p = subprocess.run([BIN, *map(str, args)], capture_output=True, timeout=timeout)
    if p.returncode not in ok:
        raise AssertionError("%s exited %d\nstderr: %s" % (args, p.returncode, p.stderr.decode(errors="replace")))
    return p


def path(name):
    return os.path.join(TMP, name)


def read(p, mode="rb"):
    with open(p, mode) as f:
        return f.read()


def fresh_state(world, t, *extra):
    out = path("fresh.json")
    run("run", world, "--until", repr(t), "--state-out", out, *extra)
    return read(out)


def keyframes(rec):
    out = []
    with open(rec, "rb") as f:
        offset = 0
        for line in f:
            if line.startswith(b'{"keyframe":') and line.endswith(b"\n"):
                out.append((offset, json.loads(line)))
            offset += len(line)
    return out


def state_line(text):
    """The state file's text as a keyframe holds it: its layout newlines dropped."""
    return text.replace(b"\n", b"")


def keyframe_state_text(rec, offset):
    with open(rec, "rb") as f:
        f.seek(offset)
        line = f.readline()
    start = line.index(b', "state": ') + len(b', "state": ')
    return line[start:-2]  # the line ends with "}\n" after the state's own closing brace


def check_recording(world, until, rng, *extra):
    rec, events, plain = path("r.tgrec"), path("rec-events.jsonl"), path("plain-events.jsonl")
    run("run", world, "--until", until, "--record", rec, "--events", events, "--keyframe-seconds", 0.5, *extra)
    run("run", world, "--until", until, "--events", plain, *extra)
    ev = read(events)
    assert ev == read(plain), "recording changed the event log of %s" % world
    lines = [l for l in read(rec).splitlines(keepends=True) if l.startswith(b'{"t":')]
    assert b"".join(lines) == ev, "the recording's event lines differ from --events for %s" % world
    header = json.loads(read(rec).split(b"\n", 1)[0])
    assert header["format"] == "turtlegas-recording/1" and header["world"]["format"] == "turtlegas-world/1"
    assert read(rec).rstrip(b"\n").rsplit(b"\n", 1)[1].startswith(b'{"end_of_recording":'), "no end line"
    kfs = keyframes(rec)
    times = [k["t"] for _, k in kfs]
    assert times[0] == 0 and times[-1] == until, times
    assert len(kfs) >= until / 0.5, "expected a keyframe every 0.5 s: %s" % times
    # Keyframes against fresh runs, to the bit (the text is the state file's, numbers round-trip).
    for offset, k in rng.sample(kfs[1:], min(5, len(kfs) - 1)):
        fresh = fresh_state(world, k["t"], *extra)
        assert keyframe_state_text(rec, offset) == state_line(fresh), "keyframe at t=%r differs from a fresh run" % k["t"]
        assert k["state"] == json.loads(fresh)
    return rec


def get_state(server):
    with urllib.request.urlopen("http://127.0.0.1:%d/api/state" % server.http_port, timeout=30) as r:
        return r.read()


def check_replay(rec, world, until, rng, *extra):
    server = harness.Server(rec, "--paused", command="replay")
    try:
        w = World.connect(port=server.line_port, timeout=60)
        assert "replay" in w.welcome["capabilities"], w.welcome
        times = sorted(rng.uniform(0, until) for _ in range(5))
        # Forward and back: every other seek goes backwards (the world is rebuilt and re-simulated).
        order = [times[4], times[0], times[3], times[1], times[2]]
        for t in order:
            r = w.request({"type": "seek", "t": t}, timeout=120)
            assert r["status"]["t"] == t and r["status"]["paused"], r
            fresh = fresh_state(world, t, *extra)
            got = get_state(server)
            assert got == fresh, "replay state at t=%r differs from a fresh run (seed %d)" % (t, SEED)
            snap = w.request({"type": "snapshot"}, timeout=60)
            assert snap["t"] == t, snap
            want = json.loads(fresh)
            for tu, s in zip(want["turtles"], snap.get("turtles", [])):
                assert tu["id"] == s["id"] and all(abs(a - b) <= 1e-6 * max(1, abs(a)) for a, b in zip(tu["pos"], s["pos"])), (tu, s)
        # Refusals: a replay does not change the world; seeking past the end is an error.
        try:
            w.request({"type": "seek", "t": until * 2})
            raise AssertionError("seek past the end accepted")
        except Exception as e:  # ServerError
            assert "bad_value" in str(e) or "end" in str(e), e
        # Reverse plays backwards, and stops at 0.
        w.request({"type": "speed", "factor": "max"})
        w.request({"type": "reverse"})
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and json.loads(get_state(server))["t"] != 0:
            time.sleep(0.2)
        back = json.loads(get_state(server))
        assert back == keyframes(rec)[0][1]["state"], "reverse did not come back to the state at t = 0 (t = %r)" % back["t"]
        w.close()
    finally:
        server.stop()


def check_cut(rec):
    data = read(rec)
    kfs = keyframes(rec)
    cut = path("cut.tgrec")
    at = (kfs[len(kfs) // 2][0] + kfs[len(kfs) // 2 + 1][0]) // 2  # between two keyframes
    with open(cut, "wb") as f:
        f.write(data[:at])
    last = [k for off, k in kfs if off + 1 < at and data.index(b"\n", off) < at][-1]
    server = harness.Server(cut, "--paused", command="replay")
    try:
        w = World.connect(port=server.line_port, timeout=60)
        rep = w.welcome["status"]["replay"]
        assert rep["end"] == last["t"] and rep["complete"] is False, (rep, last["t"])
        w.request({"type": "seek", "t": last["t"]}, timeout=120)
        assert json.loads(get_state(server)) == last["state"]
        w.close()
    finally:
        server.stop()
    err = server.err()
    assert "incomplete" in err and "recovered" in err, err
    p = run("render", cut, "--at", last["t"], "--out", path("cut.svg"))
    assert b"incomplete" in p.stderr, p.stderr


def check_killed():
    rec = path("killed.tgrec")
    proc = subprocess.Popen([BIN, "run", os.path.join(ROOT, "worlds", "gas.json"), "--until", "100000", "--record", rec,
                             "--keyframe-seconds", "1"], stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    partial = rec + ".partial"  # R itself appears only when the recording is whole
    while time.monotonic() < deadline and (not os.path.exists(partial) or read(partial).count(b'\n{"keyframe":') < 4):
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not os.path.exists(rec), "a killed run's recording was put in place as if whole"
    kfs = keyframes(partial)
    assert len(kfs) >= 4, "the killed run left no keyframes"
    p = run("render", partial, "--at", kfs[-1][1]["t"], "--out", path("killed.svg"))
    assert b"incomplete" in p.stderr and b"recovered" in p.stderr, p.stderr


def check_render():
    world = os.path.join(ROOT, "tests", "cli", "worlds", "render_scene.json")
    png = path("scene.png")
    run("render", world, "--at", 0, "--out", png)
    w, h, rows = png_pixels(read(png))
    # write_svg's layout: 800 px across the longer side (200 units: 4 px a unit), margin 12, title 30.
    s, left, top = 4.0, 12.0, 42.0
    px = lambda x, y: rows[int(top + (100 - y) * s)][int(left + x * s)]
    near = lambda c, want, tol=12: all(abs(a - b) <= tol for a, b in zip(c, want))
    floor = (0xf7, 0xf7, 0xf7)
    assert near(px(150, 50), floor), px(150, 50)            # empty arena
    assert near(px(100, 50), (0x22, 0x22, 0x22), 40), px(100, 50)  # the wall x = 100, y 20..80
    assert near(px(100, 90), floor), px(100, 90)            # above the wall's end
    assert near(px(0, 50), (0x22, 0x22, 0x22), 60), px(0, 50)      # the arena's left wall
    body = tuple(round(0.8 * c + 0.2 * f) for c, f in zip((0x4e, 0x79, 0xa7), floor))
    assert near(px(50, 56), body, 16), (px(50, 56), body)   # the turtle's disc (above its heading tick)
    assert near(px(56, 50), (0x22, 0x22, 0x22), 60), px(56, 50)    # its heading tick, east (90 degrees)
    assert near(px(50, 44), body, 16) and near(px(44, 50), body, 16)
    assert near(px(50, 63), floor), px(50, 63)              # just outside its radius of 10
    # No balls, so no speed legend and no 90 px column for it (issue 32); sides even (an mp4's).
    assert (w, h) == (int(200 * s + 24), int(100 * s + 30 + 24)), (w, h)
    # Later, the turtle has moved: at t = 1 s it drove 20 units east (speed 20).
    run("render", world, "--at", 1, "--out", png)
    _, _, rows = png_pixels(read(png))
    assert near(px(70, 56), body, 16), px(70, 56)
    assert near(px(44, 50), floor), px(44, 50)
    # --view: a fixed view crops (40 x 40 units around the turtle's start: 20 px a unit) ...
    run("render", world, "--at", 0, "--view", "corner", "--out", png)
    w, h, rows = png_pixels(read(png))
    assert (w, h) == (800 + 24, 800 + 30 + 24), (w, h)
    vx = lambda x, y, size, sc: rows[int(top + (size / 2 - y) * sc)][int(left + (x + size / 2) * sc)]
    assert near(vx(0, 6, 40, 20), body, 16), vx(0, 6, 40, 20)        # the turtle at the view's centre
    assert near(vx(6, 0, 40, 20), (0x22, 0x22, 0x22), 60)          # its tick, east
    assert near(vx(0, 15, 40, 20), floor), vx(0, 15, 40, 20)       # outside its radius
    # ... and a follow view with rotate keeps the moving turtle centred, heading up: at t = 1 s it
    # is at (70, 50) heading east, and the wall x = 100 is 30 units ahead: at the view's top edge.
    run("render", world, "--at", 1, "--view", "cam", "--out", png)
    w, h, rows = png_pixels(read(png))
    sc = 800 / 60
    assert near(vx(0, 6, 60, sc), (0x22, 0x22, 0x22), 60), vx(0, 6, 60, sc)   # the tick points up
    assert near(vx(0, -6, 60, sc), body, 16) and near(vx(6, 0, 60, sc), body, 16) and near(vx(-6, 0, 60, sc), body, 16)
    edge = [rows[int(top) + k][int(left + 30 * sc)] for k in range(2)]              # the wall, ahead: the top edge
    assert any(near(c, (0x22, 0x22, 0x22), 60) for c in edge), edge
    assert near(vx(0, 20, 60, sc), floor), vx(0, 20, 60, sc)
    p = run("render", world, "--at", 1, "--view", "nope", "--out", png, ok=(2,))
    assert b"corner" in p.stderr and b"cam" in p.stderr, p.stderr
    # Frames: fps (T1 - T0) + 1 of them, numbered from 0.
    frames = path("frames")
    run("render", world, "--frames", frames, "--fps", 10, "--from", 0.5, "--to", 1.5)
    names = sorted(os.listdir(frames))
    assert names == ["frame-%05d.png" % k for k in range(11)], names
    # A window of an odd pixel height: the frame's sides are made even, the extra row white (an mp4
    # needs even sides, and ffmpeg's padding of an odd one was a black row).
    odd = path("odd")
    run("render", world, "--frames", odd, "--fps", 1, "--from", 0, "--to", 0, "--width", 1001)  # 500.5 + 54 px high
    w, h, rows = png_pixels(read(os.path.join(odd, "frame-00000.png")))
    assert w % 2 == 0 and h % 2 == 0, (w, h)
    assert all(c == (255, 255, 255) for c in rows[-1]) and all(r[-1] == (255, 255, 255) for r in rows), "white edges"
    # A turtle's id at the right edge stays in the picture, drawn to its left (it was cut off).
    edge = path("edge.json")
    with open(world) as f:
        scene = json.load(f)
    scene["turtles"][0]["pos"] = [188, 50]
    scene["turtles"][0]["id"] = "a-long-turtle-name"
    scene["views"] = []
    with open(edge, "w") as f:
        json.dump(scene, f)
    run("render", edge, "--at", 0, "--out", png)
    w, h, rows = png_pixels(read(png))
    # The turtle's disc spans x 712..772 px; its upper edge is at y 202 px, where the label's baseline goes.
    cx, cy, r = left + 188 * s, top + 50 * s, 10 * s
    dark = lambda x0, x1: sum(1 for y in range(int(cy - r - 14), int(cy - r + 2)) for x in range(int(x0), int(x1))
                              if max(rows[y][x]) < 80)
    assert dark(cx - r - 130, cx - r - 1) > 20, "the label, left of the turtle"
    assert w >= cx + r, (w, cx)
    # An SVG from the same scene.
    run("render", world, "--at", 0.25, "--out", path("scene.svg"))
    assert b"<svg" in read(path("scene.svg"))
    # Video: through ffmpeg when installed, else a clear refusal (exit 2).
    env_no_ffmpeg = dict(os.environ, PATH="/nonexistent")
    p = subprocess.run([BIN, "render", world, "--video", path("v.mp4"), "--to", "0.5"], capture_output=True, env=env_no_ffmpeg)
    assert p.returncode == 2 and b"ffmpeg" in p.stderr, p
    if shutil.which("ffmpeg"):
        run("render", world, "--video", path("v.mp4"), "--to", 0.5)
        assert read(path("v.mp4"))[4:8] == b"ftyp"
    # Bad input: exit 2, naming the fix.
    p = run("render", world, "--at", 1, "--out", path("x.gif"), ok=(2,))
    assert b".svg or .png" in p.stderr


def check_replay_warns(rec, at):
    """Seeks a replay of `rec` forward and back; its stderr names the first difference once."""
    server = harness.Server(rec, "--paused", command="replay")
    try:
        w = World.connect(port=server.line_port, timeout=60)
        for t in (2.5, 0.5, 2.5):
            r = w.request({"type": "seek", "t": t}, timeout=120)
            assert r["status"]["t"] == t, r
        w.close()
    finally:
        server.stop()
    err = server.err()
    assert "this replay differs from the recording's keyframe" in err, err
    assert " here, " in err and " in the recording" in err, err
    if at:
        assert at in err, err
    assert err.count("differs from the recording") == 1, err


def check_altered(rec):
    """A render re-simulates the recording's header world: it checks the run against each keyframe it
    passes and names the first difference (before: an altered header world drew another run without a
    word)."""
    png = path("altered.png")
    p = run("render", rec, "--at", 2.5, "--out", png)
    assert b"differs from the recording" not in p.stderr, p.stderr
    server = harness.Server(rec, "--paused", command="replay")
    try:
        w = World.connect(port=server.line_port, timeout=60)
        w.request({"type": "seek", "t": 2.5}, timeout=120)
        w.close()
    finally:
        server.stop()
    assert "differs from the recording" not in server.err(), server.err()
    data = read(rec)
    header, rest = data.split(b"\n", 1)
    # The same length, so that the index's byte offsets still hold: only the physics changes.
    for old, new, at in ((b'"restitution":1.0', b'"restitution":0.9', None), (b'"seed":7,', b'"seed":8,', "t = 0 s")):
        assert old in header, header[:400]
        altered = path("altered.tgrec")
        with open(altered, "wb") as f:
            f.write(header.replace(old, new, 1) + b"\n" + rest)
        p = run("render", altered, "--at", 2.5, "--out", png)
        err = p.stderr.decode()
        assert "this run differs from the recording's keyframe" in err, err
        assert " here, " in err and " in the recording" in err, err
        if at:
            assert at in err, err
        assert err.count("differs from the recording") == 1, err  # once
        # `replay` checks the keyframes it passes as render does (before: it showed another run
        # without a word).
        check_replay_warns(altered, at)
    # A header re-written with spaces after the colons is still a recording (before: read as a world
    # file and refused, exit 2).
    spaced = path("spaced.tgrec")
    with open(spaced, "wb") as f:
        f.write(json.dumps(json.loads(header)).encode() + b"\n" + rest)
    p = run("render", spaced, "--at", 1.0, "--out", path("spaced.svg"))
    assert b"not a world" not in p.stderr and os.path.getsize(path("spaced.svg")) > 1000, p.stderr
    # A crash can leave a recording with a zero-filled tail and no newline: it is not read as one
    # line (before: a 6 GB tail took 9 s and all memory). Here 1 GiB, sparse: the render's peak
    # memory stays far below it.
    zeros = path("zeros.tgrec")
    with open(zeros, "wb") as f:
        f.write(data[: data.rfind(b'{"index"')])
        f.truncate(f.tell() + (1 << 30))
    with open(path("zeros.err"), "wb") as err:
        child = subprocess.Popen([BIN, "render", zeros, "--at", "1", "--out", path("zeros.svg")], stderr=err,
                                 stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
    child.returncode = 0  # reaped by wait4
    peak_mib = usage.ru_maxrss / 1024
    assert os.waitstatus_to_exitcode(status) == 0 and b"the recording is incomplete" in read(path("zeros.err"))
    assert peak_mib < 256, "reading a zero-filled tail took %.0f MiB" % peak_mib
    os.remove(zeros)


def main():
    rng = random.Random(SEED)
    try:
        gas = os.path.join(ROOT, "worlds", "gas.json")
        rec = check_recording(gas, 3.0, rng)
        check_replay(rec, gas, 3.0, rng)
        check_cut(rec)
        check_altered(rec)
        tag = os.path.join(ROOT, "worlds", "tag.json")
        rec = check_recording(tag, 4.0, rng)
        check_replay(rec, tag, 4.0, rng)
        check_recording(os.path.join(ROOT, "worlds", "pen_walls.json"), 3.0, rng, "--mode", "step")
        # Views: a program's view events are in the log, so in the recording (tag_camera opens one).
        views = check_recording(os.path.join(ROOT, "worlds", "tag_views.json"), 4.0, rng)
        assert b'"kind": "view"' in read(views), "no view events in the recording of tag_views.json"
        check_killed()
        check_render()
    except AssertionError:
        print("record_test: failed with seed %d (RECORD_TEST_SEED=%d reproduces it)" % (SEED, SEED))
        raise
    finally:
        shutil.rmtree(TMP, ignore_errors=True)
    print("record_test: ok")


if __name__ == "__main__":
    main()
