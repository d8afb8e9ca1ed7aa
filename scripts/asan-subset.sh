#!/usr/bin/env bash
# CI's sanitizer pass: the debug-asan preset (Debug, AddressSanitizer + UBSan) for a named subset
# of the suite that fits the CI's time: the runtime (fibers, teardown, faults), the world-file
# loader and expect, the output formats and the CLI's robustness cases. Builds only what those
# tests need. The engine's long physics suites (field_toi_test, ...) stay in the release run.
set -euo pipefail
cd "$(dirname "$0")/.."
tests=(world_server_test tag_game_test pen_walls_test world_file_test world_file_turtles_test expect_test
       event_log_test state_file_test cli_robust_test)
cmake --preset debug-asan >/dev/null
cmake --build --preset debug-asan --target "${tests[@]}"
regex="^($(IFS='|'; echo "${tests[*]}"))\$"
ctest --preset debug-asan -R "$regex"
