// SPDX-License-Identifier: MIT
// The protocol from C++ (client.hpp), over WebSocket and TCP lines: hello, subscribe (a snapshot,
// then frames), claim, forward into a wall: the touch interrupt comes before the result, with the
// front sensor, bearing 0, the wall's id and the contact time (200 - r) / speed; then spawn, a
// teleport and a remove of a body, each answered at a boundary.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "client.hpp"

using namespace turtlegas::test;

namespace {

void round_trip(Client& c) {
  const json welcome = c.request({{"type", "hello"}, {"protocol", "turtlegas/1"}});
  REQUIRE(welcome["type"] == "welcome");
  CHECK(welcome["protocol"] == "turtlegas/1");
  CHECK(welcome["world"]["name"] == "one remote turtle and a wall");
  const double r = welcome["world"]["turtles"][0]["radius"].get<double>();
  const json sub = c.request({{"type", "subscribe"}, {"rate", 20}, {"events", json::array({"touch"})}});
  CHECK(sub["type"] == "subscribed");
  const json snap = c.next();
  CHECK(snap["type"] == "snapshot");
  CHECK(snap["turtles"][0]["id"] == "t1");
  const json claimed = c.request({{"type", "claim"}, {"turtle", "t1"}});
  CHECK(claimed["type"] == "claimed");
  CHECK(claimed["sensors"] == json::array({"front", "right", "back", "left"}));
  c.request({{"type", "resume"}});
  // East from x = 100 into the wall at x = 300 at 50 units/s: the centre stops r short of it.
  const json res = c.request({{"type", "forward"}, {"turtle", "t1"}, {"amount", 1000}});
  REQUIRE(res["type"] == "result");
  CHECK(res["touched"] == true);
  CHECK_THAT(res["done"].get<double>(), Catch::Matchers::WithinAbs(200 - r, 1e-9));
  const json& touch = res["touch"];
  CHECK(touch["sensors"] == json::array({"front"}));
  CHECK(touch["what"] == "target");
  CHECK(touch["kind"] == "wall");
  CHECK(std::abs(std::fmod(touch["bearing"].get<double>() + 360.0, 360.0)) < 1e-9);
  CHECK_THAT(touch["t"].get<double>(), Catch::Matchers::WithinAbs((200 - r) / 50.0, 1e-9));
  // The interrupt came first, as its own message, and frames went on meanwhile.
  bool interrupt = false, frame = false;
  for (const json& m : c.kept()) {
    if (m["type"] == "touch" && m["turtle"] == "t1") interrupt = interrupt || m["touch"]["t"] == touch["t"];
    if (m["type"] == "frame") frame = true;
  }
  CHECK(interrupt);
  CHECK(frame);
  // Released, so that boundaries come without its commands (lockstep waits for claimed turtles).
  c.request({{"type", "release"}, {"turtle", "t1"}});
  // Bodies: a ball spawned clear of everything, moved, removed; one on the turtle is refused.
  const json spawned = c.request({{"type", "spawn"}, {"ball", {{"id", "b-c"}, {"pos", {50, 50}}, {"vel", {5, 0}}, {"radius", 3}}}});
  CHECK(spawned["kind"] == "ball");
  CHECK(spawned["index"] == 0);
  try {
    c.request({{"type", "spawn"}, {"ball", {{"id", "b-d"}, {"pos", {300 - r - 1, 150}}, {"radius", 3}}}});
    FAIL("an overlapping spawn is refused");
  } catch (const ServerError& e) {
    CHECK(e.reply["code"] == "refused");
    CHECK(e.reply["message"].get<std::string>().find("'t1'") != std::string::npos);
  }
  CHECK(c.request({{"type", "teleport"}, {"body", "b-c"}, {"pos", {60, 250}}})["type"] == "ok");
  CHECK(c.request({{"type", "remove"}, {"body", "b-c"}})["type"] == "ok");
}

const std::string kWorld = std::string(TURTLEGAS_SOURCE_DIR) + "/tests/server/worlds/wall_touch.json";

}  // namespace

TEST_CASE("a C++ client over WebSocket: hello, subscribe, claim, a touch with sensors and contact time", "[server]") {
  ServeProcess s(TURTLEGAS_BIN, kWorld, {"--paused", "--speed", "max"});
  auto c = Client::ws(s.http_port);
  round_trip(*c);
  CHECK(s.stop() == 0);
}

TEST_CASE("a C++ client over TCP lines: the same session", "[server]") {
  ServeProcess s(TURTLEGAS_BIN, kWorld, {"--paused", "--speed", "max"});
  auto c = Client::lines(s.line_port);
  round_trip(*c);
  CHECK(s.stop() == 0);
}
