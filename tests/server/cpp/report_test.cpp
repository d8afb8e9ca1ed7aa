// SPDX-License-Identifier: MIT
// report_text (server/src/protocol.cpp) writes a remote turtle's reports by hand for speed. Here
// it is checked against the json object the protocol describes, built and dumped by nlohmann
// (what report_text was before): the same text for ordinary numbers, the same values for any,
// and every number that is a double in the protocol reads back as a double.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "turtlegas/server/protocol.hpp"

using nlohmann::json;
using namespace turtlegas;

namespace {

// The reference: the message as a json object, dumped.
std::string reference(const turtle::RemoteReport& r, std::string_view turtle_id, const json& id) {
  using Kind = turtle::RemoteReport::Kind;
  json out;
  switch (r.kind) {
    case Kind::result:
      out["type"] = "result";
      if (!id.is_null()) out["id"] = id;
      out["turtle"] = turtle_id;
      out["command"] = turtle::to_string(r.command.kind);
      if (turtle::takes_amount(r.command.kind)) out["amount"] = r.command.amount;
      if (const auto keys = turtle::steer_keys(r.command.kind); !keys.empty()) {
        json args = json::object();
        for (std::size_t k = 0; k < keys.size(); ++k) args[std::string(keys[k])] = r.command.steer[k];
        out["args"] = std::move(args);
      }
      out["done"] = r.result.done();
      out["touched"] = r.result.touched();
      if (r.result.touched()) out["touch"] = server::touch_json(r.result.touch());
      break;
    case Kind::touch: out = {{"type", "touch"}, {"turtle", turtle_id}, {"touch", server::touch_json(r.touch)}}; break;
    case Kind::message: out = {{"type", "message"}, {"turtle", turtle_id}, {"data", r.message.data}, {"sent", r.message.t}}; break;
    case Kind::fault: out = {{"type", "fault"}, {"turtle", turtle_id}, {"message", r.fault}}; break;
  }
  out["t"] = r.t;
  out["step"] = r.step;
  if (r.kind == Kind::result) {
    json state = {{"heading", r.heading}, {"odometer", r.odometer}, {"pen", server::pen_name(r.pen_down, r.pen_mode)}, {"it", r.it}};
    if (r.position) state["pos"] = {r.position->x, r.position->y};
    out["state"] = std::move(state);
  }
  return out.dump(-1, ' ', false, json::error_handler_t::replace);
}

const std::vector<std::string> sensor_names = {"front", "right", "back", "left"};

turtle::Touch a_touch(double bearing, double t) {
  turtle::Touch touch;
  touch.sensors = 0b1001;
  touch.sensor_names = &sensor_names;
  touch.bearing = bearing;
  touch.what = "pillar \"bottom\"";
  touch.kind = "wall";
  touch.t = t;
  return touch;
}

// Every double the protocol has in a report reads back as a double (not an integer).
void doubles_stay_doubles(const json& j) {
  for (const char* key : {"amount", "done", "t", "sent"})
    if (j.contains(key)) CHECK(j[key].is_number_float());
  if (j.contains("state")) {
    CHECK(j["state"]["heading"].is_number_float());
    CHECK(j["state"]["odometer"].is_number_float());
  }
  if (j.contains("touch")) {
    CHECK(j["touch"]["bearing"].is_number_float());
    CHECK(j["touch"]["t"].is_number_float());
  }
}

}  // namespace

TEST_CASE("report_text writes what the json object wrote") {
  using Kind = turtle::RemoteReport::Kind;
  std::vector<turtle::RemoteReport> reports;
  const std::vector<double> ordinary = {0.0, 1.0, 40.0, 2.6750000000000003, 0.1, 1.0 / 3.0, 359.99999999999994, 123456.5};
  for (double v : ordinary) {
    turtle::RemoteReport r;
    r.kind = Kind::result;
    r.turtle = 0;
    r.step = 81;
    r.t = v == 0.0 ? 0.0 : 2.7;
    r.command = {turtle::RemoteCommand::Kind::forward, 12.0};
    r.result = turtle::Result(v, a_touch(v, 2.6750000000000003));
    r.heading = v;
    r.odometer = 66.0;
    r.pen_down = true;
    reports.push_back(r);
    r.result = turtle::Result(v, std::nullopt);
    for (const auto kind : {turtle::RemoteCommand::Kind::arc, turtle::RemoteCommand::Kind::drive,
                            turtle::RemoteCommand::Kind::wheels}) {
      r.command = {kind, 0.0};
      r.command.steer = {v, -v - 1.0, 2.5};
      reports.push_back(r);
    }
    r.command = {turtle::RemoteCommand::Kind::pen_down, 0.0};
    r.pen_mode = turtle::PenMode::wall;
    r.position = sim::Vec2{v, 250.0};
    r.it = true;
    reports.push_back(r);
    turtle::RemoteReport t;
    t.kind = Kind::touch;
    t.step = 30;
    t.t = 1.0;
    t.touch = a_touch(v, 1.0);
    reports.push_back(t);
  }
  turtle::RemoteReport m;
  m.kind = Kind::message;
  m.t = 3.5;
  m.message.data = {{"kind", "tag"}, {"it", true}, {"by", "t2"}};
  m.message.t = 3.5;
  reports.push_back(m);
  turtle::RemoteReport f;
  f.kind = Kind::fault;
  f.t = 4.0;
  f.fault = "turtle 't1' may not lay walls:\n\"builder\" is false";
  reports.push_back(f);
  for (const json& id : {json(nullptr), json(12), json("req-7"), json(2.5)})
    for (const turtle::RemoteReport& r : reports) {
      INFO(reference(r, "righty", id));
      const std::string text = server::report_text(r, "righty", id);
      CHECK(text == reference(r, "righty", id));
      doubles_stay_doubles(json::parse(text));
    }
}

TEST_CASE("report_text's numbers read back to the same doubles, whatever their size") {
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-30, 30);
  for (int k = 0; k < 2000; ++k) {
    const double v = std::ldexp(mantissa(rng), exponent(rng) * 2);
    const double w = std::round(v * 1e6);  // integral values of every size
    turtle::RemoteReport r;
    r.kind = turtle::RemoteReport::Kind::result;
    r.command = {turtle::RemoteCommand::Kind::forward, std::abs(w)};
    r.result = turtle::Result(std::abs(v), std::nullopt);
    r.t = std::abs(w);
    r.heading = std::abs(v);
    r.odometer = std::abs(w);
    INFO("v = " << v << ", w = " << w << " (seed 20261202)");
    const json got = json::parse(server::report_text(r, "t1", json(k)));
    const json want = json::parse(reference(r, "t1", json(k)));
    CHECK(got == want);
    CHECK(got["done"].get<double>() == std::abs(v));
    CHECK(got["amount"].get<double>() == std::abs(w));
    doubles_stay_doubles(got);
  }
}
