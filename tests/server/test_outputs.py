#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The served run's files (issue 29 items 5 and 6; docs/cli.md, "serve"): --events, --inputs-out
and --record on a full disk (/dev/full: every write fails with ENOSPC) make the server say which
file failed and exit non-zero rather than 0; --inputs-out is written and flushed as each input is
taken, so a server killed with SIGKILL leaves an input log that `run --inputs` replays."""

import json
import os
import shutil
import signal
import tempfile

from harness import Server, check, main, run, world
from turtlegas_client import World


def test_full_disk_exits_non_zero():
    if not os.path.exists("/dev/full"):
        print("skip: no /dev/full on this machine")
        return
    for option in ("--events", "--inputs-out", "--record"):
        try:
            s = Server(world("gas_1000.json"), "--speed", "max", "--until", "0.5", option, "/dev/full", start_timeout=10)
        except AssertionError as e:  # it may refuse at once: then before listening, non-zero, named
            text = str(e)
            check("/dev/full" in text and option in text, "%s /dev/full: the failure names the option and file: %s" % (option, text))
            continue
        with s:
            code = s.wait(60)
            err = s.err()
            check(code != 0, "%s /dev/full: exit non-zero (got %d); stderr: %s" % (option, code, err))
            check(option in err and "/dev/full" in err, "%s /dev/full: stderr names the option and the file: %s" % (option, err))


def test_inputs_survive_sigkill():
    d = tempfile.mkdtemp()
    try:
        inputs = os.path.join(d, "inputs.jsonl")
        with Server(world("protocol_room.json"), "--inputs-out", inputs) as s:
            w = World.connect(port=s.line_port)
            for k in range(3):
                w.add_wall("w-kill-%d" % k, [20 + 30 * k, 20], [40 + 30 * k, 20])  # waits for its ok
            t = w.request({"type": "ping"})["t"]
            s.proc.send_signal(signal.SIGKILL)
            s.proc.wait(10)
            w.close()
        lines = [json.loads(x) for x in open(inputs).read().splitlines()]
        check(len(lines) == 4, "the header and three walls survive SIGKILL (got %d lines: %r)" % (len(lines), lines))
        check([l.get("add_wall", {}).get("id") for l in lines[1:]] == ["w-kill-0", "w-kill-1", "w-kill-2"],
              "the walls in the order taken: %r" % lines[1:])
        events = os.path.join(d, "replay.jsonl")
        run(["run", world("protocol_room.json"), "--inputs", inputs, "--until", max(t, 0.5), "--events", events])
        walls = [json.loads(x) for x in open(events) if "wall-added" in x]
        check(len(walls) == 3, "the replay adds the three walls: %r" % walls)
    finally:
        shutil.rmtree(d)


if __name__ == "__main__":
    main([test_full_disk_exits_non_zero, test_inputs_survive_sigkill])
