#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Slow and stalling clients do not slow the others (issue 12, section 6): beside a client that
never reads its frames, one that sends half a WebSocket frame and stalls, one that sends half a
line and stalls, and one that sends half an HTTP request, a good viewer of a 10^3-ball gas gets
its frames and the world keeps pace. Asserted on counters: the good client's frames against its
rate, the never-reader's dropped frames, the world's simulated time against the wall clock."""

import json
import socket
import time

from harness import Server, check, main, world
from turtlegas_client import World

SECONDS = 4.0
RATE = 20


def test_stallers_do_not_slow_a_good_viewer():
    with Server(world("gas_1000.json"), "--speed", "1") as s:
        # The never-reader: a tiny receive buffer, subscribed at the highest rate, never reads.
        lazy = socket.socket()
        lazy.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        lazy.connect(("127.0.0.1", s.line_port))
        lazy.sendall(b'{"type": "hello", "protocol": "turtlegas/1"}\n{"type": "subscribe", "rate": 120, "events": "all"}\n')
        # Half a WebSocket frame: the upgrade, then 2 bytes of a frame header promising 100 bytes.
        ws_half = socket.create_connection(("127.0.0.1", s.http_port))
        ws_half.sendall(b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                        b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n" % s.http_port)
        check(b"101" in ws_half.recv(4096), "the half-frame client was upgraded")
        ws_half.sendall(bytes([0x81, 0x80 | 100]))
        # Half a line, and half an HTTP request.
        line_half = socket.create_connection(("127.0.0.1", s.line_port))
        line_half.sendall(b'{"type": "hello", "proto')
        http_half = socket.create_connection(("127.0.0.1", s.http_port))
        http_half.sendall(b"GET /api/sta")
        time.sleep(0.5)

        good = World.connect("127.0.0.1", s.line_port)
        t0 = good.ping()["t"]
        good.subscribe(rate=RATE)
        start = time.monotonic()
        frames = 0
        while time.monotonic() - start < SECONDS:
            f = good.frames.get(timeout=5)
            frames += f["type"] == "frame"
        wall = time.monotonic() - start
        t1 = good.ping()["t"]
        stats = good.stats()
        print("good viewer: %d frames in %.2f s (rate %d); sim advanced %.2f s; stats %r" % (frames, wall, RATE, t1 - t0, stats))
        check(frames >= 0.5 * RATE * SECONDS, "the good viewer got at least half its frames (%d of %g)" % (frames, RATE * wall))
        check(t1 - t0 >= 0.5 * wall, "the world kept (at least half) pace with the wall clock at speed 1 (%.2f s in %.2f s)" % (t1 - t0, wall))
        # The never-reader: its frames were dropped, not queued; it can still ask for its stats.
        lazy.sendall(b'{"type": "stats", "id": "lazy"}\n')
        f = lazy.makefile("rb")
        lazy.settimeout(30)
        deadline = time.monotonic() + 30
        mine = None
        while time.monotonic() < deadline:
            m = json.loads(f.readline())
            if m.get("id") == "lazy":
                mine = m
                break
        check(mine and mine["frames_dropped"] > 0, "the never-reader's frames were dropped: %r" % mine)
        print("never-reader: %r" % mine)
        check(s.alive() and s.stop() == 0, "stops cleanly")


if __name__ == "__main__":
    main([test_stallers_do_not_slow_a_good_viewer])
