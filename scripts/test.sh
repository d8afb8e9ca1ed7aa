#!/usr/bin/env bash
# Quick start (2): install what is missing, build (Release) and run the whole test suite.
# Set PRESET=debug-asan for a Debug build with AddressSanitizer and UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${PRESET:-release}
bash scripts/install-deps.sh
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset"
ctest --preset "$preset"
