#!/usr/bin/env bash
# CI's sanitizer pass (scripts/test.sh runs it after the release suite): the debug-asan preset
# (Debug, AddressSanitizer + UBSan) for a named subset of the suite that fits CI's time, building
# only what those tests need. docs/fuzzing.md, "Sanitizers in CI", has the measured costs.
#   scripts/asan-subset.sh                # SUBSET=ci: the engine's and the runtime's tests below
#   SUBSET=full scripts/asan-subset.sh    # also the loader, expect, the formats and the CLI's
#                                         # robustness cases (builds the whole program: ~2x the time)
# The engine's long suites (squeeze_test, field_toi_test, event_queue_test, ...) stay in the release run.
set -euo pipefail
cd "$(dirname "$0")/.."
# sim/: the engine's core scenes, hard cases, body operations, the pivot and moving walls, turtle
# contacts, resting contact, the grid's limits, times of impact, control steps, scene checks.
# turtle_runtime/: the world server (fibers, teardown, faults), remote programs, tag, pen walls.
ci=(world_test hard_cases_test operations_test windmill_pivot_test moving_walls_test turtle_physics_test
    resting_contact_test grid_limits_test toi_test control_steps_test scene_checks_test validate_test
    world_server_test remote_test tag_game_test pen_walls_test)
extra=(world_file_test world_file_turtles_test expect_test event_log_test state_file_test cli_robust_test)
case ${SUBSET:-ci} in
  ci) tests=("${ci[@]}") ;;
  full) tests=("${ci[@]}" "${extra[@]}") ;;
  *) echo "asan-subset.sh: SUBSET is ci or full (got '${SUBSET}')" >&2; exit 2 ;;
esac
start=$SECONDS
cmake --preset debug-asan >/dev/null
cmake --build --preset debug-asan --target "${tests[@]}"
built=$SECONDS
regex="^($(IFS='|'; echo "${tests[*]}"))\$"
ctest --preset debug-asan -R "$regex"
echo "asan-subset: ${#tests[@]} tests (SUBSET=${SUBSET:-ci}) under AddressSanitizer + UBSan passed:" \
     "build $((built - start)) s, tests $((SECONDS - built)) s"
