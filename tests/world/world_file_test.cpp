// SPDX-License-Identifier: MIT
#include "turtlegas/world/world_file.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "file_errors.hpp"

namespace tw = turtlegas::world;
namespace sim = turtlegas::sim;

using turtlegas::test::contains;

namespace {

const std::string head = R"("format": "turtlegas-world/1")";

/// A world file's text: the format line followed by `body` (which starts with a comma if not empty).
std::string world(const std::string& body) { return "{" + head + body + "}"; }

/// The error that parsing `text` raises; fails the test if it parses.
tw::WorldFileError error_of(const std::string& text) {
  return turtlegas::test::error_of([](const std::string& t) { return tw::parse_world(t, "w.json"); }, text);
}

std::uint64_t fnv(std::uint64_t h, double v) {
  const auto bits = std::bit_cast<std::uint64_t>(v);
  for (int k = 0; k < 8; ++k) h = (h ^ ((bits >> (8 * k)) & 0xff)) * 0x100000001b3ULL;
  return h;
}

}  // namespace

TEST_CASE("a minimal file gets the documented defaults") {
  const sim::WorldDef def = tw::parse_world(world(""), "dir/minimal.json");
  CHECK(def.name == "minimal");
  CHECK(def.seed == 1);
  CHECK(def.dt == 1.0 / 30.0);
  CHECK(def.arena.width == 1600);
  CHECK(def.arena.height == 1600);
  CHECK_FALSE(def.arena.cell.has_value());
  CHECK(def.arena.boundary == sim::Boundary::none);
  CHECK(def.effects.gravity == sim::Vec2{});
  CHECK(def.effects.restitution == 1.0);
  CHECK(def.effects.ball_ball);
  CHECK(def.effects.tc == 1e-4);
  CHECK(def.walls.empty());
  CHECK(def.balls.empty());
}

TEST_CASE("a full file parses into the expected WorldDef") {
  const std::string text = world(R"(,
    "name": "full", "seed": 42, "dt": 0.01,
    "arena": {"width": 200, "height": 100, "cell": 20, "boundary": "walls"},
    "effects": {"gravity": [0, -9.8], "electric": [0, 0], "magnetic": 0, "restitution": 0.9,
                "ball_ball": false, "tc": 0.001},
    "walls": [{"id": "w1", "from": [50, 10], "to": [50, 90]}],
    "balls": [{"id": "b1", "pos": [20, 20], "vel": [3, -4], "radius": 2, "mass": 5, "charge": 0.5},
              {"id": "b2", "pos": [100, 50], "radius": 1.5}],
    "x-note": {"anything": [1, 2, 3]}
  )");
  const sim::WorldDef def = tw::parse_world(text, "full.json");
  CHECK(def.name == "full");
  CHECK(def.seed == 42);
  CHECK(def.dt == 0.01);
  CHECK(def.arena.width == 200);
  CHECK(def.arena.height == 100);
  CHECK(def.arena.cell == 20.0);
  CHECK(def.arena.boundary == sim::Boundary::walls);
  CHECK(def.effects.gravity == sim::Vec2{0, -9.8});
  CHECK(def.effects.restitution == 0.9);
  CHECK_FALSE(def.effects.ball_ball);
  CHECK(def.effects.tc == 0.001);
  REQUIRE(def.walls.size() == 1);  // arena walls are the engine's to add
  CHECK(def.walls[0].id == "w1");
  CHECK(def.walls[0].from == sim::Vec2{50, 10});
  CHECK(def.walls[0].to == sim::Vec2{50, 90});
  REQUIRE(def.balls.size() == 2);
  CHECK(def.balls[0].id == "b1");
  CHECK(def.balls[0].pos == sim::Vec2{20, 20});
  CHECK(def.balls[0].vel == sim::Vec2{3, -4});
  CHECK(def.balls[0].radius == 2);
  CHECK(def.balls[0].mass == 5);
  CHECK(def.balls[0].charge == 0.5);
  CHECK(def.balls[1].vel == sim::Vec2{});
  CHECK(def.balls[1].mass == 1);
  CHECK(def.balls[1].charge == 0);
}

TEST_CASE("x- keys are accepted at every level") {
  const std::string text = world(R"(, "x-top": 1,
    "arena": {"width": 100, "height": 100, "x-a": true},
    "effects": {"x-e": "note"},
    "walls": [{"id": "w", "from": [0, 50], "to": [10, 50], "x-colour": "red"}],
    "balls": [{"id": "b", "pos": [50, 20], "radius": 1, "x-label": "hi"}],
    "gas": [{"count": 3, "radius": 1, "speed": 1, "x-g": null}])");
  const sim::WorldDef def = tw::parse_world(text, "w.json");
  CHECK(def.balls.size() == 4);
}

TEST_CASE("invalid JSON names line and column") {
  const std::string text = "{\n  \"format\": \"turtlegas-world/1\",\n  \"name\": ,\n}";
  const tw::WorldFileError e = error_of(text);
  INFO(e.what());
  CHECK(e.line == 3);
  CHECK(e.column == 11);
  CHECK(e.json_path.empty());
  CHECK(std::string(e.what()).starts_with("w.json:3:11: invalid JSON: "));
  CHECK_FALSE(contains(e.what(), "[json.exception"));

  const tw::WorldFileError overflow = error_of(world(R"(, "dt": 1e999)"));
  CHECK(std::string(overflow.what()) == "w.json: invalid JSON: number overflow parsing '1e999'");

  const tw::WorldFileError empty = error_of("");
  CHECK(empty.line == 1);
  CHECK(contains(empty.what(), "invalid JSON"));
}

TEST_CASE("format must be turtlegas-world/1") {
  CHECK_ERROR(R"({"name": "x"})", "", "missing \"format\"");
  CHECK_ERROR(R"({"format": "turtlegas-world/2"})", "/format", "unsupported format \"turtlegas-world/2\"");
  CHECK_ERROR(R"({"format": 1})", "/format", "this turtlegas reads \"turtlegas-world/1\"");
  CHECK_ERROR(R"([1, 2])", "", "must be a JSON object");
}

TEST_CASE("wrong types name the expected type") {
  CHECK_ERROR(world(R"(, "dt": "fast")"), "/dt", "expected a number, got a string");
  CHECK_ERROR(world(R"(, "seed": -3)"), "/seed", "expected an integer >= 0, got -3");
  CHECK_ERROR(world(R"(, "seed": 1.5)"), "/seed", "expected an integer >= 0, got 1.5");
  CHECK_ERROR(world(R"(, "name": 7)"), "/name", "expected a string, got a number");
  CHECK_ERROR(world(R"(, "arena": [1600, 1600])"), "/arena", "arena must be a JSON object");
  CHECK_ERROR(world(R"(, "arena": {"boundary": "wall"})"), "/arena/boundary",
              "boundary must be \"none\", \"walls\" or \"periodic\" (got \"wall\")");
  CHECK_ERROR(world(R"(, "effects": {"ball_ball": 1})"), "/effects/ball_ball", "expected true or false, got a number");
  CHECK_ERROR(world(R"(, "effects": {"gravity": [0, -9.8, 0]})"), "/effects/gravity",
              "expected [x, y] (an array of 2 numbers), got an array of 3");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "pos": [1, "2"], "radius": 1}])"), "/balls/0/pos/1",
              "expected a number, got a string");
  CHECK_ERROR(world(R"(, "balls": {"id": "b"})"), "/balls", "balls must be a JSON array");
  CHECK_ERROR(world(R"(, "balls": [{"id": 3, "pos": [1, 2], "radius": 1}])"), "/balls/0/id",
              "expected a string, got a number");
  CHECK_ERROR(world(R"(, "walls": [{"id": "w", "from": null, "to": [1, 2]}])"), "/walls/0/from",
              "expected [x, y] (an array of 2 numbers), got null");
}

TEST_CASE("missing required keys are named") {
  CHECK_ERROR(world(R"(, "balls": [{"pos": [1, 2], "radius": 1}])"), "/balls/0", "a ball needs \"id\"");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "radius": 1}])"), "/balls/0", "a ball needs \"pos\"");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "pos": [1, 2]}])"), "/balls/0", "a ball needs \"radius\"");
  CHECK_ERROR(world(R"(, "walls": [{"id": "w", "from": [1, 2]}])"), "/walls/0", "a wall needs \"to\"");
  CHECK_ERROR(world(R"(, "gas": [{"radius": 1, "speed": 1}])"), "/gas/0", "a gas needs \"count\"");
}

TEST_CASE("unknown keys are errors with a suggestion") {
  CHECK_ERROR(world(R"(, "balsl": [])"), "/balsl", "unknown key \"balsl\" in the world; did you mean \"balls\"?");
  CHECK_ERROR(world(R"(, "arena": {"widht": 10})"), "/arena/widht", "did you mean \"width\"?");
  CHECK_ERROR(world(R"(, "balls": [{"id": "b", "pos": [1, 2], "radius": 1, "color": "red"}])"), "/balls/0/color",
              "unknown key \"color\" in a ball");
  CHECK_ERROR(world(R"(, "gas": [{"count": 1, "radius": 1, "speed": 1, "zzz": 1}])"), "/gas/0/zzz",
              "keys starting with x- are ignored");
  // JSON-pointer escaping of odd keys.
  CHECK_ERROR(world(R"(, "a/b~c": 1)"), "/a~1b~0c", "unknown key \"a/b~c\"");
}

TEST_CASE("learn: a reward expression for VecWorld is checked and does not change the world") {
  const sim::WorldDef plain = tw::parse_world(world(""), "w.json");
  const sim::WorldDef with = tw::parse_world(world(R"(, "learn": {"reward": "distance / stroke - touch"})"), "w.json");
  CHECK(with.balls.size() == plain.balls.size());
  CHECK(with.dt == plain.dt);
  CHECK_ERROR(world(R"(, "learn": "touch")"), "/learn", "an object");
  CHECK_ERROR(world(R"(, "learn": {"reward": ""})"), "/learn/reward", "not an empty string");
  CHECK_ERROR(world(R"(, "learn": {"reward": 3})"), "/learn/reward", "expected a string");
  CHECK_ERROR(world(R"(, "learn": {"rewrad": "touch"})"), "/learn/rewrad", "did you mean \"reward\"?");
}

TEST_CASE("electric and magnetic fields and charges are read") {
  const sim::WorldDef def = tw::parse_world(
      world(R"(, "effects": {"electric": [1, -2], "magnetic": 0.5},
        "balls": [{"id": "b", "pos": [100, 100], "radius": 1, "charge": -3}],
        "gas": [{"count": 3, "radius": 1, "speed": 1, "charge": 2, "mass": 4, "region": [[0, 0], [50, 50]]}])"),
      "w.json");
  CHECK(def.effects.electric == sim::Vec2{1, -2});
  CHECK(def.effects.magnetic == 0.5);
  REQUIRE(def.balls.size() == 4);
  CHECK(def.balls[0].charge == -3);
  for (std::size_t k = 1; k < 4; ++k) CHECK(def.balls[k].charge == 2);
  CHECK_ERROR(world(R"(, "effects": {"magnetic": "strong"})"), "/effects/magnetic", "expected a number");
  CHECK_ERROR(world(R"(, "gas": [{"count": 1, "radius": 1, "speed": 1, "charge": "plus"}])"), "/gas/0/charge",
              "expected a number");
}

TEST_CASE("bad values") {
  const std::string ball = R"(, "balls": [{"id": "b1", "pos": [100, 100], )";
  CHECK_ERROR(world(ball + R"("radius": -1}])"), "/balls/0/radius", "radius must be > 0 (got -1)");
  CHECK_ERROR(world(ball + R"("radius": 0}])"), "/balls/0/radius", "radius must be > 0 (got 0)");
  CHECK_ERROR(world(ball + R"("radius": 1, "mass": 0}])"), "/balls/0/mass", "mass must be > 0 (got 0)");
  CHECK_ERROR(world(R"(, "dt": 0)"), "/dt", "dt must be > 0 (got 0)");
  CHECK_ERROR(world(R"(, "arena": {"width": -5})"), "/arena/width", "arena width must be > 0 (got -5)");
  CHECK_ERROR(world(R"(, "effects": {"restitution": 1.5})"), "/effects/restitution",
              "restitution must be in [0, 1] (got 1.5)");
  CHECK_ERROR(world(R"(, "effects": {"tc": 0})"), "/effects/tc", "tc must be > 0");
  // The exact form of the message the design asks for.
  const tw::WorldFileError e = error_of(world(R"(, "balls": [{"id": "a", "pos": [1, 1], "radius": 1},
    {"id": "b", "pos": [9, 9], "radius": 1}, {"id": "c", "pos": [20, 20], "radius": 1},
    {"id": "d", "pos": [30, 30], "radius": -1}])"));
  CHECK(std::string(e.what()) == "w.json: /balls/3/radius: radius must be > 0 (got -1)");
}

TEST_CASE("zero-length walls") {
  CHECK_ERROR(world(R"(, "walls": [{"id": "w1", "from": [0, 0], "to": [5, 0]},
                                   {"id": "w2", "from": [3, 4], "to": [3, 4]}])"),
              "/walls/1/to", "wall 'w2' has zero length");
}

TEST_CASE("duplicate ids") {
  CHECK_ERROR(world(R"(, "balls": [{"id": "b1", "pos": [10, 10], "radius": 1},
                                   {"id": "b1", "pos": [20, 10], "radius": 1}])"),
              "/balls/1/id", "duplicate id \"b1\" (already used at /balls/0/id)");
  CHECK_ERROR(world(R"(, "walls": [{"id": "x", "from": [0, 50], "to": [10, 50]}],
                        "balls": [{"id": "x", "pos": [20, 10], "radius": 1}])"),
              "/balls/0/id", "already used at /walls/0/id");
  CHECK_ERROR(world(R"(, "arena": {"boundary": "walls"},
                        "walls": [{"id": "arena-top", "from": [0, 50], "to": [10, 50]}])"),
              "/walls/0/id", "taken by an arena wall");
  // Without boundary walls the arena ids are free.
  CHECK_NOTHROW(tw::parse_world(world(R"(, "walls": [{"id": "arena-top", "from": [0, 50], "to": [10, 50]}])"), "w.json"));
  CHECK_ERROR(world(R"(, "balls": [{"id": "", "pos": [10, 10], "radius": 1}])"), "/balls/0/id",
              "id must not be empty");
  // A generated id that collides with an explicit one is reported at the gas.
  CHECK_ERROR(world(R"(, "balls": [{"id": "g2", "pos": [1500, 1500], "radius": 1}],
                        "gas": [{"count": 5, "radius": 1, "speed": 1, "region": [[0, 0], [100, 100]]}])"),
              "/gas/0", "this gas's id \"g2\" is already used at /balls/0/id; set an id_prefix");
  // Gases whose generated ids could coincide.
  const std::string g = R"({"count": 20, "radius": 1, "speed": 1, "region": [[0, 0], [100, 100]])";
  CHECK_ERROR(world(R"(, "gas": [)" + g + R"(, "id_prefix": "x"}, )" + g + R"(, "id_prefix": "x"}])"), "/gas/1",
              "(prefixes \"x\" and \"x\") overlap; give each gas its own id_prefix");
  CHECK_ERROR(world(R"(, "gas": [)" + g + R"(}, )" + g + R"(, "id_prefix": "g1"}])"), "/gas/1",
              "(prefixes \"g\" and \"g1\") overlap");
  // "g" with 5 balls makes g0..g4, which "g1" + n never equals.
  CHECK_NOTHROW(tw::parse_world(world(R"(, "gas": [{"count": 5, "radius": 1, "speed": 1}, )" + g +
                                      R"(, "id_prefix": "g1"}])"), "w.json"));
}

TEST_CASE("overlaps and balls outside the arena") {
  CHECK_ERROR(world(R"(, "balls": [{"id": "b1", "pos": [10, 10], "radius": 2},
                                   {"id": "b2", "pos": [13, 10], "radius": 2}])"),
              "/balls/1/pos", "ball 'b2' at [13, 10] overlaps ball 'b1' at [10, 10]");
  CHECK_ERROR(world(R"(, "walls": [{"id": "w", "from": [0, 50], "to": [100, 50]}],
                        "balls": [{"id": "b", "pos": [40, 51], "radius": 2}])"),
              "/balls/0/pos", "ball 'b' (radius 2) at [40, 51] overlaps wall 'w'");
  CHECK_ERROR(world(R"(, "arena": {"width": 100, "height": 100},
                        "balls": [{"id": "b", "pos": [150, 50], "radius": 2}])"),
              "/balls/0/pos", "is outside the arena [0, 100] x [0, 100]");
  CHECK_ERROR(world(R"(, "arena": {"width": 100, "height": 100, "boundary": "walls"},
                        "balls": [{"id": "b", "pos": [1, 50], "radius": 2}])"),
              "/balls/0/pos", "sticks out of the arena walls");
  // Exactly touching is fine.
  CHECK_NOTHROW(tw::parse_world(world(R"(, "balls": [{"id": "b1", "pos": [10, 10], "radius": 2},
                                                      {"id": "b2", "pos": [14, 10], "radius": 2}])"), "w.json"));
}

TEST_CASE("gas entries are checked") {
  const std::string gas = R"(, "gas": [{"count": 10, "speed": 5, )";
  CHECK_ERROR(world(gas + R"("radius": 0}])"), "/gas/0/radius", "radius must be > 0");
  CHECK_ERROR(world(gas + R"("radius": 1, "speed": -1}])"), "/gas/0/speed", "speed must be >= 0");
  CHECK_ERROR(world(gas + R"("radius": 1, "mass": -2}])"), "/gas/0/mass", "mass must be > 0");
  CHECK_ERROR(world(R"(, "gas": [{"count": -1, "radius": 1, "speed": 1}])"), "/gas/0/count", "expected an integer >= 0");
  CHECK_ERROR(world(gas + R"("radius": 1, "region": [[10, 10], [5, 20]]}])"), "/gas/0/region", "is empty");
  CHECK_ERROR(world(gas + R"("radius": 1, "region": [0, 0, 10, 10]}])"), "/gas/0/region",
              "expected [[x0, y0], [x1, y1]] (two corners), got an array of 4");
  CHECK_ERROR(world(gas + R"("radius": 10, "region": [[0, 0], [15, 100]]}])"), "/gas/0/region",
              "balls of radius 10 do not fit in region");
  CHECK_ERROR(world(R"(, "gas": [{"count": 500, "radius": 10, "speed": 1, "region": [[0, 0], [100, 100]]}])"), "/gas/0",
              "could only place");
  const tw::WorldFileError e = error_of(world(R"(, "gas": [{"count": 1, "radius": 1, "speed": 1},
      {"count": 500, "radius": 10, "speed": 1, "region": [[0, 0], [100, 100]]}])"));
  CHECK(e.json_path == "/gas/1");
  CHECK(contains(e.reason, " of 500 balls of radius 10 in region [[0, 0], [100, 100]]; enlarge the region or reduce count/radius"));
}

TEST_CASE("a missing file is a WorldFileError") {
  try {
    tw::load_world_file("no/such/world.json");
    FAIL("no error");
  } catch (const tw::WorldFileError& e) {
    CHECK(std::string(e.what()) == "no/such/world.json: no such file; check the path");
  }
  CHECK_THROWS_AS(tw::load_world_file(TURTLEGAS_SOURCE_DIR), tw::WorldFileError);
}

TEST_CASE("the shipped worlds load") {
  for (const char* file : {"worlds/gas.json", "worlds/gas_gravity.json"}) {
    INFO(file);
    const sim::WorldDef def = tw::load_world_file(std::string(TURTLEGAS_SOURCE_DIR) + "/" + file);
    CHECK(def.balls.size() > 300);
    CHECK(def.arena.boundary == sim::Boundary::walls);
    CHECK_FALSE(sim::validate(def).has_value());
  }
}

namespace {

sim::WorldDef gas_world(const std::string& gas, const std::string& extra = "") {
  return tw::parse_world(world(R"(, "arena": {"width": 400, "height": 300, "boundary": "walls"})" + extra +
                               R"(, "gas": [)" + gas + "]"),
                         "gas.json");
}

void check_gas(const sim::WorldDef& def, std::size_t first, std::size_t count, double radius, double speed, sim::Vec2 lo,
               sim::Vec2 hi) {
  REQUIRE(def.balls.size() >= first + count);
  for (std::size_t i = first; i < first + count; ++i) {
    const sim::BallDef& b = def.balls[i];
    INFO("ball " << b.id << " at " << b.pos.x << ", " << b.pos.y);
    CHECK(b.radius == radius);
    CHECK(b.pos.x - radius >= lo.x);
    CHECK(b.pos.x + radius <= hi.x);
    CHECK(b.pos.y - radius >= lo.y);
    CHECK(b.pos.y + radius <= hi.y);
    CHECK(std::abs(sim::norm(b.vel) - speed) <= 1e-12 * speed);
  }
  // Brute force: no pair overlaps, and nothing overlaps a wall.
  for (std::size_t i = 0; i < def.balls.size(); ++i) {
    for (std::size_t j = i + 1; j < def.balls.size(); ++j) {
      const double s = def.balls[i].radius + def.balls[j].radius;
      if (sim::norm2(def.balls[i].pos - def.balls[j].pos) < s * s) FAIL("balls " << i << " and " << j << " overlap");
    }
  }
}

}  // namespace

TEST_CASE("gas placement: inside the region, apart, at the given speed") {
  const sim::WorldDef def = gas_world(R"({"count": 500, "radius": 3, "mass": 2, "speed": 40, "region": [[50, 20], [350, 280]]})");
  REQUIRE(def.balls.size() == 500);
  CHECK(def.balls[0].id == "g0");
  CHECK(def.balls[499].id == "g499");
  CHECK(def.balls[7].mass == 2);
  check_gas(def, 0, 500, 3, 40, {50, 20}, {350, 280});
}

TEST_CASE("gas placement avoids walls, explicit balls and earlier gases") {
  const std::string extra = R"(, "walls": [{"id": "diag", "from": [0, 0], "to": [400, 300]},
                                           {"id": "v", "from": [200, 0], "to": [200, 150]}],
                               "balls": [{"id": "big", "pos": [100, 200], "radius": 50}])";
  const sim::WorldDef def = gas_world(R"({"count": 300, "radius": 2, "speed": 10},
                                         {"count": 200, "radius": 4, "speed": 20, "id_prefix": "h"})",
                                      extra);
  REQUIRE(def.balls.size() == 501);
  CHECK(def.balls[1].id == "g0");
  CHECK(def.balls[301].id == "h0");
  check_gas(def, 1, 300, 2, 10, {0, 0}, {400, 300});
  check_gas(def, 301, 200, 4, 20, {0, 0}, {400, 300});
  CHECK_FALSE(sim::validate(def).has_value());  // includes ball-wall overlaps
}

TEST_CASE("gas default ids and seeds differ per entry") {
  const sim::WorldDef def = gas_world(R"({"count": 3, "radius": 1, "speed": 1}, {"count": 3, "radius": 1, "speed": 1})");
  REQUIRE(def.balls.size() == 6);
  CHECK(def.balls[0].id == "g0");
  CHECK(def.balls[3].id == "g1-0");
  CHECK(def.balls[0].pos != def.balls[3].pos);
}

TEST_CASE("gas placement is deterministic") {
  const std::string g7 = R"({"count": 400, "radius": 2, "speed": 30, "seed": 7})";
  const sim::WorldDef a = gas_world(g7), b = gas_world(g7);
  const sim::WorldDef c = gas_world(R"({"count": 400, "radius": 2, "speed": 30, "seed": 8})");
  REQUIRE(a.balls.size() == 400);
  bool all_same = true;
  std::size_t same_as_c = 0;
  for (std::size_t i = 0; i < 400; ++i) {
    all_same = all_same && std::memcmp(&a.balls[i].pos, &b.balls[i].pos, sizeof(sim::Vec2)) == 0 &&
               std::memcmp(&a.balls[i].vel, &b.balls[i].vel, sizeof(sim::Vec2)) == 0;
    same_as_c += a.balls[i].pos == c.balls[i].pos ? 1 : 0;
  }
  CHECK(all_same);
  CHECK(same_as_c == 0);

  // The seed defaults to the world's seed.
  const sim::WorldDef d = gas_world(R"({"count": 400, "radius": 2, "speed": 30})", R"(, "seed": 7)");
  CHECK(d.balls[123].pos == a.balls[123].pos);

  // Pinned: the same seed must give the same gas on every compiler and platform (the generator
  // uses only mt19937_64, integer-to-double conversion, +, *, / and sqrt). If this changes on
  // purpose, every world with a gas changes; update the value and say so in the change log.
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const auto& ball : a.balls) h = fnv(fnv(fnv(fnv(h, ball.pos.x), ball.pos.y), ball.vel.x), ball.vel.y);
  CHECK(h == 0xcd1b7472c2424a1eULL);
}

TEST_CASE("a dense gas is placed on a jittered lattice") {
  // Area fraction 0.6 of the region: beyond what random sequential addition reaches.
  const double r = 2.0;
  const auto count = static_cast<std::size_t>(0.6 * 400 * 300 / (std::numbers::pi * r * r));
  const std::string g = R"({"count": )" + std::to_string(count) + R"(, "radius": 2, "speed": 5, "seed": 3})";
  const sim::WorldDef a = gas_world(g), b = gas_world(g);
  REQUIRE(a.balls.size() == count);
  check_gas(a, 0, count, 2, 5, {0, 0}, {400, 300});
  for (std::size_t i = 0; i < count; ++i) REQUIRE(a.balls[i].pos == b.balls[i].pos);
  // Denser than a hexagonal packing allows cannot be placed.
  const auto too_many = static_cast<std::size_t>(0.95 * 400 * 300 / (std::numbers::pi * r * r));
  const tw::WorldFileError e = error_of(world(R"(, "arena": {"width": 400, "height": 300, "boundary": "walls"},
      "gas": [{"count": )" + std::to_string(too_many) + R"(, "radius": 2, "speed": 5}])"));
  CHECK(e.json_path == "/gas/0");
  CHECK(contains(e.reason, "could only place"));
}

TEST_CASE("moving walls: keyframes parse, and bad ones name their path") {
  const sim::WorldDef def = tw::parse_world(
      world(R"(, "walls": [{"id": "p", "from": [10, 0], "to": [10, 5], "keys": [{"t": 2, "from": [20, 0], "to": [20, 5]}, {"t": 3, "from": [20, 1], "to": [20, 6]}]}])"),
      "w.json");
  REQUIRE(def.walls[0].keys.size() == 2);
  CHECK(def.walls[0].keys[1].t == 3);
  CHECK(def.walls[0].keys[1].from.y == 1);
  CHECK_ERROR(world(R"(, "walls": [{"id": "p", "from": [10, 0], "to": [10, 5], "keys": [{"t": 2, "from": [20, 0], "to": [20, 5]}, {"t": 2, "from": [20, 1], "to": [20, 6]}]}])"),
              "/walls/0/keys/1/t", "keyframe times must increase");
  // Turning and stretching load; a wall whose ends would pass through each other does not.
  CHECK(tw::parse_world(world(R"(, "walls": [{"id": "p", "from": [10, 0], "to": [10, 5], "keys": [{"t": 2, "from": [20, 0], "to": [25, 5]}]}])"), "w.json")
            .walls[0].keys[0].to.x == 25);
  CHECK_ERROR(world(R"(, "walls": [{"id": "p", "from": [10, 0], "to": [10, 5], "keys": [{"t": 2, "from": [10, 5], "to": [10, 0]}]}])"),
              "/walls/0/keys", "keyframe 0: on the way to this pose the wall would shrink to a point");
  CHECK_ERROR(world(R"(, "walls": [{"id": "p", "from": [10, 0], "to": [10, 5], "keys": [{"t": 2, "from": [20, 0], "to": [20, 5]}, {"t": 3, "from": [20, 0], "to": [20, 0]}]}])"),
              "/walls/0/keys", "keyframe 1: the wall has zero length");
  CHECK_ERROR(world(R"(, "walls": [{"id": "p", "from": [10, 0], "to": [10, 5], "keys": [{"t": 2, "from": [20, 0], "to": [20, 5], "angle": 3}]}])"),
              "/walls/0/keys/0/angle", "unknown key");
}

TEST_CASE("walls that come and go: visibility keys parse, and bad ones name their path") {
  const sim::WorldDef def = tw::parse_world(
      world(R"(, "walls": [{"id": "g", "from": [10, 0], "to": [10, 5], "visible": [{"t": 0, "visible": false}, {"t": 4, "visible": true}]}])"),
      "w.json");
  REQUIRE(def.walls[0].visibility.size() == 2);
  CHECK_FALSE(def.walls[0].visibility[0].visible);
  CHECK(def.walls[0].visibility[1].t == 4);
  CHECK_ERROR(world(R"(, "walls": [{"id": "g", "from": [10, 0], "to": [10, 5], "visible": [{"t": 3, "visible": false}, {"t": 2, "visible": true}]}])"),
              "/walls/0/visible/1/t", "visibility times must increase");
  CHECK_ERROR(world(R"(, "walls": [{"id": "g", "from": [10, 0], "to": [10, 5], "visible": [{"t": 3, "visible": 1}]}])"),
              "/walls/0/visible/0/visible", "expected");
}

namespace {

/// The 2-D Maxwell-Boltzmann speed law's distribution function at kT for mass m (Rayleigh).
double rayleigh_cdf(double v, double kT, double m) { return 1.0 - std::exp(-m * v * v / (2.0 * kT)); }

}  // namespace

TEST_CASE("a thermal gas: Maxwell-Boltzmann velocities, zero momentum, exactly the asked kT, seeded") {
  const std::string spec = R"({"count": 4000, "radius": 0.5, "mass": 2, "temperature": 3, "seed": 11})";
  const sim::WorldDef def = gas_world(spec);
  REQUIRE(def.balls.size() == 4000);
  const double n = 4000.0, m = 2.0, kT = 3.0;
  sim::Vec2 p{};
  double twice_ke = 0.0, x2 = 0.0, x4 = 0.0, xy = 0.0;
  std::vector<double> speeds;
  for (const sim::BallDef& b : def.balls) {
    p += m * b.vel;
    twice_ke += m * sim::norm2(b.vel);
    x2 += b.vel.x * b.vel.x, x4 += b.vel.x * b.vel.x * b.vel.x * b.vel.x, xy += b.vel.x * b.vel.y;
    speeds.push_back(sim::norm(b.vel));
  }
  // Zero momentum to round-off (the rms momentum of one ball is sqrt(2 m kT) = 3.5), kT exactly.
  CHECK(std::abs(p.x) < 1e-9);
  CHECK(std::abs(p.y) < 1e-9);
  CHECK(twice_ke / (2.0 * (n - 1.0)) == Approx(kT).epsilon(1e-13));
  // Moments of one component: <vx^2> = kT/m (to 1/N: the fixed energy), kurtosis 3 for a Gaussian
  // (standard error sqrt(24/N) = 0.08; a fixed speed in random directions has 1.5), no x-y correlation.
  const double var = x2 / n;
  CHECK(var == Approx(kT / m).epsilon(0.04));
  CHECK(x4 / n / (var * var) == Approx(3.0).margin(4.0 * std::sqrt(24.0 / n)));
  CHECK(std::abs(xy / n) < 4.0 * var / std::sqrt(n));
  // Kolmogorov-Smirnov against Rayleigh at kT: D < 1.949/sqrt(N) (significance 1e-3); the same
  // speeds against the law at 1.2 kT fail it.
  std::sort(speeds.begin(), speeds.end());
  auto ks = [&](double t) {
    double d = 0.0;
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      const double f = rayleigh_cdf(speeds[i], t, m);
      d = std::max({d, std::abs(f - static_cast<double>(i) / n), std::abs(static_cast<double>(i + 1) / n - f)});
    }
    return d;
  };
  INFO("KS distance " << ks(kT) << ", at 1.2 kT " << ks(1.2 * kT));
  CHECK(ks(kT) < 1.949 / std::sqrt(n));
  CHECK(ks(1.2 * kT) > 1.949 / std::sqrt(n));
  // Seeded: the same seed gives the same velocities, another seed others; the positions are those of
  // the gas at a fixed speed.
  const sim::WorldDef again = gas_world(spec);
  CHECK(again.balls[17].vel == def.balls[17].vel);
  const sim::WorldDef other = gas_world(R"({"count": 4000, "radius": 0.5, "mass": 2, "temperature": 3, "seed": 12})");
  CHECK(other.balls[17].vel != def.balls[17].vel);
  const sim::WorldDef fixed = gas_world(R"({"count": 4000, "radius": 0.5, "mass": 2, "speed": 1, "seed": 11})");
  CHECK(fixed.balls[17].pos == def.balls[17].pos);
}

TEST_CASE("a thermal gas's keys are checked") {
  CHECK_ERROR(world(R"(, "gas": [{"count": 3, "radius": 1, "speed": 1, "temperature": 1}])"), "/gas/0/temperature",
              "not both");
  CHECK_ERROR(world(R"(, "gas": [{"count": 3, "radius": 1}])"), "/gas/0", "\"speed\"");
  CHECK_ERROR(world(R"(, "gas": [{"count": 3, "radius": 1, "temperature": 0}])"), "/gas/0/temperature", "temperature");
  CHECK_ERROR(world(R"(, "gas": [{"count": 1, "radius": 1, "temperature": 1}])"), "/gas/0/temperature", "at least 2");
}
