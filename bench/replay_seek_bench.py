#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Times `seek` in `turtlegas replay`: one forward seek to 59.5 s, then seeks back and forth.
Usage: python3 bench/replay_seek_bench.py TURTLEGAS R.tgrec  (docs/performance.md, "Replay seeks")."""
import sys, time, os
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "server"))
import harness
from turtlegas_client import World
binary, rec = sys.argv[1], sys.argv[2]
harness.BIN = binary
s = harness.Server(rec, "--paused", command="replay", start_timeout=120)
try:
    w = World.connect(port=s.line_port, timeout=120)
    def seek(t):
        t0 = time.monotonic(); w.request({"type": "seek", "t": t}, timeout=600); return time.monotonic() - t0
    print("forward seek 0 -> 59.5: %.2f s" % seek(59.5))
    for t in (50.5, 30.5, 10.5, 55.25):
        print("seek -> %s: %.3f s" % (t, seek(t)))
finally:
    s.stop()
