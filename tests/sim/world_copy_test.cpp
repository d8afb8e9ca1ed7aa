// SPDX-License-Identifier: MIT
// World::copy (world.hpp): an exact copy of the engine's whole state. The copy and the original,
// advanced to the same later time, take the same events and reach the same state bit for bit, and
// so does a fresh world run there in one go (a run does not depend on where it is cut); advancing
// the copy leaves the original alone. Exact mode (free flights, gravity, a periodic arena, past a
// rebase of its internal time) and step mode.
#include <catch2/catch.hpp>

#include <vector>

#include "same_bits.hpp"
#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

namespace {

using namespace turtlegas;
using turtlegas::test::random_gas;
using turtlegas::test::same_balls;
using turtlegas::test::same_bits;
using turtlegas::test::same_events;

bool same_state(const sim::World& x, const sim::World& y) {
  return same_balls(x, y) && x.stats().events == y.stats().events;
}

/// Returns the events the original took.
std::uint64_t check_copy(const sim::WorldDef& def, sim::Mode mode, double at, double until) {
  INFO("mode " << (mode == sim::Mode::exact ? "exact" : "step") << ", copy at t = " << at << ", until " << until);
  sim::World original(def, mode), fresh(def, mode);
  std::vector<sim::Event> log_original, log_copy, log_fresh, before;
  original.set_event_log(&before);
  original.advance_to(at);
  sim::World copy = original.copy();
  REQUIRE(same_state(copy, original));
  // The copy logs nowhere until told to (not into the original's log), and takes events.
  const std::size_t logged = before.size();
  copy.advance_to(at + (until - at) / 3);
  REQUIRE(before.size() == logged);
  REQUIRE(copy.stats().events > original.stats().events);
  sim::World copy2 = original.copy();
  // Advancing a copy leaves the original where it was.
  REQUIRE(same_bits(original.time(), at));
  original.set_event_log(&log_original);
  copy2.set_event_log(&log_copy);
  original.advance_to(until);
  copy2.advance_to(until);
  fresh.set_event_log(&log_fresh);
  fresh.advance_to(until);
  REQUIRE(log_original.size() > 100);
  CHECK(same_events(log_original, log_copy));
  CHECK(same_state(original, copy2));
  // The fresh run's events after `at` are the copy's.
  std::vector<sim::Event> tail(log_fresh.end() - static_cast<std::ptrdiff_t>(log_copy.size()), log_fresh.end());
  CHECK(log_fresh.size() == before.size() + log_copy.size());
  CHECK(same_events(tail, log_copy));
  CHECK(same_state(fresh, copy2));
  return original.stats().events;
}

}  // namespace

TEST_CASE("a copied world runs on exactly as the original and as a fresh run", "[world][copy]") {
  SECTION("exact mode, walled gas") { check_copy(random_gas(400, 0.2, 2.0, 30.0, 11), sim::Mode::exact, 1.37, 4.0); }
  SECTION("exact mode, past rebases of internal time") {
    // A rebase every max(4N, 4096) events: 40 balls rebase every 4096 events, several times here.
    CHECK(check_copy(random_gas(40, 0.4, 2.0, 200.0, 3), sim::Mode::exact, 2.1, 12.0) > 3 * 4096);
  }
  SECTION("exact mode, gravity in a box") {
    sim::WorldDef d = random_gas(300, 0.15, 2.0, 40.0, 5);
    d.effects.gravity = {0.0, -9.8};
    check_copy(d, sim::Mode::exact, 0.93, 3.0);
  }
  SECTION("exact mode, periodic arena") {
    check_copy(random_gas(300, 0.2, 2.0, 30.0, 7, sim::Boundary::periodic), sim::Mode::exact, 1.01, 3.5);
  }
  SECTION("exact mode, a gas whose records lie on huge pages") {
    // 70,000 balls: 8.96 MB of records, allocated on 2 MiB boundaries (big_memory.hpp); the copy
    // allocates its own.
    check_copy(random_gas(70'000, 0.2, 2.0, 30.0, 13, sim::Boundary::periodic), sim::Mode::exact, 0.011, 0.03);
  }
  SECTION("step mode") {
    sim::WorldDef d = random_gas(300, 0.2, 2.0, 30.0, 9);
    d.dt = 1.0 / 30;
    check_copy(d, sim::Mode::step, 1.0, 3.0);
  }
}
