#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`turtlegas sweep` (docs/sweeps.md): a spec of 3 overrides x 4 seeds gives the same results
file run locally, with --jobs 2, under `mpirun --oversubscribe -n 3` on loopback (when the
program is built with MPI; without, sweep must say how to get it), and when a killed sweep is
resumed: a journal cut mid-line, and a real SIGKILL of a running sweep.
"""
import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from sweeptest import Checker


CHECK = Checker("sweep_test")
fail, run = CHECK.fail, CHECK.run


def check_mpi_crash(mpirun, tg, plugin, tmp, env):
    """Under mpirun a run that crashes (a plugin's segfault) is named and the other runs finish, as on
    one machine. Before: the rank died, mpirun aborted every rank without naming the run, and every
    resume met the same run and died again."""
    world = {"format": "turtlegas-world/1", "name": "crash sweep", "arena": {"width": 200, "height": 200},
             "turtles": [{"id": "t", "pos": [100, 100], "controller": "wander"}]}
    (tmp / "crash_world.json").write_text(json.dumps(world))
    spec = {"format": "turtlegas-sweep/1", "world": "crash_world.json", "until": 2, "mode": "exact", "seeds": [1, 2],
            "grid": {"/turtles/0/controller": ["wander", "segfaulter", "wander"]}}
    (tmp / "crash.json").write_text(json.dumps(spec))
    out = tmp / "crash.jsonl"
    cmd = [mpirun, "--oversubscribe", "-n", "3", tg, "sweep", "crash.json", "--out", out, "--plugin", plugin]
    for attempt in ("first", "resumed"):
        res = run(cmd, tmp, env=env, ok=(1,))
        for k in (2, 3):
            if "sweep: run {} failed".format(k) not in res.stderr or "signal 11" not in res.stderr:
                fail("{} mpirun sweep did not name crashed run {}:\n{}".format(attempt, k, res.stderr[-3000:]))
            if "(sweep run {})".format(k) not in res.stderr or "'segfaulter'" not in res.stderr:
                fail("{} mpirun sweep: crashed run {}'s turtle and controller not named:\n{}".format(
                    attempt, k, res.stderr[-3000:]))
        journal = [json.loads(l) for l in Path(str(out) + ".partial").read_text().splitlines()[2:]]
        if sorted(j["run"] for j in journal) != [0, 1, 4, 5]:
            fail("{} mpirun sweep did not finish the runs that do not crash: {}".format(attempt, [j["run"] for j in journal]))
        if attempt == "resumed" and "resuming: 4 of 6 runs" not in res.stderr:
            fail("the second mpirun sweep did not resume:\n" + res.stderr[-2000:])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", required=True, type=Path)
    ap.add_argument("--source", required=True, type=Path)
    ap.add_argument("--test-plugin", type=Path, help="tests/cli's plugin (its segfaulter crashes a run)")
    a = ap.parse_args()
    tg = a.turtlegas.resolve()
    tmp = Path(tempfile.mkdtemp(prefix="turtlegas-sweep-test-"))
    try:
        shutil.copytree(a.source / "worlds", tmp / "worlds")
        spec = "worlds/sweeps/tag_no_tag_back.json"
        ref = tmp / "local.jsonl"
        out = run([tg, "sweep", spec, "--out", ref], tmp)
        lines = ref.read_text().splitlines()
        head = json.loads(lines[0])
        if head.get("format") != "turtlegas-sweep-results/1" or head.get("runs") != 12 or len(lines) != 13:
            fail("the results file has {} lines, header {}".format(len(lines), lines[0][:200]))
        runs = [json.loads(l) for l in lines[1:]]
        if [r["run"] for r in runs] != list(range(12)):
            fail("runs out of order: {}".format([r["run"] for r in runs]))
        values = [r["overrides"]["/game/no_tag_back"] for r in runs]
        if values != [0.5] * 4 + [2] * 4 + [8] * 4 or [r["seed"] for r in runs] != [1, 2, 3, 4] * 3:
            fail("the grid x seeds expansion is wrong: {} {}".format(values, [r["seed"] for r in runs]))
        for r in runs:
            t = r["tag"]["turtles"]
            if abs(sum(x["time_it"] for x in t) - 30.0) > 1e-9 or "collisions" not in r["stats"]:
                fail("run {}: tag score or stats missing: {}".format(r["run"], json.dumps(r)[:300]))
        if "wall_seconds" in lines[1]:
            fail("a wall-clock figure is in the results")
        if "/game/no_tag_back=8" not in out.stdout or "12 runs; results in" not in out.stdout:
            fail("no summary table:\n" + out.stdout)
        # Different seeds differ (the runs are not all one run), and the grid reaches the world.
        if len({json.dumps(r["tag"]) for r in runs[:4]}) != 4:
            fail("the 4 seeds of a grid point gave fewer than 4 distinct tag scores")
        if [r["tag"] for r in runs[4:8]] == [r["tag"] for r in runs[8:12]]:
            fail("no_tag_back 2 and 8 gave the same games: the override does not reach the world")

        jobs2 = tmp / "jobs2.jsonl"
        run([tg, "sweep", spec, "--out", jobs2, "--jobs", "2", "--quiet"], tmp)
        if jobs2.read_bytes() != ref.read_bytes():
            fail("--jobs 2 gave another results file")

        # Resumed after a real kill: SIGKILL once the journal holds a run or two.
        killed = tmp / "killed.jsonl"
        proc = subprocess.Popen([str(tg), "sweep", spec, "--out", str(killed), "--quiet"], cwd=tmp,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        kpartial = Path(str(killed) + ".partial")
        deadline = time.time() + 60
        while time.time() < deadline and proc.poll() is None:
            if kpartial.exists() and len(kpartial.read_text().splitlines()) >= 3:  # two header lines, a run
                proc.send_signal(signal.SIGKILL)
                break
            time.sleep(0.001)
        proc.wait()
        really_killed = not killed.exists()
        if really_killed:
            if not kpartial.exists():
                fail("a killed sweep left no journal")
            res = run([tg, "sweep", spec, "--out", killed], tmp)
            if "resuming:" not in res.stderr:
                fail("the killed sweep did not resume:\n" + res.stderr[-2000:])
        if killed.read_bytes() != ref.read_bytes():
            fail("a sweep killed with SIGKILL and resumed gave another results file")

        # Resumed from a journal cut mid-line, as a kill during a write leaves it: 5 runs and half
        # of the next. The journal's header comes from a sweep whose every run fails (a timeout
        # too short for any run), which keeps its journal.
        cut = tmp / "cut.jsonl"
        partial = Path(str(cut) + ".partial")
        run([tg, "sweep", spec, "--out", cut, "--quiet", "--timeout", "0.000001"], tmp, ok=(1,))
        header = partial.read_text().splitlines()[0]
        if cut.exists() or len(partial.read_text().splitlines()) != 2:  # the header, written twice
            fail("a sweep whose runs all failed wrote results, or recorded runs")
        partial.write_text(header + "\n" + "\n".join(lines[1:6]) + "\n" + lines[7][: len(lines[7]) // 2])
        res = run([tg, "sweep", spec, "--out", cut], tmp)
        if "resuming: 5 of 12 runs already recorded" not in res.stderr:
            fail("the resumed sweep did not take the 5 recorded runs:\n" + res.stderr[-2000:])
        if cut.read_bytes() != ref.read_bytes():
            fail("a sweep resumed from a journal cut mid-line gave another results file")
        if partial.exists():
            fail("the journal was left behind a finished sweep")
        # A journal of another spec is refused.
        other = tmp / "other.jsonl"
        Path(str(other) + ".partial").write_text('{"fingerprint": "0000000000000000"}\n')
        bad = run([tg, "sweep", spec, "--out", other], tmp, ok=(2,))
        if "a partial sweep of another spec" not in bad.stderr:
            fail("a foreign journal was not refused:\n" + bad.stderr)

        version = run([tg, "--version"], tmp).stdout
        mpi = "mpi no" not in version
        note = ""
        if mpi:
            mpirun = shutil.which("mpirun")
            if not mpirun:
                fail("turtlegas is built with MPI but mpirun is missing (Debian: openmpi-bin)")
            env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                       OMPI_MCA_btl="self,tcp", OMPI_MCA_btl_tcp_if_include="lo", OMPI_MCA_oob_tcp_if_include="lo",
                       OMPI_MCA_plm="isolated", OMPI_MCA_rmaps_base_oversubscribe="1")
            mpi_out = tmp / "mpi.jsonl"
            res = run([mpirun, "--oversubscribe", "-n", "3", tg, "sweep", spec, "--out", mpi_out], tmp, env=env)
            if "over 3 MPI ranks" not in res.stderr:
                fail("mpirun -n 3 did not run the sweep over 3 ranks:\n" + res.stderr[-2000:])
            if mpi_out.read_bytes() != ref.read_bytes():
                fail("mpirun -n 3 gave another results file")
            note = "; mpirun -n 3 gives the same file"
            if a.test_plugin:
                check_mpi_crash(mpirun, tg, a.test_plugin.resolve(), tmp, env)
                note += "; a crashing run is named and the rest finish"
        else:
            res = run([tg, "sweep", spec, "--out", tmp / "nompi.jsonl"], tmp)
            if "libopenmpi-dev" not in res.stderr:
                fail("a build without MPI does not say how to get it:\n" + res.stderr)
            env = dict(os.environ, OMPI_COMM_WORLD_SIZE="3")
            res = run([tg, "sweep", spec, "--out", tmp / "nompi2.jsonl"], tmp, env=env, ok=(2,))
            note = "; built without MPI (it says how to get it)"
        print("sweep_test: ok: 12 runs; --jobs 2, resumed (SIGKILL{}, cut journal) give the same file{}".format(
            "" if really_killed else " came too late", note))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
