// SPDX-License-Identifier: MIT
// The loader's gases: their specs (placed by gas.cpp after the rest of the scene is checked), and
// the ids they generate, checked against every other id without making a million strings.
#include <algorithm>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "reader.hpp"

namespace turtlegas::world::detail {

std::vector<GasSpec> Reader::read_gases(const json& v, const sim::WorldDef& def) {
  const std::string path = "/gas";
  expect_array(v, path, "gas");
  std::vector<GasSpec> out;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const std::string p = at(path, k);
    const json& g = v[k];
    expect_object(g, p, "a gas");
    check_keys(g, p, "a gas", {"count", "radius", "mass", "charge", "speed", "temperature", "region", "seed", "id_prefix", "category", "collides_with"});
    GasSpec gas;
    const std::uint64_t count = natural(require(g, p, "count", "a gas"), at(p, "count"));
    constexpr std::uint64_t max_count = 100'000'000;
    if (count > max_count)
      fail(at(p, "count"), "count " + std::to_string(count) + " is more than this loader places (" +
                               std::to_string(max_count) + "); split the gas or use fewer, larger balls");
    gas.count = static_cast<std::size_t>(count);
    gas.radius = positive(require(g, p, "radius", "a gas"), at(p, "radius"), "radius");
    if (const json* x = find(g, "mass")) gas.mass = positive(*x, at(p, "mass"), "mass");
    if (const json* x = find(g, "charge")) gas.charge = number(*x, at(p, "charge"));
    const json* temperature = find(g, "temperature");
    if (temperature && find(g, "speed"))
      fail(at(p, "temperature"), "a gas has either \"speed\" (every ball at it) or \"temperature\" (Maxwell-Boltzmann "
                                 "velocities at that kT), not both; leave one out");
    if (temperature) {
      gas.temperature = positive(*temperature, at(p, "temperature"), "temperature");
      if (count < 2)
        fail(at(p, "temperature"), "a thermal gas needs at least 2 balls (its total momentum is 0); give \"count\" >= 2 "
                                   "or a \"speed\"");
    } else {
      if (!find(g, "speed"))
        fail(p, "a gas needs \"speed\" (every ball at that speed, random directions) or \"temperature\" (kT: "
                "Maxwell-Boltzmann velocities)");
      gas.speed = number(*find(g, "speed"), at(p, "speed"));
      if (gas.speed < 0.0) fail(at(p, "speed"), "speed must be >= 0 (got " + num(gas.speed) + "); directions are random");
    }
    gas.lo = {0.0, 0.0};
    gas.hi = {def.arena.width, def.arena.height};
    if (const json* r = find(g, "region")) {
      const std::string rp = at(p, "region");
      const std::string shape = "expected [[x0, y0], [x1, y1]] (two corners), got ";
      if (!r->is_array()) fail(rp, shape + json_kind(*r));
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
    centre_range(gas, def.arena, lo, hi);
    if (lo.x > hi.x || lo.y > hi.y)
      fail(at(p, "region"), "balls of radius " + num(gas.radius) + " do not fit in region [" + vec(gas.lo) + ", " +
                                vec(gas.hi) + "] inside the arena; enlarge the region or reduce radius");
    out.push_back(std::move(gas));
  }
  return out;
}

namespace {

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

}  // namespace

void Reader::check_gas_ids(const std::vector<GasSpec>& gases) const {
  // Gas k's ids are id_prefix + n for n < count. One collides with an explicit id when that id is
  // the prefix followed by such an n.
  for (std::size_t k = 0; k < gases.size(); ++k) {
    const GasSpec& g = gases[k];
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
      const GasSpec &ga = gases[a], &gb = gases[b];
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

}  // namespace turtlegas::world::detail
