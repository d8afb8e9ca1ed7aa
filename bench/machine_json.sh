#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
#
# Prints, as JSON, the machine and build a benchmark ran on: CPU, cores, compiler, flags, kernel,
# commit (and whether the source folders or bench/ had uncommitted changes), date, load average.
#
#   bash bench/machine_json.sh BUILD_DIR > RESULTS.machine.json
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$1
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
compiler=$(grep '^CMAKE_CXX_COMPILER:' "$build/CMakeCache.txt" | cut -d= -f2)
flags=$(grep '^CMAKE_CXX_FLAGS_RELEASE:' "$build/CMakeCache.txt" | cut -d= -f2)
dirty=$( (git -C "$root" status --porcelain -- sim turtle_runtime controllers world_files formats apps bench 2>/dev/null || true) | wc -l)
CPU=$(lscpu | sed -n 's/^Model name: *//p' | head -1) \
CORES=$(nproc) \
COMPILER=$("$compiler" --version | head -1) \
FLAGS="Release ($flags -ffp-contract=off)" \
KERNEL=$(uname -sr) \
COMMIT="$commit$( (( dirty )) && echo " + uncommitted changes in $dirty files of the source folders and bench/")" \
DATE=$(date -u '+%Y-%m-%d %H:%M') \
LOADAVG=$(cut -d' ' -f1-3 /proc/loadavg) \
python3 -c 'import json, os; print(json.dumps({k.lower(): os.environ[k] for k in
  ["CPU", "CORES", "COMPILER", "FLAGS", "KERNEL", "COMMIT", "DATE", "LOADAVG"]}, indent=2))'
