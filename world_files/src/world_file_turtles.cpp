// SPDX-License-Identifier: MIT
// The loader's turtles: bodies, programs, sensor arcs, and the `script` controller's commands
// checked before the run against the runtime's table (turtle/script.hpp).
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "reader.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/remote.hpp"
#include "turtlegas/turtle/script.hpp"

namespace turtlegas::world::detail {

void Reader::read_turtles(const json& v, std::vector<sim::TurtleDef>& turtles,
                          std::vector<turtle::TurtleProgram>& programs) {
  const std::string path = "/turtles";
  expect_array(v, path, "turtles");
  turtles.reserve(v.size());
  programs.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = at(path, i);
    const json& t = v[i];
    expect_object(t, p, "a turtle");
    check_keys(t, p, "a turtle",
               {"id", "pos", "heading", "radius", "speed", "turn_rate", "controller", "params", "sensors", "pen", "gps",
                "bounce", "category", "collides_with", "builder", "senses", "axle", "colour"});
    sim::TurtleDef body;
    turtle::TurtleProgram program;
    body.id = id(t, p, "a turtle");
    read_colour(t, p, body.id);
    body.pos = vec2(require(t, p, "pos", "a turtle"), at(p, "pos"));
    body.layers = layers(t, p);
    // Angles are degrees in the file and radians inside: converted here, once. The heading is
    // wrapped into [0, 360) first so that a state written back reads like the file.
    double heading = 0.0;
    if (const json* x = find(t, "heading")) heading = number(*x, at(p, "heading"));
    body.heading = sim::to_radians(sim::wrap_degrees(heading));
    body.radius = 10.0;
    if (const json* x = find(t, "radius")) body.radius = positive(*x, at(p, "radius"), "radius");
    body.speed = 30.0;
    if (const json* x = find(t, "speed")) body.speed = positive(*x, at(p, "speed"), "speed (units/s)");
    double turn_rate = 90.0;
    if (const json* x = find(t, "turn_rate")) turn_rate = positive(*x, at(p, "turn_rate"), "turn_rate (degrees/s)");
    body.turn_rate = sim::to_radians(turn_rate);
    if (const json* x = find(t, "bounce")) {
      body.bounce = number(*x, at(p, "bounce"));
      if (!(body.bounce >= 0.0 && body.bounce <= 1.0))
        fail(at(p, "bounce"), "bounce must be in [0, 1] (got " + num(body.bounce) +
                                  "); leave it out for the memo's dead stop at a contact");
    }

    if (const json* x = find(t, "controller")) {
      program.controller = string(*x, at(p, "controller"));
      // "remote" is the runtime's own program (turtle/remote.hpp), in no registry.
      if (registry_ && program.controller != turtle::remote_controller_name && !registry_->find(program.controller))
        fail(at(p, "controller"), registry_->not_registered(program.controller));
    }
    if (const json* x = find(t, "params")) {
      expect_object(*x, at(p, "params"), "params");
      program.params = *x;
    }
    if (const json* x = find(t, "senses")) program.senses = read_senses(*x, at(p, "senses"));
    if (program.controller == "script") {
      check_script(program.params, at(p, "params"), program.senses);
    } else if (const turtle::ControllerInfo* info = registry_ ? registry_->info(program.controller) : nullptr) {
      // A controller that declares its parameters (registry.hpp): a typo ("stpe") or a value out
      // of range would otherwise silently take the default or fault at run time.
      if (auto problem = turtle::check_params(program.controller, *info, program.params))
        fail(at(p, "params") + problem->pointer, problem->reason);
    }
    if (const json* x = find(t, "sensors")) program.sensors = read_sensors(*x, at(p, "sensors"));
    if (const json* x = find(t, "pen")) {
      const std::string pp = at(p, "pen");
      if (x->is_boolean()) {
        program.pen_down = x->get<bool>();
      } else if (x->is_string() && (*x == "up" || *x == "down" || *x == "wall")) {
        program.pen_down = *x != "up";
        program.pen_walls = *x == "wall";
      } else {
        fail(pp, "pen must be \"up\", \"down\", \"wall\" (down, laying walls), true (down) or false (up), got " +
                     (x->is_string() ? "\"" + x->get<std::string>() + "\"" : json_kind(*x)));
      }
    }
    // A turtle that may lay walls gets a private collision category in the world server; it must
    // be known before the run. A wall pen or a script with ["pendown", "wall"] says so itself.
    program.builder = program.pen_walls;
    if (program.controller == "script")
      if (const json* cs = find(program.params, "commands"); cs && cs->is_array())
        for (const json& c : *cs)
          if (c.is_array() && c.size() == 2 && c[0] == "pendown" && c[1] == "wall") program.builder = true;
    if (const json* x = find(t, "builder")) {
      const bool b = boolean(*x, at(p, "builder"));
      if (!b && program.builder)
        fail(at(p, "builder"), "builder is false but this turtle lays walls (its pen is \"wall\" or its script has "
                               "[\"pendown\", \"wall\"]); remove \"builder\"");
      program.builder = b;
    }
    if (const json* x = find(t, "gps")) program.gps = boolean(*x, at(p, "gps"));
    // The wheels' track for Turtle::wheels (and the script's "wheels"); left out, the runtime
    // puts the wheels at the rim of the disc (twice the radius).
    if (const json* x = find(t, "axle")) {
      program.axle = number(*x, at(p, "axle"));
      if (!(program.axle > 0.0))
        fail(at(p, "axle"), "axle (units between the wheels) must be > 0 (got " + num(program.axle) +
                                "); leave it out for twice the turtle's radius");
    }
    turtles.push_back(std::move(body));
    programs.push_back(std::move(program));
  }
}

std::vector<turtle::SensorArc> Reader::read_sensors(const json& v, const std::string& path) const {
  constexpr std::uint64_t max_sensors = 64;  // the runtime reports fired sensors as a 64-bit mask
  if (v.is_number()) {
    const std::uint64_t n = natural(v, path);
    if (n < 1 || n > max_sensors)
      fail(path, "a sensor count must be from 1 to " + std::to_string(max_sensors) + " (got " + std::to_string(n) + ")");
    return turtle::equal_sensors(static_cast<int>(n));
  }
  const std::string shape =
      "sensors must be a count (4: four equal arcs) or a list of arcs "
      "[{\"name\": \"front\", \"from\": -45, \"to\": 45}, ...], got ";
  if (!v.is_array()) fail(path, shape + json_kind(v));
  if (v.empty()) fail(path, "a turtle needs at least one sensor; leave \"sensors\" out for the default four");
  if (v.size() > max_sensors) fail(path, "at most " + std::to_string(max_sensors) + " sensors (got " + std::to_string(v.size()) + ")");
  std::vector<turtle::SensorArc> arcs;
  std::set<std::string> names;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const std::string p = at(path, k);
    const json& a = v[k];
    expect_object(a, p, "a sensor arc");
    check_keys(a, p, "a sensor arc", {"name", "from", "to"});
    turtle::SensorArc arc;
    arc.name = string(require(a, p, "name", "a sensor arc"), at(p, "name"));
    if (arc.name.empty()) fail(at(p, "name"), "a sensor's name must not be empty");
    if (!names.insert(arc.name).second) fail(at(p, "name"), "duplicate sensor name \"" + arc.name + "\"");
    arc.from = number(require(a, p, "from", "a sensor arc"), at(p, "from"));
    arc.to = number(require(a, p, "to", "a sensor arc"), at(p, "to"));
    // Degrees clockwise from the heading, [from, to): an arc through the heading has a negative from.
    if (!(arc.from < arc.to) || arc.to - arc.from > 360.0)
      fail(p, "sensor \"" + arc.name + "\" covers [" + num(arc.from) + ", " + num(arc.to) +
                  ") degrees; need from < to <= from + 360 (clockwise from the heading; an arc through the "
                  "heading is written with a negative from, e.g. -45 to 45)");
    arcs.push_back(std::move(arc));
  }
  return arcs;
}

std::vector<turtle::RangeSensor> Reader::read_senses(const json& v, const std::string& path) const {
  constexpr std::uint64_t max_rays = 100000;
  const std::string shape =
      "senses must be a list of range sensors, e.g. [{\"name\": \"front\", \"bearing\": 0, \"range\": 80}, "
      "{\"name\": \"ir\", \"ring\": 8, \"range\": 40}, {\"name\": \"lidar\", \"lidar\": {\"rays\": 360, "
      "\"fov\": 270, \"range\": 100}}, {\"name\": \"cam\", \"camera\": {\"pixels\": 64, \"fov\": 60, \"range\": 200}}], got ";
  if (!v.is_array()) fail(path, shape + json_kind(v));
  std::vector<turtle::RangeSensor> out;
  std::set<std::string> names;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const std::string p = at(path, k);
    const json& s = v[k];
    expect_object(s, p, "a range sensor");
    check_keys(s, p, "a range sensor", {"name", "bearing", "range", "ring", "lidar", "camera", "noise"});
    turtle::RangeSensor sensor;
    sensor.name = string(require(s, p, "name", "a range sensor"), at(p, "name"));
    if (sensor.name.empty()) fail(at(p, "name"), "a sensor's name must not be empty");
    if (!names.insert(sensor.name).second) fail(at(p, "name"), "duplicate sensor name \"" + sensor.name + "\"");
    if (const json* noise = find(s, "noise")) {
      const std::string np = at(p, "noise");
      expect_object(*noise, np, "a sensor's noise");
      check_keys(*noise, np, "a sensor's noise", {"sd", "dropout"});
      if (const json* x = find(*noise, "sd")) sensor.noise = non_negative(*x, at(np, "sd"));
      if (const json* x = find(*noise, "dropout")) {
        sensor.dropout = number(*x, at(np, "dropout"));
        if (!(sensor.dropout >= 0.0 && sensor.dropout <= 1.0))
          fail(at(np, "dropout"), "a dropout is a probability in [0, 1] (got " + num(sensor.dropout) + ")");
      }
    }
    const json* ring = find(s, "ring");
    const json* lidar = find(s, "lidar");
    const json* camera = find(s, "camera");
    if ((ring ? 1 : 0) + (lidar ? 1 : 0) + (camera ? 1 : 0) > 1) {
      std::string kinds;
      for (const auto& [given, kind] : {std::pair{ring, "a ring"}, {lidar, "a lidar"}, {camera, "a camera"}})
        if (given) kinds += (kinds.empty() ? "" : " and ") + std::string(kind);
      fail(p, "a range sensor is a ray (\"bearing\"), a \"ring\", a \"lidar\" or a \"camera\": not " + kinds + " at once");
    }
    double bearing = 0.0;
    if (const json* x = find(s, "bearing")) bearing = number(*x, at(p, "bearing"));
    if (camera) {
      if (find(s, "range")) fail(at(p, "range"), "a camera's range goes inside it: \"camera\": {\"pixels\": 64, \"fov\": 60, \"range\": 200}");
      const std::string cp = at(p, "camera");
      expect_object(*camera, cp, "a camera");
      check_keys(*camera, cp, "a camera", {"pixels", "fov", "range", "background"});
      const std::uint64_t n = natural(require(*camera, cp, "pixels", "a camera"), at(cp, "pixels"));
      if (n < 1 || n > max_rays)
        fail(at(cp, "pixels"), "a camera has from 1 to " + std::to_string(max_rays) + " pixels (got " + std::to_string(n) + ")");
      const double fov = positive(require(*camera, cp, "fov", "a camera"), at(cp, "fov"), "fov (degrees)");
      if (fov > 360.0) fail(at(cp, "fov"), "a camera's fov is at most 360 degrees (got " + num(fov) + ")");
      sensor.range = positive(require(*camera, cp, "range", "a camera"), at(cp, "range"), "range (units)");
      if (const json* x = find(*camera, "background")) sensor.background = colour(*x, at(cp, "background"));
      sensor.camera = true;
      // Pixel k of n looks along the centre of its own slice of the fov, left to right:
      // bearing - fov/2 + (k + 1/2) fov/n (docs/worlds.md, "Cameras"); no ray on the fov's edges.
      for (std::uint64_t k = 0; k < n; ++k)
        sensor.bearings.push_back(bearing - fov / 2.0 + (static_cast<double>(k) + 0.5) * fov / static_cast<double>(n));
    } else if (lidar) {
      if (find(s, "range")) fail(at(p, "range"), "a lidar's range goes inside it: \"lidar\": {\"rays\": 360, \"fov\": 270, \"range\": 100}");
      const std::string lp = at(p, "lidar");
      expect_object(*lidar, lp, "a lidar");
      check_keys(*lidar, lp, "a lidar", {"rays", "fov", "range"});
      const std::uint64_t n = natural(require(*lidar, lp, "rays", "a lidar"), at(lp, "rays"));
      if (n < 1 || n > max_rays) fail(at(lp, "rays"), "a lidar has from 1 to " + std::to_string(max_rays) + " rays (got " + std::to_string(n) + ")");
      const double fov = positive(require(*lidar, lp, "fov", "a lidar"), at(lp, "fov"), "fov (degrees)");
      if (fov > 360.0) fail(at(lp, "fov"), "a lidar's fov is at most 360 degrees (got " + num(fov) + ")");
      sensor.range = positive(require(*lidar, lp, "range", "a lidar"), at(lp, "range"), "range (units)");
      // Centred on the bearing; a full circle has n equal steps, a narrower fan its two edges as rays.
      const double step = n == 1 ? 0.0 : (fov >= 360.0 ? fov / static_cast<double>(n) : fov / static_cast<double>(n - 1));
      const double first = n == 1 ? bearing : (fov >= 360.0 ? bearing : bearing - fov / 2.0);
      for (std::uint64_t r = 0; r < n; ++r) sensor.bearings.push_back(first + static_cast<double>(r) * step);
    } else {
      sensor.range = positive(require(s, p, "range", "a range sensor"), at(p, "range"), "range (units)");
      if (ring) {
        const std::uint64_t n = natural(*ring, at(p, "ring"));
        if (n < 1 || n > max_rays) fail(at(p, "ring"), "a ring has from 1 to " + std::to_string(max_rays) + " rays (got " + std::to_string(n) + ")");
        // n equal steps, the first at the bearing (0: straight ahead), clockwise.
        for (std::uint64_t r = 0; r < n; ++r) sensor.bearings.push_back(bearing + 360.0 * static_cast<double>(r) / static_cast<double>(n));
      } else {
        sensor.bearings.push_back(bearing);
      }
    }
    out.push_back(std::move(sensor));
  }
  return out;
}

void Reader::check_script(const json& params, const std::string& path,
                          const std::vector<turtle::RangeSensor>& senses) const {
  // The script controller would only find these at run time, as a fault that stops the turtle; a
  // typo in a scripted test world should stop the load instead.
  check_keys(params, path, "the script controller's params", {"commands"});
  const json* commands = find(params, "commands");
  if (!commands) return;  // a script turtle without commands stands still: an obstacle
  const std::string cp = at(path, "commands");
  if (!commands->is_array())
    fail(cp, "commands must be a list of [command, amount], e.g. [[\"forward\", 100], [\"right\", 90]], got " +
                 json_kind(*commands));
  const std::string known = sim::join_names(turtle::script_command_names());
  for (std::size_t k = 0; k < commands->size(); ++k) {
    const std::string p = at(cp, k);
    const json& c = (*commands)[k];
    if (!c.is_array() || c.empty() || !c[0].is_string())
      fail(p, "a command must be [command, amount], e.g. [\"forward\", 100], got " + c.dump());
    const std::string name = c[0].get<std::string>();
    const turtle::ScriptCommand* command = turtle::find_script_command(name);
    if (!command) fail(at(p, 0), "unknown command '" + name + "'; known: " + known);
    if (name == "pendown" && c.size() == 2 && c[1].is_string()) {
      if (c[1] != "wall" && c[1] != "line")
        fail(at(p, 1), "a pen mode is \"line\" (draws the path) or \"wall\" (lays walls), got " + c[1].dump());
      continue;
    }
    if (command->senses()) {
      // ["sense", NAME] reads any range sensor, ["camera", NAME] only a camera.
      const bool camera = command->op == turtle::ScriptCommand::Op::camera;
      if (c.size() != 2 || !c[1].is_string())
        fail(p, "'" + name + "' needs a sensor's name, e.g. [\"" + name + "\", \"" + (camera ? "cam" : "front") +
                    "\"], got " + c.dump());
      const std::string sensor = c[1].get<std::string>();
      std::vector<std::string> known_senses;
      for (const auto& s : senses)
        if (s.camera || !camera) known_senses.push_back(s.name);
      if (std::find(known_senses.begin(), known_senses.end(), sensor) == known_senses.end())
        fail(at(p, 1), "this turtle has no " + std::string(camera ? "camera" : "range sensor") + " \"" + sensor + "\"" +
                           (known_senses.empty() ? std::string("; declare it under the turtle's \"senses\"")
                                                 : "; its " + std::string(camera ? "cameras" : "senses") + ": " +
                                                       sim::join_names(known_senses)));
      continue;
    }
    if (command->steers()) {
      // ["arc", radius, degrees], ["drive", v, omega, seconds], ["wheels", left, right, seconds].
      const std::string example(command->example());
      if (c.size() != 1 + command->numbers())
        fail(p, "'" + name + "' needs " + std::to_string(command->numbers()) + " numbers (" +
                    std::string(turtle::unit_name(command->amount)) + "), e.g. " + example + ", got " + c.dump());
      std::vector<double> xs;
      for (std::size_t j = 1; j < c.size(); ++j) xs.push_back(number(c[j], at(p, j)));
      if (command->op == turtle::ScriptCommand::Op::arc && xs[0] < 0.0)
        fail(at(p, 1), "an arc's radius must be >= 0 (got " + num(xs[0]) +
                           "); negative degrees turn left, and [\"drive\", v, omega, seconds] with v < 0 goes backwards");
      if (command->op != turtle::ScriptCommand::Op::arc && xs[2] < 0.0)
        fail(at(p, 3), "'" + name + "' needs a time >= 0 in seconds (got " + num(xs[2]) + ")");
      continue;
    }
    if (name == "pendown" || name == "penup") {
      if (c.size() != 1)
        fail(p, "'" + name + "' takes no amount: [\"" + name + "\"]" +
                    (name == "pendown" ? " (or a pen mode: [\"pendown\", \"wall\"])" : ""));
      continue;
    }
    if (c.size() != 2) fail(p, "'" + name + "' needs one number, e.g. [\"" + name + "\", 100], got " + c.dump());
    const double amount = number(c[1], at(p, 1));
    // A negative distance or angle is a direction, as in the Turtle API: ["forward", -5] drives
    // backwards like ["back", 5]. Time only runs forwards.
    if (command->op == turtle::ScriptCommand::Op::wait && amount < 0.0)
      fail(at(p, 1), "'wait' needs an amount >= 0 in seconds (got " + num(amount) + ")");
  }
}

}  // namespace turtlegas::world::detail
