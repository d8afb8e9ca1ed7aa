// SPDX-License-Identifier: MIT
#include "turtlegas/formats/engine_state.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>

namespace turtlegas::formats {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "turtlegas-engine-state/1";

/// A double that reads back to the same bits: nlohmann writes the shortest round-trip form, and
/// JSON has no infinities.
json number(double v) {
  if (std::isfinite(v)) return v;
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

/// Reads what number() wrote; `where` names it in the error.
double real(const json& j, const std::string& where) {
  if (j.is_number()) return j.get<double>();
  if (j.is_string()) {
    const std::string s = j.get<std::string>();
    if (s == "inf") return HUGE_VAL;
    if (s == "-inf") return -HUGE_VAL;
    if (s == "nan") return std::nan("");
  }
  throw std::invalid_argument(where + ": not a number");
}

template <class T>
T whole(const json& j, const std::string& where) {
  if (!j.is_number_unsigned()) throw std::invalid_argument(where + ": not a whole number >= 0");
  const auto v = j.get<std::uint64_t>();
  if (v > std::numeric_limits<T>::max()) throw std::invalid_argument(where + ": out of range");
  return static_cast<T>(v);
}

/// Row `j` of `width` entries, at `where`.
const json& row(const json& j, std::size_t width, const std::string& where) {
  if (!j.is_array() || j.size() != width)
    throw std::invalid_argument(where + ": not an array of " + std::to_string(width) + " entries");
  return j;
}

const json& key(const json& j, const char* k, const std::string& where) {
  if (!j.is_object() || !j.contains(k)) throw std::invalid_argument(where + "/" + k + ": missing");
  return j.at(k);
}

const json& array(const json& j, const char* k, const std::string& where) {
  const json& a = key(j, k, where);
  if (!a.is_array()) throw std::invalid_argument(where + "/" + k + ": not an array");
  return a;
}

// The columns of one body's row; the file names them (body_columns) so that it reads on its own.
constexpr const char* kBodyColumns[] = {"x",     "y",      "vx",      "vy",      "t",       "count",
                                        "cell",  "next",   "prev",    "t_coll",  "t_cross", "partner",
                                        "partner_count", "last", "kind", "cross_dir", "queued", "key"};
constexpr std::size_t kBodyWidth = std::size(kBodyColumns);

// The Stats counters, by name (the energies apart: doubles).
struct Counter {
  const char* name;
  std::uint64_t sim::Stats::*field;
};
constexpr Counter kCounters[] = {
    {"ball_ball", &sim::Stats::ball_ball},       {"ball_wall", &sim::Stats::ball_wall},
    {"ball_wall_end", &sim::Stats::ball_wall_end}, {"exits", &sim::Stats::exits},
    {"wedged", &sim::Stats::wedged},             {"crushed", &sim::Stats::crushed},
    {"folded", &sim::Stats::folded},             {"slides", &sim::Stats::slides},
    {"turtle_wall", &sim::Stats::turtle_wall},   {"turtle_wall_end", &sim::Stats::turtle_wall_end},
    {"turtle_turtle", &sim::Stats::turtle_turtle}, {"turtle_ball", &sim::Stats::turtle_ball},
    {"cell_crossings", &sim::Stats::cell_crossings}, {"stale", &sim::Stats::stale},
    {"steps", &sim::Stats::steps},               {"events", &sim::Stats::events},
};
struct Energy {
  const char* name;
  double sim::Stats::*field;
};
constexpr Energy kEnergies[] = {{"energy_wedged", &sim::Stats::energy_wedged},
                                {"energy_crushed", &sim::Stats::energy_crushed},
                                {"energy_folded", &sim::Stats::energy_folded}};

static_assert(sizeof(sim::Stats) == (std::size(kCounters) + std::size(kEnergies)) * sizeof(std::uint64_t),
              "Stats has a field the saved state does not carry: add it to kCounters or kEnergies");

json reals(const std::vector<double>& v) {
  json a = json::array();
  for (double x : v) a.push_back(number(x));
  return a;
}
std::vector<double> reals(const json& a, const std::string& where) {
  std::vector<double> v;
  v.reserve(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) v.push_back(real(a[i], where + "/" + std::to_string(i)));
  return v;
}

}  // namespace

json engine_state_json(const sim::EngineState& s) {
  json j;
  j["format"] = kFormat;
  j["variant"] = s.variant;
  j["now"] = number(s.now);
  j["t_base"] = number(s.t_base);
  j["events_since_rebase"] = s.events_since_rebase;
  j["walls"] = s.walls;
  j["body_columns"] = kBodyColumns;
  json bodies = json::array();
  for (const sim::EngineState::Body& b : s.bodies)
    bodies.push_back({number(b.x.x), number(b.x.y), number(b.v.x), number(b.v.y), number(b.t), b.count, b.cell, b.next,
                      b.prev, number(b.t_coll), number(b.t_cross), b.partner, b.partner_count, b.last, b.kind,
                      b.cross_dir, b.queued ? 1 : 0, number(b.key)});
  j["bodies"] = std::move(bodies);
  json held = json::array();
  for (const sim::EngineState::Held& h : s.held)
    held.push_back({h.a, h.b, h.count, h.count_a, h.count_b, h.straight ? 1 : 0, number(h.t)});
  j["held"] = std::move(held);
  j["last_time"] = reals(s.last_time);
  json slides = json::array();
  for (const sim::EngineState::Slide& sl : s.slides)
    slides.push_back({number(sl.a.x), number(sl.a.y), number(sl.p1.x), number(sl.p1.y), number(sl.u.x), number(sl.u.y),
                      number(sl.n.x), number(sl.n.y), number(sl.p2.x), number(sl.p2.y), number(sl.len), sl.wall});
  j["slides"] = std::move(slides);
  j["step"] = {{"index", s.step_index}, {"dmax", number(s.step_dmax)}, {"scan", s.step_scan},
               {"stamp", s.step_stamp}, {"travel", reals(s.step_travel)}};
  json stats = json::object();
  for (const Counter& c : kCounters) stats[c.name] = s.stats.*c.field;
  for (const Energy& e : kEnergies) stats[e.name] = number(s.stats.*e.field);
  j["stats"] = std::move(stats);
  j["max_contact"] = {number(s.max_contact.depth), number(s.max_contact.relative)};
  j["energy_taken"] = reals(s.energy_taken);
  return j;
}

sim::EngineState engine_state_from_json(const json& j) {
  const std::string w = "/engine";
  if (!j.is_object() || !j.contains("format") || j.at("format") != kFormat)
    throw std::invalid_argument(w + "/format: not \"" + std::string(kFormat) + "\"");
  sim::EngineState s;
  if (!key(j, "variant", w).is_string()) throw std::invalid_argument(w + "/variant: not a string");
  s.variant = j.at("variant").get<std::string>();
  s.now = real(key(j, "now", w), w + "/now");
  s.t_base = real(key(j, "t_base", w), w + "/t_base");
  s.events_since_rebase = whole<std::uint64_t>(key(j, "events_since_rebase", w), w + "/events_since_rebase");
  s.walls = whole<std::size_t>(key(j, "walls", w), w + "/walls");
  const json& bodies = array(j, "bodies", w);
  s.bodies.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::string at = w + "/bodies/" + std::to_string(i);
    const json& r = row(bodies[i], kBodyWidth, at);
    auto d = [&](std::size_t c) { return real(r[c], at + "/" + std::to_string(c)); };
    auto u = [&](std::size_t c) { return whole<std::uint32_t>(r[c], at + "/" + std::to_string(c)); };
    sim::EngineState::Body& b = s.bodies[i];
    b.x = {d(0), d(1)};
    b.v = {d(2), d(3)};
    b.t = d(4);
    b.count = u(5);
    b.cell = u(6);
    b.next = u(7);
    b.prev = u(8);
    b.t_coll = d(9);
    b.t_cross = d(10);
    b.partner = u(11);
    b.partner_count = u(12);
    b.last = u(13);
    b.kind = static_cast<std::uint8_t>(std::min<std::uint32_t>(u(14), 255));
    b.cross_dir = static_cast<std::uint8_t>(std::min<std::uint32_t>(u(15), 255));
    b.queued = u(16) != 0;
    b.key = d(17);
  }
  const json& held = array(j, "held", w);
  for (std::size_t i = 0; i < held.size(); ++i) {
    const std::string at = w + "/held/" + std::to_string(i);
    const json& r = row(held[i], 7, at);
    auto u = [&](std::size_t c) { return whole<std::uint32_t>(r[c], at + "/" + std::to_string(c)); };
    s.held.push_back({u(0), u(1), u(2), u(3), u(4), u(5) != 0, real(r[6], at + "/6")});
  }
  s.last_time = reals(array(j, "last_time", w), w + "/last_time");
  const json& slides = array(j, "slides", w);
  for (std::size_t i = 0; i < slides.size(); ++i) {
    const std::string at = w + "/slides/" + std::to_string(i);
    const json& r = row(slides[i], 12, at);
    auto d = [&](std::size_t c) { return real(r[c], at + "/" + std::to_string(c)); };
    s.slides.push_back({{d(0), d(1)}, {d(2), d(3)}, {d(4), d(5)}, {d(6), d(7)}, {d(8), d(9)}, d(10),
                        whole<std::uint32_t>(r[11], at + "/11")});
  }
  const json& step = key(j, "step", w);
  s.step_index = whole<std::uint64_t>(key(step, "index", w + "/step"), w + "/step/index");
  s.step_dmax = real(key(step, "dmax", w + "/step"), w + "/step/dmax");
  s.step_scan = whole<std::uint32_t>(key(step, "scan", w + "/step"), w + "/step/scan");
  const json& stamp = array(step, "stamp", w + "/step");
  for (std::size_t i = 0; i < stamp.size(); ++i)
    s.step_stamp.push_back(whole<std::uint32_t>(stamp[i], w + "/step/stamp/" + std::to_string(i)));
  s.step_travel = reals(array(step, "travel", w + "/step"), w + "/step/travel");
  const json& stats = key(j, "stats", w);
  for (const Counter& c : kCounters)
    s.stats.*c.field = whole<std::uint64_t>(key(stats, c.name, w + "/stats"), w + "/stats/" + c.name);
  for (const Energy& e : kEnergies) s.stats.*e.field = real(key(stats, e.name, w + "/stats"), w + "/stats/" + e.name);
  const json& mc = row(key(j, "max_contact", w), 2, w + "/max_contact");
  s.max_contact = {real(mc[0], w + "/max_contact/0"), real(mc[1], w + "/max_contact/1")};
  s.energy_taken = reals(array(j, "energy_taken", w), w + "/energy_taken");
  return s;
}

}  // namespace turtlegas::formats
