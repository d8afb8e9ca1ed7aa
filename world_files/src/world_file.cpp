// SPDX-License-Identifier: MIT
#include "turtlegas/world/world_file.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "reader.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/sim/suggest.hpp"
#include "turtlegas/turtle/script.hpp"
#include "turtlegas/world/draw_walker.hpp"
#include "turtlegas/world/game_file.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::world {
namespace detail {
namespace {

/// Features that later versions add to the format: named so that a file written for them fails
/// with a clear message rather than as an unknown key. (None at present: `views` was one.)
constexpr std::array<std::string_view, 0> reserved_keys = {};

/// The commands of a `draw` builder: the script commands (turtle/script.hpp) of turtle geometry,
/// without those that only take time.
std::vector<std::string_view> draw_commands() {
  std::vector<std::string_view> names;
  for (const turtle::ScriptCommand& c : turtle::script_commands)
    if (!c.timed_only() && !c.senses() && !c.steers()) names.push_back(c.name);
  return names;
}

}  // namespace

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
    fail(p, "category must be a name (\"walls\") or a list of names, got " + json_kind(*c));
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
  if (!v.is_array()) fail(path, "expected a category name or a list of names, got " + json_kind(v));
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
    if (const auto boundary = sim::boundary_from_string(s)) arena.boundary = *boundary;
    else fail(at(path, "boundary"), "boundary must be \"none\", \"walls\" or \"periodic\" (got \"" + s + "\")");
  }
}

void Reader::read_effects(const json& v, sim::EffectsDef& e) {
  const std::string path = "/effects";
  expect_object(v, path, "effects");
  check_keys(v, path, "effects", {"gravity", "electric", "magnetic", "restitution", "ball_ball", "tc"});
  if (const json* g = find(v, "gravity")) e.gravity = vec2(*g, at(path, "gravity"));
  // The fields act on charged balls only (a ball's `charge`, a gas's `charge`): dv/dt = g + (q/m) E
  // + (q Bz / m) (v.y, -v.x), docs/physics.md.
  if (const json* el = find(v, "electric")) e.electric = vec2(*el, at(path, "electric"));
  if (const json* m = find(v, "magnetic")) e.magnetic = number(*m, at(path, "magnetic"));
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
    check_keys(w, p, "a wall", {"id", "from", "to", "category", "collides_with", "keys", "visible", "colour"});
    sim::WallDef def;
    def.id = id(w, p, "a wall");
    read_colour(w, p, def.id);
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
                            " (it runs at load time, so there is no wait, sense, camera, arc, drive or wheels)");
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
    check_keys(b, p, "a ball", {"id", "pos", "vel", "radius", "mass", "charge", "category", "collides_with", "colour"});
    sim::BallDef def;
    def.id = id(b, p, "a ball");
    read_colour(b, p, def.id);
    def.pos = vec2(require(b, p, "pos", "a ball"), at(p, "pos"));
    if (const json* x = find(b, "vel")) def.vel = vec2(*x, at(p, "vel"));
    def.radius = positive(require(b, p, "radius", "a ball"), at(p, "radius"), "radius");
    if (const json* x = find(b, "mass")) def.mass = positive(*x, at(p, "mass"), "mass");
    if (const json* x = find(b, "charge")) def.charge = number(*x, at(p, "charge"));
    def.layers = layers(b, p);
    balls.push_back(std::move(def));
  }
}

std::string Reader::path_of(const sim::DefProblem& p) const {
  using Where = sim::DefProblem::Where;
  auto with_field = [&](const std::string& base) { return p.field.empty() ? base : at(base, p.field); };
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

std::string Reader::colour(const json& v, const std::string& path) const {
  const std::string s = string(v, path);
  if (std::optional<std::string> c = turtle::parse_colour(s)) return *c;
  std::vector<std::string> names;
  for (const auto& named : turtle::colour_names) names.emplace_back(named.first);
  fail(path, "a colour is \"#rrggbb\" (e.g. \"#e15759\") or one of " + sim::join_names(names) + ", got \"" + s + "\"");
}

void Reader::read_colour(const json& obj, const std::string& path, const std::string& body_id) {
  if (const json* x = find(obj, "colour")) colours_.by_id[body_id] = colour(*x, at(path, "colour"));
}

Scene Reader::read(const json& doc, std::string_view default_name) {
  if (!doc.is_object()) fail("", "a world file must be a JSON object ({\"format\": \"turtlegas-world/1\", ...}), got " + json_kind(doc));
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
              "draw", "views", "plugins", "learn"});

  Scene scene;
  sim::WorldDef& def = scene.def;
  def.name = std::string(default_name);
  if (const json* v = find(doc, "name")) def.name = string(*v, "/name");
  if (const json* v = find(doc, "plugins")) {
    // Loaded by the program before the file is read (apps/turtlegas/plugins.hpp); checked here.
    if (!v->is_array()) fail("/plugins", "a list of controller plugin files, relative to the world file, e.g. [\"build/libfeeler.so\"]");
    for (std::size_t k = 0; k < v->size(); ++k)
      if (!(*v)[k].is_string() || (*v)[k].get_ref<const std::string&>().empty())
        fail("/plugins/" + std::to_string(k), "a plugin file's path (a non-empty string), relative to the world file");
  }
  if (const json* v = find(doc, "learn")) {
    // For turtlegas.VecWorld (docs/python.md, "Rewards from the world file"), which parses the
    // expression and names its errors; a run ignores it.
    if (!v->is_object()) fail("/learn", "an object, e.g. {\"reward\": \"distance / stroke - touch\"}, got " + json_kind(*v));
    check_keys(*v, "/learn", "learn", {"reward"});
    if (const json* r = find(*v, "reward"); r && string(*r, "/learn/reward").empty())
      fail("/learn/reward", "a reward expression, e.g. \"distance / stroke - touch\", not an empty string");
  }
  if (const json* v = find(doc, "seed")) def.seed = natural(*v, "/seed");
  if (const json* v = find(doc, "dt")) def.dt = positive(*v, "/dt", "dt");
  if (const json* v = find(doc, "arena")) read_arena(*v, def.arena);
  if (const json* v = find(doc, "effects")) read_effects(*v, def.effects);
  if (def.arena.boundary == sim::Boundary::walls)
    for (const sim::WallDef& w : sim::arena_walls(def.arena)) ids_.emplace(w.id, "");  // the engine's ids
  collect_categories(doc);
  if (const json* v = find(doc, "walls")) read_walls(*v, def.walls);
  if (const json* v = find(doc, "draw")) read_draw(*v, def.walls);
  if (const json* v = find(doc, "balls")) read_balls(*v, def.balls);
  explicit_balls_ = def.balls.size();
  if (const json* v = find(doc, "turtles")) read_turtles(*v, def.turtles, scene.programs);
  scene.colours = colours_;
  if (def.arena.boundary == sim::Boundary::periodic) {
    // A ray in a periodic arena wraps on until its range: one that meets nothing walks every cell
    // it crosses (a range of 1e308 never ended). 1000 periods is far past any sensor's use.
    const double most = 1000.0 * std::max(def.arena.width, def.arena.height);
    for (std::size_t k = 0; k < scene.programs.size(); ++k)
      for (std::size_t j = 0; j < scene.programs[k].senses.size(); ++j)
        if (scene.programs[k].senses[j].range > most)
          fail("/turtles/" + std::to_string(k) + "/senses/" + std::to_string(j),
               "range " + num(scene.programs[k].senses[j].range) + " in a periodic arena: at most 1000 times its longer "
               "side (" + num(most) + "), as a ray wraps round it until its range");
  }
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
    scene.game = read_game(*v, def, *this);

  // The scene without its gases first: gases are placed around the walls, balls and turtles,
  // which must therefore be sound.
  if (auto problem = sim::validate(def)) fail(path_of(*problem), problem->message);

  if (const json* v = find(doc, "gas")) {
    const std::vector<GasSpec> gases = read_gases(*v, def);
    std::size_t total = def.balls.size();
    for (const auto& g : gases) total += g.count;
    def.balls.reserve(total);
    for (std::size_t k = 0; k < gases.size(); ++k) {
      const GasSpec& gas = gases[k];
      gas_first_.push_back(def.balls.size());
      const std::size_t placed = place_gas(def, gas);
      if (placed < gas.count)
        fail(at("/gas", k), "could only place " + std::to_string(placed) + " of " + std::to_string(gas.count) +
                                " balls of radius " + num(gas.radius) + " in region [" + vec(gas.lo) + ", " +
                                vec(gas.hi) + "]; enlarge the region or reduce count/radius");
    }
    // Gases are placed clear of everything (and World validates again when it is built), so only
    // their generated ids remain to be checked; that needs only their prefixes, not a million strings.
    check_gas_ids(gases);
  }
  if (const json* v = find(doc, "views")) scene.views = read_views(*v, def);
  // Scripted test worlds (expect.hpp): read last, so that their ids can name any body.
  if (const json* v = find(doc, "expect")) {
    scene.expect = parse_expect(*v, file(), def);
    for (const auto& e : scene.expect.entries)
      if (e.kind == "it" && !scene.game)
        fail(at(at("/expect", e.index), "it"), "an \"it\" expectation needs a game; add \"game\": {\"kind\": \"tag\", ...}");
  }
  return scene;
}

}  // namespace detail

namespace {

using detail::json;

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
  if (const auto deep = turtle::json_too_deep(text)) throw WorldFileError(file, "", *deep + " (docs/worlds.md)");
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
  return detail::Reader(file, registry).read(doc, stem);
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
