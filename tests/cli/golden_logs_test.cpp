// SPDX-License-Identifier: MIT
// Pinned event logs: every demo world in worlds/, run by the turtlegas program in both modes, must
// give the very bytes it gave when its hash was pinned here (event log and final state).
//
// The determinism tests elsewhere compare two runs of one build with each other; this one compares
// a run with history, so a change that moves any collision by one bit (a reordered sum, a new
// tie-break, a different rounding in the output) fails here even when both of its runs agree.
// The project builds with -ffp-contract=off and SSE2 arithmetic, so the bytes do not depend on the
// optimisation level (this test passes in the release and the debug-asan presets alike).
//
// When a change is meant to alter the physics or the log format (not a refactor, which must keep
// every hash), the failure prints the new hash of each world: replace the table's entry and say in
// the commit why the logs changed.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "run_cli.hpp"

using namespace turtlegas::test;

namespace {

/// FNV-1a, 64 bits: small, stable, and enough to tell two logs apart.
std::uint64_t fnv1a(const std::string& bytes, std::uint64_t h = 0xcbf29ce484222325ULL) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string hex(std::uint64_t h) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(h));
  return s;
}

struct Pinned {
  const char* world;  ///< under worlds/
  const char* mode;   ///< exact or step
  const char* hash;   ///< fnv1a(events) then the state file, as hex
};

// `turtlegas run worlds/W --until 20 --mode M --events E --state-out S`, pinned at 894b2f5 (the
// four field worlds, cyclotron, exb_drift, magnetic_bottle and memo_gas_fields, when they were added).
const std::vector<Pinned> pinned = {
    {"cyclotron.json", "exact", "0ffe05d204120f30"},
    {"cyclotron.json", "step", "e11332d574635120"},
    {"draw.json", "exact", "fb9cca1e30b04a20"},
    {"draw.json", "step", "4c640f4fdc114dfc"},
    {"exb_drift.json", "exact", "7dd4360ff4d7d7fd"},
    {"exb_drift.json", "step", "afeddbf2e25524c7"},
    {"gas.json", "exact", "f60c655c9149b11e"},
    {"gas.json", "step", "5c27031e3ec3c7f7"},
    {"gas_gravity.json", "exact", "241ac23cdf1e67dc"},
    {"gas_gravity.json", "step", "a148bc1d2f43722b"},
    {"ghost.json", "exact", "b4515ec3d4e2a21d"},
    {"ghost.json", "step", "c425d0b1b0deb964"},
    {"magnetic_bottle.json", "exact", "123ef990cae01d5f"},
    {"magnetic_bottle.json", "step", "1b1c31fed1f55cfc"},
    {"memo_gas_fields.json", "exact", "91fdd2c3c673e846"},
    {"memo_gas_fields.json", "step", "3ba59b48bea438ee"},
    {"mirror.json", "exact", "d4c032722a652820"},
    {"mirror.json", "step", "45b33dc5031f6389"},
    {"mixed.json", "exact", "facb2031eda406f5"},
    {"mixed.json", "step", "339cc69f970023a9"},
    {"pen_walls.json", "exact", "83196cb805b17231"},
    {"pen_walls.json", "step", "6646d96f0e8bafff"},
    {"piston.json", "exact", "cb6c02d7880a4c02"},
    {"piston.json", "step", "b12d679fe48ba081"},
    {"script.json", "exact", "cd72b0645815ecf1"},
    {"script.json", "step", "5d1929787991b77f"},
    {"spiral.json", "exact", "4ec42a104606ec35"},
    {"spiral.json", "step", "5807f3536c7034e9"},
    {"square.json", "exact", "1d226da229699c25"},
    {"square.json", "step", "c39a00f140871ac7"},
    {"tag.json", "exact", "932a9689608119af"},
    {"tag.json", "step", "d22925bcf9505e45"},
    {"wall_follower.json", "exact", "b4b7e7e6b8f91118"},
    {"wall_follower.json", "step", "6d3c9f1ad557f966"},
    {"wander.json", "exact", "fdf49231acaddb0e"},
    {"wander.json", "step", "6d5c87b308a1164f"},
    {"windmill.json", "exact", "e713cf57e444ccb7"},
    {"windmill.json", "step", "354e4c5ca5046ecd"},
};

}  // namespace

TEST_CASE("golden logs: every demo world gives the bytes pinned for it") {
  TempDir dir;
  std::string table;  // the whole table as it now stands, printed once if anything moved
  int moved = 0;
  for (const Pinned& p : pinned) {
    const std::string world = std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/" + p.world;
    const auto events = dir.path / "events.jsonl", state = dir.path / "state.json";
    const Result r = run(dir, {"run", world, "--until", "20", "--mode", p.mode, "--events", events.string(),
                               "--state-out", state.string()});
    INFO(p.world << " --mode " << p.mode << ": " << r.err);
    REQUIRE(r.code == 0);
    const std::string log = read(events), end = read(state);
    REQUIRE(!end.empty());
    const std::string h = hex(fnv1a(end, fnv1a(log)));
    table += std::string("    {\"") + p.world + "\", \"" + p.mode + "\", \"" + h + "\"},\n";
    if (h != p.hash) {
      ++moved;
      UNSCOPED_INFO(p.world << " --mode " << p.mode << ": pinned " << p.hash << ", now " << h << " ("
                            << std::count(log.begin(), log.end(), '\n') << " events)");
    }
  }
  if (moved > 0) UNSCOPED_INFO("the table as it now stands:\n" << table);
  CHECK(moved == 0);
}
