// SPDX-License-Identifier: MIT
// The scene checks of validate() as `turtlegas check` reports them for a world file: the file, the
// JSON path of the offending field, and the message (no mode: they are the scene's problems, not
// exact mode's). Runs the built program; TURTLEGAS_BIN comes from the compile definitions.
#include <string>

#include <catch2/catch.hpp>

#include "../cli/run_cli.hpp"

using namespace turtlegas::test;

namespace {

Result check(const TempDir& dir, const std::string& name, const std::string& world) {
  const auto file = dir.write(name, world);
  return run(dir, {"check", file.string()});
}

const char* const kPeriodic = R"("format": "turtlegas-world/1", "arena": {"width": 100, "height": 100, "boundary": "periodic"})";

}  // namespace

TEST_CASE("check: a wall reaching outside a periodic arena names /walls/i/from or /to", "[cli][validate]") {
  TempDir dir;
  const Result r = check(dir, "periodic_wall.json",
                         std::string("{") + kPeriodic +
                             R"(, "walls": [{"id": "w0", "from": [10, 10], "to": [20, 10]},
                                            {"id": "w1", "from": [10, 20], "to": [120, 20]}]})");
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("periodic_wall.json: /walls/1/to: wall 'w1' reaches outside a periodic arena "
                                    "(its end to [120, 20] is not in [0, 100] x [0, 100]); keep walls inside it"));
  CHECK_THAT(r.err, !Catch::Contains("exact mode"));
}

TEST_CASE("check: a moving wall in a periodic arena names /walls/i/keys", "[cli][validate]") {
  TempDir dir;
  const Result r = check(dir, "periodic_door.json",
                         std::string("{") + kPeriodic +
                             R"(, "walls": [{"id": "door", "from": [10, 10], "to": [20, 10],
                                             "keys": [{"t": 2, "from": [10, 30], "to": [20, 30]}]}]})");
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("periodic_door.json: /walls/0/keys: wall 'door' moves: moving walls are not "
                                    "supported in a periodic arena yet"));
}

TEST_CASE("check: visibility out of order names the key's time", "[cli][validate]") {
  // The loader checks the order itself, one level deeper than validate() can name.
  TempDir dir;
  const Result r = check(dir, "blink.json",
                         R"({"format": "turtlegas-world/1", "walls": [{"id": "gate", "from": [10, 10], "to": [20, 10],
                             "visible": [{"t": 1, "visible": false}, {"t": 0.5, "visible": true}]}]})");
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("blink.json: /walls/0/visible/1/t: visibility times must increase and be >= 0"));
}
