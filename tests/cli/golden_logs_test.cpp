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
    {"ghost.json", "exact", "7cd10681e5b0edd4"},
    {"ghost.json", "step", "a680805cd5ed34e1"},
    {"magnetic_bottle.json", "exact", "123ef990cae01d5f"},
    {"magnetic_bottle.json", "step", "1b1c31fed1f55cfc"},
    {"memo_gas_fields.json", "exact", "91fdd2c3c673e846"},
    {"memo_gas_fields.json", "step", "3ba59b48bea438ee"},
    {"mirror.json", "exact", "f526474f48117b13"},
    {"mirror.json", "step", "62a081302ada495f"},
    {"mixed.json", "exact", "5282bfc9279bf77a"},
    {"mixed.json", "step", "0a43a481b16b8c2a"},
    {"pen_walls.json", "exact", "8a16bba47aac7265"},
    {"pen_walls.json", "step", "1a92dbabc17fca62"},
    {"piston.json", "exact", "cb6c02d7880a4c02"},
    {"piston.json", "step", "b12d679fe48ba081"},
    {"script.json", "exact", "3235f9998f0ececc"},
    {"script.json", "step", "78cb3d26558f691f"},
    {"spiral.json", "exact", "69eefbcc8eab6a31"},
    {"spiral.json", "step", "6943fbbdac3013d4"},
    {"square.json", "exact", "1d226da229699c25"},
    {"square.json", "step", "3fff20a9be3871a8"},
    {"tag.json", "exact", "b4cf802461c47246"},
    {"tag.json", "step", "e71030771ecee1e2"},
    {"wall_follower.json", "exact", "aa163fcc5023fa25"},
    {"wall_follower.json", "step", "3a37f4fe5081b01b"},
    {"wander.json", "exact", "dcd27f3ab878555d"},
    {"wander.json", "step", "6396fc88161ed7d9"},
    {"windmill.json", "exact", "2edb3fd882b65c32"},
    {"windmill.json", "step", "b5862ebf64344a64"},
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
