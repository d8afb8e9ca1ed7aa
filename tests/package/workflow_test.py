#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The CI example of docs/ci/turtlegas-worlds.yml does what it says: its `turtlegas test` line,
run here with the built program in the repository, exits 0 and writes a JUnit file that python3's
XML parser reads, with one passing <testcase> per world in worlds/tests.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path


def fail(msg):
    print("workflow_test: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", required=True, type=Path)
    ap.add_argument("--source", required=True, type=Path)
    a = ap.parse_args()
    text = (a.source / "docs/ci/turtlegas-worlds.yml").read_text()
    lines = re.findall(r"^\s*run: (turtlegas test .*)$", text, re.M)
    if len(lines) != 1:
        fail("expected one 'run: turtlegas test ...' step in the workflow, found {}".format(lines))
    command = lines[0]
    m = re.search(r"--junit (\S+)", command)
    if not m or "worlds/tests/*.json" not in command:
        fail("the workflow's test step does not run worlds/tests/*.json with --junit: " + command)
    if not re.search(r"apt-get install -y \./turtlegas_\*\.deb", text):
        fail("the workflow does not install the .deb")

    tmp = Path(tempfile.mkdtemp(prefix="turtlegas-workflow-test-"))
    try:
        # The checkout: the repository's worlds, as the workflow's actions/checkout gives them.
        shutil.copytree(a.source / "worlds", tmp / "worlds")
        bindir = tmp / "bin"
        bindir.mkdir()
        os.symlink(a.turtlegas.resolve(), bindir / "turtlegas")
        env = dict(os.environ, PATH=str(bindir) + os.pathsep + os.environ.get("PATH", ""))
        r = subprocess.run(["bash", "-c", command], cwd=tmp, env=env, capture_output=True, text=True)
        if r.returncode != 0:
            fail("`{}` exited with {}\n{}{}".format(command, r.returncode, r.stdout[-3000:], r.stderr[-3000:]))
        report = tmp / m.group(1)
        root = ET.parse(report).getroot()
        suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
        cases = [c for s in suites for c in s.findall("testcase")]
        worlds = sorted(p.relative_to(tmp).as_posix() for p in (tmp / "worlds/tests").glob("*.json"))
        names = sorted(c.get("name") for c in cases)
        if names != worlds:
            fail("the JUnit report's testcases {} are not the worlds {}".format(names, worlds))
        bad = [c.get("name") for c in cases if c.find("failure") is not None or c.find("error") is not None]
        if bad:
            fail("failed in the report: {}".format(bad))
        total = sum(int(s.get("tests")) for s in suites)
        if total != len(worlds) or any(int(s.get("failures")) or int(s.get("errors")) for s in suites):
            fail("the suite counts are wrong: {}".format([s.attrib for s in suites]))
        print("workflow_test: ok: `{}` passed {} worlds; the JUnit report parses".format(command, len(worlds)))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
