#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""examples/learn_avoidance.py, short: the cross-entropy method over VecWorld raises the swarm's
reward, and a learner that keeps a random fifth of each generation instead of the best does not
rise as far (so the rise is learning, not drift).

    learn_avoidance_test.py --source SOURCE_DIR      (turtlegas importable: PYTHONPATH set by ctest)
"""
import argparse
import importlib.util
import os
import sys

p = argparse.ArgumentParser()
p.add_argument("--source", required=True)
a = p.parse_args()
spec = importlib.util.spec_from_file_location("learn_avoidance", os.path.join(a.source, "examples", "learn_avoidance.py"))
example = importlib.util.module_from_spec(spec)
spec.loader.exec_module(example)

GENERATIONS, POPULATION, STEPS = 8, 16, 60
RISE, FLOOR, GAP = 0.4, 0.4, 0.25

SHORT = dict(generations=GENERATIONS, population=POPULATION, copies_each=2, steps=STEPS, seed=3, threads=2)


def curve(select):
    h = [r for r in example.cem(select=select, log=lambda s: print(select, s), **SHORT) if "generation" in r]
    return [r["mean_policy"] for r in h], [r["population_mean"] for r in h]


learned, learned_pop = curve("best")
control, control_pop = curve("random")
first = learned_pop[0]
last = sum(learned[-2:]) / 2
last_control = sum(control[-2:]) / 2
print(f"learned: population mean at first {first:+.3f}, mean policy over the last two generations {last:+.3f}; "
      f"random-elite control {last_control:+.3f}")
failures = []
if not last > first + RISE:
    failures.append(f"the reward did not rise by {RISE}: {first:+.3f} -> {last:+.3f}")
if not last > FLOOR:
    failures.append(f"the learned policy scores {last:+.3f}, not above {FLOOR}")
if not last > last_control + GAP:
    failures.append(f"the learner ({last:+.3f}) is not {GAP} above the random-elite control ({last_control:+.3f})")
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
