// SPDX-License-Identifier: MIT
// A stress run: 100 turtles running wander in a cluttered arena for 10^5 control steps. No overlap,
// no escape, no NaN.
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;

TEST_CASE("100 turtles running wander in a cluttered arena for 10^5 steps: no overlap, no escape, no NaN",
          "[controllers][stress]") {
  constexpr int side = 10;  // turtles on a 10 x 10 lattice, one every 100 units
  constexpr double spacing = 100.0, radius = 8.0;
  constexpr std::uint64_t steps = 100'000;
  sim::WorldDef d;
  d.name = "many wanderers";
  d.seed = 20240;
  d.arena.width = d.arena.height = side * spacing;
  d.arena.boundary = sim::Boundary::walls;
  d.dt = 0.01;  // 10^5 steps: 1000 s
  // Clutter: a short wall at every inner lattice corner, turned a different way each time, so the
  // turtles meet walls, wall ends and each other.
  for (int i = 1; i < side; ++i)
    for (int j = 1; j < side; ++j) {
      const sim::Vec2 c{i * spacing, j * spacing};
      const double a = 0.7 * (i * side + j);
      const sim::Vec2 half{24 * std::cos(a), 24 * std::sin(a)};
      d.walls.push_back({"w" + std::to_string(i) + "-" + std::to_string(j), c - half, c + half});
    }
  std::vector<turtle::TurtleProgram> programs;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      sim::TurtleDef t;
      t.id = "t" + std::to_string(i * side + j);
      t.pos = {(i + 0.5) * spacing, (j + 0.5) * spacing};
      t.heading = 0.37 * (i * side + j);
      t.radius = radius;
      t.speed = 40.0 + (i + j) % 5 * 10.0;
      t.turn_rate = 3.0;
      d.turtles.push_back(t);
      turtle::TurtleProgram p;
      p.controller = "wander";
      p.params = {{"back_off", 3}, {"step", 300}};
      programs.push_back(p);
    }

  turtle::WorldServer s(d, programs, controllers::builtin_registry());
  std::vector<turtle::LogEvent> log;
  s.set_event_log(&log);
  std::uint64_t touches = 0, faults = 0;
  double worst_overlap = 0.0;
  const auto start = std::chrono::steady_clock::now();
  auto check_all = [&] {
    for (std::size_t i = 0; i < s.turtle_count(); ++i) {
      const sim::TurtleState st = s.world().turtle(i);
      INFO("seed " << d.seed << ", turtle " << i << " at t = " << s.time() << ": " << st.pos.x << ", " << st.pos.y);
      REQUIRE(std::isfinite(st.pos.x));
      REQUIRE(std::isfinite(st.pos.y));
      REQUIRE(std::isfinite(st.heading));
      REQUIRE(st.pos.x - radius >= -1e-9);
      REQUIRE(st.pos.x + radius <= d.arena.width + 1e-9);
      REQUIRE(st.pos.y - radius >= -1e-9);
      REQUIRE(st.pos.y + radius <= d.arena.height + 1e-9);
    }
    const sim::Overlap o = s.world().measure_overlap();
    worst_overlap = std::max(worst_overlap, o.relative);
    REQUIRE(o.relative <= 1e-9);
  };
  for (std::uint64_t k = 1; k <= steps; ++k) {
    s.run_until(static_cast<double>(k) * d.dt);
    for (const auto& e : log) {
      touches += e.kind == "touch" ? 1 : 0;
      faults += e.kind == "fault" ? 1 : 0;
    }
    log.clear();
    if (k % 1000 == 0) check_all();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  check_all();
  WARN("100 turtles, " << steps << " steps: " << seconds << " s wall, " << s.world().stats().collisions()
                       << " collisions, " << touches << " touches, worst overlap " << worst_overlap << " of a radius");
  CHECK(faults == 0);
  CHECK(touches > 10'000);  // they are busy: about one touch per turtle every 10 s at least
  CHECK(s.world().max_contact_overlap().relative <= 1e-9);
  CHECK(s.time() == Approx(1000.0));
}
