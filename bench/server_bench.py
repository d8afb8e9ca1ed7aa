#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The world server's benchmark (issue 12, section 7; figures in docs/performance.md). Not a test.

    python3 bench/server_bench.py [--turtlegas build/release/turtlegas] [--quick]

1. Frames per second and bandwidth to 1, 10 and 50 viewers of a gas of 10^3 and 10^4 balls at
   30 frames/s, JSON over TCP lines and binary over WebSocket (the viewers count bytes and frames
   without decoding, so that the client is not what is measured).
2. Round-trip latency of a remote command in lockstep: pen commands (answered at the same control
   boundary: protocol and scheduling only) and `left 1` (one control step each), from Python over
   TCP lines; and the Python wall follower's commands per second.
3. Simulation speed of the 10^3-ball gas at --speed max with and without 50 viewers, A/B
   interleaved, the median of the per-pair ratios.
"""

import argparse
import json
import os
import socket
import statistics
import struct
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "server"))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
import harness  # noqa: E402
from turtlegas_client import Closed, World  # noqa: E402


def gas_world(n, path):
    side = 1600 if n <= 1000 else 5000
    json.dump({"format": "turtlegas-world/1", "name": "gas %d" % n, "seed": 12,
               "arena": {"width": side, "height": side, "boundary": "walls"},
               "effects": {"restitution": 1.0, "ball_ball": True},
               "gas": [{"count": n, "radius": 5, "mass": 1, "speed": 100, "region": [[0, 0], [side, side]], "seed": 7}]},
              open(path, "w"))
    return path


class LineCounter(threading.Thread):
    def __init__(self, port, rate):
        super().__init__(daemon=True)
        self.sock = socket.create_connection(("127.0.0.1", port))
        self.sock.sendall(b'{"type": "hello", "protocol": "turtlegas/1"}\n' +
                          (b'{"type": "subscribe", "rate": %d}\n' % rate))
        self.bytes = self.lines = 0
        self.counting = False
        self.stop = False

    def run(self):
        while not self.stop:
            data = self.sock.recv(1 << 20)
            if not data:
                break
            if self.counting:
                self.bytes += len(data)
                self.lines += data.count(b"\n")


class WsCounter(threading.Thread):
    def __init__(self, port, rate):
        super().__init__(daemon=True)
        self.sock = socket.create_connection(("127.0.0.1", port))
        self.sock.sendall(b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                          b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n" % port)
        self.f = self.sock.makefile("rb")
        while self.f.readline() not in (b"\r\n", b""):
            pass
        for text in (b'{"type": "hello", "protocol": "turtlegas/1"}', b'{"type": "subscribe", "rate": %d, "format": "binary"}' % rate):
            self.sock.sendall(bytes([0x81, 0x80 | len(text)]) + b"\0\0\0\0" + text)
        self.bytes = self.frames = 0
        self.counting = False
        self.stop = False
        self.binary = False

    def run(self):
        while not self.stop:
            h = self.f.read(2)
            if len(h) < 2:
                break
            n = h[1] & 0x7F
            if n == 126:
                n = struct.unpack("!H", self.f.read(2))[0]
            elif n == 127:
                n = struct.unpack("!Q", self.f.read(8))[0]
            self.f.read(n)
            opcode = h[0] & 0x0F
            if self.counting and opcode in (0, 2):  # a binary message, or a continuation of one
                self.bytes += n
                self.frames += 1 if (h[0] & 0x80) and (opcode == 2 or self.binary) else 0
            if opcode in (1, 2):
                self.binary = opcode == 2


def cpp_frames_bench(n_balls, viewers, seconds, d, reader):
    """The same measure with the C++ reader (bench/server_viewers.cpp) over WebSocket, binary."""
    import subprocess
    w = gas_world(n_balls, os.path.join(d, "gas%d.json" % n_balls))
    with harness.Server(w, "--speed", "1") as s:
        out = subprocess.run([reader, str(s.http_port), str(viewers), "30", str(seconds), "binary"],
                             capture_output=True, text=True, timeout=120 + seconds)
        s.stop()
    r = json.loads(out.stdout)
    r.update({"balls": n_balls, "transport": "binary/ws (C++ reader)"})
    return r


def frames_bench(n_balls, viewers, transport, seconds, d):
    w = gas_world(n_balls, os.path.join(d, "gas%d.json" % n_balls))
    with harness.Server(w, "--speed", "1") as s:
        cls = LineCounter if transport == "json/lines" else WsCounter
        port = s.line_port if cls is LineCounter else s.http_port
        vs = [cls(port, 30) for _ in range(viewers)]
        for v in vs:
            v.start()
        time.sleep(1.0)
        for v in vs:
            v.counting = True
        t0 = time.monotonic()
        time.sleep(seconds)
        wall = time.monotonic() - t0
        for v in vs:
            v.counting = False
        total_bytes = sum(v.bytes for v in vs)
        frames = sum(getattr(v, "frames", 0) or getattr(v, "lines", 0) for v in vs)
        s.stop()
    return {"balls": n_balls, "viewers": viewers, "transport": transport,
            "frames_per_s_per_viewer": frames / wall / viewers, "MB_per_s": total_bytes / wall / 1e6,
            "MB_per_s_per_viewer": total_bytes / wall / 1e6 / viewers}


def latency_bench(n, d):
    out = {}
    with harness.Server(harness.world("wall_touch.json"), "--speed", "max", "--paused") as s:
        w = World.connect("127.0.0.1", s.line_port)
        t = w.claim("t1")
        w.resume()
        for name, cmd in (("pen (same boundary)", lambda: t.pen_down()), ("left 1 (one control step)", lambda: t.left(1))):
            for _ in range(50):
                cmd()
            samples = []
            for _ in range(n):
                a = time.perf_counter()
                cmd()
                samples.append(time.perf_counter() - a)
            samples.sort()
            out[name] = {"median_us": 1e6 * samples[len(samples) // 2], "p90_us": 1e6 * samples[int(0.9 * len(samples))],
                         "commands_per_s": len(samples) / sum(samples)}
        s.stop()
    # The wall follower example, two turtles, lockstep, flat out.
    import importlib.util
    spec = importlib.util.spec_from_file_location("wf", os.path.join(ROOT, "clients", "python", "examples", "wall_follower.py"))
    wf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(wf)
    with harness.Server(harness.world("remote_followers.json"), "--speed", "max", "--paused", "--until", 600,
                        "--inputs-out", os.path.join(d, "inputs.jsonl")) as s:
        w = World.connect("127.0.0.1", s.line_port)
        r, l = w.claim("righty"), w.claim("lefty")
        w.resume()
        a = time.perf_counter()
        World.run_turtles({r: lambda t: wf.wall_follower(t, True), l: lambda t: wf.wall_follower(t, False)})
        wall = time.perf_counter() - a
        s.wait(60)
        commands = sum(1 for _ in open(os.path.join(d, "inputs.jsonl"))) - 1
    out["python wall follower (2 turtles, 600 s simulated)"] = {"commands": commands, "wall_s": wall, "commands_per_s": commands / wall}
    return out


def sim_speed_bench(pairs, until, d):
    w = harness.world("gas_1000.json")

    def one(viewers):
        with harness.Server(w, "--speed", "max", "--paused", "--until", until) as s:
            vs = [LineCounter(s.line_port, 30) for _ in range(viewers)]
            for v in vs:
                v.start()
            time.sleep(0.5)
            World.connect("127.0.0.1", s.line_port).resume()
            a = time.perf_counter()
            s.wait(600)
            return time.perf_counter() - a

    ratios, bare, watched = [], [], []
    for _ in range(pairs):
        b = one(0)
        v = one(50)
        bare.append(b)
        watched.append(v)
        ratios.append(v / b)
    return {"until": until, "bare_s": bare, "with_50_viewers_s": watched, "median_ratio": statistics.median(ratios)}


def cpp_sim_speed_bench(pairs, until, n_balls, viewers, d, reader):
    """Simulation speed of an n_balls gas at --speed max with `viewers` C++ readers of binary
    frames at 30/s (bench/server_viewers) against none: wall seconds to --until, interleaved
    pairs (bare, watched), and the median ratio watched / bare."""
    import subprocess
    w = gas_world(n_balls, os.path.join(d, "gas%d.json" % n_balls))

    def one(k):
        with harness.Server(w, "--speed", "max", "--paused", "--until", until) as s:
            p = None
            if k:
                p = subprocess.Popen([reader, str(s.http_port), str(k), "30", "600", "binary"],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                time.sleep(1.5)  # all connected and subscribed
            World.connect("127.0.0.1", s.line_port).resume()
            a = time.perf_counter()
            s.wait(600)
            wall = time.perf_counter() - a
            if p:
                p.kill()
                p.wait()
            return wall

    ratios, bare, watched = [], [], []
    for _ in range(pairs):
        b = one(0)
        v = one(viewers)
        bare.append(b)
        watched.append(v)
        ratios.append(v / b)
    return {"balls": n_balls, "viewers": viewers, "reader": "C++ binary/ws", "until": until, "bare_s": bare,
            "with_viewers_s": watched, "ratios": ratios, "median_ratio": statistics.median(ratios)}


def per_step_wall_follower_bench(until, d):
    """A wall follower written as a robot control loop: one command per control step (a step's
    worth of forward, or of turning), deciding on each result. Each command is one round trip and
    one control step, so commands/s is the round-trip rate. One turtle, one connection, lockstep."""
    with harness.Server(harness.world("remote_followers.json"), "--speed", "max", "--paused", "--until", until,
                        "--inputs-out", os.path.join(d, "inputs_step.jsonl")) as s:
        w = World.connect("127.0.0.1", s.line_port)
        t = w.claim("righty")
        info = w.welcome["world"]
        dt = info["dt"]
        step_len, step_turn = 40 * dt, 180 * dt  # the turtle's speed and turn rate (remote_followers.json)
        w.resume()
        a = time.perf_counter()
        try:
            turning = 0  # steps of turning left still to do
            probe = 0
            while True:
                if turning:
                    t.left(step_turn)
                    turning -= 1
                    continue
                r = t.forward(step_len)
                if r.touched:
                    t.back(step_len)
                    turning = int(round(90 / step_turn))
                    continue
                probe += 1
                if probe % 15 == 0:  # now and then, lean towards the wall on the right
                    t.right(step_turn)
        except Closed:
            pass
        wall = time.perf_counter() - a
        s.wait(60)
        commands = sum(1 for _ in open(os.path.join(d, "inputs_step.jsonl"))) - 1
    return {"python per-step wall follower (1 turtle)": {"commands": commands, "steps": int(round(until / dt)),
                                                          "wall_s": wall, "commands_per_s": commands / wall}}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", default=os.path.join(ROOT, "build", "release", "turtlegas"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--cpp-viewers", help="bench/server_viewers (built with the benchmarks): C++ readers for the binary frames")
    ap.add_argument("--only", choices=("frames", "latency", "speed", "cpp-frames", "cpp-speed", "per-step"), help="run one part")
    a = ap.parse_args()
    harness.BIN = a.turtlegas
    secs = 2.0 if a.quick else 4.0
    with tempfile.TemporaryDirectory() as d:
        if a.only in (None, "frames"):
            for n in (1000, 10000):
                for transport in ("json/lines", "binary/ws"):
                    for viewers in (1, 10, 50):
                        print(json.dumps(frames_bench(n, viewers, transport, secs, d)), flush=True)
                if a.cpp_viewers:
                    for viewers in (1, 10, 50):
                        print(json.dumps(cpp_frames_bench(n, viewers, secs, d, a.cpp_viewers)), flush=True)
        if a.only in (None, "latency"):
            print(json.dumps(latency_bench(500 if a.quick else 2000, d)), flush=True)
        if a.only in (None, "speed"):
            print(json.dumps(sim_speed_bench(3 if a.quick else 5, 20 if a.quick else 40, d)), flush=True)
        if a.only == "cpp-frames":
            for viewers in (1, 10, 50):
                print(json.dumps(cpp_frames_bench(10000, viewers, secs, d, a.cpp_viewers)), flush=True)
        if a.only in (None, "cpp-speed") and a.cpp_viewers:
            print(json.dumps(cpp_sim_speed_bench(3 if a.quick else 5, 20 if a.quick else 40, 10000, 50, d, a.cpp_viewers)), flush=True)
        if a.only in (None, "per-step"):
            print(json.dumps(per_step_wall_follower_bench(100 if a.quick else 300, d)), flush=True)


if __name__ == "__main__":
    main()
