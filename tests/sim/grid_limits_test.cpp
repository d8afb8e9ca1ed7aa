// SPDX-License-Identifier: MIT
// The grid and step mode's neighbourhood at the limits of their numbers (issue 17's fuzzing
// findings): coordinates past int's range, arenas of absurd aspect, speeds that make step mode's
// scan reach past the arena, walls on a periodic arena's seam, the overlap measure's cell indices.
// Every run is bounded by an event limit.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>

#include "cell_grid.hpp"
#include "overlap.hpp"
#include "scenes.hpp"
#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

std::size_t count(const std::vector<Event>& log, EventKind k) {
  std::size_t n = 0;
  for (const Event& e : log) n += e.kind == k;
  return n;
}

bool inside(const World& w, std::size_t i, double width, double height) {
  const Vec2 p = w.ball(i).pos;
  return p.x >= 0.0 && p.x <= width && p.y >= 0.0 && p.y <= height;
}

}  // namespace

TEST_CASE("a wall reaching y = 1e30 is listed in the grid, and a ball bounces off it", "[grid]") {
  // far-wall-passthrough.json: the cell index of 1e30 overflowed an int, the wall landed in no
  // cell, and the ball passed through it.
  for (Mode mode : {Mode::exact, Mode::step}) {
    WorldDef d = box(100, 100, Boundary::none);
    d.walls.push_back({"w", {50, 10}, {50, 1e30}});
    d.balls.push_back(ball("b", {20, 50}, {10, 0}, 1));
    World w(d, mode);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(10000);
    w.advance_to(5.0);
    CHECK(count(log, EventKind::ball_wall) == 1);
    CHECK(w.ball(0).pos.x < 49.0);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("only the part of a wall within a cell of the arena is listed", "[grid]") {
  // slow-check-long-walls.json: over an arena 7e13 x 400 (cells 400 high, 3.7e6 across), a wall
  // from (299, 0) to (1e15, 1e6) leaves the arena at x = 4e11 but ran on through the ring row
  // above it to x = 7e13: it was listed in all 3.7e6 ring cells and their neighbourhoods (`check`:
  // 60 s, 1.4 GB). Beyond one cell outside the arena no body can reach it.
  const double width = 7e13, height = 400, cell = 7e13 / 3741657;
  const std::vector<Segment> walls{make_segment({299, 0}, {1e15, 1e6})};
  const detail::CellGrid grid(width, height, cell, false, walls, {});
  CHECK(grid.memory_bytes() < 100e6);  // the table: 45 MB (3.7e6 x 3 cells of 4 bytes), its lines 30 MB
  auto lists = [&](double x, int iy) {
    const int c = grid.index(static_cast<int>(std::floor(x / grid.cell_w())) + 1, iy);
    return grid.walls_begin(c) != grid.walls_end(c);
  };
  // Still listed where a body can meet it: in the arena's row under it (y = 390 at x = 3.9e11) and
  // in the ring cell above the arena within a cell of it (y = 500 at x = 5e11) ...
  CHECK(lists(3.9e11, 1));
  CHECK(lists(5e11, 2));
  // ... but not further out (y = 1000 at x = 1e12, more than a cell above the arena).
  CHECK_FALSE(lists(1e12, 2));
}

TEST_CASE("an arena of absurd aspect is refused with the key to change, not an overflow or a hang", "[grid]") {
  // aspect-nx-ub-check-hang.json: 1e10 x 1e-10 overflowed the cell count.
  WorldDef d = box(1e10, 1e-10, Boundary::none);
  d.balls.push_back(ball("b", {5, 5e-11}, {1, 0}, 1e-11));
  for (Mode mode : {Mode::exact, Mode::step}) {
    try {
      World w(d, mode);
      FAIL("the grid of 1e21 cells was accepted");
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find("arena.cell") != std::string::npos);
    }
  }
}

TEST_CASE("step mode at speeds whose scan reaches past the arena finds every wall", "[grid][step]") {
  // step-rings-*.json: the ring count grew with speed dt and overflowed an int (no scan at all:
  // the ball left the walled box), or scanned (2k+1)^2 cells that do not exist (a hang).
  struct Case {
    Vec2 v;
    double until;
  };
  for (const Case c : {Case{{3e9, 1e9}, 1e-7}, Case{{1e7, 3e6}, 2.0 / 30.0}, Case{{1e15, 3e14}, 1e-12}}) {
    INFO("velocity " << c.v.x << ", " << c.v.y);
    WorldDef d = box(100, 100);
    d.balls.push_back(ball("b", {50, 50}, c.v, 1));
    World w(d, Mode::step);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(200000);
    REQUIRE_NOTHROW(w.advance_to(c.until));
    // Every bounce found: the ball is in the box, and the count of bounces off the x walls is
    // what its path length says (98 units between two of them), to one.
    CHECK(inside(w, 0, 100, 100));
    const double path_x = std::abs(c.v.x) * c.until;
    const double expected = std::floor((path_x + 49.0) / 98.0);
    std::size_t x_bounces = 0;
    for (const Event& e : log)
      if (e.kind == EventKind::ball_wall && (w.walls()[e.b].from.x == w.walls()[e.b].to.x)) ++x_bounces;
    CHECK(std::abs(static_cast<double>(x_bounces) - expected) <= 1.0);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a periodic arena too small for step mode's scan is refused naming the speed, the dt and the cell rule", "[grid][step]") {
  WorldDef d = box(100, 100, Boundary::periodic);
  d.balls.push_back(ball("b", {50, 50}, {1e5, 0}, 1));
  try {
    World w(d, Mode::step);
    w.set_event_limit(1000);
    w.advance_to(1.0);
    FAIL("accepted");
  } catch (const std::exception& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("speed " + format_number(1e5)) != std::string::npos);
    CHECK(what.find("dt = ") != std::string::npos);
    CHECK(what.find("cell rule") != std::string::npos);
  }
}

TEST_CASE("walls and wall ends on a periodic arena's seam are seen from both sides", "[grid][periodic]") {
  // A wall from (60, 50) to (100, 50): its end on the seam x = W. A disc coming from x = 10
  // towards -x meets that end across the seam at x = 1 (the end's image is (0, 50)).
  {
    WorldDef d = box(100, 100, Boundary::periodic);
    d.walls.push_back({"w", {60, 50}, {100, 50}});
    d.balls.push_back(ball("b", {10, 50}, {-1, 0}, 1));
    World w(d, Mode::exact);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(10000);
    w.advance_to(12.0);
    REQUIRE(!log.empty());
    CHECK(log[0].kind == EventKind::ball_wall_end);
    CHECK(log[0].t == Approx(9.0).epsilon(1e-12));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
  // A wall lying along x = W: a disc at x = 3 moving -x meets its image x = 0 at x = 1.
  {
    WorldDef d = box(100, 100, Boundary::periodic);
    d.walls.push_back({"w", {100, 20}, {100, 80}});
    d.balls.push_back(ball("b", {3, 50}, {-1, 0}, 1));
    d.balls.push_back(ball("c", {95, 30}, {1, 0}, 1));
    World w(d, Mode::exact);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(10000);
    w.advance_to(2.5);
    REQUIRE(count(log, EventKind::ball_wall) == 1);
    CHECK(log[0].t == Approx(2.0).epsilon(1e-12));
    w.advance_to(5.0);
    CHECK(count(log, EventKind::ball_wall) == 2);  // the other at x = 99, t = 4
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("step mode sees walls and wall ends on a periodic arena's seam too", "[grid][periodic][step]") {
  // Its ring scans wrap onto arena cells only, and the seam x = W lists its walls and ends in the
  // ring column col(W) = nx + 1, which they never read: the end at (100, 50) was invisible and a
  // disc ran half a radius into it and on through the wall (docs/physics.md, "The grid").
  for (double y : {50.0, 50.5, 49.2}) {
    INFO("the disc at y = " << y);
    WorldDef d = box(100, 100, Boundary::periodic);
    d.walls.push_back({"w", {60, 50}, {100, 50}});
    d.balls.push_back(ball("b", {10, y}, {-1, 0}, 1));
    World w(d, Mode::step);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(100000);
    double worst = 0.0;
    for (int k = 1; k <= 120; ++k) {
      w.advance_to(k * 0.1);
      worst = std::max(worst, w.measure_overlap().relative);
    }
    REQUIRE(!log.empty());
    CHECK(log[0].kind == EventKind::ball_wall_end);
    // It meets the end's image (0, 50) when its centre is one radius from it.
    CHECK(log[0].t == Approx(9.0 + (1.0 - std::sqrt(1.0 - (y - 50) * (y - 50)))).epsilon(1e-12));
    CHECK(worst <= 1e-9);
  }
  {
    // A wall lying along x = W: discs from both sides meet it (at x = 1 and x = 99).
    WorldDef d = box(100, 100, Boundary::periodic);
    d.walls.push_back({"w", {100, 20}, {100, 80}});
    d.balls.push_back(ball("b", {3, 50}, {-1, 0}, 1));
    d.balls.push_back(ball("c", {95, 30}, {1, 0}, 1));
    World w(d, Mode::step);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(100000);
    double worst = 0.0;
    for (int k = 1; k <= 50; ++k) {
      w.advance_to(k * 0.1);
      worst = std::max(worst, w.measure_overlap().relative);
    }
    REQUIRE(count(log, EventKind::ball_wall) == 2);
    CHECK(log[0].t == Approx(2.0).epsilon(1e-12));
    CHECK(log[1].t == Approx(4.0).epsilon(1e-12));
    CHECK(worst <= 1e-9);
  }
  {
    // A wall ending on the seam y = H, met from y = 5 going down: its image ends at (50, 0).
    WorldDef d = box(100, 100, Boundary::periodic);
    d.walls.push_back({"w", {50, 60}, {50, 100}});
    d.balls.push_back(ball("b", {50, 5}, {0, -1}, 1));
    World w(d, Mode::step);
    std::vector<Event> log;
    w.set_event_log(&log);
    w.set_event_limit(100000);
    double worst = 0.0;
    for (int k = 1; k <= 60; ++k) {
      w.advance_to(k * 0.1);
      worst = std::max(worst, w.measure_overlap().relative);
    }
    REQUIRE(!log.empty());
    CHECK(log[0].kind == EventKind::ball_wall_end);
    CHECK(log[0].t == Approx(4.0).epsilon(1e-12));
    CHECK(worst <= 1e-9);
  }
}

TEST_CASE("the overlap measure sees a disc inside a long wall on the seam, through the right image", "[overlap][periodic]") {
  // For a wall longer than half the arena, the image of a disc nearest to the wall's first end
  // is not the one nearest to the wall: the measure reported 0 against a real overlap of 0.5.
  const std::vector<Vec2> pos{{85, 50.5}};
  detail::DiscView discs{1, [&](std::size_t i) { return pos[i]; }, [](std::size_t) { return 1.0; },
                         [](std::size_t) { return true; }};
  const std::vector<Segment> walls{make_segment({10, 50}, {90, 50})};
  CHECK(detail::deepest_overlap(discs, walls, 100, 100, false).relative == Approx(0.5).epsilon(1e-9));
}

TEST_CASE("the overlap measure of a gas of tiny discs has its cell indices in range", "[overlap]") {
  // overlap-int64-ub.min.json: discs of radius 1e-22 at coordinates ~50 have cell indices past
  // int64's range (undefined behaviour once); 100 of them take the grid path, not the brute one.
  WorldDef d = box(100, 100);
  for (int k = 0; k < 100; ++k) d.balls.push_back(ball("g" + std::to_string(k), {5.0 + k * 0.9, 50.0 + (k % 7)}, {0, 0}, 1e-22));
  World w(d, Mode::exact);
  CHECK(w.measure_overlap().depth == 0.0);
}

TEST_CASE("the overlap measure finds the same pairs with narrow and wide cell indices", "[overlap]") {
  // The measure keeps cells in 32-bit indices when every one fits (|index| < 2^30) and in 64-bit
  // ones otherwise. A lattice of 200 discs (the grid path) with one pair overlapping by 0.25 r,
  // placed where the cells are small numbers, just below 2^30 cells from the origin (narrow), and
  // past it (wide); every placement must report that pair and nothing deeper. The lattice's pairs
  // straddle cell edges and rows, so a wrong neighbour cell would miss the overlapping one.
  for (double origin : {0.0, 2.0 * 0x1p30 - 600.0, 2.0 * 0x1p30 + 600.0, 1e12}) {
    INFO("origin " << origin);
    std::vector<Vec2> pos;
    pos.reserve(200);
    for (int k = 0; k < 200; ++k) {
      const int row = k / 20, col = k % 20;
      pos.push_back({origin + 3.0 * col, 3.0 * row});
    }
    pos[137] = pos[136] + Vec2{1.75, 0.0};  // radius 1: overlap 0.25, moved left onto its neighbour
    detail::DiscView discs{pos.size(), [&](std::size_t i) { return pos[i]; }, [](std::size_t) { return 1.0; },
                           [](std::size_t) { return true; }};
    const Overlap o = detail::deepest_overlap(discs, {});
    CHECK(o.relative == Approx(0.25).epsilon(1e-6));
  }
}

TEST_CASE("the overlap measure's hashed grid agrees with every pair checked, and sees one injected overlap", "[overlap]") {
  // The measure buckets cells by a hash (issue 31: O(N) a sample, buffers kept between samples).
  // Against an O(N^2) check of every pair, on gases of mixed radii, open and periodic, with one
  // pair pushed into each other by a known depth; the same scratch measures them all in turn,
  // so its kept buffers and cell side are reused across sizes (seed printed on failure).
  detail::OverlapScratch scratch;
  for (const std::uint32_t seed : {1u, 2u, 3u}) {
    for (const double periodic : {0.0, 300.0}) {
      for (const std::size_t n : {50u, 700u, 3000u}) {
        INFO("seed " << seed << ", periodic " << periodic << ", n " << n);
        std::uint64_t x = seed * 0x9E3779B97F4A7C15ull;
        auto uniform = [&] {
          x ^= x << 13, x ^= x >> 7, x ^= x << 17;
          return static_cast<double>(x >> 11) * 0x1p-53;
        };
        std::vector<Vec2> pos(n);
        std::vector<double> r(n);
        for (std::size_t i = 0; i < n; ++i) {
          pos[i] = {uniform() * 300.0, uniform() * 300.0};
          r[i] = 0.2 + 0.8 * uniform();
        }
        // Push disc 7 into disc 3 (across the seam when periodic), 0.3 of the smaller radius deep.
        const double depth = 0.3 * std::min(r[3], r[7]);
        pos[3] = {periodic > 0.0 ? 299.9 : 150.0, 40.0};
        pos[7] = pos[3] + Vec2{r[3] + r[7] - depth, 0.0};
        if (periodic > 0.0) pos[7].x -= periodic;
        std::vector<bool> alive(n, true);
        alive[11] = false;  // a retired disc is not measured
        pos[11] = pos[3];
        Overlap brute;
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t j = i + 1; j < n; ++j) {
            if (!alive[i] || !alive[j]) continue;
            Vec2 d = pos[j] - pos[i];
            if (periodic > 0.0) d = {d.x - periodic * std::round(d.x / periodic), d.y - periodic * std::round(d.y / periodic)};
            const double o = r[i] + r[j] - norm(d);
            if (o <= 0.0) continue;
            brute.depth = std::max(brute.depth, o);
            brute.relative = std::max(brute.relative, o / std::min(r[i], r[j]));
          }
        const Overlap o = detail::deepest_overlap(
            scratch, n, [&](std::size_t i) { return pos[i]; }, [&](std::size_t i) { return r[i]; },
            [&](std::size_t i) { return static_cast<bool>(alive[i]); }, {}, periodic, periodic, true, nullptr, nullptr,
            300.0);
        CHECK(o.depth == brute.depth);
        CHECK(o.relative == brute.relative);
        CHECK(o.relative >= 0.3 * (1.0 - 1e-9));
      }
    }
  }
}
