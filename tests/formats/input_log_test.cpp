// SPDX-License-Identifier: MIT
// The input log's lines (formats/input_log.hpp), pinned byte for byte: the text serve writes with
// --inputs-out and run --inputs reads back. Every line is `{"step": N, ...}` and a newline.
#include <catch2/catch.hpp>

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/turtle/remote.hpp"

using namespace turtlegas;

TEST_CASE("input log: the header and every kind of line, byte for byte") {
  CHECK(formats::input_header_line("demo \"x\"", 0.05) ==
        "{\"format\": \"" + std::string(formats::input_log_format) + "\", \"world\": \"demo \\\"x\\\"\", \"dt\": 0.05}\n");

  turtle::RemoteCommand fwd;
  fwd.kind = turtle::RemoteCommand::Kind::forward;
  fwd.amount = 12.5;
  CHECK(formats::input_command_line(7, "t1", fwd) == "{\"step\": 7, \"turtle\": \"t1\", \"command\": \"forward\", \"amount\": 12.5}\n");
  turtle::RemoteCommand pen;
  pen.kind = turtle::RemoteCommand::Kind::pen_down;
  pen.pen = turtle::PenMode::wall;
  CHECK(formats::input_command_line(0, "t2", pen) == "{\"step\": 0, \"turtle\": \"t2\", \"command\": \"pen_down\", \"mode\": \"wall\"}\n");
  turtle::RemoteCommand arc;
  arc.kind = turtle::RemoteCommand::Kind::arc;
  arc.steer = {50, -90, 0};
  CHECK(formats::input_command_line(4, "t1", arc) ==
        "{\"step\": 4, \"turtle\": \"t1\", \"command\": \"arc\", \"radius\": 50, \"degrees\": -90}\n");
  turtle::RemoteCommand wheels;
  wheels.kind = turtle::RemoteCommand::Kind::wheels;
  wheels.steer = {20, -10.5, 2};
  CHECK(formats::input_command_line(5, "t1", wheels) ==
        "{\"step\": 5, \"turtle\": \"t1\", \"command\": \"wheels\", \"left\": 20, \"right\": -10.5, \"seconds\": 2}\n");
  turtle::RemoteCommand drive;
  drive.kind = turtle::RemoteCommand::Kind::drive;
  drive.steer = {-20, 45, 0.5};
  CHECK(formats::input_command_line(6, "t1", drive) ==
        "{\"step\": 6, \"turtle\": \"t1\", \"command\": \"drive\", \"v\": -20, \"omega\": 45, \"seconds\": 0.5}\n");
  turtle::RemoteCommand camera;
  camera.kind = turtle::RemoteCommand::Kind::camera;
  camera.sensor = "eye";
  CHECK(formats::input_command_line(8, "t1", camera) ==
        "{\"step\": 8, \"turtle\": \"t1\", \"command\": \"camera\", \"sensor\": \"eye\"}\n");
  turtle::RemoteCommand yield;
  CHECK(formats::input_command_line(3, "t3", yield) == "{\"step\": 3, \"turtle\": \"t3\", \"command\": \"yield\"}\n");

  CHECK(formats::input_takeover_line(42, "t1") == "{\"step\": 42, \"takeover\": \"t1\"}\n");

  sim::WallDef wall;
  wall.id = "w9";
  wall.from = {1, 2.5};
  wall.to = {-3, 4};
  CHECK(formats::input_wall_line(5, wall) ==
        "{\"step\": 5, \"add_wall\": {\"id\": \"w9\", \"from\": [1, 2.5], \"to\": [-3, 4]}}\n");
  // Made while the world waited at a boundary for a turtle's command (issue 32 section 1).
  CHECK(formats::input_while_waiting(formats::input_wall_line(5, wall), "t1", 0) ==
        "{\"step\": 5, \"add_wall\": {\"id\": \"w9\", \"from\": [1, 2.5], \"to\": [-3, 4]}, \"waiting\": \"t1\"}\n");
  CHECK(formats::input_while_waiting(formats::input_remove_line(6, "b1"), "t\"2", 3) ==
        "{\"step\": 6, \"remove\": \"b1\", \"waiting\": \"t\\\"2\", \"taken\": 3}\n");

  const nlohmann::json ball = {{"id", "b1"}, {"pos", {1.5, 2}}};
  CHECK(formats::input_spawn_line(9, "ball", ball) ==
        "{\"step\": 9, \"spawn\": {\"ball\": {\"id\":\"b1\",\"pos\":[1.5,2]}}}\n");

  const nlohmann::json view = {{"id", "v"}};
  CHECK(formats::input_view_line(11, "open", view) == "{\"step\": 11, \"view\": {\"op\": \"open\", \"view\": {\"id\":\"v\"}}}\n");

  CHECK(formats::input_remove_line(12, "b1") == "{\"step\": 12, \"remove\": \"b1\"}\n");

  CHECK(formats::input_teleport_line(13, "t1", {1, 2}, std::nullopt, std::nullopt) ==
        "{\"step\": 13, \"teleport\": {\"id\": \"t1\", \"pos\": [1, 2]}}\n");
  CHECK(formats::input_teleport_line(14, "b1", {1, 2}, sim::Vec2{0.5, -1}, 90.0) ==
        "{\"step\": 14, \"teleport\": {\"id\": \"b1\", \"pos\": [1, 2], \"vel\": [0.5, -1], \"heading\": 90}}\n");
}

TEST_CASE("input log: every line reads back as JSON with its step") {
  const std::string line = formats::input_remove_line(12, "a \"quoted\" id");
  const nlohmann::json j = nlohmann::json::parse(line);
  CHECK(j.at("step") == 12);
  CHECK(j.at("remove") == "a \"quoted\" id");
}
