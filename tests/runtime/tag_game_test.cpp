// SPDX-License-Identifier: MIT
// The tag referee: passing "it" on turtle-turtle contacts, no-tag-back, messages to programs,
// time as "it".
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "turtlegas/turtle/tag_game.hpp"
#include "fixtures.hpp"
#include "turtlegas/turtle/turtle.hpp"
#include "turtlegas/turtle/world_server.hpp"

using namespace turtlegas;
using namespace turtlegas::turtle;
using turtlegas::test::arena;
using turtlegas::test::body;

namespace {

TurtleProgram script(const std::string& commands) {
  TurtleProgram p;
  p.controller = "script";
  p.params = nlohmann::json::parse(R"({"commands": )" + commands + "}");
  return p;
}

std::vector<LogEvent> of_kind(const std::vector<LogEvent>& log, const std::string& kind) {
  std::vector<LogEvent> out;
  for (const LogEvent& e : log)
    if (e.kind == kind) out.push_back(e);
  return out;
}

const TagGame& tag_of(const WorldServer& s) { return dynamic_cast<const TagGame&>(*s.game()); }

}  // namespace

TEST_CASE("it passes on a turtle-turtle contact, not on a wall contact", "[runtime][tag]") {
  sim::WorldDef d = arena();
  // t1 drives 80 units into t2 (centres 100 apart, radii 10), at 50 units/s: contact at 1.6 s.
  d.turtles.push_back(body("t1", {100, 200}, 90));
  d.turtles.push_back(body("t2", {200, 200}, 90));
  // t3 drives into the right arena wall and never meets anyone.
  d.turtles.push_back(body("t3", {350, 50}, 90));
  WorldServer s(d, {script(R"([["forward", 200]])"), script(R"([["wait", 100]])"), script(R"([["forward", 200]])")},
                base_registry());
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.set_game(std::make_unique<TagGame>(TagRules{"t1", 2.0}));
  CHECK(tag_of(s).tally(0.0).it == "t1");
  s.run_until(1.5);
  CHECK(of_kind(log, "tag").empty());
  s.run_until(5.0);
  CHECK(!of_kind(log, "turtle-wall").empty());  // t3 did touch a wall
  const auto tags = of_kind(log, "tag");
  REQUIRE(tags.size() == 1);
  CHECK(tags[0].a == "t1");
  CHECK(tags[0].b == "t2");
  const auto contact = of_kind(log, "turtle-turtle");
  REQUIRE(!contact.empty());
  // The referee rules at the first boundary after the contact.
  CHECK(tags[0].t >= contact[0].t);
  CHECK(tags[0].t - contact[0].t <= d.dt + 1e-9);
  const TagScore score = tag_of(s).tally(s.time());
  CHECK(score.it == "t2");
  CHECK(score.tags == std::vector<std::size_t>{1, 0, 0});
  CHECK(score.tagged == std::vector<std::size_t>{0, 1, 0});
  CHECK(score.time_it[0] == Approx(tags[0].t));
  CHECK(score.time_it[1] == Approx(5.0 - tags[0].t));
  CHECK(score.time_it[2] == 0.0);
}

TEST_CASE("the last tagger cannot be tagged back within no_tag_back", "[runtime][tag]") {
  // t1 tags t2 at about 1.6 s; t2's wait is cut short by the contact, it backs off 10 and drives
  // straight back into t1 (about 0.4 s later).
  auto play = [](double no_tag_back) {
    sim::WorldDef d = arena();
    d.turtles.push_back(body("t1", {100, 200}, 90));
    d.turtles.push_back(body("t2", {200, 200}, 270));
    auto s = std::make_unique<WorldServer>(
        d, std::vector<TurtleProgram>{script(R"([["forward", 200]])"),
                                      script(R"([["wait", 100], ["back", 10], ["forward", 50]])")},
        base_registry());
    auto log = std::make_unique<std::vector<LogEvent>>();
    s->set_event_log(log.get());
    s->set_game(std::make_unique<TagGame>(TagRules{"t1", no_tag_back}));
    s->run_until(5.0);
    s->set_event_log(nullptr);
    return std::pair{of_kind(*log, "tag"), tag_of(*s).tally(5.0)};
  };
  SECTION("within the interval: no tag back") {
    const auto [tags, score] = play(2.0);
    REQUIRE(tags.size() == 1);
    CHECK(tags[0].a == "t1");
    CHECK(score.it == "t2");
  }
  SECTION("after the interval: tagged back") {
    const auto [tags, score] = play(0.1);
    REQUIRE(tags.size() == 2);
    CHECK(tags[1].a == "t2");
    CHECK(tags[1].b == "t1");
    CHECK(tags[1].t - tags[0].t > 0.1);
    CHECK(tags[1].t - tags[0].t < 2.0);
    CHECK(score.it == "t1");
  }
}

TEST_CASE("a tag message reaches the program at the next step, before it resumes", "[runtime][tag]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 200}, 90));
  d.turtles.push_back(body("t2", {200, 200}, 90));
  std::vector<std::string> seen;  // what t2's program saw, in order
  double touch_at = -1, message_at = -1, resumed_at = -1, message_t = -1;
  bool it_in_handler = false, it_on_resume = false, it_before = true;
  Registry r = base_registry();
  r.add("listener", [&](Turtle& t, const Params&) {
    it_before = t.it();
    t.on_touch([&](const Touch& touch) {
      seen.push_back("touch " + touch.what);
      touch_at = t.time();
    });
    t.on_message([&](const Message& m) {
      seen.push_back(m.kind() + " it=" + (m.data.at("it").get<bool>() ? "true" : "false") + " by=" +
                     m.data.at("by").get<std::string>());
      message_at = t.time();
      message_t = m.t;
      it_in_handler = t.it();
    });
    t.wait(100);
    seen.push_back("resumed");
    resumed_at = t.time();
    it_on_resume = t.it();
    t.wait(100);
  });
  std::vector<TurtleProgram> programs{script(R"([["forward", 200]])"), TurtleProgram{}};
  programs[1].controller = "listener";
  WorldServer s(d, programs, r);
  s.set_game(std::make_unique<TagGame>(TagRules{"t1", 2.0}));
  s.run_until(3.0);
  CHECK(!it_before);
  REQUIRE(seen == std::vector<std::string>{"touch t1", "tag it=true by=t1", "resumed"});
  CHECK(touch_at == message_at);
  CHECK(message_at == resumed_at);
  CHECK(message_t == message_at);
  CHECK(it_in_handler);
  CHECK(it_on_resume);
  // The boundary right after the 1.6 s contact.
  CHECK(std::abs(std::round(resumed_at / d.dt) * d.dt - resumed_at) < 1e-12);
  CHECK(resumed_at > 1.5);
  CHECK(resumed_at < 1.75);
}

TEST_CASE("time as it adds up to the run's length", "[runtime][tag]") {
  sim::WorldDef d = arena();
  d.seed = 3;
  Registry r = base_registry();
  r.add("bumper", [](Turtle& t, const Params&) {
    for (;;) {
      if (t.forward(300 * t.uniform()).touched()) t.back(3);
      t.right(360 * t.uniform() - 180);
    }
  });
  std::vector<TurtleProgram> programs;
  const sim::Vec2 at[] = {{100, 100}, {300, 100}, {200, 200}, {100, 300}, {300, 300}};
  for (int i = 0; i < 5; ++i) {
    d.turtles.push_back(body("t" + std::to_string(i + 1), at[i], 72.0 * i));
    programs.push_back(TurtleProgram{});
    programs.back().controller = "bumper";
  }
  WorldServer s(d, programs, r);
  std::vector<LogEvent> log;
  s.set_event_log(&log);
  s.set_game(std::make_unique<TagGame>(TagRules{"t3", 0.5}));
  s.run_until(60.05);  // not on a boundary
  const TagScore score = tag_of(s).tally(s.time());
  double total = 0;
  std::size_t tags = 0, tagged = 0;
  for (std::size_t i = 0; i < 5; ++i) total += score.time_it[i], tags += score.tags[i], tagged += score.tagged[i];
  CHECK(total == Approx(60.05).epsilon(1e-12));
  CHECK(tags == of_kind(log, "tag").size());
  CHECK(tagged == tags);
  CHECK(tags > 0);  // five bumpers in a small room do meet
  const nlohmann::json j = s.game()->score(s.time());
  CHECK(j.at("kind") == "tag");
  CHECK(j.at("turtles").size() == 5);
}

TEST_CASE("a tag game must name a turtle as it", "[runtime][tag]") {
  sim::WorldDef d = arena();
  d.turtles.push_back(body("t1", {100, 200}, 90));
  d.turtles.push_back(body("t2", {200, 200}, 90));
  WorldServer s(d, {script("[]"), script("[]")}, base_registry());
  CHECK_THROWS_WITH(s.set_game(std::make_unique<TagGame>(TagRules{"t9", 2.0})), Catch::Contains("'t9'"));
}

TEST_CASE("a player reads the game's rules, its radius, speed and turn rate, and dt", "[runtime][tag]") {
  sim::WorldDef d = arena();
  d.dt = 0.05;
  d.turtles.push_back(body("t1", {100, 200}, 90));
  d.turtles.push_back(body("t2", {300, 200}, 90));
  d.turtles[1].radius = 7.5;
  d.turtles[1].speed = 42.0;
  d.turtles[1].turn_rate = M_PI;  // 180 degrees/s
  nlohmann::json seen;
  Registry r = base_registry();
  r.add("reader", [&seen](Turtle& t, const Params&) {
    seen = {{"rules", t.game_rules()}, {"radius", t.radius()}, {"speed", t.speed()}, {"turn_rate", t.turn_rate()},
            {"dt", t.dt()}};
    // The same through a mirror: none of these is reflected.
    const Turtle m = t.mirrored();
    seen["mirror_same"] = m.radius() == t.radius() && m.speed() == t.speed() && m.dt() == t.dt() &&
                          m.game_rules() == t.game_rules();
    t.wait(100);
  });
  TurtleProgram reader;
  reader.controller = "reader";
  SECTION("in a tag game") {
    WorldServer s(d, {script(R"([["wait", 100]])"), reader}, r);
    s.set_game(std::make_unique<TagGame>(TagRules{"t1", 3.25}));
    s.run_until(0.2);
    CHECK(seen.at("rules") == nlohmann::json{{"kind", "tag"}, {"no_tag_back", 3.25}});
    CHECK(seen.at("radius") == 7.5);
    CHECK(seen.at("speed") == 42.0);
    CHECK(seen.at("turn_rate").get<double>() == Approx(180.0).epsilon(1e-15));
    CHECK(seen.at("dt") == 0.05);
    CHECK(seen.at("mirror_same") == true);
  }
  SECTION("without a game") {
    WorldServer s(d, {script(R"([["wait", 100]])"), reader}, r);
    s.run_until(0.2);
    CHECK(seen.at("rules") == nlohmann::json::object());
  }
}
