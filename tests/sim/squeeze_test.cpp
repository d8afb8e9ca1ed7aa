// SPDX-License-Identifier: MIT
// The squeeze rule (docs/physics.md, "Wedged and crushed bodies"): a body caught between two
// obstacles of infinite mass is wedged (its velocity along the squeeze taken away, a `wedged`
// event) or, when the two close on it, crushed (removed, a `crushed` event naming both). Every
// scene here hung before the rule (events without time advancing); each runs under an event
// limit, so that a regression fails with EventLimitReached instead of hanging.
#include <catch2/catch.hpp>

#include <cmath>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

constexpr std::uint64_t kLimit = 200000;  // far above what any scene here needs

struct Run {
  std::vector<Event> log;
  std::size_t count(EventKind k) const {
    std::size_t n = 0;
    for (const Event& e : log) n += e.kind == k;
    return n;
  }
  const Event* first(EventKind k) const {
    for (const Event& e : log)
      if (e.kind == k) return &e;
    return nullptr;
  }
};

/// Runs w to t under the event limit, logging into run.
void run_to(World& w, Run& run, double t) {
  w.set_event_log(&run.log);
  w.set_event_limit(kLimit);
  REQUIRE_NOTHROW(w.advance_to(t));
}

const Mode kModes[] = {Mode::exact, Mode::step};

/// The piston: a 300 x 200 walled arena, a wall from (20, 10)-(20, 190) keyed to x = 290
/// at t = 10 (27 units/s), and a ball or turtle of radius 8 at rest at (150, 150). The arena's
/// right wall is x = 300, so the room closes when the piston reaches x = 284: t* = 264/27.
WorldDef piston_scene() {
  WorldDef d = box(300, 200);
  d.walls.push_back(moving("piston", {20, 10}, {20, 190}, {{10.0, {290, 10}, {290, 190}}}));
  return d;
}
constexpr double kCrushTime = 264.0 / 27.0;

}  // namespace

TEST_CASE("a ball crushed by a piston against a wall is removed at the instant the room closes", "[squeeze]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = piston_scene();
    d.balls.push_back(ball("b", {150, 150}, {0, 0}, 8));
    World w(d, mode);
    Run run;
    run_to(w, run, 9.7);  // before the crush: the ball is there, no overlap
    CHECK(w.ball(0).alive);
    CHECK(run.count(EventKind::crushed) == 0);
    CHECK(w.measure_overlap().relative <= 1e-9);
    run_to(w, run, 12.0);
    REQUIRE(run.count(EventKind::crushed) == 1);
    const Event& e = *run.first(EventKind::crushed);
    CHECK(e.a == 0);
    CHECK(e.flags == 0);  // a ball, between two walls
    // Both walls are named: the piston (index 0) and the arena's right wall.
    const auto& walls = w.walls();
    const std::string b = walls[e.b].id, c = walls[e.c].id;
    CHECK(((b == "piston") != (c == "piston")));
    CHECK(e.t == Approx(kCrushTime).epsilon(1e-9));
    CHECK_FALSE(w.ball(0).alive);
    CHECK(w.stats().crushed == 1);
    CHECK(w.measure_overlap().relative <= 1e-9);
    CHECK(w.max_contact_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a ball moving along the piston's line is crushed too, and a ball that gets out is not", "[squeeze]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    {
      WorldDef d = piston_scene();
      d.balls.push_back(ball("b", {150, 150}, {3, 1}, 8));  // drifts up by 10 before the crush: still inside
      World w(d, mode);
      Run run;
      run_to(w, run, 12.0);
      CHECK(run.count(EventKind::crushed) == 1);
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
    {
      // A piston with a gap above it (it spans y in [10, 120]): a ball rising at 12 units/s leaves
      // the squeeze over the piston's end before the room closes, and survives.
      WorldDef d = box(300, 200);
      d.walls.push_back(moving("piston", {20, 10}, {20, 120}, {{10.0, {290, 10}, {290, 120}}}));
      d.balls.push_back(ball("b", {150, 60}, {0, 12}, 8));
      World w(d, mode);
      Run run;
      run_to(w, run, 12.0);
      CHECK(run.count(EventKind::crushed) == 0);
      CHECK(w.ball(0).alive);
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
  }
}

TEST_CASE("a turtle crushed by a piston against a wall is removed, in both modes", "[squeeze][turtle]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = piston_scene();
    d.turtles.push_back(turtle("t", {150, 150}, 0, 8));
    World w(d, mode);
    Run run;
    run_to(w, run, 9.7);
    CHECK(run.count(EventKind::crushed) == 0);
    run_to(w, run, 12.0);
    REQUIRE(run.count(EventKind::crushed) == 1);
    const Event& e = *run.first(EventKind::crushed);
    CHECK(e.a == 0);
    CHECK(e.flags == kTurtleA);
    CHECK(e.t == Approx(kCrushTime).epsilon(1e-9));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("two pistons closing on a ball or a turtle crush it where they meet", "[squeeze]") {
  for (Mode mode : kModes) {
    for (bool turtle_body : {false, true}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << (turtle_body ? ", turtle" : ", ball"));
      WorldDef d = box(300, 200);
      // x = 20 + 20 t and x = 280 - 20 t: they are 2 r = 10 apart at t = 250 / 40.
      d.walls.push_back(moving("left", {20, 10}, {20, 190}, {{10.0, {220, 10}, {220, 190}}}));
      d.walls.push_back(moving("right", {280, 10}, {280, 190}, {{10.0, {80, 10}, {80, 190}}}));
      if (turtle_body) d.turtles.push_back(turtle("t", {100, 100}, 0, 5));
      else d.balls.push_back(ball("b", {100, 100}, {7, 0}, 5));
      World w(d, mode);
      Run run;
      run_to(w, run, 9.0);
      REQUIRE(run.count(EventKind::crushed) == 1);
      const Event& e = *run.first(EventKind::crushed);
      CHECK(e.t == Approx(250.0 / 40.0).epsilon(1e-9));
      const std::string b = w.walls()[e.b].id, c = w.walls()[e.c].id;
      CHECK(((b == "left" && c == "right") || (b == "right" && c == "left")));
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
  }
}

TEST_CASE("a ball exactly as wide as its corridor cannot move across it: wedged, it slides along", "[squeeze]") {
  for (Mode mode : kModes) {
    for (double e : {1.0, 0.9}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", e = " << e);
      // The fuzzing reproducer (zeno-wedged-ball.json): arena 1 wide, ball of radius 0.5 moving
      // across it; and the adversarial corridor: velocity (1e-3, 1) along a corridor 2 r wide.
      {
        WorldDef d = box(1, 100);
        d.effects.restitution = e;
        d.balls.push_back(ball("b", {0.5, 50}, {1, 0}, 0.5));
        World w(d, mode);
        Run run;
        run_to(w, run, 1e-12);
        run_to(w, run, 5.0);
        CHECK(run.count(EventKind::wedged) >= 1);
        CHECK(w.ball(0).vel.x == 0.0);
        CHECK(w.ball(0).pos.x == 0.5);
        CHECK(w.measure_overlap().relative <= 1e-9);
      }
      {
        WorldDef d = box(100, 1000);
        d.effects.restitution = e;
        d.walls.push_back({"l", {40, 0}, {40, 1000}});
        d.walls.push_back({"r", {42, 0}, {42, 1000}});
        d.balls.push_back(ball("b", {41, 10}, {1e-3, 1}, 1));
        World w(d, mode);
        Run run;
        run_to(w, run, 100.0);
        CHECK(run.count(EventKind::wedged) >= 1);
        CHECK(w.ball(0).pos.y == Approx(110).epsilon(1e-9));  // it kept its speed along the corridor
        CHECK(std::abs(w.ball(0).pos.x - 41) <= 1e-9);
        CHECK(w.measure_overlap().relative <= 1e-9);
      }
    }
  }
}

TEST_CASE("a tilted corridor exactly 2r wide wedges a ball too (normals from round-off)", "[squeeze]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    // A corridor at 30 degrees; its walls 2 apart, the ball of radius 1 between them moving across.
    const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
    const Vec2 u{c, s}, n{-s, c};
    const Vec2 o{20, 20};
    WorldDef d = box(200, 200);
    // 2 + 2e-12 apart: exactly 2 would overlap the ball by round-off, which validate() refuses.
    d.walls.push_back({"a", o - (1 + 1e-12) * n, o - (1 + 1e-12) * n + 150.0 * u});
    d.walls.push_back({"b", o + (1 + 1e-12) * n, o + (1 + 1e-12) * n + 150.0 * u});
    d.balls.push_back(ball("disc", o + 10.0 * u, 2.0 * n + 1.0 * u, 1));
    World w(d, mode);
    Run run;
    run_to(w, run, 20.0);
    CHECK(run.count(EventKind::wedged) >= 1);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

TEST_CASE("a ball exactly filling the gap between a wall and a standing turtle is wedged", "[squeeze][turtle]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(200, 200);
    d.turtles.push_back(turtle("t", {30, 100}, 0, 10));  // reaches x = 40
    d.balls.push_back(ball("b", {41, 100}, {1, 0.5}, 1));  // touches the turtle and the wall x = 42
    d.walls.push_back({"w", {42, 0}, {42, 200}});
    World w(d, mode);
    Run run;
    run_to(w, run, 10.0);
    CHECK(run.count(EventKind::wedged) >= 1);
    CHECK(w.measure_overlap().relative <= 1e-9);
    CHECK(w.ball(0).alive);
  }
}

TEST_CASE("a bouncing turtle in a corridor exactly its width, heading 89 degrees, is wedged and drives on", "[squeeze][turtle]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(400, 100);
    d.walls.push_back({"lo", {0, 40}, {400, 40}});
    d.walls.push_back({"hi", {0, 60}, {400, 60}});
    TurtleDef t = turtle("t", {50, 50}, 89, 10);
    t.bounce = 1.0;
    d.turtles.push_back(t);
    World w(d, mode);
    Run run;
    w.set_event_log(&run.log);
    w.set_event_limit(kLimit);
    w.command_turtle(0, {TurtleCommand::Kind::move, 100});
    REQUIRE_NOTHROW(w.advance_to(5.0));
    CHECK(run.count(EventKind::wedged) >= 1);
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

namespace {

/// Advances w to `until` in `samples` slices under the event limit; the deepest overlap seen.
double deepest_over_run(World& w, Run& run, double until, int samples, std::uint64_t limit = kLimit) {
  w.set_event_log(&run.log);
  w.set_event_limit(limit);
  return turtlegas::test::deepest_over_run(w, until, samples);
}

}  // namespace

TEST_CASE("a disc dropped into a sharp V under gravity comes to rest where it wedges, in both modes", "[squeeze][rest]") {
  for (Mode mode : kModes) {
    for (double half_deg : {1.0, 0.1}) {
      for (double e : {0.9, 0.5}) {
        for (double x0 : {100.0, 100.3}) {
          INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", opening " << 2 * half_deg << " degrees, e = "
                       << e << ", dropped at x = " << x0);
          const double h = half_deg * M_PI / 180.0;
          const Vec2 apex{100, 20};
          const double len = 1.5 / std::sin(h);  // the walls reach past where the disc wedges
          WorldDef d = box(200, 20 + len + 50);
          d.walls.push_back({"l", apex, apex + len * Vec2{-std::sin(h), std::cos(h)}});
          d.walls.push_back({"r", apex, apex + len * Vec2{std::sin(h), std::cos(h)}});
          d.effects.gravity = {0, -10};
          d.effects.restitution = e;
          const double wedge_y = apex.y + 1.0 / std::sin(h);  // centre of a disc of radius 1 touching both
          d.balls.push_back(ball("b", {x0, wedge_y + 0.9 * (len * std::cos(h) - 1.0 / std::sin(h))}, {0, 0}, 1));
          World w(d, mode);
          Run run;
          // (Wedged, it hops at the rest threshold's scale, about one hop per t_c = 1e-4 s: some
          // 1e5 events in 12 s.)
          const double worst = deepest_over_run(w, run, 12.0, 40, 1000000);
          CHECK(worst <= 1e-9);
          CHECK(w.ball(0).pos.y == Approx(wedge_y).margin(1e-3));
          CHECK(w.ball(0).pos.x == Approx(100).margin(1e-3));
        }
      }
    }
  }
}

TEST_CASE("a disc in a vertical tube exactly 2r wide falls along it, wedged", "[squeeze][rest]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(100, 400);
    d.walls.push_back({"l", {49, 10}, {49, 390}});
    d.walls.push_back({"r", {51, 10}, {51, 390}});
    d.effects.gravity = {0, -10};
    d.effects.restitution = 0.9;
    d.balls.push_back(ball("b", {50, 380}, {0.5, 0}, 1));
    World w(d, mode);
    Run run;
    const double worst = deepest_over_run(w, run, 5.0, 20);
    CHECK(worst <= 1e-9);
    CHECK(run.count(EventKind::wedged) >= 1);
    CHECK(w.ball(0).pos.x == Approx(50).margin(1e-9));
  }
}

TEST_CASE("a disc sliding along a 2r corridor built of 80 two-unit segments goes through, in both modes", "[squeeze]") {
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    WorldDef d = box(200, 100);
    for (int k = 0; k < 80; ++k) {
      const double x = 10.0 + 2.0 * k;
      d.walls.push_back({"lo" + std::to_string(k), {x, 49}, {x + 2, 49}});
      d.walls.push_back({"hi" + std::to_string(k), {x, 51}, {x + 2, 51}});
    }
    d.balls.push_back(ball("b", {12, 50}, {10, 0.3}, 1));
    World w(d, mode);
    Run run;
    run_to(w, run, 20.0);
    CHECK(w.measure_overlap().relative <= 1e-9);
    CHECK(w.ball(0).alive);
  }
}

TEST_CASE("a disc pressed by gravity into one side of a tilted slot exactly 2r wide slides down it, never sinking",
          "[squeeze][rest]") {
  // The squeeze rule leaves the pressed wall at the rest threshold's speed, which in a slot with no
  // room took the disc a_n t_c^2 / 8 into the other wall (1.1e-8 of a radius here); the hop is
  // now capped so that it rises at most half the overlap budget into it.
  for (Mode mode : kModes) {
    for (double e : {1.0, 0.5}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", e = " << e);
      const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
      const Vec2 u{c, s}, n{-s, c};
      const Vec2 o{20, 20};
      WorldDef d = box(200, 200);
      d.walls.push_back({"lo", o - (1 + 1e-12) * n, o - (1 + 1e-12) * n + 150.0 * u});
      d.walls.push_back({"hi", o + (1 + 1e-12) * n, o + (1 + 1e-12) * n + 150.0 * u});
      d.effects.gravity = {0, -10};
      d.effects.restitution = e;
      d.balls.push_back(ball("disc", o + 100.0 * u, {0, 0}, 1));
      World w(d, mode);
      Run run;
      const double until = 0.5;
      const double worst = deepest_over_run(w, run, until, 50, 1000000);
      CHECK(worst <= 1e-9);
      // Frictionless: it slides down at g sin 30 degrees, whatever it does across the slot. At
      // e = 1 the rest threshold turns the velocity (|v| kept, Restitution::bounce) and the
      // slot's cap takes the hop back, keeping |v| too (squeeze.hpp): each hop trades a little
      // between the slide and the hop, measured 3.4e-4 of the slide over this run (before the
      // squeeze kept |v| the slide stalled at 2.7e-4 of its length): a constant speed offset from
      // the first lift, not growing ("the elastic slide ...", below). Exact to 1e-6 at e < 1.
      const double along = dot(w.ball(0).pos - o, u);
      const double tol = mode == Mode::exact ? (e == 1.0 ? 1e-3 : 1e-6) : 0.1;
      CHECK(100.0 - along == Approx(0.5 * 10 * s * until * until).epsilon(tol));
      CHECK(std::abs(dot(w.ball(0).pos - o, n)) <= 1e-6);
    }
  }
}

TEST_CASE("a piston crushing a ball against a wall end or a standing turtle, head on, ends in a crush, not a hang",
          "[squeeze]") {
  // The ball bounces between the piston and the point obstacle ever faster (e = 1: speed times room
  // is an adiabatic invariant), some g0 / (1e-9 r) times before the room closes, unless the rule
  // sees that the crush is certain.
  for (Mode mode : kModes) {
    for (bool turtle_obstacle : {false, true}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << (turtle_obstacle ? ", a turtle" : ", a wall end"));
      WorldDef d = piston_scene();
      double contact_x = 0;  // where the ball's centre is when it touches the obstacle
      if (turtle_obstacle) {
        d.turtles.push_back(turtle("t", {250, 150}, 0, 10));
        contact_x = 250 - 10 - 8;
      } else {
        d.walls.push_back({"spike", {250, 150}, {300, 150}});
        contact_x = 250 - 8;
      }
      d.balls.push_back(ball("b", {150, 150}, {0, 0}, 8));
      World w(d, mode);
      Run run;
      run_to(w, run, 9.0);  // (the piston carries a turtle to the right wall by t = 260 / 27)
      REQUIRE(run.count(EventKind::crushed) == 1);
      // The piston (x = 20 + 27 t) is 2 r from the contact point then.
      CHECK(run.first(EventKind::crushed)->t == Approx((contact_x - 8 - 20) / 27.0).epsilon(1e-9));
      CHECK(w.measure_overlap().relative <= 1e-9);
    }
  }
}

namespace {

/// 40 discs of radius 1 above a V of 10 degrees (half-angle 5, apex (100, 10)) in a 200 x 400 box,
/// under gravity, e = 0.8: they fall and pile up in the V.
WorldDef v_pour() {
  const double h = 5.0 * M_PI / 180.0;
  const Vec2 apex{100, 10};
  const double len = 380 / std::cos(h);
  WorldDef d = box(200, 400);
  d.walls.push_back({"l", apex, apex + len * Vec2{-std::sin(h), std::cos(h)}});
  d.walls.push_back({"r", apex, apex + len * Vec2{std::sin(h), std::cos(h)}});
  d.effects.gravity = {0, -10};
  d.effects.restitution = 0.8;
  for (int k = 0; k < 40; ++k)
    d.balls.push_back(ball("b" + std::to_string(k), {100 + ((k % 3) - 1) * 2.5 + 0.01 * k, 150 + 3.0 * k}, {0, 0}, 1));
  return d;
}

}  // namespace

TEST_CASE("40 discs poured into a 10-degree V under gravity settle, in step mode, without a hang", "[squeeze][rest]") {
  // Discs squeezed by discs: the first disc wedges at the apex (held by the rule), the next presses
  // onto it, and the two exchanged round-off velocities (1e-19) with the walls for ever at one
  // instant (t = 6.19 s). A held disc pushed into both its holders now counts as heavy as they are.
  World w(v_pour(), Mode::step);
  Run run;
  w.set_event_log(nullptr);
  w.set_event_limit(3000000);
  const double e0 = w.energy();
  double worst = 0.0, e_settled = 0.0;
  for (int k = 1; k <= 100; ++k) {
    REQUIRE_NOTHROW(w.advance_to(0.2 * k));
    worst = std::max(worst, w.measure_overlap().relative);
    if (k == 75) e_settled = w.energy();
    // Never above the splitting's own gain in free fall (next test): 40 m g^2 dt t / 2.
    CHECK(w.energy() <= e0 + 40 * 100.0 * (1.0 / 30.0) * (0.2 * k) / 2.0 + 1e-12 * e0);
  }
  CHECK(worst <= 1e-9);
  for (std::size_t i = 0; i < w.ball_count(); ++i) CHECK(w.ball(i).alive);
  // Inelastic: the pile loses energy, and once settled (15 s) it gains none beyond the kick's
  // own scale, m (g dt)^2 a disc (a disc at rest takes a kick of g dt every step and bounces it off).
  CHECK(w.energy() < 0.5 * e0);
  CHECK(w.energy() <= e_settled + 40 * std::pow(10.0 / 30.0, 2));
}

TEST_CASE("40 discs poured into a 10-degree V settle in exact mode within an event budget (open)", "[.][open][squeeze][rest]") {
  // Hidden: no rule meets it yet (docs/physics.md, "Why the settled V pour costs what it does").
  // The acceptance test for one: the step-mode scene above, event-driven. The pour costs 2.1e4
  // events to t = 6 s; the settled pile then costs 1.5e7 events a simulated second today, because
  // its weight is carried by impulses at the t_c scale. Today it reaches the budget at t ~ 9.
  World w(v_pour(), Mode::exact);
  w.set_event_limit(3000000);
  const double e0 = w.energy();
  double worst = 0.0, e_settled = 0.0;
  for (int k = 1; k <= 100; ++k) {
    INFO("t = " << 0.2 * k << ", events " << w.stats().events);
    REQUIRE_NOTHROW(w.advance_to(0.2 * k));
    worst = std::max(worst, w.measure_overlap().relative);
    if (k == 75) e_settled = w.energy();
    CHECK(w.energy() <= e0 * (1.0 + 1e-12));
  }
  CHECK(worst <= 1e-9);
  for (std::size_t i = 0; i < w.ball_count(); ++i) CHECK(w.ball(i).alive);
  CHECK(w.energy() < 0.5 * e0);
  CHECK(w.energy() <= e_settled * (1.0 + 1e-12));
}

namespace {

/// Runs w to `until` one control step at a time, as a program that drives on whenever it is
/// stopped would: every turtle in `drivers` is told to go forward 1000 at each control boundary
/// where its command is not running (after a touch, say). The deepest overlap seen at the steps.
double drive_on(World& w, Run& run, const std::vector<std::size_t>& drivers, double until) {
  w.set_event_log(&run.log);
  w.set_event_limit(kLimit);
  const double dt = 1.0 / 30.0;
  double worst = 0.0;
  for (int k = 0; k * dt < until; ++k) {
    REQUIRE_NOTHROW(w.advance_to(k * dt));
    for (std::size_t i : drivers)
      if (w.turtle_alive(i) && !w.turtle(i).busy) w.command_turtle(i, {TurtleCommand::Kind::move, 1000});
    worst = std::max(worst, w.measure_overlap().relative);
  }
  return worst;
}

}  // namespace

TEST_CASE("turtles driving head on onto a ball or a turtle stop at it: it is wedged, never crushed", "[squeeze][turtle]") {
  // Turtles stop when they touch, so a driving turtle never closes a squeeze. The squeeze rule
  // took the speed of a turtle still driving onto the body (about to touch it and stop) for a
  // closing obstacle and crushed the ball, or the standing turtle, between the two.
  for (Mode mode : kModes) {
    for (bool turtle_body : {false, true}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << (turtle_body ? ", a turtle between" : ", a ball between"));
      WorldDef d = box(300, 200);
      d.effects.restitution = 0.5;
      d.turtles.push_back(turtle("t1", {100, 100}, 90, 10, 20));
      d.turtles.push_back(turtle("t2", {200, 100}, 270, 10, 20));
      if (turtle_body) d.turtles.push_back(turtle("m", {150, 100}, 0, 5));
      else d.balls.push_back(ball("b", {150, 100}, {3, 0}, 5));
      World w(d, mode);
      Run run;
      const double worst = drive_on(w, run, {0, 1}, 8.0);
      CHECK(worst <= 1e-9);
      CHECK(run.count(EventKind::crushed) == 0);
      CHECK(w.stats().crushed == 0);
      if (turtle_body) CHECK(w.turtle_alive(2));
      else CHECK(w.ball(0).alive);
      // Both stopped touching it, on its axis: 10 + 5 + 5 + 10 apart.
      CHECK(norm(w.turtle(0).pos - w.turtle(1).pos) == Approx(30).epsilon(1e-9));
    }
  }
}

TEST_CASE("a turtle a piston carries pushes a ball before it and crushes it against the wall, then is crushed",
          "[squeeze][turtle]") {
  // It stopped dead at the ball, the piston caught it at once and carried it on into the ball
  // again, for ever at one instant (the run hung, deaf even to SIGTERM). A carried turtle goes on
  // at the piston's speed: the ball bounces off it, and is crushed where the room closes.
  for (Mode mode : kModes) {
    for (double e : {1.0, 0.5}) {
      for (int chain : {1, 2}) {
        INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", e = " << e << ", turtles " << chain);
        WorldDef d = piston_scene();  // the piston reaches x = 290 at t = 10 (27 units/s)
        d.effects.restitution = e;
        d.turtles.push_back(turtle("t1", {100, 150}, 0, 10));
        if (chain == 2) d.turtles.push_back(turtle("t2", {200, 150}, 0, 10));  // carried by t1 in turn
        d.balls.push_back(ball("b", {250, 150}, {0, 0}, 8));
        World w(d, mode);
        Run run;
        run_to(w, run, 12.0);
        CHECK(w.measure_overlap().relative <= 1e-9);
        CHECK(w.max_contact_overlap().relative <= 1e-9);
        REQUIRE(run.count(EventKind::crushed) == static_cast<std::size_t>(chain + 1));
        // The front turtle's front is the piston + 20 chain; the ball is crushed when it is 2 r from
        // the wall at x = 300, then each turtle when its centre is r from it.
        std::vector<double> want{(300.0 - 16 - 20 * chain - 20) / 27.0};
        for (int k = chain; k >= 1; --k) want.push_back((290.0 - 20 * k + 10 - 20) / 27.0);
        std::vector<double> got;
        for (const Event& ev : run.log)
          if (ev.kind == EventKind::crushed) got.push_back(ev.t);
        for (std::size_t k = 0; k < want.size(); ++k) CHECK(got[k] == Approx(want[k]).epsilon(1e-9));
        CHECK_FALSE(w.ball(0).alive);
      }
    }
  }
}

TEST_CASE("a ball between a piston and a turtle driving at it is crushed by the piston against the stopped turtle",
          "[squeeze][turtle]") {
  // The turtle stops at the ball (a touch); the ball is then caught between the piston and a
  // standing turtle, and the turtle, carried by the piston afterwards, is crushed at the wall.
  for (Mode mode : kModes) {
    for (double e : {1.0, 0.5}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", e = " << e);
      WorldDef d = piston_scene();
      d.effects.restitution = e;
      d.turtles.push_back(turtle("t", {250, 150}, 270, 10, 5));
      d.balls.push_back(ball("b", {150, 150}, {0, 0}, 8));
      World w(d, mode);
      Run run;
      const double worst = drive_on(w, run, {0}, 12.0);
      CHECK(worst <= 1e-9);
      REQUIRE(run.count(EventKind::crushed) == 2);
      const Event& first = *run.first(EventKind::crushed);
      CHECK((first.flags & kTurtleA) == 0);  // a ball, between the piston and the turtle
      CHECK(((first.flags & kTurtleB) != 0) != ((first.flags & kTurtleC) != 0));
      CHECK(first.a == 0);
      CHECK(run.log.back().kind == EventKind::crushed);
      CHECK(run.log.back().t == Approx(260.0 / 27.0).epsilon(1e-9));  // the turtle, when the piston is 2 r from x = 300
      CHECK_FALSE(w.ball(0).alive);
      CHECK_FALSE(w.turtle_alive(0));
    }
  }
}

TEST_CASE("a step-mode pour into a V never gains more energy than the splitting's free-fall error", "[squeeze][rest]") {
  // The issue measured a 38 % gain for 40 discs poured into a 10-degree V (e = 0.8) in step mode.
  // In a walled arena it does not happen in any reading of the scene tried (a 10-degree opening or
  // walls 10 degrees off the horizontal, one segment or four, centred or 20 off, dt 1/30, 0.1,
  // 0.01): the total energy (kinetic plus potential) rises only while the discs fall, by exactly
  // the Lie splitting's error (docs/physics.md, "Step mode under fields"): drift at v then kick by
  // g dt gains m (g dt)^2 / 2 a step in free flight, N m g^2 dt t / 2 by time t (0.42 % of E0 at
  // t = 5.2 s here at dt = 1/30), and the bounces (e = 0.8) then take far more than that away.
  // (In a periodic arena a disc that leaves the V's rim falls through the floor seam and comes
  // back at the top with m g H more potential energy: bookkeeping of the wrapped height, 4000 a
  // wrap here; docs/physics.md.)
  const double g = 10.0;
  for (double dt : {1.0 / 30.0, 0.1, 0.01}) {
    for (int segs : {1, 4}) {
      for (double xoff : {0.0, 20.0}) {
        INFO("dt " << dt << ", segments " << segs << ", off centre by " << xoff);
        const double a = 10.0 * M_PI / 180.0;  // each wall 10 degrees off the horizontal
        const Vec2 apex{100, 10};
        const double len = 95 / std::cos(a);
        const Vec2 ul{-std::cos(a), std::sin(a)}, ur{std::cos(a), std::sin(a)};
        WorldDef d = box(200, 400);
        d.dt = dt;
        for (int k = 0; k < segs; ++k) {
          d.walls.push_back({"l" + std::to_string(k), apex + (len * k / segs) * ul, apex + (len * (k + 1) / segs) * ul});
          d.walls.push_back({"r" + std::to_string(k), apex + (len * k / segs) * ur, apex + (len * (k + 1) / segs) * ur});
        }
        d.effects.gravity = {0, -g};
        d.effects.restitution = 0.8;
        const int n = 40;
        for (int k = 0; k < n; ++k)
          d.balls.push_back(ball("b" + std::to_string(k), {100 + xoff + ((k % 3) - 1) * 2.5 + 0.01 * k, 150 + 3.0 * k}, {0, 0}, 1));
        World w(d, Mode::step);
        w.set_event_limit(1000000);
        const double e0 = w.energy();
        double worst = 0.0, highest = 0.0;
        for (int k = 1; k <= 400; ++k) {
          const double t = 0.05 * k;
          REQUIRE_NOTHROW(w.advance_to(t));
          worst = std::max(worst, w.measure_overlap().relative);
          const double bound = n * g * g * dt * t / 2.0;
          CHECK(w.energy() - e0 <= bound + 1e-12 * e0);
          highest = std::max(highest, w.energy() - e0);
        }
        CHECK(worst <= 1e-9);
        // The bound is reached (it is the splitting's error, not slack): the first disc lands at
        // t = sqrt(2 * 140 / g) = 5.3 s, and until then every disc is in free fall.
        CHECK(highest >= 0.9 * n * g * g * dt * 5.0 / 2.0);
        CHECK(w.energy() < 0.3 * e0);
      }
    }
  }
}

TEST_CASE("the elastic slide down a tilted 2r slot is off by one constant speed, which does not grow", "[squeeze][rest]") {
  // At e = 1 the disc, at rest at first, is lifted off the pressed wall at the rest threshold's
  // speed w = a_n t_c / 2 (energy added: it is slower than the threshold), and the slot's hop cap
  // c = sqrt(2 w r 1e-9 / t_c) then turns sqrt(w^2 - c^2) of it along the slot (squeeze.hpp keeps
  // |v| at e = 1). After that every hop keeps the energy: the slide runs ahead of the exact one by
  // that constant speed (4.2e-4 units/s here), so its error is 4.2e-4 t: 3.4e-4 of the distance at
  // 0.5 s, 1.05e-5 at 16 s (measured), never growing faster than t. docs/physics.md.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const Vec2 u{c, s}, n{-s, c};
  const Vec2 o{20, 20};
  WorldDef d = box(400, 300);
  d.walls.push_back({"lo", o - (1 + 1e-12) * n, o - (1 + 1e-12) * n + 350.0 * u});
  d.walls.push_back({"hi", o + (1 + 1e-12) * n, o + (1 + 1e-12) * n + 350.0 * u});
  const double g = 10;
  d.effects.gravity = {0, -g};
  d.balls.push_back(ball("disc", o + 300.0 * u, {0, 0}, 1));
  World w(d, Mode::exact);
  w.set_event_limit(5000000);
  const double tc = d.effects.tc;
  const double hop = g * c * tc / 2.0, cap = std::sqrt(2.0 * hop / tc * 1e-9);
  const double offset = std::sqrt(hop * hop - cap * cap);
  for (double t : {0.5, 1.0, 2.0, 4.0}) {
    INFO("t = " << t);
    REQUIRE_NOTHROW(w.advance_to(t));
    const double slide = 300.0 - dot(w.ball(0).pos - o, u);
    const double speed = norm(w.ball(0).vel);
    CHECK(speed - g * s * t == Approx(offset).epsilon(0.02));
    CHECK(slide - 0.5 * g * s * t * t == Approx(offset * t).epsilon(0.02));
    CHECK(w.measure_overlap().relative <= 1e-9);
  }
}

namespace {

/// A pile pressed onto a held disc by a piston: a 300 x 200 walled arena, a V opening to the left
/// with its apex at (290, 100) and a half-angle of 30°, a disc of radius 8 exactly at the apex
/// (2 r from it) moving into it, `between` discs of radius 8 at rest on its axis, and a short
/// piston (y from 90 to 110) sweeping from x = 20 to x = 290 in 10 s (27 units/s).
WorldDef held_pile_scene(int between, double e) {
  WorldDef d = box(300, 200);
  d.effects.restitution = e;
  const double h = M_PI / 6;
  const Vec2 apex{290, 100};
  d.walls.push_back({"vu", apex, apex + 150.0 * Vec2{-std::cos(h), std::sin(h)}});
  d.walls.push_back({"vl", apex, apex + 150.0 * Vec2{-std::cos(h), -std::sin(h)}});
  d.walls.push_back(moving("piston", {20, 90}, {20, 110}, {{10.0, {290, 90}, {290, 110}}}));
  d.balls.push_back(ball("held", {290 - 16, 100}, {1, 0}, 8));
  for (int k = 0; k < between; ++k) d.balls.push_back(ball("b" + std::to_string(k), {200 - 40.0 * k, 100}, {0, 0}, 8));
  return d;
}

}  // namespace

namespace {

/// Runs a held-pile scene to t = 12 s in steps of 0.1 s under the event limit, logging into run;
/// the deepest overlap seen at the steps.
double run_held_pile(World& w, Run& run) {
  w.set_event_log(&run.log);
  w.set_event_limit(kLimit);
  double worst = 0.0;
  for (int k = 1; k <= 120; ++k) {
    REQUIRE_NOTHROW(w.advance_to(0.1 * k));
    worst = std::max(worst, w.measure_overlap().relative);
  }
  return worst;
}

}  // namespace

TEST_CASE("a piston pressing discs onto a disc held in a V crushes them against it, then it", "[squeeze]") {
  // The held disc is as heavy as the V's walls. A disc the piston drives onto it slips into the
  // corner between it and a wall, and the piston closes that corner: no velocity leaves all three
  // (a wall, the held disc, the piston), so it is crushed there, when the piston is at
  // x = 290 - 16 - 16 cos 30° - 8; the last disc left is crushed when the piston is r from the
  // apex disc's place (246 / 27 s): the piston and the V's two walls leave it no way out. Before, the discs bounced
  // between the three at one instant for ever (e = 0.5, both modes: the event limit).
  for (Mode mode : kModes) {
    for (int between : {1, 2}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", discs between " << between);
      World w(held_pile_scene(between, 0.5), mode);
      Run run;
      const double worst = run_held_pile(w, run);
      CHECK(worst <= 1e-9);
      CHECK(w.max_contact_overlap().relative <= 1e-9);
      CHECK(w.stats().events < 2000);
      REQUIRE(run.count(EventKind::crushed) == static_cast<std::size_t>(between + 1));
      const double corner = (290 - 16 - 16 * std::cos(M_PI / 6) - 8 - 20) / 27.0;
      std::vector<const Event*> crushed;
      for (const Event& ev : run.log)
        if (ev.kind == EventKind::crushed) crushed.push_back(&ev);
      // `between` crushes in the corners, then the last disc between the piston and the V.
      for (int k = 0; k < between; ++k) CHECK(crushed[k]->t == Approx(corner).epsilon(1e-9));
      CHECK(crushed.back()->t == Approx(246.0 / 27.0).epsilon(1e-9));
      for (std::size_t i = 0; i < w.ball_count(); ++i) CHECK_FALSE(w.ball(i).alive);
    }
  }
}

TEST_CASE("three discs pressed onto the held disc, or any at e = 1, are crushed where the room closes", "[squeeze]") {
  // The room the piston and the V leave the centres is a triangle; it can hold two discs (16
  // apart) until its side is 16, at (246 - 16 cos 30°) / 27 s, and one until it closes to a point
  // at 246 / 27 s (docs/physics.md, rule 3). Discs that slip past the piston's ends before it is
  // 240.7 units along escape. Before: a chain of four touching discs served round-off contacts at
  // t = 7.3348 s for ever (three between, e = 0.5), and at e = 1 the discs' speeds grew to 1e26
  // before 8.598 s (the event limit).
  const double corner = (290 - 16 - 16 * std::cos(M_PI / 6) - 8 - 20) / 27.0;
  for (Mode mode : kModes) {
    for (auto [between, e] : {std::pair{1, 1.0}, {2, 1.0}, {3, 1.0}, {3, 0.5}}) {
      INFO("mode " << (mode == Mode::exact ? "exact" : "step") << ", discs between " << between << ", e " << e);
      World w(held_pile_scene(between, e), mode);
      Run run;
      const double worst = run_held_pile(w, run);
      CHECK(worst <= 1e-9);
      CHECK(w.max_contact_overlap().relative <= 1e-9);
      CHECK(w.stats().events < 3000);
      CHECK(std::isfinite(w.energy()));
      CHECK(w.energy() < 1e4);  // a sanity bound: the runaway reached 1e13
      std::vector<double> crushed;
      for (const Event& ev : run.log)
        if (ev.kind == EventKind::crushed) crushed.push_back(ev.t);
      REQUIRE(crushed.size() >= 2);
      for (std::size_t k = 0; k + 1 < crushed.size(); ++k) CHECK(crushed[k] == Approx(corner).epsilon(1e-9));
      CHECK(crushed.back() == Approx(246.0 / 27.0).epsilon(1e-12));
    }
  }
}

TEST_CASE("the energy ledger: what the wedged and crushed rules take, by rule and by ball, adds up", "[squeeze][ledger]") {
  // docs/physics.md, "The energy ledger" (issue 28, Accounting). Without fields or moving walls the
  // world's energy changes only by what the rules take: E_start - E_end = the ledger's total.
  for (Mode mode : kModes) {
    INFO("mode " << (mode == Mode::exact ? "exact" : "step"));
    {
      // A 2r corridor at e = 1 (issue 28 item 2): the transverse energy is taken, 0.5 (1e-3)^2,
      // and reported, all of it, by rule and by ball; the second ball, free, gives nothing.
      WorldDef d = box(100, 1000);
      d.walls.push_back({"l", {40, 0}, {40, 1000}});
      d.walls.push_back({"r", {42, 0}, {42, 1000}});
      d.balls.push_back(ball("free", {80, 500}, {3, 4}, 1));
      d.balls.push_back(ball("b", {41, 10}, {1e-3, 1}, 1, 2.0));
      World w(d, mode);
      const double e0 = w.energy();
      Run run;
      run_to(w, run, 100.0);
      REQUIRE(run.count(EventKind::wedged) >= 1);
      const Stats& st = w.stats();
      CHECK(st.energy_wedged == Approx(0.5 * 2.0 * 1e-6).epsilon(1e-9));
      CHECK(st.energy_crushed == 0.0);
      CHECK(std::abs((e0 - w.energy()) - st.energy_rules()) <= 1e-12 * e0);
      REQUIRE(w.energy_taken().size() == 2);
      CHECK(w.energy_taken()[0] == 0.0);
      CHECK(w.energy_taken()[1] == st.energy_wedged);
    }
    {
      // The piston crushes a ball that drifts along it at 1 unit/s. The rules take speed along the
      // squeeze on the way (wedged); at the last instant the piston (u = 27) has just reflected the
      // ball at e = 1, to 2u along x with its 1 along y, and the crush takes that kinetic energy,
      // 0.5 m (54^2 + 1^2) (crushed).
      WorldDef d = piston_scene();
      d.balls.push_back(ball("b", {150, 150}, {0, 1}, 8, 3.0));
      World w(d, mode);
      Run run;
      run_to(w, run, 12.0);
      REQUIRE(run.count(EventKind::crushed) == 1);
      const Stats& st = w.stats();
      CHECK(st.energy_crushed == Approx(0.5 * 3.0 * (54.0 * 54.0 + 1.0)).epsilon(1e-12));
      CHECK(st.energy_wedged > 0.0);  // the ride on the right wall took the speed the piston gave
      REQUIRE(!w.energy_taken().empty());
      CHECK(w.energy_taken()[0] == Approx(st.energy_wedged + st.energy_crushed).epsilon(1e-15));
      CHECK(w.energy() == 0.0);
    }
  }
}
