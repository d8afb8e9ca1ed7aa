#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""VecWorld beside VMAS, in one run: the two alternate (A B A B ...), each configuration in turn,
so that a machine whose speed drifts slows both alike (docs/performance.md, "Vectorised worlds").

  bench/vec_vs_vmas.py --vec-bench BUILD/bench/vec_bench --vmas-dir VMAS_CHECKOUT \\
      [--peer ../shared/peers/vmas] [--reps 3] [--sizes 64,1024] [--threads 1,2] [--out runs.jsonl]

turtlegas side: vec_bench on worlds/learn/swarm16.json (16 turtles, an 8-ray ring of range 35,
random (v, omega) actions, observations into one float array (N, 16, 16)). VMAS side: the peer's
bench_vmas.py, navigation scenario, 16 agents, 8 lidar rays, random actions, CPU, observations
stacked into one numpy array (N, 16, 14); it runs under Debian's /usr/bin/python3 (python3-torch).
Prints one JSON line per run (also to --out) and a table of medians: agent-steps per wall second,
per CPU second, and turtlegas / VMAS. Python standard library only.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
p.add_argument("--vec-bench", required=True)
p.add_argument("--vmas-dir", required=True, help="a checkout of VMAS (the peer's README says which commit)")
p.add_argument("--peer", default=os.path.join(ROOT, "..", "shared", "peers", "vmas"))
p.add_argument("--python", default="/usr/bin/python3", help="the interpreter that has torch (Debian's)")
p.add_argument("--reps", type=int, default=3)
p.add_argument("--sizes", default="64,1024")
p.add_argument("--threads", default="1,2")
p.add_argument("--out")
a = p.parse_args()

# Steps per run: about 1-3 s of timed stepping each on a quiet 2-core machine.
VEC_STEPS = {64: (1000, 20), 1024: (100, 5)}
VMAS_STEPS = {64: (150, 10), 1024: (20, 3)}


def run(cmd, env=None):
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600, cwd=ROOT)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def vec(n, th):
    steps, warm = VEC_STEPS.get(n, (100, 5))
    r = run([a.vec_bench, "--worlds", str(n), "--threads", str(th), "--steps", str(steps), "--warmup", str(warm)])
    return r


def vmas(n, th):
    steps, warm = VMAS_STEPS.get(n, (20, 3))
    env = dict(os.environ, PYTHONPATH=a.vmas_dir + os.pathsep + os.path.join(a.peer, "stubs"))
    r = run([a.python, os.path.join(a.peer, "bench_vmas.py"), "--scenario", "navigation", "--num-envs", str(n),
             "--threads", str(th), "--lidar", "on", "--steps", str(steps), "--warmup", str(warm)], env)
    r["cpu_s"] = r["cpu_s"]
    return r


sizes = [int(x) for x in a.sizes.split(",")]
threads = [int(x) for x in a.threads.split(",")]
rows = []
out = open(a.out, "a") if a.out else None
for rep in range(1, a.reps + 1):
    for n in sizes:
        for th in threads:
            for side, fn in (("turtlegas", vec), ("vmas", vmas)):
                r = fn(n, th)
                steps = r["steps"]
                rec = {"side": side, "rep": rep, "worlds": n, "threads": th, "steps": steps,
                       "wall_s": r["wall_s"], "cpu_s": r["cpu_s"],
                       "agent_steps_per_s": r["agent_steps_per_s"],
                       "agent_steps_per_cpu_s": n * 16 * steps / r["cpu_s"],
                       "load": os.getloadavg()[0], "utc": time.strftime("%H:%M:%S", time.gmtime())}
                rows.append(rec)
                line = json.dumps(rec)
                print(line, flush=True)
                if out:
                    out.write(line + "\n")
                    out.flush()

print()
print("| worlds | threads | turtlegas agent-steps/s | VMAS agent-steps/s | ratio | turtlegas per CPU s | VMAS per CPU s | ratio |")
print("|---|---|---|---|---|---|---|---|")
for n in sizes:
    for th in threads:
        def med(side, key):
            return statistics.median(r[key] for r in rows if r["side"] == side and r["worlds"] == n and r["threads"] == th)
        tw, vw = med("turtlegas", "agent_steps_per_s"), med("vmas", "agent_steps_per_s")
        tc, vc = med("turtlegas", "agent_steps_per_cpu_s"), med("vmas", "agent_steps_per_cpu_s")
        print(f"| {n} | {th} | {tw:,.0f} | {vw:,.0f} | {tw / vw:.1f}x | {tc:,.0f} | {vc:,.0f} | {tc / vc:.1f}x |")
