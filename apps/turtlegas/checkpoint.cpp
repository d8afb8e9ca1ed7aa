// SPDX-License-Identifier: MIT
#include "checkpoint.hpp"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "version_info.hpp"
#include "turtlegas/formats/engine_state.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::apps {
namespace {

constexpr const char* checkpoint_format = "turtlegas-checkpoint/1";

// Hashes as 16 hex digits: a JSON number would lose their low bits in most readers.
std::string hex(std::uint64_t v) {
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

}  // namespace

std::string engine_build() { return std::string(version_string) + " " + version_commit; }

std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::uint64_t file_hash(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BadInput(what + " " + path + ": cannot read it");
  std::ostringstream s;
  s << in.rdbuf();
  return fnv1a64(s.str());
}

void write_checkpoint(std::ostream& out, const Checkpoint& c) {
  nlohmann::json j = {
      {"format", checkpoint_format},
      {"world", c.world},
      {"world_fnv1a", hex(c.world_hash)},
      {"mode", sim::to_string(c.mode).data()},
      {"dt", c.dt},
      {"t", c.t},
      {"events", c.events},
      {"state_fnv1a", hex(c.state_hash)},
      {"why", c.why},
      {"resume", "turtlegas run " + c.world + " --resume THIS_FILE --until T: " +
                     (c.engine ? "builds the world from the engine state below, checks it, and goes on"
                               : "replays the run to t without outputs, checks the state there, and goes on")},
  };
  if (c.engine) {
    j["engine"] = formats::engine_state_json(*c.engine);
    j["engine_build"] = c.engine_build;
  }
  // Its own hash: a checkpoint edited or cut is told from a run that does not replay.
  j["fnv1a"] = hex(fnv1a64(j.dump()));
  // A key a line; the values on one line each (the engine's state is long: indenting it would
  // double the file).
  out << "{\n";
  bool first = true;
  for (const auto& [key, value] : j.items()) {
    out << (first ? "" : ",\n") << "  " << nlohmann::json(key).dump() << ": " << value.dump();
    first = false;
  }
  out << "\n}\n";
}

Checkpoint read_checkpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BadInput("--resume " + path + ": no such file, or it cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  if (const auto deep = turtle::json_too_deep(text.str())) throw BadInput("--resume " + path + ": not a checkpoint: " + *deep);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::exception& e) {
    throw BadInput("--resume " + path + ": not a checkpoint (invalid JSON: " + e.what() + ")");
  }
  const std::string where = "--resume " + path + ": ";
  if (!j.is_object() || j.value("format", std::string()) != checkpoint_format)
    throw BadInput(where + "not a checkpoint: /format must be \"" + checkpoint_format +
                   "\" (write one with run --checkpoint F)");
  if (j.contains("fnv1a")) {  // checkpoints before it have none
    // Taken out rather than copied: an engine state makes the rest long.
    const nlohmann::json own = std::move(j["fnv1a"]);
    j.erase("fnv1a");
    if (!own.is_string() || own.get<std::string>() != hex(fnv1a64(j.dump())))
      throw BadInput(where + "the checkpoint is damaged: its contents do not match its own hash (/fnv1a); it was "
                     "edited or cut. Resume from an undamaged copy, or rerun from the start");
  }
  Checkpoint c;
  auto field = [&](const char* key) -> const nlohmann::json& {
    if (!j.contains(key)) throw BadInput(where + "/" + key + ": missing; the checkpoint is damaged");
    return j.at(key);
  };
  auto hash = [&](const char* key) {
    const nlohmann::json& v = field(key);
    std::uint64_t h = 0;
    if (!v.is_string() || std::sscanf(v.get<std::string>().c_str(), "%" SCNx64, &h) != 1)
      throw BadInput(where + "/" + key + ": not a hash; the checkpoint is damaged");
    return h;
  };
  try {
    c.world = field("world").get<std::string>();
    c.world_hash = hash("world_fnv1a");
    const auto mode = sim::mode_from_string(field("mode").get<std::string>());
    if (!mode) throw BadInput(where + "/mode: not exact or step; the checkpoint is damaged");
    c.mode = *mode;
    c.dt = field("dt").get<double>();
    c.t = field("t").get<double>();
    c.events = field("events").get<std::uint64_t>();
    c.state_hash = hash("state_fnv1a");
    c.why = j.value("why", std::string());
    if (j.contains("engine")) {
      try {
        c.engine = formats::engine_state_from_json(j.at("engine"));
        c.engine_build = field("engine_build").get<std::string>();
      } catch (const std::invalid_argument& e) {
        throw BadInput(where + e.what() + "; the checkpoint is damaged");
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw BadInput(where + "a key has the wrong type (" + e.what() + "); the checkpoint is damaged");
  }
  if (!(c.t >= 0.0) || !(c.dt > 0.0)) throw BadInput(where + "/t or /dt out of range; the checkpoint is damaged");
  return c;
}

}  // namespace turtlegas::apps
