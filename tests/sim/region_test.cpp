// SPDX-License-Identifier: MIT
// World::balls_in_rect, the grid's region query, against the O(N) filter over every ball, on
// random rectangles: inside the arena, reaching past it, crossing a periodic arena's seams,
// wider than the arena, empty; walled, open (balls exit) and periodic arenas; both modes, at
// control boundaries and between them.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas;
using namespace turtlegas::test;

namespace {

/// Whether x has an image x + k * period in [lo, hi] (k = 0 only when period is 0).
bool has_image(double x, double lo, double hi, double period) {
  if (period == 0.0) return x >= lo && x <= hi;
  for (int k = -4; k <= 4; ++k)
    if (x + k * period >= lo && x + k * period <= hi) return true;
  return false;
}

std::vector<std::uint32_t> brute(const sim::World& w, sim::Vec2 lo, sim::Vec2 hi, double px, double py) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < w.ball_count(); ++i) {
    const sim::BallState b = w.ball(i);
    if (b.alive && has_image(b.pos.x, lo.x, hi.x, px) && has_image(b.pos.y, lo.y, hi.y, py))
      out.push_back(static_cast<std::uint32_t>(i));
  }
  return out;
}

}  // namespace

TEST_CASE("the region query equals the O(N) filter on random rectangles", "[region]") {
  for (sim::Boundary boundary : {sim::Boundary::walls, sim::Boundary::periodic, sim::Boundary::none}) {
    for (sim::Mode mode : {sim::Mode::exact, sim::Mode::step}) {
      const std::uint64_t seed = 17 + static_cast<int>(boundary) * 10 + (mode == sim::Mode::step);
      INFO("boundary " << static_cast<int>(boundary) << ", mode " << (mode == sim::Mode::step ? "step" : "exact")
                       << ", seed " << seed);
      WorldDef def = random_gas(600, 0.15, 3.0, 80.0, seed, boundary);
      sim::World w(def, mode);
      const double W = def.arena.width, H = def.arena.height;
      const bool periodic = boundary == sim::Boundary::periodic;
      std::mt19937_64 rng(seed);
      auto u = [&](double a, double b) { return a + (b - a) * (static_cast<double>(rng() >> 11) * 0x1.0p-53); };
      std::size_t found = 0, crossing = 0;
      for (int k = 1; k <= 12; ++k) {
        // At control boundaries and between them (a third of a step on).
        w.advance_to(k * 0.25 + (k % 2 ? w.dt() / 3 : 0.0));
        for (int q = 0; q < 60; ++q) {
          sim::Vec2 lo{u(-0.3 * W, 1.1 * W), u(-0.3 * H, 1.1 * H)};
          sim::Vec2 size{u(0, 0.6 * W), u(0, 0.6 * H)};
          if (q % 10 == 0) size = {u(1.0 * W, 2.5 * W), u(0.1 * H, 0.4 * H)};  // wider than the arena
          if (q % 10 == 1) size = {0, 0};                                       // a point
          if (q % 10 == 2) lo = {W - 0.5 * size.x, H - 0.5 * size.y};           // across both seams
          const sim::Vec2 hi = lo + size;
          if (lo.x < 0 || hi.x > W || lo.y < 0 || hi.y > H) ++crossing;
          std::vector<std::uint32_t> got;
          w.balls_in_rect(lo, hi, got);
          const auto want = brute(w, lo, hi, periodic ? W : 0.0, periodic ? H : 0.0);
          INFO("rect [" << lo.x << ", " << hi.x << "] x [" << lo.y << ", " << hi.y << "] at t = " << w.time());
          REQUIRE(got == want);
          found += got.size();
        }
        std::vector<std::uint32_t> none;
        w.balls_in_rect({10, 10}, {5, 20}, none);  // lo > hi: nothing
        REQUIRE(none.empty());
      }
      CHECK(found > 3000);  // the rectangles found balls, many of them
      CHECK(crossing > 200);
      if (boundary == sim::Boundary::none) CHECK(w.stats().exits > 0);  // and exited balls are left out
    }
  }
}

TEST_CASE("the region query finds spawned balls and leaves removed ones out", "[region]") {
  WorldDef def = random_gas(100, 0.1, 3.0, 50.0, 4, sim::Boundary::periodic);
  sim::World w(def, sim::Mode::exact);
  w.advance_to(1.0);
  const double W = def.arena.width;
  // A spot clear of every ball: try a few.
  std::size_t b = 0;
  for (double x = 5; x < W; x += 7.3) {
    try {
      b = w.spawn_ball(ball("s", {x, 0.5 * W}, {0, 0}, 1.0));
      break;
    } catch (const sim::PlacementError&) {
    }
  }
  REQUIRE(b == 100);
  const sim::Vec2 p = w.ball(b).pos;
  std::vector<std::uint32_t> got;
  w.balls_in_rect({p.x - 0.5, p.y - 0.5}, {p.x + 0.5, p.y + 0.5}, got);
  CHECK(got == std::vector<std::uint32_t>{static_cast<std::uint32_t>(b)});
  // Its image one period over.
  got.clear();
  w.balls_in_rect({p.x + W - 0.5, p.y - W - 0.5}, {p.x + W + 0.5, p.y - W + 0.5}, got);
  CHECK(got == std::vector<std::uint32_t>{static_cast<std::uint32_t>(b)});
  w.remove_ball(b);
  got.clear();
  w.balls_in_rect({p.x - 0.5, p.y - 0.5}, {p.x + 0.5, p.y + 0.5}, got);
  CHECK(got.empty());
}
