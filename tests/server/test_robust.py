#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""What a damaged recording or a crowd of connections cannot do to the server (issue 29 item 11,
MEDIUM and LOW): a recording whose index claims an end beyond its last keyframe is replayed to
that keyframe (a seek to 1e300 used to freeze the server, SIGTERM included); HTTP connections count
against --max-clients; out of file descriptors, the listener waits instead of spinning at 100 %
CPU; a huge URL gets 414 and huge headers 431."""

import http.client
import json
import os
import resource
import shutil
import signal
import socket
import tempfile
import time

from harness import Server, check, main, run, world
from turtlegas_client import ServerError, World


def test_replay_index_beyond_keyframes():
    d = tempfile.mkdtemp()
    try:
        rec = os.path.join(d, "r.tgrec")
        run(["run", world("protocol_room.json"), "--until", 2.5, "--record", rec])
        text = open(rec).read().splitlines(True)
        k = next(i for i, l in enumerate(text) if l.startswith('{"index":'))
        index = json.loads(text[k])
        last = index["index"][-1]["t"]
        index["end"] = 1e308
        text[k] = json.dumps(index, separators=(",", ":")) + "\n"
        open(rec, "w").write("".join(text))
        with Server(rec, "--paused", command="replay") as s:
            w = World.connect(port=s.line_port)
            end = w.welcome["status"]["replay"]["end"]
            check(end == last, "the end is the last keyframe's time, %s (got %s)" % (last, end))
            try:
                w.request({"type": "seek", "t": 1e300}, timeout=10)
                check(False, "a seek beyond the last keyframe is refused")
            except ServerError as e:
                check(e.code == "bad_value", "seek 1e300: bad_value (%s)" % e)
            check(w.request({"type": "seek", "t": last}, timeout=10)["status"]["t"] == last, "a seek to the end works")
            w.close()
            start = time.monotonic()
            check(s.stop(signal.SIGTERM, timeout=10) == 0, "SIGTERM stops it")
            check(time.monotonic() - start < 5, "promptly")
            check("last keyframe" in s.err(), "the clamp is said: %s" % s.err())
    finally:
        shutil.rmtree(d)


def test_http_counted_by_max_clients():
    with Server(world("protocol_room.json"), "--paused", "--max-clients", 2) as s:
        idle = [socket.create_connection(("127.0.0.1", s.http_port), timeout=10) for _ in range(2)]
        time.sleep(0.3)
        c = http.client.HTTPConnection("127.0.0.1", s.http_port, timeout=10)
        try:
            c.request("GET", "/api/world")
            st = c.getresponse().status
        except (ConnectionError, http.client.HTTPException):
            st = "closed"
        c.close()
        check(st == 503, "a third HTTP connection over --max-clients 2: 503 (got %s)" % st)
        for x in idle:
            x.close()
        deadline, st = time.monotonic() + 10, None
        while time.monotonic() < deadline and st != 200:
            c = http.client.HTTPConnection("127.0.0.1", s.http_port, timeout=10)
            c.request("GET", "/api/world")
            st = c.getresponse().status
            c.close()
            time.sleep(0.05)
        check(st == 200, "served again once they are closed (%s)" % st)
        check(s.stop() == 0, "stops")


def cpu_seconds(pid):
    fields = open("/proc/%d/stat" % pid).read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def test_out_of_descriptors_does_not_spin():
    with Server(world("protocol_room.json"), "--paused") as s:
        pid = s.proc.pid
        used = len(os.listdir("/proc/%d/fd" % pid))
        soft, hard = resource.prlimit(pid, resource.RLIMIT_NOFILE)
        resource.prlimit(pid, resource.RLIMIT_NOFILE, (used + 4, hard))
        conns = []
        for _ in range(12):
            try:
                conns.append(socket.create_connection(("127.0.0.1", s.line_port), timeout=5))
            except OSError:
                break
        time.sleep(0.5)
        before, t0 = cpu_seconds(pid), time.monotonic()
        time.sleep(1.5)
        busy = (cpu_seconds(pid) - before) / (time.monotonic() - t0)
        check(busy < 0.1, "out of descriptors, the server waits: %.0f %% CPU" % (100 * busy))
        for c in conns:
            c.close()
        resource.prlimit(pid, resource.RLIMIT_NOFILE, (soft, hard))
        deadline = time.monotonic() + 10
        while True:
            try:
                w = World.connect(port=s.line_port, timeout=2)
                check(w.ping()["type"] == "pong", "served again")
                w.close()
                break
            except Exception:
                check(time.monotonic() < deadline, "served again once descriptors are free")
                time.sleep(0.1)
        check(s.stop() == 0, "stops")


def test_huge_url_and_headers():
    with Server(world("protocol_room.json"), "--paused") as s:
        c = http.client.HTTPConnection("127.0.0.1", s.http_port, timeout=10)
        c.request("GET", "/" + "a" * 10000)
        st = c.getresponse().status
        c.close()
        check(st == 414, "a 10 KB URL: 414 (got %s)" % st)
        c = http.client.HTTPConnection("127.0.0.1", s.http_port, timeout=10)
        try:
            c.request("GET", "/api/world", headers={"X-Junk": "j" * 40000})
            st = c.getresponse().status
        except (ConnectionError, http.client.HTTPException) as e:
            st = "closed (%s)" % e
        c.close()
        check(st == 431, "40 KB of headers: 431 (got %s)" % st)
        check(s.stop() == 0, "stops")


def rss_bytes(pid):
    for line in open("/proc/%d/status" % pid):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0


def test_static_files_streamed():
    root = tempfile.mkdtemp()
    try:
        size = 64 << 20
        with open(os.path.join(root, "big.bin"), "wb") as f:
            f.write(os.urandom(1 << 20) * 64)
        with Server(world("protocol_room.json"), "--paused", "--web-root", root) as s:
            before = rss_bytes(s.proc.pid)
            slow = socket.create_connection(("127.0.0.1", s.http_port), timeout=10)
            slow.sendall(b"GET /big.bin HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % s.http_port)
            got = slow.recv(4096)
            check(got.startswith(b"HTTP/1.1 200"), "the big file is served: %r" % got[:40])
            time.sleep(0.5)
            grown = rss_bytes(s.proc.pid) - before
            check(grown < 16 << 20, "a slow reader of a 64 MiB file: the server grew %.1f MiB (it is streamed, not read whole)" % (grown / 2**20))
            n = len(got) - got.index(b"\r\n\r\n") - 4
            slow.settimeout(30)
            while n < size:
                chunk = slow.recv(1 << 20)
                if not chunk:
                    break
                n += len(chunk)
            slow.close()
            check(n == size, "all of it arrives: %d of %d bytes" % (n, size))
            c = http.client.HTTPConnection("127.0.0.1", s.http_port, timeout=10)
            c.request("HEAD", "/big.bin")
            r = c.getresponse()
            check(r.status == 200 and r.getheader("Content-Length") == str(size) and r.read() == b"", "HEAD: the length, no body")
            c.close()
            check(s.stop() == 0, "stops")
    finally:
        shutil.rmtree(root)


if __name__ == "__main__":
    main([test_replay_index_beyond_keyframes, test_http_counted_by_max_clients, test_out_of_descriptors_does_not_spin,
          test_huge_url_and_headers, test_static_files_streamed])
