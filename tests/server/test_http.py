#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""HTTP (docs/protocol.md, "Transports"): GET / (the placeholder page, or the web root's
index.html), static files without traversal, /api/world as loaded, /api/state in --state-out's
format, 404 and 405; and the Python example run as a program against a real server."""

import http.client
import json
import os
import shutil
import subprocess
import sys
import tempfile

from harness import BIN, ROOT, Server, check, main, world


def get(port, path, method="GET", headers=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    c.request(method, path, headers=headers or {})
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, r.getheader("Content-Type"), body


def test_http_routes():
    root = tempfile.mkdtemp()
    outside = tempfile.mkdtemp()
    try:
        open(os.path.join(root, "index.html"), "w").write("<p>viewer</p>")
        os.mkdir(os.path.join(root, "js"))
        open(os.path.join(root, "js", "app.js"), "w").write("let x = 1;")
        open(os.path.join(root, ".secret"), "w").write("hidden")
        open(os.path.join(outside, "passwd"), "w").write("outside")
        os.symlink(os.path.join(outside, "passwd"), os.path.join(root, "link.txt"))
        src = world("protocol_room.json")
        with Server(src, "--paused", "--web-root", root) as s:
            st, ct, body = get(s.http_port, "/")
            check(st == 200 and ct.startswith("text/html") and body == b"<p>viewer</p>", "GET / serves index.html: %r" % body)
            st, ct, body = get(s.http_port, "/js/app.js")
            check(st == 200 and ct.startswith("text/javascript") and body == b"let x = 1;", "a static file with its type")
            for bad in ("/../" + os.path.basename(outside) + "/passwd", "/.secret", "/js/../.secret", "/link.txt",
                        "/%2e%2e/passwd", "/js//app.js", "/nothing.html"):
                st, _, body = get(s.http_port, bad)
                check(st == 404 and b"outside" not in body and b"hidden" not in body, "%s: 404 (%d)" % (bad, st))
            st, ct, body = get(s.http_port, "/api/world")
            check(st == 200 and ct == "application/json" and body == open(src, "rb").read(), "the world file as loaded")
            st, _, body = get(s.http_port, "/api/state")
            state = json.loads(body)
            check(st == 200 and state["t"] == 0 and [b["id"] for b in state["balls"]] == ["b1", "b2"] and
                  [t["id"] for t in state["turtles"]] == ["t1", "t2"], "the state: %r" % state)
            st, _, _ = get(s.http_port, "/api/nope")
            check(st == 404, "unknown API: 404")
            st, _, _ = get(s.http_port, "/", method="POST")
            check(st == 405, "POST: 405")
            st, _, body = get(s.http_port, "/", method="HEAD")
            check(st == 200 and body == b"", "HEAD: headers only")
            check(s.stop() == 0, "stops")
        with Server(src, "--paused", "--web-root", outside) as s:  # no index.html there
            st, ct, body = get(s.http_port, "/")
            check(st == 200 and b"turtlegas serve" in body, "the placeholder page")
            s.stop()
    finally:
        shutil.rmtree(root)
        shutil.rmtree(outside)


def test_example_program():
    with Server(world("remote_followers.json"), "--paused", "--speed", "max", "--until", 10) as s:
        r = subprocess.run([sys.executable, os.path.join(ROOT, "clients", "python", "examples", "wall_follower.py"),
                            "--port", str(s.line_port), "--turtle", "righty:right", "--turtle", "lefty:left"],
                           capture_output=True, text=True, timeout=120)
        check(r.returncode == 0 and "done: until" in r.stdout, "the example runs to --until: %r %r" % (r.stdout, r.stderr))
        check(s.wait(30) == 0, "and the server exits 0")


def test_bad_command_lines_exit_2():
    bad_world = tempfile.NamedTemporaryFile("w", suffix=".json", delete=False)
    bad_world.write('{"format": "turtlegas-world/1", "balls": [{"id": "b", "pos": [1, 1], "radius": -1}]}')
    bad_world.close()
    try:
        for args, words in (([bad_world.name], "/balls/0/radius"), ([world("protocol_room.json"), "--speed", "0"], "--speed"),
                            ([world("protocol_room.json"), "--bind", "0.0.0.0"], "--token"),
                            ([world("protocol_room.json"), "--bind", "nowhere"], "--bind"),
                            ([world("protocol_room.json"), "--save-dir", "/nonexistent/dir"], "--save-dir")):
            r = subprocess.run([BIN, "serve", *args, "--port", "0"], capture_output=True, text=True, timeout=60)
            check(r.returncode == 2 and words in r.stderr, "exit 2 naming %s: %d %r" % (words, r.returncode, r.stderr))
    finally:
        os.unlink(bad_world.name)


if __name__ == "__main__":
    main([test_http_routes, test_example_program, test_bad_command_lines_exit_2])
