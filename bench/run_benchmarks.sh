#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
#
# Builds gas_bench (Release, build-bench/), runs every worlds/bench/*.json scene in exact and step
# mode, each run in its own process, writes the JSON lines to docs/bench/results-DATE-HOST-COMMIT.jsonl and
# regenerates the tables and the plot in docs/performance.md.
#
#   bash bench/run_benchmarks.sh           # the full set, 3-5 minutes on 2 cores
#   bash bench/run_benchmarks.sh --quick   # small budgets, to check the script; leaves docs/ alone
#
# Extra gas_bench options for every run can be given in GAS_BENCH_ARGS (e.g. "--max-wall 120").
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/bench_lib.sh"
build=${BUILD_DIR:-$root/build-bench}
quick=0
if [[ ${1:-} == --quick ]]; then quick=1; fi

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF > /dev/null
cmake --build "$build" --target gas_bench
bench=$build/bench/gas_bench

stamp=$(date -u +%Y-%m-%d)
host=$(hostname -s 2>/dev/null || echo host)
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
if (( quick )); then
  out_dir=$build/quick
  exact_budget=(--collisions 2e5)
  step_budget=(--ball-steps 2e6)
else
  out_dir=$root/docs/bench
  exact_budget=()  # gas_bench's defaults: max(5e6, 10 N) collisions
  step_budget=()   # and max(1e7, 10 N) ball-steps
fi
mkdir -p "$out_dir"
results=$out_dir/results-$stamp-$host-$commit.jsonl
machine=$out_dir/results-$stamp-$host-$commit.machine.json
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT

bash "$root/bench/machine_json.sh" "$build" > "$machine"

# One line per run on stderr while the set runs.
progress='import json, sys
r = json.loads(sys.stdin.read())
print("%7.2f s  %6.3f M coll/s  %7.3f M ball-steps/s  %6.0f B/ball" % (r["wall_seconds"],
      r["collisions_per_second"] / 1e6, r["ball_steps_per_second"] / 1e6, r["bytes_per_ball"]))'

start=$SECONDS
for world in "$root"/worlds/bench/gas_*.json; do
  for mode in exact step; do
    if [[ $mode == exact ]]; then budget=("${exact_budget[@]}"); else budget=("${step_budget[@]}"); fi
    printf '%-28s %-5s ' "$(basename "$world" .json)" "$mode" >&2
    # shellcheck disable=SC2086  # GAS_BENCH_ARGS is a list of options
    "$bench" "$world" --mode "$mode" "${budget[@]}" ${GAS_BENCH_ARGS:-} >> "$tmp"
    tail -n 1 "$tmp" | python3 -c "$progress" >&2
  done
done
mv "$tmp" "$results"
trap - EXIT
echo "$(( SECONDS - start )) s; results in $results" >&2

report make_tables.py "$results" "$machine" "$quick" "$root/docs/bench/ns_per_collision.svg"
