#!/usr/bin/env bash
# Quick start (2): install what is missing, build (Release) and run the whole test suite, then the
# sanitizer pass: the debug-asan preset on a named subset (scripts/asan-subset.sh; ASAN=0 skips it).
# Set PRESET=debug-asan for a Debug build with AddressSanitizer and UndefinedBehaviorSanitizer of
# everything (then the subset pass is not run again).
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${PRESET:-release}
bash scripts/install-deps.sh
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset"
ctest --preset "$preset"
if [ "$preset" != debug-asan ] && [ "${ASAN:-1}" != 0 ]; then
  echo "== sanitizer pass: debug-asan (AddressSanitizer + UBSan) on the named subset of scripts/asan-subset.sh (ASAN=0 skips) =="
  bash scripts/asan-subset.sh
fi
