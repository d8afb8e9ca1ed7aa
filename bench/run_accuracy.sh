#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
#
# Builds accuracy_bench (Release, build-bench/), runs it (exact mode and step mode at six dt on the
# ballistic scene and the memo's gas under gravity, one process, about 30 s), writes the JSON lines
# to docs/bench/accuracy-DATE-HOST-COMMIT.jsonl and regenerates the "What accuracy costs" tables and
# the plot docs/bench/accuracy.svg in docs/performance.md.
#
#   bash bench/run_accuracy.sh           # the full set
#   bash bench/run_accuracy.sh --quick   # T = 5 s, three dt: checks the script; leaves docs/ alone
#
# BUILD_DIR picks another build directory (an existing Release build is reused as it is).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/bench/bench_lib.sh"
build=${BUILD_DIR:-$root/build-bench}
quick=0
if [[ ${1:-} == --quick ]]; then quick=1; fi

if [[ ! -f $build/CMakeCache.txt ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF > /dev/null
fi
cmake --build "$build" --target accuracy_bench

stamp=$(date -u +%Y-%m-%d)
host=$(hostname -s 2>/dev/null || echo host)
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
if (( quick )); then
  out_dir=$build/quick
  args=(--until 5 --dts 10,100,1000 --min-cpu 0.1)
else
  out_dir=$root/docs/bench
  args=()
fi
mkdir -p "$out_dir"
results=$out_dir/accuracy-$stamp-$host-$commit.jsonl
machine=$out_dir/accuracy-$stamp-$host-$commit.machine.json
bash "$root/bench/machine_json.sh" "$build" > "$machine"

start=$SECONDS
# From the repository root: the bench's default world files are relative to it.
(cd "$root" && "$build/bench/accuracy_bench" "${args[@]}") > "$results.tmp"
mv "$results.tmp" "$results"
echo "$(( SECONDS - start )) s; results in $results" >&2

report make_accuracy.py "$results" "$machine" "$quick" "$root/docs/bench/accuracy.svg"
