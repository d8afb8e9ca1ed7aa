#!/usr/bin/env bash
# Quick start (1): install what is missing, build (Release) and run the main demo: the memo's gas
# in a box with interior walls. Writes out/gas.svg (a picture of the final state) and
# out/gas-stats.json, and prints the run's statistics.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target turtlegas
mkdir -p out
./build/release/turtlegas run worlds/gas.json --until 20 --stats \
  --stats-json out/gas-stats.json --events out/gas-events.jsonl --svg out/gas.svg
echo "demo: wrote out/gas.svg, out/gas-stats.json and out/gas-events.jsonl"
