#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Hostile clients (issue 12, section 6): 1,000 malformed or hostile messages from six
connections (TCP lines and WebSocket; invalid JSON, 10 MiB payloads, unknown types, wrong types,
missing and wrong tokens, claims of claimed turtles, spawns, paths with '..', a symlink out of
the save directory): every one is answered with the documented error, the server stays up, and
the world's state and event log are unchanged. Also the rate limit and the connection limit."""

import collections
import json
import os
import shutil
import socket
import tempfile
import time
import urllib.request

from harness import Server, check, main, world
from turtlegas_client import World

TOKEN = "s3cret"

COMMON = [
    ("{not json", "bad_json"), ("[1, 2", "bad_json"), ("[1,2,3]", "not_object"), ("42", "not_object"),
    ('"s"', "not_object"), ("null", "not_object"), ("{}", "missing_field"), ('{"type": 5}', "wrong_type"),
    ('{"type": "explode"}', "unknown_type"), ('{"type": "hello", "protocol": "turtlegas/0"}', "bad_protocol"),
    ('{"type": "hello"}', "missing_field"), ('{"type": "ping", "id": {"a": 1}}', "bad_value"),
    ('{"type": "' + "x" * 5000 + '"}', "unknown_type"),
    # Nested past 512 levels: refused before parsing (docs/protocol.md), whatever the type.
    ("[" * 30000 + "]" * 30000, "bad_json"), ("[" * 30000, "bad_json"),
    ('{"type": "ping", "id": ' + "[" * 20000 + "]" * 20000 + "}", "bad_json"),
    ("[" * 512 + "]" * 512, "not_object"),
]
NO_HELLO = COMMON + [
    ('{"type": "pause"}', "hello_first"), ('{"type": "claim", "turtle": "t1"}', "hello_first"),
    ('{"type": "save", "file": "../x.json"}', "hello_first"), ('{"type": "ping"}', "hello_first"),
]
UNAUTHORIZED = COMMON + [
    ('{"type": "pause"}', "unauthorized"), ('{"type": "claim", "turtle": "t1"}', "unauthorized"),
    ('{"type": "forward", "turtle": "t1", "amount": 1}', "unauthorized"),
    ('{"type": "save", "file": "../x.json"}', "unauthorized"), ('{"type": "add_wall", "wall": {}}', "unauthorized"),
    ('{"type": "load", "file": "room.json"}', "unauthorized"),
    ('{"type": "spawn", "ball": {"id": "x", "pos": [50, 50], "radius": 2}}', "unauthorized"),
    ('{"type": "remove", "body": "b1"}', "unauthorized"),
    ('{"type": "hello", "protocol": "turtlegas/1", "token": "wrong"}', "bad_token"),
    ('{"type": "subscribe", "rate": 0}', "bad_value"), ('{"type": "subscribe", "rate": "fast"}', "wrong_type"),
]
AUTHORIZED = COMMON + [
    ('{"type": "forward", "turtle": "t1", "amount": "far"}', "wrong_type"),
    ('{"type": "forward", "turtle": "t1", "amount": -5}', "bad_value"),
    ('{"type": "forward", "turtle": "nobody", "amount": 1}', "unknown_turtle"),
    ('{"type": "forward", "turtle": ["t1"], "amount": 1}', "wrong_type"),
    ('{"type": "forward", "turtle": "t1"}', "missing_field"),
    ('{"type": "forward", "turtle": "t2", "amount": 1}', "not_claimed"),
    ('{"type": "forward", "turtle": "t1", "amount": 1}', "busy"),
    ('{"type": "claim", "turtle": "t1"}', "claimed"), ('{"type": "claim", "turtle": "t2"}', "not_remote"),
    ('{"type": "release", "turtle": "t2"}', "not_claimed"), ('{"type": "step", "steps": -1}', "bad_value"),
    ('{"type": "step", "steps": 1.5}', "bad_value"), ('{"type": "speed", "factor": 1e9}', "bad_value"),
    ('{"type": "speed"}', "missing_field"), ('{"type": "speed", "factor": true}', "wrong_type"),
    ('{"type": "run_until", "t": -5}', "bad_value"), ('{"type": "run_until", "t": "soon"}', "wrong_type"),
    ('{"type": "subscribe", "format": "jpeg"}', "bad_value"), ('{"type": "subscribe", "events": [1]}', "wrong_type"),
    ('{"type": "pen", "turtle": "t1"}', "missing_field"),
    ('{"type": "pen", "turtle": "t1", "down": true, "mode": "crayon"}', "bad_value"),
    ('{"type": "add_wall"}', "missing_field"), ('{"type": "add_wall", "wall": [1]}', "wrong_type"),
    ('{"type": "add_wall", "wall": {"id": "x", "from": [0, 0]}}', "missing_field"),
    ('{"type": "add_wall", "wall": {"id": "x", "from": [0, "a"], "to": [1, 1]}}', "wrong_type"),
    ('{"type": "add_wall", "wall": {"id": "", "from": [0, 0], "to": [1, 1]}}', "wrong_type"),
    ('{"type": "save", "file": "../evil.json"}', "bad_path"), ('{"type": "load", "file": "/etc/passwd"}', "bad_path"),
    ('{"type": "save", "file": ".hidden"}', "bad_path"), ('{"type": "save", "file": "a/b.json"}', "bad_path"),
    ('{"type": "load", "file": "..\\\\x"}', "bad_path"), ('{"type": "save"}', "missing_field"),
    ('{"type": "save", "file": "link.json"}', "bad_path"), ('{"type": "load", "file": "link.json"}', "bad_path"),
    ('{"type": "load", "file": "missing.json"}', "not_found"), ('{"type": "load", "file": "garbage.json"}', "bad_world"),
    # Bodies: spawns onto the turtle t1 (at rest at (250, 60), radius 10) or the ball b1 (400, 300),
    # bad entries, bad or unknown bodies: each refused at once, nothing queued.
    ('{"type": "spawn", "ball": {"id": "x", "pos": [250, 60], "radius": 5}}', "refused"),
    ('{"type": "spawn", "turtle": {"id": "x", "pos": [400, 300]}}', "refused"),
    ('{"type": "spawn", "ball": {"id": "x", "pos": [250, 200], "radius": -5}}', "bad_value"),
    ('{"type": "spawn", "ball": {"id": "x", "pos": [250, 200]}}', "bad_value"),
    ('{"type": "spawn", "ball": {"id": "x", "pos": [250, 200], "radius": 2, "category": "sneaky"}}', "bad_value"),
    ('{"type": "spawn", "turtle": {"id": "x", "pos": [250, 200], "controller": "rm -rf"}}', "bad_value"),
    ('{"type": "spawn", "ball": [1, 2]}', "bad_value"), ('{"type": "spawn"}', "missing_field"),
    ('{"type": "spawn", "ball": {"id": "x", "pos": [250, 200], "radius": 2}, "turtle": {}}', "bad_value"),
    ('{"type": "teleport", "body": "b1", "pos": [250, 60]}', "refused"),
    ('{"type": "teleport", "body": "b1", "pos": "here"}', "wrong_type"),
    ('{"type": "teleport", "body": "b1", "pos": [250, 200], "heading": 5}', "bad_value"),
    ('{"type": "remove", "body": "nobody"}', "unknown_body"), ('{"type": "remove", "id": "b1"}', "missing_field"),
    ('{"type": "remove", "body": 7}', "wrong_type"), ('{"type": "teleport", "body": "../../etc", "pos": [1, 1]}', "unknown_body"),
]
SECOND = [('{"type": "claim", "turtle": "t1"}', "claimed"), ('{"type": "forward", "turtle": "t1", "amount": 1}', "not_claimed"),
          ('{"type": "release", "turtle": "t1"}', "not_claimed"),
          # Another connection's turtle is theirs to remove or move.
          ('{"type": "remove", "body": "t1"}', "claimed"), ('{"type": "teleport", "body": "t1", "pos": [250, 200]}', "claimed")] + COMMON
HUGE = '{"type": "ping", "pad": "' + "x" * (10 * 1024 * 1024) + '"}'


def lines_conn(port):
    s = socket.create_connection(("127.0.0.1", port), timeout=60)
    return s, s.makefile("rb")


def send_lines(sock, texts):
    sock.sendall("".join(t + "\n" for t in texts).encode())


def read_lines(f, n):
    out = []
    while len(out) < n:
        line = f.readline()
        check(line, "the server answered %d of %d messages before closing" % (len(out), n))
        out.append(json.loads(line))
    return out


def state(s):
    return urllib.request.urlopen("http://127.0.0.1:%d/api/state" % s.http_port, timeout=30).read()


def plan(msgs, n):
    return [msgs[k % len(msgs)] for k in range(n)]


def test_thousand_hostile_messages():
    d = tempfile.mkdtemp()
    outside = tempfile.mkdtemp()
    try:
        open(os.path.join(d, "garbage.json"), "w").write("{this is not a world")
        shutil.copy(world("protocol_room.json"), os.path.join(outside, "secret.json"))
        os.symlink(os.path.join(outside, "secret.json"), os.path.join(d, "link.json"))
        events = os.path.join(d, "events.jsonl")
        with Server(world("protocol_room.json"), "--paused", "--token", TOKEN, "--save-dir", d, "--events", events) as s:
            before = state(s)
            # The authorized connection claims t1 and queues a command (the world is paused).
            a_sock, a_file = lines_conn(s.line_port)
            send_lines(a_sock, ['{"type": "hello", "protocol": "turtlegas/1", "token": "%s"}' % TOKEN,
                                '{"type": "claim", "turtle": "t1"}', '{"type": "forward", "turtle": "t1", "amount": 100}'])
            r = read_lines(a_file, 2)
            check(r[0]["type"] == "welcome" and r[0]["authorized"] and r[1]["type"] == "claimed", "set-up: %r" % r)
            a2_sock, a2_file = lines_conn(s.line_port)
            send_lines(a2_sock, ['{"type": "hello", "protocol": "turtlegas/1", "token": "%s"}' % TOKEN])
            b_sock, b_file = lines_conn(s.line_port)
            send_lines(b_sock, ['{"type": "hello", "protocol": "turtlegas/1"}'])
            d_sock, d_file = lines_conn(s.line_port)
            check(read_lines(a2_file, 1)[0]["authorized"] and not read_lines(b_file, 1)[0]["authorized"], "tokens")
            ws_b = World.connect_ws("127.0.0.1", s.http_port)  # no token: unauthorized
            ws_a = World.connect_ws("127.0.0.1", s.http_port, token=TOKEN)
            check(not ws_b.welcome["authorized"] and ws_a.welcome["authorized"], "WebSocket tokens")
            jobs = [(a_sock, a_file, plan(AUTHORIZED, 300) + [(HUGE, "too_large")] * 2),
                    (a2_sock, a2_file, plan(SECOND, 100)),
                    (b_sock, b_file, plan(UNAUTHORIZED, 150)),
                    (d_sock, d_file, plan(NO_HELLO, 150))]
            ws_jobs = [(ws_b, plan(UNAUTHORIZED, 148) + [(HUGE, "too_large")] * 2), (ws_a, plan([m for m in AUTHORIZED if m[1] != "busy"], 150))]
            total = sum(len(j[2]) for j in jobs) + sum(len(j[1]) for j in ws_jobs)
            check(total >= 1000, "at least 1,000 messages (%d)" % total)
            for sock, _, msgs in jobs:
                send_lines(sock, [m for m, _ in msgs])
            for w, msgs in ws_jobs:
                for m, _ in msgs:
                    w._t.send(m)
            for sock, f, msgs in jobs:
                got = read_lines(f, len(msgs))
                check(all(g["type"] == "error" for g in got), "only errors: %r" % [g for g in got if g["type"] != "error"][:3])
                want = collections.Counter(code for _, code in msgs)
                have = collections.Counter(g["code"] for g in got)
                check(want == have, "the codes as documented: want-have %r, have-want %r" % (want - have, have - want))
                check(all(g["message"] for g in got), "every error says why")
            for w, msgs in ws_jobs:
                got = []
                deadline = time.monotonic() + 60
                while len(got) < len(msgs) and time.monotonic() < deadline:
                    got.append(w.notices.get(timeout=60))
                want = collections.Counter(code for _, code in msgs)
                have = collections.Counter(g.get("code") for g in got)
                check(want == have, "WebSocket codes: want-have %r, have-want %r" % (want - have, have - want))
            # Still up, and nothing changed.
            check(s.alive(), "the server is still running")
            check(World.connect("127.0.0.1", s.line_port).ping()["type"] == "pong", "still answers")
            check(state(s) == before, "the world's state is unchanged")
            check(not os.path.exists(os.path.join(outside, "evil.json")) and os.listdir(outside) == ["secret.json"],
                  "nothing was written outside the save directory")
            check(sorted(os.listdir(d)) == ["events.jsonl", "garbage.json", "link.json"], "nor inside: %r" % os.listdir(d))
            check(s.stop() == 0, "stops cleanly: " + s.err()[-2000:])
        check(open(events).read() == "", "the event log is unchanged (empty: the world stayed paused)")
    finally:
        shutil.rmtree(d)
        shutil.rmtree(outside)


def test_rate_limit():
    with Server(world("protocol_room.json"), "--paused", "--max-rate", 50) as s:
        sock, f = lines_conn(s.line_port)
        send_lines(sock, ['{"type": "hello", "protocol": "turtlegas/1"}'] + ['{"type": "ping"}'] * 199)
        got = read_lines(f, 200)
        codes = collections.Counter(g.get("code", g["type"]) for g in got)
        check(codes["rate_limited"] > 0 and codes["welcome"] + codes["pong"] + codes["rate_limited"] == 200,
              "over 50 a second: rate_limited, each answered: %r" % codes)
        check(s.stop() == 0, "stops")


def test_connection_limit():
    with Server(world("protocol_room.json"), "--paused", "--max-clients", 2) as s:
        w1 = World.connect("127.0.0.1", s.line_port)
        w2 = World.connect_ws("127.0.0.1", s.http_port)
        sock, f = lines_conn(s.line_port)
        r = json.loads(f.readline())
        check(r["code"] == "too_many_clients" and f.readline() == b"", "the third connection is told and closed: %r" % r)
        try:
            World.connect_ws("127.0.0.1", s.http_port)
            check(False, "a third WebSocket is refused")
        except ConnectionError as e:
            check("503" in str(e), "HTTP 503: %s" % e)
        check(w1.ping()["type"] == "pong" and w2.ping()["type"] == "pong", "the first two are served")
        w1.close()
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:  # the slot frees once the server has seen the close
            try:
                World.connect("127.0.0.1", s.line_port).ping()
                break
            except Exception:
                time.sleep(0.05)
        else:
            check(False, "a closed connection frees its slot")
        check(s.stop() == 0, "stops")


def test_claim_limit_and_disconnect_release():
    with Server(world("remote_followers.json"), "--max-claims", 1, "--speed", "max", "--lockstep-timeout", 5) as s:
        a = World.connect("127.0.0.1", s.line_port)
        a.claim("righty")
        try:
            a.claim("lefty")
            check(False, "a second claim is over --max-claims 1")
        except Exception as e:
            check(e.reply["code"] == "too_many_claims", "too_many_claims: %r" % e.reply)
        b = World.connect("127.0.0.1", s.line_port)
        try:
            b.claim("righty")
            check(False, "righty is a's")
        except Exception as e:
            check(e.reply["code"] == "claimed", "claimed: %r" % e.reply)
        t0 = b.ping()["t"]
        a.close()  # a's turtle is released: the lockstep world does not wait for it
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and b.ping()["t"] <= t0 + 1:
            time.sleep(0.05)
        check(b.ping()["t"] > t0 + 1 and not b.status["ended"], "the world goes on without a's turtle")
        righty = b.claim("righty")
        check(righty.forward(5).done == 5, "and another connection can claim and drive it")
        check(s.stop() == 0, "stops")



def test_deep_json():
    """A spawn nested 100,000 deep in an ignored x- key (200 KB, under --max-message): before, the
    server died of SIGSEGV with no word. Now an error reply naming the limit, and the server and
    the world go on."""
    with Server(world("protocol_room.json"), "--paused") as s:
        sock, f = lines_conn(s.line_port)
        deep = "[" * 100000 + "]" * 100000
        send_lines(sock, ['{"type": "hello", "protocol": "turtlegas/1"}',
                          '{"type": "spawn", "id": 7, "ball": {"id": "deep", "pos": [50, 50], "radius": 2}, "x-deep": %s}' % deep,
                          '{"type": "ping", "id": 8}'])
        # (bad_json may overtake the welcome: docs/protocol.md, section 3.)
        replies = {m["type"]: m for m in read_lines(f, 3)}
        check(set(replies) == {"welcome", "error", "pong"}, "three replies: %r" % replies)
        err = replies["error"]
        check(err["code"] == "bad_json" and "512 levels" in err["message"], "the deep message is refused, naming the limit: %r" % err)
        check(replies["pong"].get("id") == 8, "and the server answers the next: %r" % replies["pong"])
        check(b'"deep"' not in state(s), "nothing was spawned")
        check(s.stop() == 0, "stops")


if __name__ == "__main__":
    main([test_deep_json, test_thousand_hostile_messages, test_rate_limit, test_connection_limit, test_claim_limit_and_disconnect_release])
