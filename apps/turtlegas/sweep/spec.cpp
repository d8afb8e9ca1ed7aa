// SPDX-License-Identifier: MIT
// `turtlegas sweep`: the spec (docs/sweeps.md), read, checked and expanded into runs.
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
        k.rfind("x-", 0) != 0)
      throw bad("/" + k, "unknown key; a sweep spec has format, world, until, mode, seeds, grid, summary (and x-...)");
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
