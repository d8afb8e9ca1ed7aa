// SPDX-License-Identifier: MIT
// Views (turtle/view.hpp): the world file's `views` key and its errors, the view geometry, the
// Display handle of a program, `view` events in the log, and physics unchanged by views.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "file_errors.hpp"
#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/formats/event_log.hpp"
#include "turtlegas/turtle/view.hpp"
#include "turtlegas/world/scene.hpp"
#include "turtlegas/world/world_file.hpp"

namespace tw = turtlegas::world;
namespace tt = turtlegas::turtle;
namespace sim = turtlegas::sim;
using json = nlohmann::json;

namespace {

const std::string head = R"("format": "turtlegas-world/1", "arena": {"width": 500, "height": 400, "boundary": "walls"},
  "turtles": [{"id": "t1", "pos": [250, 200], "heading": 0, "controller": "wander"}])";

std::string world(const std::string& body) { return "{" + head + body + "}"; }

const tt::Registry& registry() {
  static const tt::Registry r = turtlegas::controllers::builtin_registry();
  return r;
}

tw::WorldFileError error_of(const std::string& text) {
  return turtlegas::test::error_of([](const std::string& t) { return tw::parse_scene(t, "w.json", registry()); }, text);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The event log of `text` run to `until`, as `turtlegas run --events` writes it.
std::vector<std::string> run_log(const std::string& text, double until) {
  const tw::Scene scene = tw::parse_scene(text, "w.json", registry());
  auto server = tw::make_server(scene, registry(), {});
  std::vector<tt::LogEvent> events;
  server->set_event_log(&events);
  server->run_until(until);
  std::vector<std::string> lines;
  for (const tt::LogEvent& e : events) {
    std::string line;
    turtlegas::formats::append_event(line, turtlegas::formats::event_line(e));
    lines.push_back(line);
  }
  return lines;
}

constexpr double eps = 1e-12;

}  // namespace

TEST_CASE("views in a world file are read with every field") {
  const tw::Scene s = tw::parse_scene(world(R"(, "views": [
      {"id": "all", "center": [250, 200], "size": [500, 400], "title": "room"},
      {"id": "chase", "follow": "t1", "offset": [0, 30], "size": [100, 80], "rotate": true, "layers": ["walls", "turtles"]},
      {"id": "plain", "follow": "t1", "layers": "all", "x-note": "private keys are kept out"}])"),
                                      "w.json", registry());
  REQUIRE(s.views.size() == 3);
  CHECK(s.views[0].id == "all");
  CHECK_FALSE(s.views[0].follow);
  CHECK(s.views[0].center == sim::Vec2{250, 200});
  CHECK(s.views[0].size == sim::Vec2{500, 400});
  CHECK(s.views[0].title == "room");
  CHECK(s.views[0].layers == tt::kLayersAll);
  CHECK(s.views[1].follow == std::optional<std::string>("t1"));
  CHECK(s.views[1].offset == sim::Vec2{0, 30});
  CHECK(s.views[1].rotate);
  CHECK(s.views[1].layers == (tt::kLayerWalls | tt::kLayerTurtles));
  CHECK(s.views[2].size == sim::Vec2{200, 200});  // the default
  // The JSON form reads back to the same view.
  for (const tt::View& v : s.views) {
    CHECK(tt::parse_view(tt::view_to_json(v)) == v);
    CHECK(tt::parse_view(json::parse(tt::view_json_text(v))) == v);
  }
  CHECK(tt::view_json_text(s.views[1]) ==
        R"({"id": "chase", "follow": "t1", "offset": [0, 30], "size": [100, 80], "rotate": true, "layers": ["walls", "turtles"], "title": ""})");
}

TEST_CASE("bad views are errors at their JSON path") {
  CHECK_ERROR(world(R"(, "views": {})"), "/views", "views must be a JSON array");
  CHECK_ERROR(world(R"(, "views": [3])"), "/views/0", "a view must be a JSON object");
  CHECK_ERROR(world(R"(, "views": [{"center": [1, 2]}])"), "/views/0", "a view needs an \"id\"");
  CHECK_ERROR(world(R"(, "views": [{"id": ""}])"), "/views/0/id", "non-empty string");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "zoom": 2}])"), "/views/0/zoom", "unknown key \"zoom\" in a view");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "follow": "t9"}])"), "/views/0/follow", "follow names no turtle: \"t9\" (the world's turtles: t1)");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "follow": 3}])"), "/views/0/follow", "a turtle's id or null");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "follow": "t1", "center": [1, 2]}])"), "/views/0/center", "center is for fixed views");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "offset": [1, 2]}])"), "/views/0/offset", "offset is for views that follow");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "size": [100]}])"), "/views/0/size", "got an array of 1");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "size": [100, 0]}])"), "/views/0/size/1", "numbers > 0");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "center": "middle"}])"), "/views/0/center", "two numbers, got a string");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "rotate": true}])"), "/views/0/rotate", "a fixed view cannot rotate");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "rotate": "yes"}])"), "/views/0/rotate", "true or false");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "layers": ["walls", "ghosts"]}])"), "/views/0/layers/1", "unknown layer \"ghosts\"");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "layers": 7}])"), "/views/0/layers", "\"all\" or a list of names");
  CHECK_ERROR(world(R"(, "views": [{"id": "v", "title": 7}])"), "/views/0/title", "title must be a string");
  CHECK_ERROR(world(R"(, "views": [{"id": "v"}, {"id": "v"}])"), "/views/1/id", "duplicate view id \"v\" (already used at /views/0/id)");
}

TEST_CASE("a change to a view keeps what it does not name") {
  tt::View base = tt::parse_view(json::parse(R"({"id": "v", "follow": "t1", "offset": [1, 2], "rotate": true})"));
  tt::View v = tt::parse_view(json::parse(R"({"size": [50, 60]})"), &base);
  CHECK(v.id == "v");
  CHECK(v.follow == std::optional<std::string>("t1"));
  CHECK(v.offset == sim::Vec2{1, 2});
  CHECK(v.size == sim::Vec2{50, 60});
  CHECK(v.rotate);
  // Made fixed: rotate goes, center applies.
  v = tt::parse_view(json::parse(R"({"follow": null, "center": [7, 8]})"), &base);
  CHECK_FALSE(v.follow);
  CHECK_FALSE(v.rotate);
  CHECK(v.center == sim::Vec2{7, 8});
  CHECK_THROWS_AS(tt::parse_view(json::parse(R"({"id": "w"})"), &base), tt::ViewError);
}

TEST_CASE("view geometry: fixed, follow, follow with rotate") {
  SECTION("fixed: world axes around the centre") {
    tt::View v;
    v.center = {100, 50};
    v.size = {200, 100};
    const tt::ViewTransform t = tt::view_transform(v, tt::FollowPose{{999, 999}, 1.0});  // ignored
    CHECK(t.to_view({100, 50}).x == 0.0);
    CHECK(t.to_view({150, 60}) == sim::Vec2{50, 10});
    // Pixels: the centre in the middle, y down, the corners at the edges.
    const sim::Vec2 mid = t.to_pixels({100, 50}, 400, 200), top_left = t.to_pixels({0, 100}, 400, 200);
    CHECK(mid == sim::Vec2{200, 100});
    CHECK(top_left == sim::Vec2{0, 0});
    CHECK(t.to_pixels({200, 0}, 400, 200) == sim::Vec2{400, 200});
    CHECK(t.shows({0, 0}, 0.0));
    CHECK_FALSE(t.shows({-1, 0}, 0.5));
    CHECK(t.shows({-1, 0}, 1.0));
  }
  SECTION("follow: centred on the turtle plus the offset, unturned") {
    tt::View v;
    v.follow = "t1";
    v.offset = {10, 0};
    v.size = {100, 100};
    const tt::ViewTransform t = tt::view_transform(v, tt::FollowPose{{300, 200}, M_PI / 2});
    CHECK(t.center == sim::Vec2{310, 200});
    CHECK(t.to_view({300, 200}) == sim::Vec2{-10, 0});
    CHECK(t.heading_on_view(M_PI / 2) == M_PI / 2);  // east stays east
  }
  SECTION("follow with rotate: the heading points up, the offset is in the turtle's frame") {
    tt::View v;
    v.follow = "t1";
    v.rotate = true;
    v.offset = {0, 40};  // 40 ahead
    v.size = {100, 100};
    // Heading 90 degrees (east): ahead is +x, the turtle's right is -y.
    const tt::ViewTransform t = tt::view_transform(v, tt::FollowPose{{300, 200}, M_PI / 2});
    CHECK(std::abs(t.center.x - 340) < eps);
    CHECK(std::abs(t.center.y - 200) < eps);
    const sim::Vec2 turtle = t.to_view({300, 200});  // 40 below the centre
    CHECK(std::abs(turtle.x) < eps);
    CHECK(std::abs(turtle.y + 40) < eps);
    const sim::Vec2 south = t.to_view({340, 150});  // south of the centre: on the turtle's right
    CHECK(std::abs(south.x - 50) < eps);
    CHECK(std::abs(south.y) < eps);
    CHECK(std::abs(t.heading_on_view(M_PI / 2)) < eps);  // its own heading is up
    // to_world undoes to_view.
    for (sim::Vec2 p : {sim::Vec2{1, 2}, sim::Vec2{-300, 77}, sim::Vec2{340, 200}}) {
      const sim::Vec2 q = t.to_world(t.to_view(p));
      CHECK(std::abs(q.x - p.x) < 1e-9);
      CHECK(std::abs(q.y - p.y) < 1e-9);
    }
  }
  SECTION("a follow view without its turtle shows its centre") {
    tt::View v;
    v.follow = "gone";
    v.center = {5, 6};
    v.rotate = true;
    CHECK(tt::view_transform(v, std::nullopt).center == sim::Vec2{5, 6});
  }
}

TEST_CASE("a program's views are logged and the physics are those of the same run without them") {
  const std::string with = read_file(std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tag_views.json");
  // The same world without its views, its cameras off.
  json doc = json::parse(with);
  doc.erase("views");
  for (json& t : doc["turtles"])
    if (t["controller"] == "tag_camera") t["params"]["camera"] = false;
  const std::vector<std::string> a = run_log(with, 30.0), b = run_log(doc.dump(), 30.0);
  std::vector<std::string> physics, views;
  for (const std::string& line : a) (line.find("\"kind\": \"view\"") != std::string::npos ? views : physics).push_back(line);
  CHECK(physics == b);
  REQUIRE(physics.size() > 20);
  // t1 starts as it: it opens its view at t = 0, and closes it when it has tagged someone.
  REQUIRE(views.size() >= 2);
  const json first = json::parse(views[0]);
  CHECK(first["t"] == 0.0);
  CHECK(first["a"] == "t1-it");
  CHECK(first["op"] == "open");
  CHECK(first["by"] == "t1");
  CHECK(first["view"]["follow"] == "t1");
  const json second = json::parse(views[1]);
  CHECK(second["a"] == "t1-it");
  CHECK(second["op"] == "close");
  // The close comes at the boundary after the tag that made someone else it.
  double tag_t = -1;
  for (const std::string& line : physics)
    if (line.find("\"kind\": \"tag\"") != std::string::npos) {
      tag_t = json::parse(line)["t"].get<double>();
      break;
    }
  REQUIRE(tag_t > 0.0);
  CHECK(second["t"].get<double>() >= tag_t);
  CHECK(second["t"].get<double>() <= tag_t + 1.0 + 1e-9);
}

TEST_CASE("the Display handle refuses what the world server refuses") {
  tt::Registry r = turtlegas::controllers::builtin_registry();
  std::vector<std::string> errors;
  std::vector<std::size_t> counts;
  r.add("viewer_probe", [&](tt::Turtle& t, const tt::Params&) {
    tt::Display d = t.display();
    tt::View v;
    v.id = "mine";
    v.follow = t.id();
    d.open(v);
    counts.push_back(d.views().size());
    try { d.open(v); } catch (const std::invalid_argument& e) { errors.push_back(e.what()); }
    tt::View bad = v;
    bad.id = "other";
    bad.follow = "nobody";
    try { d.open(bad); } catch (const std::invalid_argument& e) { errors.push_back(e.what()); }
    bad.follow.reset();
    try { d.change(bad); } catch (const std::invalid_argument& e) { errors.push_back(e.what()); }
    v.size = {10, 20};
    d.change(v);
    CHECK(d.find("mine")->size == sim::Vec2{10, 20});
    CHECK(d.close("mine"));
    CHECK_FALSE(d.close("mine"));
    counts.push_back(d.views().size());
    t.wait(1.0);
  }, std::string("probes the Display handle"));
  const std::string text = R"({"format": "turtlegas-world/1", "turtles": [{"id": "t1", "pos": [50, 50], "controller": "viewer_probe"}],
    "views": [{"id": "file-view", "center": [0, 0]}]})";
  const tw::Scene scene = tw::parse_scene(text, "w.json", r);
  auto server = tw::make_server(scene, r, {});
  std::vector<tt::LogEvent> events;
  server->set_event_log(&events);
  CHECK(server->views().size() == 1);
  const auto rev = server->views_revision();
  server->run_until(0.5);
  REQUIRE(errors.size() == 3);
  CHECK(turtlegas::test::contains(errors[0], "is open already"));
  CHECK(turtlegas::test::contains(errors[1], "follow names no turtle"));
  CHECK(turtlegas::test::contains(errors[2], "no view \"other\" is open"));
  CHECK(counts == std::vector<std::size_t>{2, 1});
  CHECK(server->views_revision() == rev + 3);
  std::vector<std::string> ops;
  for (const tt::LogEvent& e : events)
    if (e.kind == "view") {
      CHECK(e.t == 0.0);
      ops.push_back(e.a + ":" + json::parse("{" + e.extra + "}")["op"].get<std::string>());
    }
  CHECK(ops == std::vector<std::string>{"mine:open", "mine:change", "mine:close"});
}

TEST_CASE("tag_camera turtles sharing one view id keep it on whoever is it") {
  // worlds/tag_follow_it.json: five tag_camera turtles share the view "it". In its first 120 s t1
  // tags t4 (the tagger comes first in world order: it closes, t4 opens) and t4 tags t3 (t3 comes
  // first: it turns the view onto itself before t4 runs, and t4 leaves it alone). At the end of
  // every instant with a tag or a view change, the view must be open and follow the one who is it.
  const std::vector<std::string> log = run_log(read_file(std::string(TURTLEGAS_SOURCE_DIR) + "/worlds/tag_follow_it.json"), 120.0);
  std::string it = "t1", follow;
  bool open = false;
  int tags = 0, changes = 0, closes = 0;
  std::vector<json> group;
  const auto check_group = [&] {
    if (group.empty()) return;
    INFO("t = " << group.front()["t"].dump());
    CHECK(open);
    CHECK(follow == it);
    group.clear();
  };
  for (const std::string& line : log) {
    const json e = json::parse(line);
    const std::string kind = e["kind"];
    if (kind != "tag" && kind != "view") continue;
    if (!group.empty() && group.front()["t"] != e["t"]) check_group();
    group.push_back(e);
    if (kind == "tag") {
      it = e["b"];
      ++tags;
      continue;
    }
    REQUIRE(e["a"] == "it");
    const std::string op = e["op"];
    if (op == "open" || op == "change") {
      CHECK((op == "open") != open);
      open = true;
      follow = e["view"]["follow"];
      CHECK(e["by"] == follow);  // a turtle turns the view onto itself only
      changes += op == "change";
    } else {
      CHECK(op == "close");
      CHECK(e["by"] == follow);  // and closes only a view on itself
      open = false;
      ++closes;
    }
  }
  check_group();
  CHECK(tags >= 2);
  CHECK(changes >= 1);
  CHECK(closes >= 1);
}
