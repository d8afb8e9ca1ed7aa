#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`turtlegas sweep --task-index I` (docs/scaling.md): tasks started as a job array would start them
(the variable set by hand: SLURM_ARRAY_TASK_ID, PBS_ARRAY_INDEX, PBS_ARRAYID), rerun idempotently,
gathered (--gather) or resumed into the same results file, byte for byte, as a local sweep writes.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from sweeptest import Checker


CHECK = Checker("sweep_tasks_test")
fail = CHECK.fail


def run(cmd, cwd, ok=(0,), env_add=None):
    env = {k: v for k, v in os.environ.items() if k not in ("SLURM_ARRAY_TASK_ID", "PBS_ARRAY_INDEX", "PBS_ARRAYID")}
    env.update(env_add or {})
    return CHECK.run(cmd, cwd, env=env, ok=ok, note=env_add)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", required=True, type=Path)
    ap.add_argument("--source", required=True, type=Path)
    a = ap.parse_args()
    tg = a.turtlegas.resolve()
    tmp = Path(tempfile.mkdtemp(prefix="turtlegas-sweep-tasks-"))
    try:
        shutil.copy(a.source / "worlds" / "thermal_gas.json", tmp / "thermal_gas.json")
        spec = {"format": "turtlegas-sweep/1", "world": "thermal_gas.json", "until": 2, "seeds": [1, 2, 3],
                "grid": {"/gas/0/count": [100, 200]}}
        (tmp / "sp.json").write_text(json.dumps(spec))
        run([tg, "sweep", "sp.json", "--out", "ref.jsonl", "--quiet"], tmp)
        ref = (tmp / "ref.jsonl").read_bytes()

        # One task per run, by Slurm's variable; tasks 2 and 5 left out at first.
        for i in (0, 1, 3, 4):
            r = run([tg, "sweep", "sp.json", "--out", "a.jsonl"], tmp, env_add={"SLURM_ARRAY_TASK_ID": str(i)})
            if "task {} of 6 (SLURM_ARRAY_TASK_ID)".format(i) not in r.stderr:
                fail("task {} did not say which task it ran:\n{}".format(i, r.stderr))
        if sorted(p.name for p in (tmp / "a.jsonl.tasks").iterdir()) != ["run-0.json", "run-1.json", "run-3.json",
                                                                          "run-4.json"]:
            fail("task results: {}".format(sorted(p.name for p in (tmp / "a.jsonl.tasks").iterdir())))
        if (tmp / "a.jsonl").exists():
            fail("a task wrote the results file")
        # Idempotent: a task run again runs nothing and leaves its file as it was.
        before = (tmp / "a.jsonl.tasks" / "run-3.json").read_bytes()
        r = run([tg, "sweep", "sp.json", "--out", "a.jsonl", "--task-index", "3"], tmp)
        if "0 run(s) run, 1 had a result already" not in r.stderr or (tmp / "a.jsonl.tasks/run-3.json").read_bytes() != before:
            fail("a task run twice ran again:\n" + r.stderr)
        # Gathering too early names the missing runs and their tasks, and writes no results.
        r = run([tg, "sweep", "sp.json", "--out", "a.jsonl", "--gather"], tmp, ok=(1,))
        if "run 2 (task 2), 5 (task 5)" not in r.stderr or (tmp / "a.jsonl").exists():
            fail("--gather with runs missing:\n" + r.stderr)
        # The rest under PBS's names, then gathered: the local sweep's file, byte for byte.
        run([tg, "sweep", "sp.json", "--out", "a.jsonl"], tmp, env_add={"PBS_ARRAY_INDEX": "2"})
        run([tg, "sweep", "sp.json", "--out", "a.jsonl"], tmp, env_add={"PBS_ARRAYID": "5"})
        run([tg, "sweep", "sp.json", "--out", "a.jsonl", "--gather"], tmp)
        if (tmp / "a.jsonl").read_bytes() != ref:
            fail("the gathered results differ from the local sweep's")
        if (tmp / "a.jsonl.tasks").exists() or (tmp / "a.jsonl.partial").exists():
            fail("the tasks' folder or the journal outlived the results file")

        # --tasks 2: task 0 runs 0, 2, 4; then the sweep resumed here runs only 1, 3, 5.
        run([tg, "sweep", "sp.json", "--out", "b.jsonl", "--tasks", "2"], tmp, env_add={"SLURM_ARRAY_TASK_ID": "0"})
        if sorted(p.name for p in (tmp / "b.jsonl.tasks").iterdir()) != ["run-0.json", "run-2.json", "run-4.json"]:
            fail("--tasks 2, task 0 ran {}".format(sorted(p.name for p in (tmp / "b.jsonl.tasks").iterdir())))
        r = run([tg, "sweep", "sp.json", "--out", "b.jsonl", "--resume"], tmp)
        if "3 run(s) collected" not in r.stderr or (tmp / "b.jsonl").read_bytes() != ref:
            fail("--resume after tasks:\n" + r.stderr)

        # A task result of another spec (another until) is not taken: that run runs again.
        run([tg, "sweep", "sp.json", "--out", "c.jsonl", "--task-index", "1"], tmp)
        spec["until"] = 3
        (tmp / "sp.json").write_text(json.dumps(spec))
        r = run([tg, "sweep", "sp.json", "--out", "c.jsonl", "--task-index", "1"], tmp)
        if "1 run(s) run, 0 had" not in r.stderr:
            fail("a task result of another spec was taken:\n" + r.stderr)

        # Bad indices are refused naming the fix.
        r = run([tg, "sweep", "sp.json", "--out", "d.jsonl"], tmp, ok=(2,), env_add={"SLURM_ARRAY_TASK_ID": "6"})
        if "past the last task" not in r.stderr or "--array=0-5" not in r.stderr:
            fail("index 6 of 6 tasks:\n" + r.stderr)
        r = run([tg, "sweep", "sp.json", "--out", "d.jsonl"], tmp, ok=(2,), env_add={"SLURM_ARRAY_TASK_ID": "x"})
        if "SLURM_ARRAY_TASK_ID=x" not in r.stderr:
            fail("a bad variable:\n" + r.stderr)
        r = run([tg, "sweep", "sp.json", "--out", "nothing.jsonl", "--resume"], tmp, ok=(2,))
        if "nothing to go on with" not in r.stderr:
            fail("--resume with nothing begun:\n" + r.stderr)
        print("sweep_tasks_test: ok")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
