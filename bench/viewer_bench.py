#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The viewer's drawing rate (issue 13, section 2; a benchmark, not a test): frames per second that
headless Chromium draws of a gas served by `turtlegas serve`, for 10^4 balls in one view and for
10^3 balls in each of four views (target: >= 30 frames/s each).

    python3 bench/viewer_bench.py [--turtlegas build/release/turtlegas] [--seconds 10] [--format binary|json]

The page runs with ?bench=1: it draws every panel at every animation frame (not only when a frame
came in), so the rate measured is what it can draw, bounded by the browser's animation clock. It
prints, per scene, the frames drawn per second in each panel (median over the run's 1-second
windows), the frames received per second and the frames dropped. The worlds are the benchmark gases
of worlds/bench/ with views added (written to a temporary directory)."""

import argparse
import json
import os
import statistics
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "server"))
import cdp  # noqa: E402
import harness  # noqa: E402


def scene_with_views(src, views, out):
    doc = json.load(open(os.path.join(ROOT, "worlds", "bench", src)))
    doc["views"] = views
    doc["name"] += " (viewer bench)"
    with open(out, "w") as f:
        json.dump(doc, f)
    return doc


def measure(browser, url, seconds):
    browser.open(url, 1600, 1000)
    browser.wait_for("window.turtlegasViewer && turtlegasViewer.state.framesIn > 5 && turtlegasViewer.state.balls.n > 0",
                     60, "the viewer gets frames")
    time.sleep(2)  # warm up
    samples = []
    for _ in range(int(seconds)):
        a = browser.eval("turtlegasViewer.stats()")
        time.sleep(1.0)
        b = browser.eval("turtlegasViewer.stats()")
        samples.append((a, b))
    # Per panel: the draws in the page's 2-second window, halved, at each sample.
    per_panel = {}
    for a, b in samples:
        for vid, n in b["draws"].items():
            per_panel.setdefault(vid, []).append(n / 2.0)
    frames_in = statistics.median(b["framesIn"] - a["framesIn"] for a, b in samples)
    dropped = samples[-1][1]["dropped"]
    return {vid: statistics.median(v) for vid, v in per_panel.items()}, frames_in, dropped


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--turtlegas", default=harness.BIN)
    ap.add_argument("--seconds", type=float, default=10)
    ap.add_argument("--format", choices=["binary", "json"], default="binary")
    args = ap.parse_args()
    harness.BIN = args.turtlegas
    chromium = cdp.find_chromium()
    if not chromium:
        sys.exit("no Chromium found; scripts/install-deps.sh installs Debian's")
    d = tempfile.mkdtemp(prefix="tg-viewer-bench-")
    side4 = 396.33272976060107
    side3 = json.load(open(os.path.join(ROOT, "worlds", "bench", "gas_N1e3_phi0p05.json")))["arena"]["width"]
    one = os.path.join(d, "one_view_1e4.json")
    scene_with_views("gas_N1e4_phi0p05.json", [{"id": "all", "center": [side4 / 2, side4 / 2], "size": [side4, side4]}], one)
    four = os.path.join(d, "four_views_1e3.json")
    h = side3 / 2
    scene_with_views("gas_N1e3_phi0p05.json",
                     [{"id": "all-%d" % k, "center": [h, h], "size": [side3, side3]} for k in range(4)], four)
    print("viewer_bench: %s, Chromium %s, %s frames at 30/s, %g s per scene" % (
        os.uname().machine, chromium, args.format, args.seconds))
    for label, world in (("10^4 balls, 1 view", one), ("10^3 balls, 4 views", four)):
        with harness.Server(world, "--speed", "1") as server, cdp.Browser(chromium, 1600, 1000) as b:
            url = "http://127.0.0.1:%d/?bench=1" % server.http_port
            if args.format == "json":
                url += "&json=1"
            drawn, frames_in, dropped = measure(b, url, args.seconds)
            print("%-22s drawn/s per panel: %s; frames received/s %.1f; dropped %d" % (
                label, ", ".join("%s %.1f" % (k, v) for k, v in sorted(drawn.items())), frames_in, dropped))


if __name__ == "__main__":
    main()
