#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`turtlegas sweep` with observables and summary pointers checked (docs/sweeps.md): a spec's
"observe" gives every result line the run's gas observables, the same figures `run --observe` writes
for that run; a misspelt summary pointer is refused before any run, naming it (before, the sweep ran
and its table had a column of "-"); one at an object is named after the runs.
"""
import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from sweeptest import Checker


CHECK = Checker("sweep_observe_test")
fail, run = CHECK.fail, CHECK.run


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", required=True, type=Path)
    ap.add_argument("--source", required=True, type=Path)
    a = ap.parse_args()
    tg = a.turtlegas.resolve()
    tmp = Path(tempfile.mkdtemp(prefix="turtlegas-sweep-observe-"))
    try:
        shutil.copytree(a.source / "worlds", tmp / "worlds")
        spec = "worlds/sweeps/thermal_observe.json"
        out = tmp / "obs.jsonl"
        res = run([tg, "sweep", spec, "--out", out, "--jobs", "2", "--quiet"], tmp)
        lines = [json.loads(l) for l in out.read_text().splitlines()]
        if len(lines) != 7:
            fail("expected a header and 6 runs, got {} lines".format(len(lines)))
        for r in lines[1:]:
            o = r.get("observables")
            if not o or "summary" not in o or "species" not in o:
                fail("run {} has no observables: {}".format(r["run"], json.dumps(r)[:300]))
            s = o["summary"]
            # A thermal start at kT = 1 keeps it exactly (energy is conserved).
            if abs(s["kT"]["mean"] - 1.0) > 1e-9:
                fail("run {}: kT {} (the thermal gas has kT 1 exactly)".format(r["run"], s["kT"]))
            for key in ("Z_canonical", "D_msd", "D_green_kubo", "g_contact"):
                if key not in s:
                    fail("run {}: observables/summary lacks {}".format(r["run"], key))
            if o["species"][0]["count"] != r["overrides"]["/gas/0/count"]:
                fail("run {}: species count {} for a gas of {}".format(r["run"], o["species"][0]["count"],
                                                                        r["overrides"]["/gas/0/count"]))
        # The same figures as `run --observe` of that run's world (seed and override applied).
        world = json.loads((tmp / "worlds" / "thermal_gas.json").read_text())
        last = lines[-1]
        world["seed"] = last["seed"]
        world["gas"][0]["count"] = last["overrides"]["/gas/0/count"]
        (tmp / "w.json").write_text(json.dumps(world))
        run([tg, "run", "w.json", "--until", "6", "--observe", "o.json", "--observe-from", "2", "--observe-window", "1",
             "--observe-samples", "20"], tmp)
        single = json.loads((tmp / "o.json").read_text())
        if single["summary"] != last["observables"]["summary"]:
            fail("the sweep's observables differ from run --observe's:\n{}\n{}".format(
                json.dumps(single["summary"])[:400], json.dumps(last["observables"]["summary"])[:400]))
        if "/gas/0/count=900" not in res.stdout and "/gas/0/count=900" not in run(
                [tg, "sweep", spec, "--out", out, "--quiet"], tmp).stdout:
            fail("no summary table")

        # "full": the whole measurement, g(r) and the MSD included.
        full = json.loads((tmp / "worlds/sweeps/thermal_observe.json").read_text())
        full["observe"]["full"] = True
        full["seeds"] = [1]
        full["grid"] = {}
        (tmp / "worlds/sweeps/full.json").write_text(json.dumps(full))
        run([tg, "sweep", "worlds/sweeps/full.json", "--out", tmp / "full.jsonl", "--quiet"], tmp)
        o = json.loads((tmp / "full.jsonl").read_text().splitlines()[1])["observables"]
        if "rdf" not in o or "msd" not in o or len(o["msd"]["lag"]) != 21:
            fail("observe full: no rdf or msd: {}".format(list(o)))

        # Misspelt summary pointers: refused before any run (exit 2), naming the pointer and what is there.
        def refused(summary, words, extra=None):
            bad = json.loads((tmp / "worlds/sweeps/thermal_observe.json").read_text())
            bad["summary"] = summary
            if extra:
                bad.update(extra)
            (tmp / "worlds/sweeps/bad.json").write_text(json.dumps(bad))
            r = run([tg, "sweep", "worlds/sweeps/bad.json", "--out", tmp / "bad.jsonl", "--quiet"], tmp, ok=(2,))
            for w in words:
                if w not in r.stderr:
                    fail("summary {}: the error does not say {!r}:\n{}".format(summary, w, r.stderr[-2000:]))
            if (tmp / "bad.jsonl").exists() or (tmp / "bad.jsonl.partial").exists() or "runs" in r.stdout:
                fail("summary {}: runs were made before the error".format(summary))

        refused(["/stats/colisions"], ['"/stats/colisions"', "collisions"])
        refused(["/stat/collisions"], ['"/stat/collisions"', "run, seed, overrides, stats"])
        refused(["/observables/summary/Dmsd/mean"], ['"/observables/summary/Dmsd/mean"', "D_msd"])
        refused(["/overrides/gas/0/count"], ['"/overrides/gas/0/count"', "~1gas~10~1count"])
        bad = json.loads((tmp / "worlds/sweeps/thermal_observe.json").read_text())
        del bad["observe"]
        bad["summary"] = ["/observables/summary/kT/mean"]
        (tmp / "worlds/sweeps/bad.json").write_text(json.dumps(bad))
        r = run([tg, "sweep", "worlds/sweeps/bad.json", "--out", tmp / "bad.jsonl", "--quiet"], tmp, ok=(2,))
        if '"/observables/summary/kT/mean"' not in r.stderr or "observe" not in r.stderr:
            fail("a summary of observables without observe is not named:\n" + r.stderr[-2000:])
        refused(["/overrides"], ['"/overrides"', "not a number"])
        # A pointer that exists but at a string: named after the runs, exit 2, results written.
        bad = json.loads((tmp / "worlds/sweeps/thermal_observe.json").read_text())
        bad["summary"] = ["/stats/mode"]
        bad["seeds"] = [1]
        (tmp / "worlds/sweeps/bad.json").write_text(json.dumps(bad))
        r = run([tg, "sweep", "worlds/sweeps/bad.json", "--out", tmp / "bad.jsonl", "--quiet"], tmp, ok=(2,))
        if '"/stats/mode" points at a string' not in r.stderr or not (tmp / "bad.jsonl").exists():
            fail("a summary pointer at a string is not named, or the results were not written:\n" + r.stderr[-2000:])
        print("sweep_observe_test: ok")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
