// SPDX-License-Identifier: MIT
// The sliding flight (issue 28 item 6; docs/physics.md, "The sliding flight"): a disc the field
// presses onto a straight wall at e < 1 bounces in a Zeno sequence whose limit is a slide along the
// wall with the field's part along it. The tests compare the engine with that closed form, show
// that its cost no longer depends on t_c, and that the rule never fires where the bounces would
// not end (e = 1, a field that pulls the ball off the wall).
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "scenes.hpp"
#include "turtlegas/sim/world.hpp"

using namespace turtlegas::sim;
using namespace turtlegas::test;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 10.0;

/// A 10-degree slope 250 long from (20, 20) in a 300 x 200 walled box, gravity 10 down.
struct Slope {
  double a = 10.0 * kPi / 180.0;
  Vec2 o{20, 20};
  Vec2 u{std::cos(a), std::sin(a)};   // up the slope
  Vec2 n{-std::sin(a), std::cos(a)};  // the slope's normal, up
  WorldDef def(double e, double tc) const {
    WorldDef d = box(300, 200);
    d.walls.push_back({"slope", o, o + 250.0 * u});
    d.effects.gravity = {0, -kG};
    d.effects.restitution = e;
    d.effects.tc = tc;
    return d;
  }
  /// A disc of radius 1 whose centre is `along` up the slope and `gap` above contact.
  BallDef disc(double along, double gap, Vec2 v = {}) const {
    return ball("b", o + along * u + (1.0 + gap) * n, v, 1.0);
  }
};

/// Runs w to time `until` and returns the deepest overlap seen at 200 samples on the way.
double run_sampled(World& w, double until) {
  double worst = 0.0;
  for (int k = 1; k <= 200; ++k) {
    w.advance_to(until * k / 200.0);
    worst = std::max(worst, w.measure_overlap().depth);
  }
  return worst;
}

}  // namespace

TEST_CASE("a disc resting on a slope slides down it as the closed form says, at every t_c", "[slide][rest]") {
  const Slope s;
  const double g_t = kG * std::sin(s.a);  // the field's part along the slope, downwards
  std::vector<std::uint64_t> late_events;
  for (double tc : {1e-3, 1e-5, 1e-7, 1e-9}) {
    INFO("tc = " << tc);
    WorldDef d = s.def(0.5, tc);
    d.balls.push_back(s.disc(150.0, 1e-12));
    World w(d, Mode::exact);
    w.set_event_limit(20000);  // it was 1/t_c events a second: 1e9 at t_c = 1e-9
    const double worst = run_sampled(w, 4.0);
    CHECK(worst <= 1e-9);
    // The closed form: s(t) = 150 - g_t t^2 / 2 along the slope, speed g_t t, on it.
    const BallState b = w.ball(0);
    const double t = w.time();
    CHECK(dot(b.pos - s.o, s.u) == Approx(150.0 - 0.5 * g_t * t * t).epsilon(1e-12));
    CHECK(std::abs(dot(b.pos - s.o, s.n) - 1.0) <= 1e-9);
    CHECK(dot(b.vel, s.u) == Approx(-g_t * t).epsilon(1e-12));
    CHECK(std::abs(dot(b.vel, s.n)) <= 1e-12);
    CHECK(w.stats().slides >= 1);
    // Its cost: the bounces before it slides (a handful), then cell crossings only.
    const std::uint64_t before = w.stats().events;
    w.advance_to(8.0);
    late_events.push_back(w.stats().events - before);
    CHECK(w.stats().events < 200);
  }
  // From t = 4 to 8 the cost does not depend on t_c at all (the same cell crossings).
  for (std::uint64_t e : late_events) CHECK(e == late_events.front());
}

TEST_CASE("a disc dropped onto a slope bounces in a Zeno sequence and then slides, exactly", "[slide][rest]") {
  const Slope s;
  const double a_n = -kG * std::cos(s.a), g_t = kG * std::sin(s.a);
  for (double e : {0.3, 0.5, 0.8}) {
    for (double tc : {1e-4, 1e-8}) {
      INFO("e = " << e << ", tc = " << tc);
      const double h = 2.0;  // dropped from 2 above contact, moving up the slope at 3
      WorldDef d = s.def(e, tc);
      d.balls.push_back(s.disc(100.0, h, 3.0 * s.u));
      World w(d, Mode::exact);
      w.set_event_limit(20000);
      // The sequence ends at T = t1 + 2 e w1 / (|a_n| (1 - e)); the motion along the slope is
      // the field's parabola throughout (a frictionless wall does not touch it).
      const double t1 = std::sqrt(2.0 * h / -a_n), w1 = -a_n * t1;
      const double T = t1 + 2.0 * e * w1 / (-a_n * (1.0 - e));
      const double until = T + 0.5;
      const double worst = run_sampled(w, until);
      CHECK(worst <= 1e-9);
      const BallState b = w.ball(0);
      CHECK(dot(b.pos - s.o, s.u) == Approx(100.0 + 3.0 * until - 0.5 * g_t * until * until).epsilon(1e-12));
      CHECK(dot(b.vel, s.u) == Approx(3.0 - g_t * until).epsilon(1e-12));
      CHECK(std::abs(dot(b.pos - s.o, s.n) - 1.0) <= 1e-9);  // on the slope: the sequence is over
      CHECK(std::abs(dot(b.vel, s.n)) <= 1e-12);
      CHECK(w.stats().slides == 1);
      // The bounces it served: as many as take the hop below the threshold, a few dozen at most.
      CHECK(w.stats().ball_wall < 80);
      // The energy: what the sequence leaves, 1/2 (v along the slope)^2 + potential, to round-off.
      const double v_t = 3.0 - g_t * until;
      CHECK(w.energy() == Approx(0.5 * v_t * v_t + kG * b.pos.y).epsilon(1e-12));
      CHECK(w.stats().energy_rules() == 0.0);
    }
  }
}

TEST_CASE("a sliding disc flies off the slope's end on the field's parabola", "[slide]") {
  const Slope s;
  const double g_t = kG * std::sin(s.a);
  WorldDef d = s.def(0.5, 1e-9);
  d.balls.push_back(s.disc(50.0, 1e-12));
  World w(d, Mode::exact);
  w.set_event_limit(20000);
  // It reaches the lower end (foot at o) when 50 = g_t t^2 / 2.
  const double t_end = std::sqrt(2.0 * 50.0 / g_t);
  w.advance_to(t_end - 1e-3);
  CHECK(w.stats().slides >= 1);
  // After the end: the free parabola from (o + n, -g_t t_end u), until it meets the floor.
  const double tau = 0.05;
  w.advance_to(t_end + tau);
  const Vec2 v0 = -g_t * t_end * s.u;
  const Vec2 x = s.o + s.n + tau * v0 + (0.5 * tau * tau) * Vec2{0, -kG};
  const BallState b = w.ball(0);
  CHECK(norm(b.pos - x) <= 1e-9);
  CHECK(norm(b.vel - (v0 + tau * Vec2{0, -kG})) <= 1e-9);
}

TEST_CASE("a sliding disc struck by another is a disc again, and slides again once it lands", "[slide]") {
  const Slope s;
  const double g_t = kG * std::sin(s.a);
  WorldDef d = s.def(0.5, 1e-8);
  d.balls.push_back(s.disc(150.0, 1e-12));
  // A second disc sliding down behind it 5 faster catches up with it at t = 48 / 5, head on along
  // the slope: their relative speed is reversed and halved (e = 0.5), and both slide on.
  BallDef c = s.disc(200.0, 1e-12, -5.0 * s.u);
  c.id = "c";
  d.balls.push_back(c);
  World w(d, Mode::exact);
  w.set_event_limit(50000);
  const double e0 = w.energy();
  const double worst = run_sampled(w, 11.0);
  CHECK(worst <= 1e-9);
  CHECK(w.stats().ball_ball == 1);
  CHECK(w.stats().slides >= 4);  // each slides before they meet, and again after
  // The closed form: their centre of mass slides on the field's parabola throughout, and they
  // separate at 2.5 from t = 9.6 on.
  const double t = w.time();
  const double s0 = dot(w.ball(0).pos - s.o, s.u), s1 = dot(w.ball(1).pos - s.o, s.u);
  CHECK((s0 + s1) / 2 == Approx(175.0 - 2.5 * t - 0.5 * g_t * t * t).epsilon(1e-12));
  CHECK(s1 - s0 == Approx(2.0 + 2.5 * (t - 9.6)).epsilon(1e-9));
  for (int k = 0; k < 2; ++k) CHECK(std::abs(dot(w.ball(k).pos - s.o, s.n) - 1.0) <= 1e-9);
  // The energy: only the collision's 1/2 mu (1 - e^2) 5^2 = 4.6875 is gone (all else tangent).
  CHECK(e0 - w.energy() == Approx(4.6875).epsilon(1e-9));
  CHECK(w.stats().energy_rules() == 0.0);
  CHECK(w.stats().events < 5000);
}

TEST_CASE("the sliding flight never fires where the bounces would not end", "[slide]") {
  const Slope s;
  SECTION("e = 1: an elastic disc keeps bouncing down the slope, energy kept") {
    WorldDef d = s.def(1.0, 1e-6);
    d.balls.push_back(s.disc(150.0, 2.0));
    World w(d, Mode::exact);
    w.set_event_limit(20000);
    const double e0 = w.energy();
    w.advance_to(5.0);
    CHECK(w.stats().slides == 0);
    CHECK(w.stats().ball_wall >= 3);
    CHECK(w.energy() == Approx(e0).epsilon(1e-12));
  }
  SECTION("a field pulling the disc off the wall: it falls away from a shelf's underside") {
    WorldDef d = box(300, 200);
    d.walls.push_back({"shelf", {50, 100}, {250, 100}});
    d.effects.gravity = {0, -kG};
    d.effects.restitution = 0.5;
    d.effects.tc = 1e-9;
    d.balls.push_back(ball("b", {150, 99.0 - 1e-12}, {2, 3}, 1.0));  // just under it, rising
    World w(d, Mode::exact);
    w.set_event_limit(20000);
    w.advance_to(0.3);
    CHECK(w.stats().ball_wall == 1);
    CHECK(w.stats().slides == 0);
  }
}
