#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Stopping (issue 12, sections 1 and 4): SIGINT and SIGTERM stop the world at a control
boundary, flush the event log (which equals `turtlegas run --until` that boundary's time), say
bye to every client and close them; a busy-loop program or a lockstep timeout ends its world and
tells its clients, not the process."""

import os
import signal
import tempfile
import time

from harness import ROOT, Server, check, main, run, world
from turtlegas_client import World


def stop_with(sig):
    with tempfile.TemporaryDirectory() as d:
        served, headless = os.path.join(d, "served.jsonl"), os.path.join(d, "headless.jsonl")
        with Server(os.path.join(ROOT, "worlds", "tag.json"), "--speed", "20", "--events", served) as s:
            a = World.connect("127.0.0.1", s.line_port)
            b = World.connect_ws("127.0.0.1", s.http_port)
            b.subscribe(rate=10, events="all")
            time.sleep(1.0)
            check(s.stop(sig) == 0, "exit 0 on signal %d: %s" % (sig, s.err()[-2000:]))
            for w in (a, b):
                closed = w.wait_closed(timeout=10)
                check(w.bye and w.bye["reason"] == "signal", "bye before the close: %r" % w.bye)
                check(closed, "the server closed the connection")
            t = a.bye["t"]
            dt = a.welcome["world"]["dt"]
            check(t > 0 and abs(t / dt - round(t / dt)) < 1e-9, "stopped at a control boundary (t=%r, dt=%r)" % (t, dt))
        run(["run", os.path.join(ROOT, "worlds", "tag.json"), "--until", repr(t), "--events", headless])
        log = open(served, "rb").read()
        check(log.count(b"\n") > 5 and log.endswith(b"\n"), "a flushed log of whole lines")
        check(log == open(headless, "rb").read(), "the served log equals `run --until %r`" % t)


def test_sigint():
    stop_with(signal.SIGINT)


def test_sigterm():
    stop_with(signal.SIGTERM)


def test_sigint_during_a_lockstep_wait():
    with Server(world("remote_followers.json"), "--lockstep-timeout", "60") as s:
        w = World.connect("127.0.0.1", s.line_port)
        w.claim("righty")  # and never a command: the world waits at its next boundary
        time.sleep(0.5)
        start = time.monotonic()
        check(s.stop(signal.SIGINT, timeout=20) == 0, "exit 0")
        check(time.monotonic() - start < 10, "the wait does not hold up the stop")


def wait_ended(w, seconds=30):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        n = w.notices.get(timeout=seconds)
        if n.get("type") == "status" and n["status"]["ended"]:
            return n["status"]["ended"]
    return None


def test_busy_loop_ends_its_world_not_the_process():
    # The program polls t.time(): the watchdog stops it at that call, by an ordinary fiber switch.
    plugin = os.environ.get("TEST_PLUGIN")
    check(plugin and os.path.exists(plugin), "TEST_PLUGIN names the test plugin (ctest sets it)")
    with Server(world("spinner.json"), "--plugin", plugin, "--program-budget", "0.5", "--speed", "max") as s:
        w = World.connect("127.0.0.1", s.line_port)
        ended = w.status["ended"] or wait_ended(w)
        check(ended and "busy loop" in ended, "the clients are told the world ended: %r" % ended)
        check(s.alive() and w.ping()["type"] == "pong", "the process serves on")
        try:
            w.pause()
            check(False, "pacing an ended world is refused")
        except Exception as e:
            check(e.reply["code"] == "ended", "ended: %r" % e.reply)
        check(s.stop() == 0, "and stops cleanly")


def test_busy_loop_without_api_calls_ends_the_process_naming_it():
    # No API call to stop it at: it may be inside malloc, so the process ends (exit 1) with a line
    # naming the turtle rather than jumping out and risking a hang (issue 29 item 7).
    plugin = os.environ.get("TEST_PLUGIN")
    check(plugin and os.path.exists(plugin), "TEST_PLUGIN names the test plugin (ctest sets it)")
    with Server(world("pure_spinner.json"), "--plugin", plugin, "--program-budget", "0.3", "--speed", "max") as s:
        code = s.wait(timeout=60)
        check(code == 1, "exit 1: %r" % code)
        err = s.err()
        check("turtle 'spin' (controller 'spinner')" in err and "busy loop" in err, "the line names it: %r" % err[-500:])


def test_lockstep_timeout_releases_the_client():
    # Issue 32 section 1: the client that holds the world up loses its claims; the world goes on.
    with Server(world("remote_followers.json"), "--lockstep-timeout", "0.5", "--speed", "max") as s:
        w = World.connect("127.0.0.1", s.line_port)
        w.claim("righty")
        deadline, err = time.monotonic() + 30, None
        while time.monotonic() < deadline and err is None:
            n = w.notices.get(timeout=30)
            check(not (n.get("type") == "status" and n["status"]["ended"]), "the world does not end: %r" % n)
            if n.get("type") == "error" and n.get("code") == "lockstep_timeout":
                err = n
        check(err and "righty" in err["message"] and "released" in err["message"], "the client is told, the turtle named: %r" % err)
        v = World.connect("127.0.0.1", s.line_port)
        t0 = v.ping()["t"]
        time.sleep(0.3)
        t1 = v.ping()["t"]
        check(v.status["ended"] is None and t1 > t0, "the world goes on for everyone: t %s -> %s" % (t0, t1))
        v.claim("righty")  # released: free to claim again
        check(s.alive() and w.ping()["type"] == "pong", "the process serves on")
        check(s.stop() == 0, "stops cleanly")


if __name__ == "__main__":
    main([test_sigint, test_sigterm, test_sigint_during_a_lockstep_wait, test_busy_loop_ends_its_world_not_the_process,
          test_busy_loop_without_api_calls_ends_the_process_naming_it, test_lockstep_timeout_releases_the_client])
