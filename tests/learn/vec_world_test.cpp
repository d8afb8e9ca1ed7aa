// SPDX-License-Identifier: MIT
// VecWorld: shapes and layout, determinism (the same seed gives the same observations, on one
// thread or two), reset, the touch bit of a turtle driven into a wall, range readings against
// closed forms, odometry, the three kinds of action, terminated and truncated.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/learn/vec_world.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tl = turtlegas::learn;
namespace tw = turtlegas::world;

namespace {

const turtlegas::turtle::Registry& registry() {
  static const turtlegas::turtle::Registry r = turtlegas::controllers::builtin_registry();
  return r;
}

tw::Scene swarm() { return tw::load_scene("worlds/learn/swarm16.json", registry()); }

/// One turtle at (100, 150) facing +x, radius 10, speed 100, turn rate 180 deg/s, a 4-ray ring of
/// range 100, in a walled 400 x 300 arena with a wall at x = 128: its front is 18 units away.
tw::Scene facing_wall(const std::string& boundary = "walls", const std::string& extra = "") {
  const std::string text = R"({"format": "turtlegas-world/1", "dt": 0.1,
    "arena": {"width": 400, "height": 300, "boundary": ")" + boundary + R"("},
    "walls": [{"id": "w", "from": [128, 0], "to": [128, 300]}],
    "turtles": [{"id": "t", "pos": [100, 150], "heading": 90, "radius": 10, "speed": 100, "turn_rate": 180,
                 "senses": [{"name": "ring", "ring": 4, "range": 100}], "controller": "remote")" + extra + "}]}";
  return tw::parse_scene(text, "facing_wall.json", registry());
}

struct Run {
  std::vector<float> obs;
  std::vector<std::uint8_t> term, trunc;
  explicit Run(const tl::VecWorld& v)
      : obs(v.size() * v.turtle_count() * v.obs_size()), term(v.size()), trunc(v.size()) {}
};

/// The observations of `steps` control steps of random actions from `seed`, all concatenated.
std::vector<float> trajectory(std::size_t n, std::size_t threads, std::uint64_t seed, int steps) {
  tl::VecWorldOptions o;
  o.threads = threads;
  tl::VecWorld v(swarm(), n, o);
  Run r(v);
  std::vector<float> all, act(n * v.turtle_count() * 2);
  v.reset(seed, r.obs);
  all.insert(all.end(), r.obs.begin(), r.obs.end());
  for (int s = 0; s < steps; ++s) {
    v.sample_actions(act);
    v.step(act, r.obs, r.term, r.trunc);
    all.insert(all.end(), r.obs.begin(), r.obs.end());
  }
  return all;
}

}  // namespace

TEST_CASE("VecWorld: shapes and the observation layout of the 16-turtle ring world") {
  tl::VecWorldOptions o;
  o.threads = 2;
  tl::VecWorld v(swarm(), 5, o);
  CHECK(v.size() == 5);
  CHECK(v.turtle_count() == 16);
  CHECK(v.thread_count() == 2);
  CHECK(v.action_size() == 2);
  const tl::ObsLayout& l = v.layout();
  CHECK(l.touch == 0);
  CHECK(l.touch_count == 4);  // the default arcs: front, right, back, left
  CHECK(l.range == 4);
  CHECK(l.range_count == 8);
  CHECK(l.odometry == 12);
  CHECK(l.heading == 14);
  CHECK(l.gps_count == 0);
  CHECK(l.size == 16);
  CHECK(v.turtle_ids().front() == "t0");
  CHECK(v.dt() == 0.1);
  Run r(v);
  std::vector<float> small(r.obs.size() - 1);
  CHECK_THROWS_AS(v.reset(1, small), std::invalid_argument);
  std::vector<float> act(5 * 16 * 2, 0.0f);
  CHECK_THROWS_AS(v.step(act, r.obs, r.term, r.trunc), std::logic_error);  // before reset
  v.reset(1, r.obs);
  std::vector<float> short_act(5 * 16);
  CHECK_THROWS_AS(v.step(short_act, r.obs, r.term, r.trunc), std::invalid_argument);
  std::vector<std::int32_t> logo(5 * 16);
  CHECK_THROWS_AS(v.step(logo, r.obs, r.term, r.trunc), std::invalid_argument);
  // Every value is finite; ranges in (0, 1], headings on the unit circle.
  for (std::size_t row = 0; row < 5 * 16; ++row) {
    const float* x = &r.obs[row * l.size];
    for (std::size_t k = 0; k < l.range_count; ++k) {
      CHECK(x[l.range + k] > 0.0f);
      CHECK(x[l.range + k] <= 1.0f);
    }
    CHECK(std::hypot(x[l.heading], x[l.heading + 1]) == Approx(1.0).margin(1e-6));
  }
}

TEST_CASE("VecWorld: the same seed gives the same observations, on one thread or two; another seed others") {
  const std::vector<float> a = trajectory(6, 1, 42, 40);
  const std::vector<float> b = trajectory(6, 2, 42, 40);
  const std::vector<float> c = trajectory(6, 2, 43, 40);
  REQUIRE(a.size() == b.size());
  CHECK(a == b);  // bit for bit
  CHECK(a != c);
  // The copies differ from one another (each has its own start and stream).
  const std::size_t row = 16 * 16;
  CHECK(!std::equal(a.begin(), a.begin() + row, a.begin() + row));
}

TEST_CASE("VecWorld: reset puts every copy back to the same start") {
  tl::VecWorldOptions o;
  o.threads = 2;
  tl::VecWorld v(swarm(), 4, o);
  Run r(v);
  v.reset(9, r.obs);
  const std::vector<float> first = r.obs;
  const turtlegas::sim::TurtleState s0 = v.world(2).turtle(3);
  std::vector<float> act(4 * 16 * 2);
  for (int s = 0; s < 20; ++s) {
    v.sample_actions(act);
    v.step(act, r.obs, r.term, r.trunc);
  }
  CHECK(v.steps(2) == 20);
  CHECK(v.world(2).time() == Approx(2.0));
  CHECK(r.obs != first);
  v.reset(9, r.obs);
  CHECK(r.obs == first);
  CHECK(v.steps(2) == 0);
  CHECK(v.world(2).time() == 0.0);
  CHECK(v.world(2).turtle(3).pos.x == s0.pos.x);
  CHECK(v.world(2).turtle(3).pos.y == s0.pos.y);
  // A random start moved the turtles off the world file's grid, inside the arena.
  CHECK((s0.pos.x != 175.0 || s0.pos.y != 25.0));
  for (std::size_t k = 0; k < 16; ++k) {
    const auto p = v.world(2).turtle(k).pos;
    CHECK(p.x >= 10.0);
    CHECK(p.x <= 190.0);
    CHECK(p.y >= 10.0);
    CHECK(p.y <= 190.0);
  }
  // reset_one rebuilds one copy as reset does.
  for (int s = 0; s < 5; ++s) {
    v.sample_actions(act);
    v.step(act, r.obs, r.term, r.trunc);
  }
  v.reset_one(1, 9, r.obs);
  const std::size_t row = 16 * v.obs_size();
  CHECK(std::equal(r.obs.begin() + row, r.obs.begin() + 2 * row, first.begin() + row));
  CHECK(!std::equal(r.obs.begin(), r.obs.begin() + row, first.begin()));
  CHECK(v.steps(1) == 0);
  CHECK(v.steps(0) == 5);
}

TEST_CASE("VecWorld: a turtle driven into a wall stops at the contact and its front touch bit fires") {
  tl::VecWorldOptions o;
  o.random_start = false;
  o.threads = 1;
  tl::VecWorld v(facing_wall(), 1, o);
  const tl::ObsLayout& l = v.layout();
  REQUIRE(l.touch_count == 4);
  REQUIRE(l.range_count == 4);
  Run r(v);
  v.reset(1, r.obs);
  // The ring at the start: front 28 units to the wall (x = 128) of range 100; right (-y) and left
  // (+y) 150 away, beyond the range; back 100 to the arena's left wall, on the range's edge.
  CHECK(r.obs[l.range + 0] == Approx(0.28).epsilon(1e-6));
  CHECK(r.obs[l.range + 1] == 1.0f);
  CHECK(r.obs[l.range + 3] == 1.0f);
  CHECK(r.obs[l.heading] == Approx(1.0).margin(1e-7));   // sin 90 deg
  CHECK(r.obs[l.heading + 1] == Approx(0.0).margin(1e-7));
  // Full ahead: 5 units a step (100 units/s over half of 0.1 s). 18 units to the contact.
  const std::vector<float> ahead{1.0f, 0.0f};
  for (int s = 0; s < 3; ++s) {
    v.step(ahead, r.obs, r.term, r.trunc);
    CHECK(r.obs[l.odometry] == Approx(5.0).epsilon(1e-9));
    CHECK(r.obs[l.odometry + 1] == 0.0f);
    for (std::size_t b = 0; b < 4; ++b) CHECK(r.obs[l.touch + b] == 0.0f);
    CHECK(v.last_contacts(0) == 0);
  }
  CHECK(v.world(0).turtle(0).pos.x == Approx(115.0).epsilon(1e-12));
  v.step(ahead, r.obs, r.term, r.trunc);
  CHECK(r.obs[l.odometry] == Approx(3.0).epsilon(1e-6));  // cut short at the contact
  CHECK(r.obs[l.touch + 0] == 1.0f);  // front
  CHECK(r.obs[l.touch + 1] == 0.0f);
  CHECK(r.obs[l.touch + 2] == 0.0f);
  CHECK(r.obs[l.touch + 3] == 0.0f);
  CHECK(v.last_contacts(0) == 1);
  CHECK(v.world(0).turtle(0).pos.x == Approx(118.0).epsilon(1e-9));
  CHECK(r.obs[l.range + 0] == Approx(0.10).epsilon(1e-5));
  CHECK(!r.term[0]);
  CHECK(!r.trunc[0]);
  // Backing off clears the bit.
  const std::vector<float> astern{-1.0f, 0.0f};
  v.step(astern, r.obs, r.term, r.trunc);
  CHECK(r.obs[l.odometry] == Approx(-5.0).epsilon(1e-9));
  CHECK(r.obs[l.touch + 0] == 0.0f);
}

TEST_CASE("VecWorld: a turn then a stroke per step; wheels as a differential drive") {
  tl::VecWorldOptions o;
  o.random_start = false;
  o.threads = 1;
  SECTION("velocity: (v, omega) = (0.5, 1) turns 9 degrees (half of 180 deg/s over 0.1 s) then drives 2.5") {
    tl::VecWorld v(facing_wall(), 1, o);
    Run r(v);
    v.reset(1, r.obs);
    const std::vector<float> a{0.5f, 1.0f};
    v.step(a, r.obs, r.term, r.trunc);
    const double h = (90.0 + 9.0) * M_PI / 180.0;
    const auto st = v.world(0).turtle(0);
    CHECK(st.heading == Approx(h).epsilon(1e-12));
    CHECK(st.pos.x == Approx(100.0 + 2.5 * std::sin(h)).epsilon(1e-12));
    CHECK(st.pos.y == Approx(150.0 + 2.5 * std::cos(h)).epsilon(1e-12));
    CHECK(r.obs[v.layout().odometry] == Approx(2.5).epsilon(1e-7));
    CHECK(r.obs[v.layout().odometry + 1] == Approx(9.0 * M_PI / 180.0).epsilon(1e-6));
  }
  SECTION("wheels: (1, -1) spins clockwise in place at the full rate; (-1, -1) backs") {
    o.actions = tl::ActionKind::wheels;
    tl::VecWorld v(facing_wall(), 1, o);
    Run r(v);
    v.reset(1, r.obs);
    v.step(std::vector<float>{1.0f, -1.0f}, r.obs, r.term, r.trunc);
    CHECK(v.world(0).turtle(0).heading == Approx(99.0 * M_PI / 180.0).epsilon(1e-12));
    CHECK(v.world(0).turtle(0).pos.x == 100.0);
    v.step(std::vector<float>{-1.0f, -1.0f}, r.obs, r.term, r.trunc);
    CHECK(r.obs[v.layout().odometry] == Approx(-5.0).epsilon(1e-7));
    CHECK(r.obs[v.layout().odometry + 1] == 0.0f);
  }
  SECTION("logo: forward drives speed x dt, right turns turn_rate x dt, out of range waits") {
    o.actions = tl::ActionKind::logo;
    tl::VecWorld v(facing_wall(), 1, o);
    CHECK(v.action_size() == 1);
    Run r(v);
    v.reset(1, r.obs);
    v.step(std::vector<std::int32_t>{1}, r.obs, r.term, r.trunc);
    CHECK(v.world(0).turtle(0).pos.x == Approx(110.0).epsilon(1e-12));
    v.step(std::vector<std::int32_t>{4}, r.obs, r.term, r.trunc);
    CHECK(v.world(0).turtle(0).heading == Approx(108.0 * M_PI / 180.0).epsilon(1e-12));
    CHECK(r.obs[v.layout().odometry + 1] == Approx(18.0 * M_PI / 180.0).epsilon(1e-6));
    v.step(std::vector<std::int32_t>{3}, r.obs, r.term, r.trunc);
    CHECK(v.world(0).turtle(0).heading == Approx(90.0 * M_PI / 180.0).epsilon(1e-12));
    CHECK(r.obs[v.layout().odometry + 1] == Approx(-18.0 * M_PI / 180.0).epsilon(1e-6));
    v.step(std::vector<std::int32_t>{17}, r.obs, r.term, r.trunc);
    CHECK(v.world(0).turtle(0).pos.x == Approx(110.0).epsilon(1e-12));
    std::vector<std::int32_t> sampled(1);
    for (int k = 0; k < 50; ++k) {
      v.sample_actions(sampled);
      CHECK(sampled[0] >= 0);
      CHECK(sampled[0] < tl::logo_action_count);
    }
  }
}

TEST_CASE("VecWorld: gps where granted; truncated after max_steps; terminated when a turtle leaves an open arena") {
  tl::VecWorldOptions o;
  o.random_start = false;
  o.threads = 1;
  o.max_steps = 3;
  {
    tl::VecWorld v(facing_wall("walls", R"(, "gps": true)"), 2, o);
    REQUIRE(v.layout().gps_count == 1);
    Run r(v);
    v.reset(1, r.obs);
    CHECK(r.obs[v.layout().gps] == 100.0f);
    CHECK(r.obs[v.layout().gps + 1] == 150.0f);
    const std::vector<float> still(4, 0.0f);
    for (int s = 0; s < 3; ++s) {
      CHECK(!r.trunc[0]);
      v.step(still, r.obs, r.term, r.trunc);
    }
    CHECK(r.trunc[0]);
    CHECK(r.trunc[1]);
    CHECK(!r.term[0]);
    v.step(still, r.obs, r.term, r.trunc);  // a done copy stands
    CHECK(v.steps(0) == 3);
  }
  // Facing -x in an open arena 100 units from its edge: out after 20 steps of 5 units, or so.
  const std::string text = R"({"format": "turtlegas-world/1", "dt": 0.1, "arena": {"width": 400, "height": 300},
    "turtles": [{"id": "t", "pos": [100, 150], "heading": 270, "radius": 10, "speed": 100, "controller": "remote"},
                {"id": "u", "pos": [300, 150], "heading": 0, "radius": 10, "speed": 100, "controller": "remote"}]})";
  o.max_steps = 0;
  tl::VecWorld v(tw::parse_scene(text, "open.json", registry()), 1, o);
  Run r(v);
  v.reset(1, r.obs);
  const std::vector<float> ahead{1.0f, 0.0f, 0.0f, 0.0f};
  int steps = 0;
  while (!r.term[0] && steps < 40) {
    v.step(ahead, r.obs, r.term, r.trunc);
    ++steps;
  }
  CHECK(r.term[0]);
  CHECK(steps >= 19);
  CHECK(steps <= 23);
  CHECK(!v.world(0).turtle_alive(0));
}

TEST_CASE("VecWorld: range sensor noise and dropout, from each copy's own stream") {
  // The front ray reads the wall 28 units away: sd 0.5, dropout 0.1, over 200 copies x 10 steps.
  const std::string noisy = R"({"format": "turtlegas-world/1", "dt": 0.1,
    "arena": {"width": 400, "height": 300, "boundary": "walls"},
    "walls": [{"id": "w", "from": [128, 0], "to": [128, 300]}],
    "turtles": [{"id": "t", "pos": [100, 150], "heading": 90, "radius": 10, "controller": "remote",
                 "senses": [{"name": "f", "bearing": 0, "range": 100, "noise": {"sd": 0.5, "dropout": 0.1}}]}]})";
  tl::VecWorldOptions o;
  o.random_start = false;
  o.threads = 2;
  auto readings = [&](std::uint64_t seed) {
    tl::VecWorld v(tw::parse_scene(noisy, "noisy.json", registry()), 200, o);
    Run r(v);
    std::vector<float> out;
    v.reset(seed, r.obs);
    const std::vector<float> still(200 * 2, 0.0f);
    for (int s = 0; s < 10; ++s) {
      v.step(still, r.obs, r.term, r.trunc);
      for (std::size_t i = 0; i < 200; ++i) out.push_back(r.obs[i * v.obs_size() + v.layout().range]);
    }
    return out;
  };
  const std::vector<float> a = readings(5), b = readings(5), c = readings(6);
  CHECK(a == b);
  CHECK(a != c);
  double n = 0, sum = 0, sum2 = 0, dropped = 0;
  for (float x : a) {
    if (x == 1.0f) {
      ++dropped;
      continue;
    }
    const double d = 100.0 * x;
    ++n, sum += d, sum2 += d * d;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean), p = dropped / 2000.0;
  CHECK(std::fabs(mean - 28.0) < 5 * 0.5 / std::sqrt(n));
  CHECK(std::fabs(sd - 0.5) < 0.05);
  CHECK(std::fabs(p - 0.1) < 5 * std::sqrt(0.1 * 0.9 / 2000.0));
}

TEST_CASE("VecWorld: refuses no copies and a world without turtles") {
  CHECK_THROWS_AS(tl::VecWorld(swarm(), 0), std::invalid_argument);
  const std::string empty = R"({"format": "turtlegas-world/1", "arena": {"width": 100, "height": 100}})";
  CHECK_THROWS_AS(tl::VecWorld(tw::parse_scene(empty, "e.json", registry()), 2), std::invalid_argument);
}
