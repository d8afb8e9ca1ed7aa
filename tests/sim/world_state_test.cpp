// SPDX-License-Identifier: MIT
// World::save_state and World::restore_state (engine_state.hpp): a world built afresh from the
// scene and given the state another world saved at t runs on exactly as that world does, bit for
// bit (events and state), in exact mode (free flights past rebases, a periodic arena, gravity
// with sliding balls, E and B fields, the TC rule) and in step mode (a state saved inside a step
// and at its boundary). And what positions and velocities alone would give: a different run.
// A state that does not fit the world is refused, changing nothing.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "same_bits.hpp"
#include "scenes.hpp"
#include "turtlegas/sim/engine_state.hpp"
#include "turtlegas/sim/world.hpp"

namespace {

using namespace turtlegas;
using turtlegas::test::random_gas;
using turtlegas::test::same_balls;
using turtlegas::test::same_bits;
using turtlegas::test::same_events;

bool same_state(const sim::World& x, const sim::World& y) {
  if (!same_balls(x, y)) return false;
  const sim::Stats &s = x.stats(), &t = y.stats();
  return s.events == t.events && s.collisions() == t.collisions() && s.cell_crossings == t.cell_crossings &&
         s.steps == t.steps && s.slides == t.slides && same_bits(x.energy(), y.energy());
}

/// Runs def to `at`, saves, restores into a fresh world, runs both to `until`: the same events and
/// state. Returns the events taken after `at`.
std::size_t check_restore(const sim::WorldDef& def, sim::Mode mode, double at, double until) {
  INFO("mode " << (mode == sim::Mode::exact ? "exact" : "step") << ", saved at t = " << at << ", until " << until);
  sim::World original(def, mode);
  original.advance_to(at);
  REQUIRE(original.can_save_state());
  const sim::EngineState state = original.save_state();
  sim::World restored(def, mode);
  restored.restore_state(state);
  REQUIRE(same_state(original, restored));
  std::vector<sim::Event> a, b;
  original.set_event_log(&a);
  restored.set_event_log(&b);
  original.advance_to(until);
  restored.advance_to(until);
  CHECK(a.size() > 100);
  CHECK(same_events(a, b));
  CHECK(same_state(original, restored));
  // The saved state of the restored world is the original's, as it went on.
  const sim::EngineState later = restored.save_state();
  CHECK(later.bodies.size() == state.bodies.size());
  return a.size();
}

}  // namespace

TEST_CASE("a restored world runs on exactly as the world that saved its state", "[world][state]") {
  SECTION("exact mode, walled gas") { check_restore(random_gas(400, 0.2, 2.0, 30.0, 11), sim::Mode::exact, 1.37, 4.0); }
  SECTION("exact mode, past rebases of internal time") {
    // A rebase every 4096 events for 40 balls: the state is saved between two, and more follow.
    check_restore(random_gas(40, 0.4, 2.0, 200.0, 3), sim::Mode::exact, 2.1, 12.0);
  }
  SECTION("exact mode, periodic arena") {
    check_restore(random_gas(300, 0.2, 2.0, 30.0, 7, sim::Boundary::periodic), sim::Mode::exact, 1.01, 3.5);
  }
  SECTION("exact mode, gravity, inelastic (the TC rule's clocks, slides)") {
    sim::WorldDef d = random_gas(200, 0.3, 2.0, 40.0, 5);
    d.effects.gravity = {0.0, -60.0};
    d.effects.restitution = 0.7;
    d.effects.tc = 1e-3;
    sim::World probe(d, sim::Mode::exact);
    probe.advance_to(3.0);
    INFO("slides begun by t = 3: " << probe.stats().slides);
    check_restore(d, sim::Mode::exact, 3.0, 5.0);
  }
  SECTION("exact mode, E and B fields (charged flights)") {
    sim::WorldDef d = random_gas(200, 0.2, 2.0, 30.0, 17);
    for (std::size_t i = 0; i < d.balls.size(); ++i) d.balls[i].charge = i % 3 == 0 ? 0.0 : (i % 3 == 1 ? 1.0 : -2.0);
    d.effects.electric = {5.0, 0.0};
    d.effects.magnetic = 0.3;
    check_restore(d, sim::Mode::exact, 0.77, 2.0);
  }
  SECTION("step mode, saved inside a step and on a boundary") {
    sim::WorldDef d = random_gas(300, 0.2, 2.0, 30.0, 9);
    d.dt = 1.0 / 30;
    d.effects.gravity = {0.0, -20.0};
    check_restore(d, sim::Mode::step, 1.01, 3.0);
    check_restore(d, sim::Mode::step, 1.0, 3.0);
  }
}

TEST_CASE("positions and velocities alone continue a different run", "[world][state]") {
  // Why the state holds each body's clock, prediction and list order: a world given only the
  // positions and velocities at t, brought to t, predicts afresh from rounded positions. Its run
  // parts from the original's in the last bits (here within the first 2 simulated seconds).
  const sim::WorldDef d = random_gas(400, 0.2, 2.0, 30.0, 11);
  sim::World original(d, sim::Mode::exact);
  original.advance_to(1.37);
  sim::EngineState s = original.save_state();
  for (sim::EngineState::Body& b : s.bodies) {
    if (b.cell == ~0u) continue;
    const double dt = s.now - b.t;
    b.x = {b.x.x + dt * b.v.x, b.x.y + dt * b.v.y};  // brought to now: the same as ball(i), rounded once
    b.t = s.now;
  }
  sim::World moved(d, sim::Mode::exact);
  moved.restore_state(s);
  original.advance_to(3.37);
  moved.advance_to(3.37);
  bool differ = false;
  for (std::size_t i = 0; i < original.ball_count() && !differ; ++i)
    differ = !same_bits(original.ball(i).pos.x, moved.ball(i).pos.x) || !same_bits(original.ball(i).pos.y, moved.ball(i).pos.y);
  CHECK(differ);
}

TEST_CASE("a state that does not fit the world is refused, changing nothing", "[world][state]") {
  const sim::WorldDef d = random_gas(100, 0.2, 2.0, 30.0, 11);
  sim::World w(d, sim::Mode::exact);
  w.advance_to(0.5);
  const sim::EngineState good = w.save_state();
  sim::World fresh(d, sim::Mode::exact);
  auto refused = [&](sim::EngineState s, const char* what) {
    try {
      fresh.restore_state(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).find(what) != std::string::npos;
    }
    return false;
  };
  sim::EngineState s = good;
  s.variant = "gravity/pairs/exact";
  CHECK(refused(s, "the state is of engine gravity/pairs/exact, this world's is free/pairs/exact"));
  s = good;
  s.bodies.pop_back();
  CHECK(refused(s, "the state has 99 bodies, the world 100"));
  s = good;
  for (sim::EngineState::Body& b : s.bodies)
    if (b.next != ~0u) {
      b.next = b.next == 0 ? 1 : 0;  // a link to a body that does not link back
      break;
    }
  CHECK(refused(s, "does not hold together"));
  s = good;
  s.bodies[3].kind = 1;  // a body partner
  s.bodies[3].partner = 1000;
  CHECK(refused(s, "body 3: its prediction names no such partner"));
  s = good;
  s.bodies[5].x.x = std::nan("");
  CHECK(refused(s, "body 5: a position, velocity or time is not finite"));
  // Nothing changed: the fresh world still runs as a fresh world does.
  sim::World other(d, sim::Mode::exact);
  fresh.advance_to(0.5);
  other.advance_to(0.5);
  CHECK(same_state(fresh, other));
  // The step-mode world's engine is another row.
  sim::WorldDef ds = d;
  ds.dt = 1.0 / 30;
  sim::World step(ds, sim::Mode::step);
  CHECK_THROWS_AS(step.restore_state(good), std::invalid_argument);
}

TEST_CASE("a world with turtles does not save its state", "[world][state]") {
  sim::WorldDef d = random_gas(20, 0.1, 2.0, 30.0, 3);
  sim::TurtleDef t;
  t.id = "t";
  t.pos = {d.arena.width / 2, d.arena.height / 2};
  t.radius = 1.0;
  d.balls.erase(std::remove_if(d.balls.begin(), d.balls.end(),
                               [&](const sim::BallDef& b) {
                                 return std::hypot(b.pos.x - t.pos.x, b.pos.y - t.pos.y) < b.radius + t.radius + 1.0;
                               }),
                d.balls.end());
  d.turtles.push_back(t);
  sim::World w(d, sim::Mode::exact);
  CHECK_FALSE(w.can_save_state());
  CHECK_THROWS_AS(w.save_state(), std::logic_error);
}
