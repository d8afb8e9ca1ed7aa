// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the spec (docs/sweeps.md), read, checked and expanded into runs.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "sweep/sweep.hpp"
#include "turtlegas/formats/stats_file.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::apps::sweep {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const std::string& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw BadInput(file + ": no such file (" + what + ")");
  std::stringstream s;
  s << in.rdbuf();
  return std::move(s).str();
}

/// A JSON pointer's reference tokens, unescaped (RFC 6901: ~1 is /, ~0 is ~).
std::vector<std::string> tokens_of(const std::string& pointer) {
  std::vector<std::string> out;
  std::size_t at = 1;
  while (at <= pointer.size() && !pointer.empty()) {
    const std::size_t next = std::min(pointer.find('/', at), pointer.size());
    std::string t = pointer.substr(at, next - at);
    for (std::size_t i = 0; (i = t.find('~', i)) != std::string::npos; ++i) t.replace(i, 2, t[i + 1] == '1' ? "/" : "~");
    out.push_back(t);
    at = next + 1;
  }
  return out;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

/// Each summary pointer against the shape of a result line, before any run: a misspelt one is
/// named now, not after the sweep (where it would have been a column of "-").
void check_summary(const Spec& spec, const std::string& file) {
  // The keys of "stats" do not depend on the world: those of an empty one.
  sim::WorldDef empty;
  empty.arena.width = empty.arena.height = 1.0;
  const json stats = formats::stats_json(formats::RunFigures{}, sim::World(empty, sim::Mode::exact));
  bool game = spec.world.contains("game"), expect = spec.world.contains("expect");
  for (const auto& [ptr, values] : spec.grid) {
    game = game || ptr.rfind("/game", 0) == 0;
    expect = expect || ptr.rfind("/expect", 0) == 0;
  }
  std::vector<std::string> tops{"run", "seed", "overrides", "stats"};
  if (game) tops.push_back("tag");
  if (expect) tops.push_back("expect");
  if (spec.observe) tops.push_back("observables");
  for (const std::string& p : spec.summary) {
    const std::vector<std::string> t = tokens_of(p);
    auto bad = [&](const std::string& why) {
      return BadInput(file + ": /summary: \"" + p + "\" is in no result line: " + why + " (docs/sweeps.md, \"Results\")");
    };
    if (t.empty()) throw bad("the empty pointer is the whole line, not a number");
    if (std::find(tops.begin(), tops.end(), t[0]) == tops.end())
      throw bad("a line has " + joined(tops) +
                (t[0] == "tag" ? " (\"tag\" with a game)" : t[0] == "expect" ? " (\"expect\" with an expect list)"
                 : t[0] == "observables" ? " (\"observables\" when the spec has \"observe\")" : ""));
    if (t.size() == 1 && t[0] != "run" && t[0] != "seed")
      throw BadInput(file + ": /summary: \"" + p + "\" points at an object in the result lines, not a number: name one "
                     "inside it (\"" + p + "/...\"; docs/sweeps.md, \"Results\")");
    if (t[0] == "stats" && t.size() > 1 && !stats.contains(t[1])) {
      std::vector<std::string> keys;
      for (const auto& [k, v] : stats.items())
        if (k != "wall_seconds" && k != "collisions_per_second") keys.push_back(k);
      throw bad("\"stats\" has " + joined(keys));
    }
    if (t[0] == "overrides" && t.size() > 1) {
      std::vector<std::string> keys;
      for (const auto& [ptr, values] : spec.grid) keys.push_back(ptr);
      if (std::find(keys.begin(), keys.end(), t[1]) == keys.end())
        throw bad("\"overrides\" has the grid's pointers: " + (keys.empty() ? std::string("none") : joined(keys)) +
                  " (escaped in a pointer: /overrides/~1gas~10~1count for /gas/0/count)");
    }
    if (t[0] == "observables" && !spec.observe_full && t.size() > 1 && t[1] != "summary" && t[1] != "species")
      throw bad("\"observables\" has summary and species (the rest with \"observe\": {\"full\": true})");
    if (t[0] == "observables" && t.size() > 2 && t[1] == "summary") {
      const std::vector<std::string> keys{"kT", "mean_speed", "collision_rate", "wall_collision_rate",
                                          "mean_free_path", "number_density", "pressure_walls", "pressure_virial",
                                          "Z_virial", "pressure_canonical", "Z_canonical", "D_msd", "D_green_kubo",
                                          "g_contact"};
      if (std::find(keys.begin(), keys.end(), t[2]) == keys.end())
        throw bad("\"observables/summary\" has " + joined(keys) + ", each {\"mean\", \"error\"}");
    }
  }
}

/// The spec's "observe" object: the options of `run --observe`, by their names there.
void read_observe(Spec& spec, const nlohmann::ordered_json& o, const std::string& file) {
  auto bad = [&](const std::string& path, const std::string& what) {
    return BadInput(file + ": /observe" + path + ": " + what);
  };
  if (!o.is_object()) throw bad("", "an object: {\"from\": T, \"window\": S, \"samples\": K, ...} (docs/sweeps.md)");
  formats::ObserveOptions opt;
  for (const auto& item : o.items()) {
    const std::string& k = item.key();  // (not a structured binding: the lambdas below use them, clang 14)
    const auto& v = item.value();
    auto number = [&] {
      if (!v.is_number()) throw bad("/" + k, "a number");
      return v.get<double>();
    };
    auto count = [&] {
      if (!v.is_number_integer() || v.get<std::int64_t>() < 1 || v.get<std::int64_t>() > 1000000)
        throw bad("/" + k, "an integer from 1 to 1000000");
      return static_cast<int>(v.get<std::int64_t>());
    };
    if (k == "from") opt.from = number();
    else if (k == "window") opt.window = number();
    else if (k == "samples") opt.samples = count();
    else if (k == "bins") opt.profile_bins = count();
    else if (k == "speed_bins") opt.speed_bins = count();
    else if (k == "rdf_bins") opt.rdf_bins = count();
    else if (k == "rdf_max") opt.rdf_max = number();
    else if (k == "axis") {
      if (!v.is_string() || (v != "x" && v != "y")) throw bad("/axis", "\"x\" or \"y\"");
      opt.axis = v.get<std::string>()[0];
    } else if (k == "full") {
      if (!v.is_boolean()) throw bad("/full", "true or false");
      spec.observe_full = v.get<bool>();
    } else {
      throw bad("/" + k, "unknown key; observe has from, window, samples, axis, bins, speed_bins, rdf_bins, rdf_max, full");
    }
  }
  if (const std::string why = formats::check_observe(opt, 0.0, spec.until); !why.empty()) throw bad("", why);
  const json& turtles = spec.world.contains("turtles") ? spec.world["turtles"] : json::array();
  if (turtles.is_array() && !turtles.empty())
    throw bad("", "observe measures a gas run by the bare engine; " + spec.world_file + " has turtles");
  spec.observe = opt;
}

}  // namespace

Spec parse_spec(const std::string& file, const Inputs* given) {
  Spec spec;
  spec.file = file;
  // The spec's own keys keep their order (grid axes are expanded in the order written).
  spec.bytes.spec = given ? given->spec : read_bytes(file, "the sweep spec");
  if (const auto deep = turtle::json_too_deep(spec.bytes.spec)) throw BadInput(file + ": " + *deep + " (the sweep spec)");
  spec.text = nlohmann::ordered_json::parse(spec.bytes.spec, nullptr, false);
  if (spec.text.is_discarded()) throw BadInput(file + ": invalid JSON (the sweep spec)");
  const nlohmann::ordered_json& ordered = spec.text;
  auto bad = [&](const std::string& path, const std::string& what) { return BadInput(file + ": " + path + ": " + what); };
  if (!ordered.is_object()) throw bad("/", "a sweep spec is a JSON object");
  for (const auto& [k, v] : ordered.items())
    if (k != "format" && k != "world" && k != "until" && k != "mode" && k != "seeds" && k != "grid" && k != "summary" &&
        k != "observe" && k.rfind("x-", 0) != 0)
      throw bad("/" + k, "unknown key; a sweep spec has format, world, until, mode, seeds, grid, summary, observe (and x-...)");
  if (ordered.value("format", "") != "turtlegas-sweep/1") throw bad("/format", "must be \"turtlegas-sweep/1\"");
  if (!ordered.contains("world") || !ordered["world"].is_string())
    throw bad("/world", "the world file to sweep, relative to this file");
  const fs::path world_path = fs::path(ordered["world"].get<std::string>());
  spec.world_file = (world_path.is_absolute() ? world_path : fs::path(file).parent_path() / world_path).lexically_normal().string();
  spec.bytes.world = given ? given->world : read_bytes(spec.world_file, "the world of sweep " + file);
  if (const auto deep = turtle::json_too_deep(spec.bytes.world))
    throw BadInput(spec.world_file + ": " + *deep + " (the world of sweep " + file + ")");
  spec.world = json::parse(spec.bytes.world, nullptr, false);
  if (spec.world.is_discarded()) throw BadInput(spec.world_file + ": invalid JSON (the world of sweep " + file + ")");
  if (!ordered.contains("until") || !ordered["until"].is_number() || !std::isfinite(ordered["until"].get<double>()) ||
      ordered["until"].get<double>() <= 0.0)
    throw bad("/until", "simulated seconds per run, a number > 0");
  spec.until = ordered["until"].get<double>();
  const std::string mode = ordered.value("mode", "exact");
  const auto m = sim::mode_from_string(mode);
  if (!m) throw bad("/mode", "exact or step (got \"" + mode + "\")");
  spec.mode = *m;
  const auto& seeds = ordered.contains("seeds") ? ordered["seeds"] : nlohmann::ordered_json();
  if (seeds.is_array() && !seeds.empty()) {
    for (const auto& s : seeds) {
      if (!s.is_number_unsigned()) throw bad("/seeds", "a list of seeds, integers >= 0");
      spec.seeds.push_back(s.get<std::uint64_t>());
    }
  } else if (seeds.is_object() && seeds.contains("count") && seeds["count"].is_number_unsigned() &&
             seeds["count"].get<std::uint64_t>() >= 1) {
    const std::uint64_t first = seeds.value("first", std::uint64_t{1});
    for (std::uint64_t k = 0; k < seeds["count"].get<std::uint64_t>() && k < max_runs; ++k) spec.seeds.push_back(first + k);
  } else {
    throw bad("/seeds", "a list of seeds, [1, 2, 3], or {\"count\": N, \"first\": 1}");
  }
  std::set<std::uint64_t> distinct(spec.seeds.begin(), spec.seeds.end());
  if (distinct.size() != spec.seeds.size()) throw bad("/seeds", "a seed is named twice");
  if (ordered.contains("grid")) {
    if (!ordered["grid"].is_object()) throw bad("/grid", "an object, JSON pointer -> list of values");
    for (const auto& [ptr, values] : ordered["grid"].items()) {
      const std::string path = "/grid/" + ptr;
      if (!values.is_array() || values.empty()) throw bad(path, "a non-empty list of values");
      std::vector<json> vs;
      for (const auto& v : values) {
        json probe = spec.world;
        try {
          probe[json::json_pointer(ptr)] = json::parse(v.dump());
        } catch (const json::exception& e) {
          throw bad(path, "not a JSON pointer into the world file (" + std::string(e.what()) + ")");
        }
        vs.push_back(json::parse(v.dump()));
      }
      spec.grid.emplace_back(ptr, std::move(vs));
    }
  }
  if (ordered.contains("summary")) {
    if (!ordered["summary"].is_array()) throw bad("/summary", "a list of JSON pointers into a result line");
    for (const auto& p : ordered["summary"]) {
      if (!p.is_string()) throw bad("/summary", "a list of JSON pointers into a result line");
      try {
        json::json_pointer check(p.get<std::string>());
      } catch (const json::exception&) {
        throw bad("/summary", "\"" + p.get<std::string>() + "\" is not a JSON pointer");
      }
      spec.summary.push_back(p.get<std::string>());
    }
  } else {
    spec.summary = {"/stats/collisions", "/stats/energy_end"};
  }
  std::size_t points = 1;
  for (const auto& [ptr, values] : spec.grid) {
    points *= values.size();
    if (points > max_runs) throw bad("/grid", "more than " + std::to_string(max_runs) + " runs");
  }
  spec.runs = points * spec.seeds.size();
  if (spec.runs > max_runs) throw bad("/seeds", "more than " + std::to_string(max_runs) + " runs");
  if (ordered.contains("observe")) read_observe(spec, ordered["observe"], file);
  check_summary(spec, file);
  return spec;
}
/// Run k's grid point (one value index per axis, the first axis slowest) and seed.
std::pair<std::vector<std::size_t>, std::uint64_t> decompose(const Spec& spec, std::size_t k) {
  const std::uint64_t seed = spec.seeds[k % spec.seeds.size()];
  std::size_t g = k / spec.seeds.size();
  std::vector<std::size_t> idx(spec.grid.size());
  for (std::size_t a = spec.grid.size(); a-- > 0;) {
    idx[a] = g % spec.grid[a].second.size();
    g /= spec.grid[a].second.size();
  }
  return {idx, seed};
}

json overrides_of(const Spec& spec, const std::vector<std::size_t>& idx) {
  json o = json::object();
  for (std::size_t a = 0; a < spec.grid.size(); ++a) o[spec.grid[a].first] = spec.grid[a].second[idx[a]];
  return o;
}

}  // namespace turtlegas::apps::sweep
