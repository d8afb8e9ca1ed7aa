#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The server's door (issue 29 item 10; docs/protocol.md, "Who gets in"): a WebSocket upgrade from
a foreign page (its Origin) and an HTTP request for a foreign Host (DNS rebinding) are refused
unless --allow-origin names them; `save` never replaces a file the server reads or writes (the
served world, the live recording, event and input logs); the token may come from a file or the
environment instead of the command line."""

import base64
import http.client
import json
import os
import shutil
import socket
import tempfile

from harness import Server, check, main, world
from turtlegas_client import ServerError, World


def upgrade(port, origin=None, host=None):
    """The status line of a WebSocket upgrade with these headers (no Origin when None)."""
    s = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        key = base64.b64encode(os.urandom(16)).decode()
        head = "GET /ws HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n" \
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n" % (host or "127.0.0.1:%d" % port, key)
        if origin is not None:
            head += "Origin: %s\r\n" % origin
        s.sendall((head + "\r\n").encode())
        buf = b""
        while b"\r\n\r\n" not in buf:
            chunk = s.recv(4096)
            if not chunk:
                break
            buf += chunk
        return buf.split(b"\r\n", 1)[0].decode()
    finally:
        s.close()


def get(port, path, host):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.putrequest("GET", path, skip_host=True)
    c.putheader("Host", host)
    c.endheaders()
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, body


def test_foreign_origin_and_host_refused():
    with Server(world("protocol_room.json"), "--paused") as s:
        p = s.http_port
        for origin in ("http://127.0.0.1:%d" % p, "http://localhost:%d" % p, "http://[::1]:%d" % p, None):
            st = upgrade(p, origin)
            check(" 101 " in st + " ", "Origin %r: the upgrade is accepted (%s)" % (origin, st))
        for origin in ("http://evil.example", "http://127.0.0.1:%d" % (p + 1), "null", "https://localhost:%d.evil.example" % p):
            st = upgrade(p, origin)
            check(" 403 " in st + " ", "Origin %r: the upgrade is refused with 403 (%s)" % (origin, st))
        for host in ("127.0.0.1:%d" % p, "localhost:%d" % p, "LOCALHOST:%d" % p):
            st, body = get(p, "/api/world", host)
            check(st == 200, "Host %r: served (%d)" % (host, st))
        for host in ("evil.example:%d" % p, "evil.example", "127.0.0.1:%d" % (p + 7)):
            st, body = get(p, "/api/world", host)
            check(st == 403 and b"--allow-origin" in body, "Host %r: refused with 403 naming the flag (%d %r)" % (host, st, body))
            st = upgrade(p, None, host)
            check(" 403 " in st + " ", "Host %r: the upgrade is refused too (%s)" % (host, st))
        check(s.stop() == 0, "stops")
    with Server(world("protocol_room.json"), "--paused", "--allow-origin", "http://viewer.example:9000") as s:
        p = s.http_port
        check(" 101 " in upgrade(p, "http://viewer.example:9000", "viewer.example:9000") + " ", "--allow-origin: that page gets in")
        check(get(p, "/api/world", "viewer.example:9000")[0] == 200, "--allow-origin: its Host is served")
        check(" 403 " in upgrade(p, "http://evil.example") + " ", "--allow-origin: other pages still do not")
        check(s.stop() == 0, "stops")


def test_save_never_replaces_a_file_in_use():
    d = tempfile.mkdtemp()
    try:
        src = os.path.join(d, "room.json")
        shutil.copy(world("protocol_room.json"), src)
        original = open(src, "rb").read()
        names = {"room.json": src}
        for n in ("events.jsonl", "inputs.jsonl", "run.tgrec"):
            names[n] = os.path.join(d, n)
        with Server(src, "--paused", "--save-dir", d, "--events", names["events.jsonl"],
                    "--inputs-out", names["inputs.jsonl"], "--record", names["run.tgrec"]) as s:
            w = World.connect(port=s.line_port)
            for name in ("room.json", "events.jsonl", "inputs.jsonl", "run.tgrec"):
                before = open(names[name], "rb").read()
                try:
                    w.save(name)
                    check(False, "save %s: refused" % name)
                except ServerError as e:
                    check(e.code == "bad_path" and "in use" in str(e), "save %s: bad_path, the file is in use (%s)" % (name, e))
                check(open(names[name], "rb").read() == before, "save %s: the file is untouched" % name)
            w.save("snap.json")  # a file of its own is fine
            check(os.path.getsize(os.path.join(d, "snap.json")) > 0, "save snap.json: written")
            w.close()
            check(s.stop() == 0, "stops")
        check(open(src, "rb").read() == original, "the served world is as it was")
    finally:
        shutil.rmtree(d)


def test_token_from_file_and_environment():
    d = tempfile.mkdtemp()
    try:
        tf = os.path.join(d, "token")
        open(tf, "w").write("s3cret-from-file\n")
        for args, env, token in ((["--token-file", tf], {}, "s3cret-from-file"),
                                 ([], {"TURTLEGAS_TOKEN": "s3cret-from-env"}, "s3cret-from-env")):
            old = dict(os.environ)
            os.environ.update(env)
            try:
                s = Server(world("protocol_room.json"), "--paused", *args)
            finally:
                os.environ.clear()
                os.environ.update(old)
            with s:
                check(all(token not in a for a in s.cmd), "the token is not on the command line")
                w = World.connect(port=s.line_port)
                try:
                    w.pause()
                    check(False, "without the token: unauthorized")
                except ServerError as e:
                    check(e.code == "unauthorized", "without the token: %s" % e)
                w.close()
                try:
                    World.connect(port=s.line_port, token="wrong").close()
                    check(False, "a wrong token: refused")
                except ServerError as e:
                    check(e.code == "bad_token", "a wrong token: %s" % e)
                w = World.connect(port=s.line_port, token=token)
                check(w.welcome["authorized"], "the token from %s: authorized" % (args or env))
                w.pause()
                w.close()
                check(s.stop() == 0, "stops")
    finally:
        shutil.rmtree(d)


def test_malformed_origin_refused():
    # Before: --allow-origin "" (or a bare host:port) was taken silently and let no page in.
    import subprocess
    from harness import BIN
    for bad in ("", "localhost:8080", "http://", "http://viewer.example:9000/page"):
        r = subprocess.run([BIN, "serve", world("protocol_room.json"), "--paused", "--port", "0", "--allow-origin", bad],
                           capture_output=True, text=True, timeout=30)
        check(r.returncode == 2 and "is not an origin" in r.stderr,
              "--allow-origin %r: refused before serving, exit 2 (%d %r)" % (bad, r.returncode, r.stderr[-300:]))


if __name__ == "__main__":
    main([test_foreign_origin_and_host_refused, test_save_never_replaces_a_file_in_use, test_token_from_file_and_environment,
          test_malformed_origin_refused])
