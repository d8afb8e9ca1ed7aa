// SPDX-License-Identifier: MIT
// A disc touching the pivot of a turning wall (issue 17, section 5b): an arm turns about its first
// end, which a disc touches. At the pivot the arm's material point does not move, so the contact
// has neither a negative first-order rate nor a positive starting gap; the arm sweeps into the disc
// at second order. It once overlapped the arm by up to one radius, in both modes. Overlap is
// sampled over the run; every run is bounded by an event limit.
#include <catch2/catch.hpp>

#include <cmath>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

const Mode kModes[] = {Mode::exact, Mode::step};

/// A 100 x 100 walled box and an arm from the pivot (50, 50), 30 long, turning counterclockwise
/// a quarter turn per second (keyframes every 90 degrees; between them its free end moves on the
/// chord, so the arm turns and stretches).
WorldDef windmill(double restitution, Vec2 gravity = {}) {
  WorldDef d = box(100, 100);
  const Vec2 p{50, 50};
  std::vector<WallKey> keys;
  for (int k = 1; k <= 8; ++k) {
    const double a = k * M_PI / 2;
    keys.push_back({static_cast<double>(k), p, p + 30.0 * Vec2{std::cos(a), std::sin(a)}});
  }
  d.walls.push_back(moving("arm", p, p + Vec2{30, 0}, keys));
  d.effects.restitution = restitution;
  d.effects.gravity = gravity;
  return d;
}

}  // namespace

TEST_CASE("a disc touching the pivot of a turning arm is pushed off, never overlapped", "[pivot]") {
  // A disc of radius 5 at rest exactly one radius from the pivot (offsets exact in binary): (0, 5)
  // touches the arm at the pivot at once; (-3, 4) and (-4, 3) touch the pivot from behind, and the
  // arm sweeps round onto them.
  for (Mode mode : kModes) {
    for (double e : {1.0, 0.5}) {
      for (Vec2 off : {Vec2{0, 5}, Vec2{-3, 4}, Vec2{-4, 3}}) {
        INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", e = " << e << ", disc at pivot + (" << off.x
                     << ", " << off.y << ")");
        WorldDef d = windmill(e);
        d.balls.push_back(ball("b", Vec2{50, 50} + off, {0, 0}, 5));
        World w(d, mode);
        w.set_event_limit(200000);
        const double worst = deepest_over_run(w, 4.0, 400);
        CHECK(worst <= 1e-9);
        CHECK(w.ball(0).alive);
        // The arm drove it away from the pivot.
        CHECK(norm(w.ball(0).pos - Vec2{50, 50}) > 6.0);
      }
    }
  }
}
