#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
#
# What an effect a scene does not declare would cost if the engine were not specialised: the
# N = 10^4, phi = 0.05 benchmark gas as it is (plain) and with gravity and/or a collision layer
# declared at strengths that change nothing measurable (worlds/bench/effects_*.json, written by
# bench/make_worlds.py), so that the engine runs its general code. The scenes run interleaved,
# ROUNDS rounds (default 5), one process each; thread CPU time per collision. Writes the JSON lines
# to docs/bench/effects-DATE-HOST-COMMIT.jsonl and prints a markdown table (docs/performance.md,
# "What an unused effect costs").
#
#   bash bench/run_effects.sh            # about 1 minute
#   ROUNDS=2 bash bench/run_effects.sh
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${BUILD_DIR:-$root/build-bench}
rounds=${ROUNDS:-5}
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF > /dev/null
cmake --build "$build" --target gas_bench
bench=$build/bench/gas_bench

commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
out=$root/docs/bench/effects-$(date -u +%Y-%m-%d)-$(hostname -s 2>/dev/null || echo host)-$commit.jsonl
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
for ((r = 1; r <= rounds; ++r)); do
  for v in plain gravity layers gravity_layers; do
    line=$("$bench" "$root/worlds/bench/effects_$v.json" --collisions 2e6)
    printf '%s\n' "$line" | VARIANT=$v ROUND=$r python3 -c 'import json, os, sys
d = json.loads(sys.stdin.read()); d["variant"] = os.environ["VARIANT"]; d["round"] = int(os.environ["ROUND"])
print(json.dumps(d))' >> "$tmp"
    echo "round $r/$rounds  $v" >&2
  done
done
mv "$tmp" "$out"
trap - EXIT
echo "results in $out" >&2

python3 - "$out" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
what = {"plain": "nothing declared (the benchmark gas)", "gravity": "gravity [0, -1e-12]: parabolic flights",
        "layers": "one wall in a category of its own: the turtles/layers/moving-walls code",
        "gravity_layers": "both"}
base = None
print("| scene | declares | ns/collision, CPU (median; min) | ÷ plain | collisions | events | cpu/wall |")
print("|---|---|---:|---:|---:|---:|---:|")
for v in ["plain", "gravity", "layers", "gravity_layers"]:
    rr = [r for r in rows if r["variant"] == v]
    ns = [r["cpu_seconds"] * 1e9 / r["collisions"] for r in rr]
    m = statistics.median(ns)
    base = base or m
    share = statistics.median(r["cpu_seconds"] / r["wall_seconds"] for r in rr)
    print(f"| effects_{v} | {what[v]} | {m:.0f}; {min(ns):.0f} | {m / base:.2f} | {rr[0]['collisions']:,} | "
          f"{rr[0]['events']:,} | {share:.2f} |")
PY
