#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The benchmark programs' command lines: --help prints the usage line and exits 0, a bad value or
an option without one exits 2 naming it, never std::terminate or a silently ignored option.

    arguments_test.py --bench-dir BUILD/bench
"""
import argparse
import os
import subprocess
import sys

parser = argparse.ArgumentParser()
parser.add_argument("--bench-dir", required=True)
bench_dir = parser.parse_args().bench_dir

failures = []


def run(program, *args):
    p = subprocess.run([os.path.join(bench_dir, program), *args], capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


def expect(program, args, code, stream, text):
    rc, out, err = run(program, *args)
    got = out if stream == "out" else err
    if rc != code or text not in got:
        failures.append(f"{program} {' '.join(args)}: exit {rc} (want {code}), {stream} {got!r} (want {text!r})")


for program in ["gas_bench", "accuracy_bench", "turtle_bench", "turtle_soak", "vec_bench"]:
    expect(program, ["--help"], 0, "out", "usage: " + program)
    expect(program, ["-h"], 0, "out", "usage: " + program)

expect("turtle_soak", ["--mode", "exat"], 2, "err", "--mode takes exact or step, got 'exat'")
expect("turtle_bench", ["--mode", "exat"], 2, "err", "--mode takes exact or step, got 'exat'")
expect("gas_bench", ["w.json", "--mode", "exat"], 2, "err", "--mode takes exact or step, got 'exat'")
expect("turtle_soak", ["--turtles", "-3"], 2, "err", "--turtles needs a whole number from 1 to 1000000, got '-3'")
expect("turtle_bench", ["--steps", "2.5"], 2, "err", "--steps needs a whole number")
expect("turtle_bench", ["--stack-kib", "8"], 2, "err", "--stack-kib needs a whole number from 16")
expect("turtle_soak", ["--turtle-steps"], 2, "err", "--turtle-steps needs a value")
expect("turtle_bench", ["--frobnicate", "1"], 2, "err", "unknown option --frobnicate")
expect("vec_bench", ["--threads", "0"], 2, "err", "--threads needs a whole number from 1 to 1024, got '0'")
expect("vec_bench", ["--actions", "jump"], 2, "err", "--actions takes velocity, wheels or logo, got 'jump'")

for f in failures:
    print("FAIL:", f)
print(f"{len(failures)} failures")
sys.exit(1 if failures else 0)
