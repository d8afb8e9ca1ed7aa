// SPDX-License-Identifier: MIT
// The 3-D world file (docs/worlds.md, "3-D worlds"): the same top-level keys as turtlegas-world/1,
// with three numbers per vector, `arena.depth`, walls as convex polygons, and no turtles.
#include "turtlegas/world/world_file_3d.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "turtlegas/world/file_error.hpp"
#include "turtlegas/world/json_read.hpp"

namespace turtlegas::world {
namespace {

using nlohmann::json;

sim::Vec3 vec3(const JsonReader& rd, const json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3) rd.fail(path, "expected [x, y, z], three numbers, got " + rd.got(v));
  return {rd.number(v[0], path + "/0"), rd.number(v[1], path + "/1"), rd.number(v[2], path + "/2")};
}

// A moving wall's keys (docs/worlds.md, "Moving walls in 3-D"): [{"t": T, "corners": [...]}, ...],
// each pose the wall's corners translated, times > 0 and increasing, every pose in the arena.
void read_keys(const JsonReader& rd, const json& ks, const std::string& path, const sim::World3Def& def, sim::Wall3Def& wd) {
  rd.expect_array(ks, path, "keys");
  if (def.boundary == sim::Boundary3::periodic)
    rd.fail(path, "moving walls are not supported in a periodic arena (use \"boundary\": \"walls\" or \"none\")");
  double scale = 0.0;
  for (std::size_t c = 0; c < wd.corners.size(); ++c)
    scale = std::max(scale, sim::norm(wd.corners[(c + 1) % wd.corners.size()] - wd.corners[c]));
  for (std::size_t k = 0; k < ks.size(); ++k) {
    const std::string at = path + "/" + std::to_string(k);
    const json& key = ks[k];
    rd.expect_object(key, at, "a key");
    rd.check_keys(key, at, "a 3-D wall's key", {"t", "corners"});
    const double t = rd.positive(rd.require(key, at, "t", "a key"), at + "/t", "t");
    if (k > 0 && !(t > wd.keys.back().t))
      rd.fail(at + "/t", "key times must increase (got " + key["t"].dump() + " after " + std::to_string(wd.keys.back().t) + ")");
    const json& cs = rd.require(key, at, "corners", "a key (the wall's corners at t, [[x, y, z], ...])");
    rd.expect_array(cs, at + "/corners", "corners");
    if (cs.size() != wd.corners.size())
      rd.fail(at + "/corners", "a key lists the wall's " + std::to_string(wd.corners.size()) + " corners, in the same order (got " +
                                   std::to_string(cs.size()) + ")");
    sim::Vec3 shift;
    for (std::size_t c = 0; c < cs.size(); ++c) {
      const std::string cp = at + "/corners/" + std::to_string(c);
      const sim::Vec3 p = vec3(rd, cs[c], cp);
      for (int a = 0; a < 3; ++a)
        if (p[a] < 0.0 || p[a] > def.size[a]) rd.fail(cp, "the wall leaves the arena here (every pose's corners must lie in it)");
      if (c == 0) shift = p - wd.corners[0];
      else if (sim::norm(p - wd.corners[c] - shift) > 1e-9 * scale)
        rd.fail(cp, "a 3-D wall may only translate: every corner must move by corner 0's shift [" + std::to_string(shift.x) +
                        ", " + std::to_string(shift.y) + ", " + std::to_string(shift.z) + "] (turning or stretching is not simulated)");
    }
    wd.keys.push_back({t, shift});
  }
}

}  // namespace

bool is_world3_text(std::string_view text) {
  const json doc = json::parse(text.begin(), text.end(), nullptr, false);
  if (!doc.is_object()) return false;
  const auto it = doc.find("dimensions");
  return it != doc.end() && it->is_number() && it->get<double>() == 3.0;
}

World3File parse_world3(std::string_view text, std::string_view file_name) {
  const std::string file(file_name);
  const json doc = json::parse(text.begin(), text.end(), nullptr, false);
  if (doc.is_discarded()) throw WorldFileError(file, "", "invalid JSON");
  JsonReader rd(file, JsonReader::Wording::kind);
  rd.expect_object(doc, "", "a world file");
  if (doc.contains("turtles"))
    rd.fail("/turtles", "turtles stay in the plane: a 3-D world cannot have turtles (drop \"dimensions\": 3 or the turtles)");
  rd.check_keys(doc, "", "a 3-D world file",
                {"format", "dimensions", "name", "seed", "dt", "arena", "effects", "walls", "balls", "gas", "expect"});
  World3File out;
  if (const json* f = rd.find(doc, "format"); f && rd.string(*f, "/format") != "turtlegas-world/1")
    rd.fail("/format", "expected \"turtlegas-world/1\"");
  if (const json* n = rd.find(doc, "name")) out.name = rd.string(*n, "/name");
  std::uint64_t seed = 1;
  if (const json* s = rd.find(doc, "seed")) seed = rd.natural(*s, "/seed");
  sim::World3Def& def = out.def;
  if (const json* d = rd.find(doc, "dt")) def.dt = rd.positive(*d, "/dt", "dt");  // step mode's step

  const json& arena = rd.require(doc, "", "arena", "a world file");
  rd.expect_object(arena, "/arena", "the arena");
  rd.check_keys(arena, "/arena", "the arena", {"width", "height", "depth", "cell", "boundary"});
  def.size = {rd.positive(rd.require(arena, "/arena", "width", "the arena"), "/arena/width", "width"),
              rd.positive(rd.require(arena, "/arena", "height", "the arena"), "/arena/height", "height"),
              rd.positive(rd.require(arena, "/arena", "depth", "a 3-D arena"), "/arena/depth", "depth")};
  if (const json* c = rd.find(arena, "cell")) def.cell = rd.positive(*c, "/arena/cell", "cell");
  if (const json* b = rd.find(arena, "boundary")) {
    const std::string s = rd.string(*b, "/arena/boundary");
    if (s == "none") def.boundary = sim::Boundary3::none;
    else if (s == "walls") def.boundary = sim::Boundary3::walls;
    else if (s == "periodic") def.boundary = sim::Boundary3::periodic;
    else rd.fail("/arena/boundary", "expected \"none\", \"walls\" or \"periodic\", got \"" + s + "\"");
  }
  // A restitution: a number in [0, 1] (docs/physics.md, "3-D: restitution").
  auto restitution = [&](const json& v, const std::string& path) {
    const double e = rd.number(v, path);
    if (!(e >= 0.0 && e <= 1.0))
      rd.fail(path, "restitution must be in [0, 1] (got " + v.dump() + "); 1 is elastic, 0 perfectly inelastic");
    return e;
  };
  double scene_e = 1.0;  // every ball's and gas's restitution unless it gives its own
  if (const json* e = rd.find(doc, "effects")) {
    rd.expect_object(*e, "/effects", "effects");
    rd.check_keys(*e, "/effects", "effects", {"gravity", "electric", "magnetic", "restitution", "tc", "ball_ball"});
    if (const json* g = rd.find(*e, "gravity")) def.gravity = vec3(rd, *g, "/effects/gravity");
    if (const json* g = rd.find(*e, "electric")) def.electric = vec3(rd, *g, "/effects/electric");
    if (const json* m = rd.find(*e, "magnetic"); m && !(m->is_number() && m->get<double>() == 0.0)) {
      if (m->is_number())
        rd.fail("/effects/magnetic", "in 3-D the magnetic field is a vector, [Bx, By, Bz] (got " + m->dump() + ")");
      def.magnetic = vec3(rd, *m, "/effects/magnetic");
    }
    if (const json* r = rd.find(*e, "restitution")) scene_e = restitution(*r, "/effects/restitution");
    if (const json* t = rd.find(*e, "tc")) def.tc = rd.non_negative(*t, "/effects/tc");
    if (const json* b = rd.find(*e, "ball_ball"); b && !rd.boolean(*b, "/effects/ball_ball"))
      rd.fail("/effects/ball_ball", "3-D spheres always collide with each other for now: ball_ball must be true");
  }
  std::set<std::string> ids;
  auto take_id = [&](const json& obj, const std::string& path, const char* what) {
    const std::string id = rd.string(rd.require(obj, path, "id", what), path + "/id");
    if (!ids.insert(id).second) rd.fail(path + "/id", "id \"" + id + "\" is used twice; ids must be unique");
    return id;
  };
  if (const json* ws = rd.find(doc, "walls")) {
    rd.expect_array(*ws, "/walls", "walls");
    for (std::size_t k = 0; k < ws->size(); ++k) {
      const std::string path = "/walls/" + std::to_string(k);
      const json& w = (*ws)[k];
      rd.expect_object(w, path, "a wall");
      rd.check_keys(w, path, "a 3-D wall", {"id", "corners", "restitution", "keys"});
      out.wall_ids.push_back(take_id(w, path, "a wall"));
      const json& cs = rd.require(w, path, "corners", "a 3-D wall (its corners, [[x, y, z], ...], in order)");
      rd.expect_array(cs, path + "/corners", "corners");
      sim::Wall3Def wd;
      if (const json* r = rd.find(w, "restitution")) wd.restitution = restitution(*r, path + "/restitution");
      for (std::size_t c = 0; c < cs.size(); ++c) wd.corners.push_back(vec3(rd, cs[c], path + "/corners/" + std::to_string(c)));
      if (const json* ks = rd.find(w, "keys")) read_keys(rd, *ks, path + "/keys", def, wd);
      def.walls.push_back(wd);
      sim::World3Def one;
      one.size = def.size;
      one.boundary = def.boundary;
      one.walls.push_back(wd);
      if (const std::string bad = sim::check_world3(one); !bad.empty()) rd.fail(path, bad.substr(bad.find(": ") + 2));
    }
  }
  if (def.boundary == sim::Boundary3::walls)
    for (const char* id : {"arena-x0", "arena-x1", "arena-y0", "arena-y1", "arena-z0", "arena-z1"}) out.wall_ids.push_back(id);
  if (const json* bs = rd.find(doc, "balls")) {
    rd.expect_array(*bs, "/balls", "balls");
    for (std::size_t k = 0; k < bs->size(); ++k) {
      const std::string path = "/balls/" + std::to_string(k);
      const json& b = (*bs)[k];
      rd.expect_object(b, path, "a ball");
      rd.check_keys(b, path, "a 3-D ball", {"id", "pos", "vel", "radius", "mass", "charge", "restitution"});
      out.ball_ids.push_back(take_id(b, path, "a ball"));
      sim::Sphere3Def s;
      s.pos = vec3(rd, rd.require(b, path, "pos", "a ball"), path + "/pos");
      if (const json* v = rd.find(b, "vel")) s.vel = vec3(rd, *v, path + "/vel");
      s.radius = rd.positive(rd.require(b, path, "radius", "a ball"), path + "/radius", "radius");
      if (const json* m = rd.find(b, "mass")) s.mass = rd.positive(*m, path + "/mass", "mass");
      if (const json* q = rd.find(b, "charge")) s.charge = rd.number(*q, path + "/charge");
      s.restitution = rd.find(b, "restitution") ? restitution(b["restitution"], path + "/restitution") : scene_e;
      for (int a = 0; a < 3; ++a)
        if (s.pos[a] < 0.0 || s.pos[a] >= def.size[a])
          rd.fail(path + "/pos", "lies outside the arena [0, width) x [0, height) x [0, depth)");
      def.spheres.push_back(s);
    }
  }
  if (const json* gs = rd.find(doc, "gas")) {
    rd.expect_array(*gs, "/gas", "gas");
    for (std::size_t k = 0; k < gs->size(); ++k) {
      const std::string path = "/gas/" + std::to_string(k);
      const json& g = (*gs)[k];
      rd.expect_object(g, path, "a gas");
      rd.check_keys(g, path, "a 3-D gas", {"count", "radius", "mass", "charge", "speed", "region", "seed", "id_prefix", "restitution"});
      const std::uint64_t count = rd.natural(rd.require(g, path, "count", "a gas"), path + "/count");
      const double r = rd.positive(rd.require(g, path, "radius", "a gas"), path + "/radius", "radius");
      const double mass = rd.find(g, "mass") ? rd.positive(g["mass"], path + "/mass", "mass") : 1.0;
      const double charge = rd.find(g, "charge") ? rd.number(g["charge"], path + "/charge") : 0.0;
      const double speed = rd.find(g, "speed") ? rd.non_negative(g["speed"], path + "/speed") : 0.0;
      const double ge = rd.find(g, "restitution") ? restitution(g["restitution"], path + "/restitution") : scene_e;
      sim::Vec3 lo{0, 0, 0}, hi = def.size;
      if (const json* reg = rd.find(g, "region")) {
        if (!reg->is_array() || reg->size() != 2) rd.fail(path + "/region", "expected [[x0, y0, z0], [x1, y1, z1]]");
        lo = vec3(rd, (*reg)[0], path + "/region/0");
        hi = vec3(rd, (*reg)[1], path + "/region/1");
      }
      const std::uint64_t gseed = rd.find(g, "seed") ? rd.natural(g["seed"], path + "/seed") : seed + k;
      const std::string prefix = rd.find(g, "id_prefix") ? rd.string(g["id_prefix"], path + "/id_prefix") : "g";
      std::mt19937_64 gen(gseed);
      auto u = [&](double a, double b) { return a + (b - a) * static_cast<double>(gen() >> 11) * 0x1.0p-53; };
      const std::size_t first = def.spheres.size();
      for (std::uint64_t n = 0; n < count; ++n) {
        bool placed = false;
        for (int tries = 0; tries < 10000 && !placed; ++tries) {
          sim::Vec3 x;
          for (int a = 0; a < 3; ++a) x[a] = u(std::max(lo[a], r), std::min(hi[a], def.size[a]) - r);
          bool ok = true;
          for (std::size_t j = 0; j < def.spheres.size() && ok; ++j)
            ok = sim::norm(def.spheres[j].pos - x) > def.spheres[j].radius + r;
          for (std::size_t w = 0; w < def.walls.size() && ok; ++w)  // nor into a wall
            ok = sim::distance_to_polygon(x, def.walls[w].corners) > r;
          if (!ok) continue;
          const double cz = u(-1, 1), phi = u(0, 6.283185307179586), sz = std::sqrt(1 - cz * cz);
          def.spheres.push_back({x, {speed * sz * std::cos(phi), speed * sz * std::sin(phi), speed * cz}, r, mass, charge, ge});
          placed = true;
        }
        if (!placed)
          rd.fail(path + "/count", "cannot place sphere " + std::to_string(n) + " of " + std::to_string(count) +
                                       " without overlap in the region: use fewer or smaller spheres, or a larger region");
        const std::string id = prefix + std::to_string(def.spheres.size() - first);
        if (!ids.insert(id).second) rd.fail(path + "/id_prefix", "the gas's id \"" + id + "\" is used twice");
        out.ball_ids.push_back(id);
      }
    }
  }
  if (const std::string bad = sim::check_world3(def); !bad.empty()) rd.fail("", bad);
  return out;
}

}  // namespace turtlegas::world
