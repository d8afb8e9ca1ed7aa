// SPDX-License-Identifier: MIT
#include "turtlegas/world/world_file.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <set>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "gas.hpp"
#include "turtlegas/sim/angles.hpp"
#include "turtlegas/sim/format.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/script.hpp"
#include "turtlegas/world/draw_walker.hpp"
#include "turtlegas/world/game_file.hpp"

namespace turtlegas::world {
namespace {

using json = nlohmann::json;
using sim::Vec2;

std::string num(double v) { return sim::format_number(v); }
std::string vec(Vec2 v) { return sim::format_vec(v); }

/// A JSON-pointer reference token: `~` and `/` escaped as RFC 6901 has it.
std::string token(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string at(const std::string& path, std::string_view key) { return path + "/" + token(key); }
std::string at(const std::string& path, std::size_t index) { return path + "/" + std::to_string(index); }

/// "a string", "an array", ...: what nlohmann calls the type, with its article.
std::string kind_of(const json& v) {
  const std::string name = v.type_name();
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "true or false";
  const bool vowel = !name.empty() && std::strchr("aeiou", name[0]) != nullptr;
  return (vowel ? "an " : "a ") + name;
}


/// Features that later versions add to the format: named so that a file written for them fails
/// with a clear message rather than as an unknown key.
constexpr std::array<std::string_view, 1> reserved_keys = {"views"};

/// The commands of a `draw` builder: the script commands (turtle/script.hpp) of turtle geometry,
/// without those that only take time.
std::vector<std::string_view> draw_commands() {
  std::vector<std::string_view> names;
  for (const turtle::ScriptCommand& c : turtle::script_commands)
    if (!c.timed_only()) names.push_back(c.name);
  return names;
}

/// The category every object is in unless it names others; bit 0, sim::Layers' default.
constexpr std::string_view default_category = "default";
/// Bits 0..31 of a category mask: "default" and at most 31 names.
constexpr std::size_t max_categories = 32;

constexpr std::array<std::string_view, 4> arena_wall_ids = {"arena-bottom", "arena-right", "arena-top", "arena-left"};

/// Reads one parsed document into a Scene, remembering where each ball came from so that a
/// problem found later (by sim::validate) can be reported at its JSON path. Controller names are
/// checked against `registry` when one is given.
class Reader {
 public:
  Reader(std::string file, const turtle::Registry* registry) : file_(std::move(file)), registry_(registry) {}

  [[noreturn]] void fail(const std::string& path, const std::string& reason) const {
    throw WorldFileError(file_, path, reason);
  }

  Scene read(const json& doc, std::string_view default_name);

 private:
  void expect_object(const json& v, const std::string& path, std::string_view what) const {
    if (!v.is_object()) fail(path, std::string(what) + " must be a JSON object ({...}), got " + kind_of(v));
  }
  void expect_array(const json& v, const std::string& path, std::string_view what) const {
    if (!v.is_array()) fail(path, std::string(what) + " must be a JSON array ([...]), got " + kind_of(v));
  }

  /// Rejects keys outside `known`, except private `x-` keys.
  void check_keys(const json& obj, const std::string& path, std::string_view what,
                  std::initializer_list<std::string_view> known) const {
    for (const auto& [key, value] : obj.items()) {
      if (key.starts_with("x-") || std::find(known.begin(), known.end(), key) != known.end()) continue;
      std::string reason = "unknown key \"" + key + "\" in " + std::string(what) + sim::suggestion(key, known);
      reason += " (known keys: " + sim::join_names(known) + "; keys starting with x- are ignored)";
      fail(at(path, key), reason);
    }
  }

  const json* find(const json& obj, std::string_view key) const {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  const json& require(const json& obj, const std::string& path, std::string_view key, std::string_view what) const {
    if (const json* v = find(obj, key)) return *v;
    fail(path, std::string(what) + " needs \"" + std::string(key) + "\"");
  }

  double number(const json& v, const std::string& path) const {
    if (!v.is_number()) fail(path, "expected a number, got " + kind_of(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(path, "expected a finite number, got " + num(d));
    return d;
  }
  double positive(const json& v, const std::string& path, std::string_view name) const {
    const double d = number(v, path);
    if (!(d > 0.0)) fail(path, std::string(name) + " must be > 0 (got " + num(d) + ")");
    return d;
  }
  /// A non-negative integer; 1e6 is accepted as well as 1000000.
  std::uint64_t natural(const json& v, const std::string& path) const {
    if (v.is_number_unsigned()) return v.get<std::uint64_t>();
    if (v.is_number_integer()) fail(path, "expected an integer >= 0, got " + std::to_string(v.get<std::int64_t>()));
    if (v.is_number_float()) {
      const double d = v.get<double>();
      if (d >= 0.0 && d < 0x1.0p64 && std::floor(d) == d) return static_cast<std::uint64_t>(d);
      fail(path, "expected an integer >= 0, got " + num(d));
    }
    fail(path, "expected an integer >= 0, got " + kind_of(v));
  }
  bool boolean(const json& v, const std::string& path) const {
    if (!v.is_boolean()) fail(path, "expected true or false, got " + kind_of(v));
    return v.get<bool>();
  }
  std::string string(const json& v, const std::string& path) const {
    if (!v.is_string()) fail(path, "expected a string, got " + kind_of(v));
    return v.get<std::string>();
  }
  Vec2 vec2(const json& v, const std::string& path) const {
    if (!v.is_array()) fail(path, "expected [x, y] (an array of 2 numbers), got " + kind_of(v));
    if (v.size() != 2) fail(path, "expected [x, y] (an array of 2 numbers), got an array of " + std::to_string(v.size()));
    return {number(v[0], at(path, 0)), number(v[1], at(path, 1))};
  }
  std::string id(const json& obj, const std::string& path, std::string_view what) {
    const std::string p = at(path, "id");
    std::string s = string(require(obj, path, "id", what), p);
    if (s.empty()) fail(p, "id must not be empty");
    auto [it, fresh] = ids_.emplace(s, p);
    if (!fresh) {
      if (it->second.empty())
        fail(p, "id \"" + s + "\" is taken by an arena wall of boundary \"walls\"; choose another id");
      fail(p, "duplicate id \"" + s + "\" (already used at " + it->second +
                  "); every wall, ball and turtle needs its own id");
    }
    return s;
  }

  void read_arena(const json& v, sim::ArenaDef& arena);
  void read_effects(const json& v, sim::EffectsDef& effects);
  void collect_categories(const json& doc);
  void collect_category(const json& obj, const std::string& path);
  sim::Layers layers(const json& obj, const std::string& path) const;
  std::uint32_t category_bits(const json& v, const std::string& path) const;
  void read_walls(const json& v, std::vector<sim::WallDef>& walls);
  void read_draw(const json& v, std::vector<sim::WallDef>& walls);
  void read_balls(const json& v, std::vector<sim::BallDef>& balls);
  void read_turtles(const json& v, std::vector<sim::TurtleDef>& turtles, std::vector<turtle::TurtleProgram>& programs);
  std::vector<turtle::SensorArc> read_sensors(const json& v, const std::string& path) const;
  void check_script(const json& params, const std::string& path) const;
  std::vector<detail::GasSpec> read_gases(const json& v, const sim::WorldDef& def);
  std::string path_of(const sim::DefProblem& p) const;
  void check_gas_ids(const std::vector<detail::GasSpec>& gases) const;

  std::string file_;
  const turtle::Registry* registry_;
  std::unordered_map<std::string, std::string> ids_;  // id -> JSON path of its "id" ("" for arena walls)
  std::size_t explicit_balls_ = 0;
  std::vector<std::size_t> gas_first_;  // index in WorldDef::balls of each gas entry's first ball
  std::vector<std::string> wall_paths_;  // JSON path of each of WorldDef::walls (file walls, then drawn)
  std::vector<std::string> categories_{std::string(default_category)};  // name of bit k
};

void Reader::collect_category(const json& obj, const std::string& path) {
  if (!obj.is_object()) return;  // reported by the section's reader
  const json* c = find(obj, "category");
  if (!c) return;
  const std::string p = at(path, "category");
  auto add = [&](const json& name, const std::string& np) {
    const std::string n = string(name, np);
    if (n.empty()) fail(np, "a category name must not be empty");
    if (std::find(categories_.begin(), categories_.end(), n) != categories_.end()) return;
    if (categories_.size() == max_categories)
      fail(np, "too many collision categories: \"" + n + "\" would be number " + std::to_string(max_categories + 1) +
                   "; a world has at most " + std::to_string(max_categories - 1) + " names besides \"default\"");
    categories_.push_back(n);
  };
  if (c->is_array()) {
    if (c->empty()) fail(p, "category must be a name or a non-empty list of names, got []");
    for (std::size_t k = 0; k < c->size(); ++k) add((*c)[k], at(p, k));
  } else if (c->is_string()) {
    add(*c, p);
  } else {
    fail(p, "category must be a name (\"walls\") or a list of names, got " + kind_of(*c));
  }
}

void Reader::collect_categories(const json& doc) {
  // Bits are given in a fixed section order (JSON objects do not keep their key order):
  // walls, balls, gas, turtles, draw; within a section, in list order.
  for (std::string_view section : {"walls", "balls", "gas", "turtles", "draw"})
    if (const json* v = find(doc, section); v && v->is_array())
      for (std::size_t i = 0; i < v->size(); ++i) collect_category((*v)[i], at(at("", section), i));
}

std::uint32_t Reader::category_bits(const json& v, const std::string& path) const {
  auto bit = [&](const json& name, const std::string& np) -> std::uint32_t {
    const std::string n = string(name, np);
    const auto it = std::find(categories_.begin(), categories_.end(), n);
    if (it == categories_.end()) {
      fail(np, "unknown category \"" + n + "\"; no wall, ball, gas or turtle has it as its \"category\" (known: " +
                   sim::join_names(categories_) + "). A misspelt name would silently turn collisions off");
    }
    return std::uint32_t{1} << static_cast<unsigned>(it - categories_.begin());
  };
  if (v.is_string()) return bit(v, path);
  if (!v.is_array()) fail(path, "expected a category name or a list of names, got " + kind_of(v));
  std::uint32_t bits = 0;
  for (std::size_t k = 0; k < v.size(); ++k) bits |= bit(v[k], at(path, k));
  return bits;
}

sim::Layers Reader::layers(const json& obj, const std::string& path) const {
  sim::Layers l;  // category "default" (bit 0), collides with everything
  if (const json* c = find(obj, "category")) {
    l.category = category_bits(*c, at(path, "category"));
    if (l.category == 0) fail(at(path, "category"), "category must name at least one category");
  }
  // An empty collides_with is allowed: the object collides with nothing (a pure spectator).
  if (const json* m = find(obj, "collides_with")) l.mask = category_bits(*m, at(path, "collides_with"));
  return l;
}

void Reader::read_arena(const json& v, sim::ArenaDef& arena) {
  const std::string path = "/arena";
  expect_object(v, path, "arena");
  check_keys(v, path, "arena", {"width", "height", "cell", "boundary"});
  if (const json* w = find(v, "width")) arena.width = positive(*w, at(path, "width"), "arena width");
  if (const json* h = find(v, "height")) arena.height = positive(*h, at(path, "height"), "arena height");
  if (const json* c = find(v, "cell")) arena.cell = positive(*c, at(path, "cell"), "arena cell");
  if (const json* b = find(v, "boundary")) {
    const std::string s = string(*b, at(path, "boundary"));
    if (s == "none") arena.boundary = sim::Boundary::none;
    else if (s == "walls") arena.boundary = sim::Boundary::walls;
    else if (s == "periodic") arena.boundary = sim::Boundary::periodic;
    else fail(at(path, "boundary"), "boundary must be \"none\", \"walls\" or \"periodic\" (got \"" + s + "\")");
  }
}

void Reader::read_effects(const json& v, sim::EffectsDef& e) {
  const std::string path = "/effects";
  expect_object(v, path, "effects");
  check_keys(v, path, "effects", {"gravity", "electric", "magnetic", "restitution", "ball_ball", "tc"});
  if (const json* g = find(v, "gravity")) e.gravity = vec2(*g, at(path, "gravity"));
  if (const json* el = find(v, "electric")) {
    e.electric = vec2(*el, at(path, "electric"));
    if (e.electric != Vec2{})
      fail(at(path, "electric"), "effects.electric is not simulated yet (only gravity is); remove it or set it to [0, 0]");
  }
  if (const json* m = find(v, "magnetic")) {
    e.magnetic = number(*m, at(path, "magnetic"));
    if (e.magnetic != 0.0)
      fail(at(path, "magnetic"), "effects.magnetic is not simulated yet (only gravity is); remove it or set it to 0");
  }
  if (const json* r = find(v, "restitution")) {
    e.restitution = number(*r, at(path, "restitution"));
    if (!(e.restitution >= 0.0 && e.restitution <= 1.0))
      fail(at(path, "restitution"),
           "restitution must be in [0, 1] (got " + num(e.restitution) + "); 1 is elastic, 0 perfectly inelastic");
  }
  if (const json* b = find(v, "ball_ball")) e.ball_ball = boolean(*b, at(path, "ball_ball"));
  if (const json* t = find(v, "tc")) e.tc = positive(*t, at(path, "tc"), "tc");
}

void Reader::read_walls(const json& v, std::vector<sim::WallDef>& walls) {
  const std::string path = "/walls";
  expect_array(v, path, "walls");
  walls.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = at(path, i);
    const json& w = v[i];
    expect_object(w, p, "a wall");
    check_keys(w, p, "a wall", {"id", "from", "to", "category", "collides_with", "keys", "visible"});
    sim::WallDef def;
    def.id = id(w, p, "a wall");
    def.from = vec2(require(w, p, "from", "a wall"), at(p, "from"));
    def.to = vec2(require(w, p, "to", "a wall"), at(p, "to"));
    def.layers = layers(w, p);
    if (const json* keys = find(w, "keys")) {
      // A moving wall: poses at later times; each end moves linearly from one to the next.
      const std::string kp = at(p, "keys");
      expect_array(*keys, kp, "keys");
      double prev = 0.0;
      for (std::size_t k = 0; k < keys->size(); ++k) {
        const std::string pk = at(kp, k);
        const json& key = (*keys)[k];
        expect_object(key, pk, "a keyframe");
        check_keys(key, pk, "a keyframe", {"t", "from", "to"});
        sim::WallKey wk;
        wk.t = number(require(key, pk, "t", "a keyframe"), at(pk, "t"));
        if (!(wk.t > prev)) fail(at(pk, "t"), "keyframe times must increase and be > 0 (got " + num(wk.t) + " after " + num(prev) + ")");
        prev = wk.t;
        wk.from = vec2(require(key, pk, "from", "a keyframe"), at(pk, "from"));
        wk.to = vec2(require(key, pk, "to", "a keyframe"), at(pk, "to"));
        def.keys.push_back(wk);
      }
    }
    if (const json* vis = find(w, "visible")) {
      // From each time on the wall is there or not (for everything); before the first, it is.
      const std::string vp = at(p, "visible");
      expect_array(*vis, vp, "visible");
      double prev = -1.0;
      for (std::size_t k = 0; k < vis->size(); ++k) {
        const std::string pk = at(vp, k);
        const json& key = (*vis)[k];
        expect_object(key, pk, "a visibility key");
        check_keys(key, pk, "a visibility key", {"t", "visible"});
        sim::VisibilityKey vk;
        vk.t = number(require(key, pk, "t", "a visibility key"), at(pk, "t"));
        if (!(vk.t > prev) || vk.t < 0.0)
          fail(at(pk, "t"), "visibility times must increase and be >= 0 (got " + num(vk.t) + ")");
        prev = vk.t;
        vk.visible = boolean(require(key, pk, "visible", "a visibility key"), at(pk, "visible"));
        def.visibility.push_back(vk);
      }
    }
    walls.push_back(std::move(def));
    wall_paths_.push_back(p);
  }
}

void Reader::read_draw(const json& v, std::vector<sim::WallDef>& walls) {
  const std::string path = "/draw";
  expect_array(v, path, "draw");
  const std::vector<std::string_view> commands_known = draw_commands();
  const std::string known = sim::join_names(commands_known);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = at(path, i);
    const json& b = v[i];
    expect_object(b, p, "a draw builder");
    check_keys(b, p, "a draw builder", {"id", "pos", "heading", "commands", "category", "collides_with"});
    const std::string builder = id(b, p, "a draw builder");
    DrawWalker walker(builder, vec2(require(b, p, "pos", "a draw builder"), at(p, "pos")), 0.0);
    if (const json* h = find(b, "heading")) walker.heading = number(*h, at(p, "heading"));
    const sim::Layers layers_of_walls = layers(b, p);
    const std::string cp = at(p, "commands");
    const json& commands = require(b, p, "commands", "a draw builder");
    expect_array(commands, cp, "commands");
    for (std::size_t k = 0; k < commands.size(); ++k) {
      const std::string kp = at(cp, k);
      const json& c = commands[k];
      if (!c.is_array() || c.empty() || !c[0].is_string())
        fail(kp, "a command must be [command, amount], e.g. [\"forward\", 100], got " + c.dump());
      const std::string name = c[0].get<std::string>();
      if (std::find(commands_known.begin(), commands_known.end(), name) == commands_known.end())
        fail(at(kp, 0), "unknown command '" + name + "'; a draw builder knows: " + known +
                            " (it runs at load time, so there is no wait)");
      if (name == "pendown" || name == "penup") {
        if (c.size() != 1) fail(kp, "'" + name + "' takes no amount: [\"" + name + "\"]");
        walker.pen_down = name == "pendown";
        continue;
      }
      if (c.size() != 2) fail(kp, "'" + name + "' needs one number, e.g. [\"" + name + "\", 100], got " + c.dump());
      const double amount = number(c[1], at(kp, 1));
      if (name == "left" || name == "right") {
        walker.turn(name == "right" ? amount : -amount);
        continue;
      }
      if (auto wall = walker.move(name == "forward" ? amount : -amount)) {
        wall->layers = layers_of_walls;
        auto [it, fresh] = ids_.emplace(wall->id, kp);
        if (!fresh)
          fail(kp, "the wall this command lays gets the id \"" + wall->id + "\", already used " +
                       (it->second.empty() ? std::string("by an arena wall") : "at " + it->second) +
                       "; rename the builder or that object");
        walls.push_back(std::move(*wall));
        wall_paths_.push_back(kp);
      }
    }
  }
}

void Reader::read_balls(const json& v, std::vector<sim::BallDef>& balls) {
  const std::string path = "/balls";
  expect_array(v, path, "balls");
  balls.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = at(path, i);
    const json& b = v[i];
    expect_object(b, p, "a ball");
    check_keys(b, p, "a ball", {"id", "pos", "vel", "radius", "mass", "charge", "category", "collides_with"});
    sim::BallDef def;
    def.id = id(b, p, "a ball");
    def.pos = vec2(require(b, p, "pos", "a ball"), at(p, "pos"));
    if (const json* x = find(b, "vel")) def.vel = vec2(*x, at(p, "vel"));
    def.radius = positive(require(b, p, "radius", "a ball"), at(p, "radius"), "radius");
    if (const json* x = find(b, "mass")) def.mass = positive(*x, at(p, "mass"), "mass");
    if (const json* x = find(b, "charge")) def.charge = number(*x, at(p, "charge"));
    def.layers = layers(b, p);
    balls.push_back(std::move(def));
  }
}

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
                "bounce", "category", "collides_with", "builder"});
    sim::TurtleDef body;
    turtle::TurtleProgram program;
    body.id = id(t, p, "a turtle");
    body.pos = vec2(require(t, p, "pos", "a turtle"), at(p, "pos"));
    body.layers = layers(t, p);
    // Angles are degrees in the file and radians inside: converted here, once. The heading is
    // wrapped into [0, 360) first so that a state written back reads like the file.
    double heading = 0.0;
    if (const json* x = find(t, "heading")) heading = number(*x, at(p, "heading"));
    body.heading = sim::to_radians(sim::wrap_heading_degrees(heading));
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
      if (registry_ && !registry_->find(program.controller))
        fail(at(p, "controller"), registry_->not_registered(program.controller));
    }
    if (const json* x = find(t, "params")) {
      expect_object(*x, at(p, "params"), "params");
      program.params = *x;
    }
    if (program.controller == "script") check_script(program.params, at(p, "params"));
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
                     (x->is_string() ? "\"" + x->get<std::string>() + "\"" : kind_of(*x)));
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
  if (!v.is_array()) fail(path, shape + kind_of(v));
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

void Reader::check_script(const json& params, const std::string& path) const {
  // The script controller would only find these at run time, as a fault that stops the turtle; a
  // typo in a scripted test world should stop the load instead.
  check_keys(params, path, "the script controller's params", {"commands"});
  const json* commands = find(params, "commands");
  if (!commands) return;  // a script turtle without commands stands still: an obstacle
  const std::string cp = at(path, "commands");
  if (!commands->is_array())
    fail(cp, "commands must be a list of [command, amount], e.g. [[\"forward\", 100], [\"right\", 90]], got " +
                 kind_of(*commands));
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
    if (name == "pendown" || name == "penup") {
      if (c.size() != 1)
        fail(p, "'" + name + "' takes no amount: [\"" + name + "\"]" +
                    (name == "pendown" ? " (or a pen mode: [\"pendown\", \"wall\"])" : ""));
      continue;
    }
    if (c.size() != 2) fail(p, "'" + name + "' needs one number, e.g. [\"" + name + "\", 100], got " + c.dump());
    const double amount = number(c[1], at(p, 1));
    if (amount < 0.0)
      fail(at(p, 1), "'" + name + "' needs an amount >= 0 in " + std::string(turtle::unit_name(command->amount)) + " (got " + num(amount) + ")" +
                         (name == "forward" ? "; use [\"back\", ...] to go backwards"
                          : name == "back"  ? "; use [\"forward\", ...] to go forwards"
                          : name == "left"  ? "; use [\"right\", ...] to turn the other way"
                          : name == "right" ? "; use [\"left\", ...] to turn the other way"
                                            : ""));
  }
}

std::vector<detail::GasSpec> Reader::read_gases(const json& v, const sim::WorldDef& def) {
  const std::string path = "/gas";
  expect_array(v, path, "gas");
  std::vector<detail::GasSpec> out;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const std::string p = at(path, k);
    const json& g = v[k];
    expect_object(g, p, "a gas");
    check_keys(g, p, "a gas", {"count", "radius", "mass", "speed", "region", "seed", "id_prefix", "category", "collides_with"});
    detail::GasSpec gas;
    const std::uint64_t count = natural(require(g, p, "count", "a gas"), at(p, "count"));
    constexpr std::uint64_t max_count = 100'000'000;
    if (count > max_count)
      fail(at(p, "count"), "count " + std::to_string(count) + " is more than this loader places (" +
                               std::to_string(max_count) + "); split the gas or use fewer, larger balls");
    gas.count = static_cast<std::size_t>(count);
    gas.radius = positive(require(g, p, "radius", "a gas"), at(p, "radius"), "radius");
    if (const json* x = find(g, "mass")) gas.mass = positive(*x, at(p, "mass"), "mass");
    gas.speed = number(require(g, p, "speed", "a gas"), at(p, "speed"));
    if (gas.speed < 0.0) fail(at(p, "speed"), "speed must be >= 0 (got " + num(gas.speed) + "); directions are random");
    gas.lo = {0.0, 0.0};
    gas.hi = {def.arena.width, def.arena.height};
    if (const json* r = find(g, "region")) {
      const std::string rp = at(p, "region");
      const std::string shape = "expected [[x0, y0], [x1, y1]] (two corners), got ";
      if (!r->is_array()) fail(rp, shape + kind_of(*r));
      if (r->size() != 2) fail(rp, shape + "an array of " + std::to_string(r->size()));
      gas.lo = vec2((*r)[0], at(rp, 0));
      gas.hi = vec2((*r)[1], at(rp, 1));
      if (!(gas.lo.x < gas.hi.x && gas.lo.y < gas.hi.y))
        fail(rp, "region " + vec(gas.lo) + " to " + vec(gas.hi) +
                     " is empty; give the lower-left corner first: [[x0, y0], [x1, y1]] with x0 < x1 and y0 < y1");
    }
    // Entry k defaults to the world seed + k, so two default gases do not repeat each other.
    gas.seed = def.seed + k;
    if (const json* s = find(g, "seed")) gas.seed = natural(*s, at(p, "seed"));
    gas.id_prefix = k == 0 ? "g" : "g" + std::to_string(k) + "-";
    if (const json* x = find(g, "id_prefix")) gas.id_prefix = string(*x, at(p, "id_prefix"));
    gas.layers = layers(g, p);

    Vec2 lo, hi;
    detail::centre_range(gas, def.arena, lo, hi);
    if (lo.x > hi.x || lo.y > hi.y)
      fail(at(p, "region"), "balls of radius " + num(gas.radius) + " do not fit in region [" + vec(gas.lo) + ", " +
                                vec(gas.hi) + "] inside the arena; enlarge the region or reduce radius");
    out.push_back(std::move(gas));
  }
  return out;
}

/// The number n if `digits` is n written as place_gas writes it (decimal, no leading zero).
std::optional<std::uint64_t> gas_number(std::string_view digits) {
  if (digits.empty() || digits.size() > 18 || (digits.size() > 1 && digits[0] == '0')) return std::nullopt;
  std::uint64_t n = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    n = n * 10 + static_cast<std::uint64_t>(c - '0');
  }
  return n;
}

void Reader::check_gas_ids(const std::vector<detail::GasSpec>& gases) const {
  // Gas k's ids are id_prefix + n for n < count. One collides with an explicit id when that id is
  // the prefix followed by such an n.
  for (std::size_t k = 0; k < gases.size(); ++k) {
    const detail::GasSpec& g = gases[k];
    if (g.count == 0) continue;
    for (const auto& [id, path] : ids_) {
      if (!id.starts_with(g.id_prefix)) continue;
      const auto n = gas_number(std::string_view(id).substr(g.id_prefix.size()));
      if (!n || *n >= g.count) continue;
      fail(at("/gas", k), "this gas's id \"" + id + "\" is already used " +
                              (path.empty() ? std::string("by an arena wall") : "at " + path) +
                              "; set an id_prefix that no other id starts with");
    }
  }
  // Two gases collide when one prefix is the other followed by digits t, so that
  // short + (t + m) == long + m; the smallest such number of the shorter one is t followed by 0.
  for (std::size_t a = 0; a < gases.size(); ++a)
    for (std::size_t b = 0; b < gases.size(); ++b) {
      const detail::GasSpec &ga = gases[a], &gb = gases[b];
      if (a == b || ga.count == 0 || gb.count == 0 || !gb.id_prefix.starts_with(ga.id_prefix)) continue;
      if (ga.id_prefix == gb.id_prefix && a > b) continue;  // reported once, at the later gas
      bool clash = ga.id_prefix == gb.id_prefix;
      if (!clash) {
        const auto t = gas_number(std::string_view(gb.id_prefix).substr(ga.id_prefix.size()));
        clash = t && *t != 0 && *t * 10 < ga.count;
      }
      if (clash)
        fail(at("/gas", std::max(a, b)), "the ids of gases " + std::to_string(std::min(a, b)) + " and " +
                                             std::to_string(std::max(a, b)) + " (prefixes \"" + ga.id_prefix +
                                             "\" and \"" + gb.id_prefix + "\") overlap; give each gas its own id_prefix");
    }
}

std::string Reader::path_of(const sim::DefProblem& p) const {
  using Where = sim::DefProblem::Where;
  auto with_field = [&](std::string base) { return p.field.empty() ? base : at(base, p.field); };
  switch (p.where) {
    case Where::world: return p.field.empty() ? "" : at("", p.field);
    case Where::arena: return with_field("/arena");
    case Where::effects: return with_field("/effects");
    case Where::wall:  // a file wall's field, or the draw command that laid it
      if (p.index < wall_paths_.size() && !wall_paths_[p.index].starts_with("/walls/")) return wall_paths_[p.index];
      return with_field(at("/walls", p.index));
    case Where::ball: {
      if (p.index < explicit_balls_) return with_field(at("/balls", p.index));
      const auto k = static_cast<std::size_t>(std::upper_bound(gas_first_.begin(), gas_first_.end(), p.index) -
                                              gas_first_.begin()) - 1;
      return at("/gas", k);
    }
    case Where::turtle: return with_field(at("/turtles", p.index));
  }
  return "";
}

Scene Reader::read(const json& doc, std::string_view default_name) {
  if (!doc.is_object()) fail("", "a world file must be a JSON object ({\"format\": \"turtlegas-world/1\", ...}), got " + kind_of(doc));
  const json* format = find(doc, "format");
  if (!format) fail("", "missing \"format\"; add \"format\": \"" + std::string(world_format) + "\" to the top-level object");
  if (!format->is_string() || format->get<std::string>() != world_format)
    fail("/format", "unsupported format " + format->dump() + "; this turtlegas reads \"" + std::string(world_format) + "\"");
  for (std::string_view key : reserved_keys)
    if (doc.contains(key))
      fail(at("", key), "\"" + std::string(key) + "\" is not supported yet by this version of turtlegas; remove it (or rename it \"x-" +
                            std::string(key) + "\" to keep it in the file)");
  check_keys(doc, "", "the world",
             {"format", "name", "seed", "dt", "arena", "effects", "walls", "balls", "turtles", "gas", "expect", "game",
              "draw"});

  Scene scene;
  sim::WorldDef& def = scene.def;
  def.name = std::string(default_name);
  if (const json* v = find(doc, "name")) def.name = string(*v, "/name");
  if (const json* v = find(doc, "seed")) def.seed = natural(*v, "/seed");
  if (const json* v = find(doc, "dt")) def.dt = positive(*v, "/dt", "dt");
  if (const json* v = find(doc, "arena")) read_arena(*v, def.arena);
  if (const json* v = find(doc, "effects")) read_effects(*v, def.effects);
  if (def.arena.boundary == sim::Boundary::walls)
    for (std::string_view id : arena_wall_ids) ids_.emplace(std::string(id), "");
  collect_categories(doc);
  if (const json* v = find(doc, "walls")) read_walls(*v, def.walls);
  if (const json* v = find(doc, "draw")) read_draw(*v, def.walls);
  if (const json* v = find(doc, "balls")) read_balls(*v, def.balls);
  explicit_balls_ = def.balls.size();
  if (const json* v = find(doc, "turtles")) read_turtles(*v, def.turtles, scene.programs);
  {
    std::size_t builders = 0;
    for (std::size_t k = 0; k < scene.programs.size(); ++k) {
      builders += scene.programs[k].builder ? 1 : 0;
      if (scene.programs[k].builder && categories_.size() + builders > max_categories)
        fail(at("/turtles", k), "this turtle lays walls and needs a collision category of its own, but the world's " +
                                    std::to_string(categories_.size()) + " categories and " + std::to_string(builders) +
                                    " builders are more than " + std::to_string(max_categories) +
                                    "; use fewer category names or builders");
    }
  }
  if (const json* v = find(doc, "game"))  // game_file.hpp
    scene.game = read_game(*v, def, [this](const std::string& path, const std::string& reason) { fail(path, reason); });

  // The scene without its gases first: gases are placed around the walls, balls and turtles,
  // which must therefore be sound.
  if (auto problem = sim::validate(def)) fail(path_of(*problem), problem->message);

  if (const json* v = find(doc, "gas")) {
    const std::vector<detail::GasSpec> gases = read_gases(*v, def);
    std::size_t total = def.balls.size();
    for (const auto& g : gases) total += g.count;
    def.balls.reserve(total);
    for (std::size_t k = 0; k < gases.size(); ++k) {
      const detail::GasSpec& gas = gases[k];
      gas_first_.push_back(def.balls.size());
      const std::size_t placed = detail::place_gas(def, gas);
      if (placed < gas.count)
        fail(at("/gas", k), "could only place " + std::to_string(placed) + " of " + std::to_string(gas.count) +
                                " balls of radius " + num(gas.radius) + " in region [" + vec(gas.lo) + ", " +
                                vec(gas.hi) + "]; enlarge the region or reduce count/radius");
    }
    // Gases are placed clear of everything (and World validates again when it is built), so only
    // their generated ids remain to be checked; that needs only their prefixes, not a million strings.
    check_gas_ids(gases);
  }
  // Scripted test worlds (expect.hpp): read last, so that their ids can name any body.
  if (const json* v = find(doc, "expect")) {
    scene.expect = parse_expect(*v, file_, def);
    for (const auto& e : scene.expect.entries)
      if (e.kind == "it" && !scene.game)
        fail(at(at("/expect", e.index), "it"), "an \"it\" expectation needs a game; add \"game\": {\"kind\": \"tag\", ...}");
  }
  return scene;
}

/// Line and column (1-based, column in bytes) of the byte that nlohmann's parser stopped at.
std::pair<std::size_t, std::size_t> line_and_column(std::string_view text, std::size_t byte) {
  // nlohmann counts bytes from 1 and may point one past the end at end of input.
  const std::size_t pos = std::min(byte == 0 ? 0 : byte - 1, text.size());
  std::size_t line = 1, line_start = 0;
  for (std::size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') ++line, line_start = i + 1;
  return {line, pos - line_start + 1};
}

Scene parse(std::string_view text, std::string_view file_name, const turtle::Registry* registry) {
  const std::string file(file_name);
  json doc;
  try {
    doc = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    // nlohmann's message is "[json.exception.parse_error.101] parse error at line 3, column 5: what";
    // keep only "what" and put the position in the usual FILE:LINE:COLUMN form.
    std::string what = e.what();
    const std::size_t head = what.find("parse error");
    const std::size_t colon = head == std::string::npos ? std::string::npos : what.find(": ", head);
    if (colon != std::string::npos) what = what.substr(colon + 2);
    const auto [line, column] = line_and_column(text, e.byte);
    throw WorldFileError(file, "", "invalid JSON: " + what, line, column);
  } catch (const json::exception& e) {
    // Number overflow ("1e999") and the like: no position, and no "[json.exception...] " tag.
    std::string what = e.what();
    if (what.starts_with("[json.exception") && what.find("] ") != std::string::npos) what.erase(0, what.find("] ") + 2);
    throw WorldFileError(file, "", "invalid JSON: " + what);
  }
  std::string stem = std::filesystem::path(file).stem().string();
  return Reader(file, registry).read(doc, stem);
}

Scene load(const std::filesystem::path& path, const turtle::Registry* registry) {
  const std::string file = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw WorldFileError(file, "", "no such file; check the path");
  if (std::filesystem::is_directory(status)) throw WorldFileError(file, "", "is a directory, not a world file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw WorldFileError(file, "", std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw WorldFileError(file, "", std::string("cannot read: ") + std::strerror(errno));
  return parse(text.str(), file, registry);
}

}  // namespace

Scene parse_scene(std::string_view text, std::string_view file_name, const turtle::Registry& registry) {
  return parse(text, file_name, &registry);
}

Scene load_scene(const std::filesystem::path& file, const turtle::Registry& registry) { return load(file, &registry); }

sim::WorldDef parse_world(std::string_view text, std::string_view file_name) {
  return parse(text, file_name, nullptr).def;
}

sim::WorldDef load_world_file(const std::filesystem::path& file) { return load(file, nullptr).def; }

}  // namespace turtlegas::world
