// SPDX-License-Identifier: MIT
#include "turtlegas/formats/recording.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/formats/json_text.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::formats {
namespace {

using nlohmann::json;

bool starts_with(std::string_view s, std::string_view p) { return s.substr(0, p.size()) == p; }

}  // namespace

RecordingWriter::RecordingWriter(std::ostream& out, const RecordingHeader& h) : out_(out), policy_(h.keyframes) {
  // Ordered, so that the format comes first (nlohmann::json sorts its keys).
  nlohmann::ordered_json header = {
      {"format", recording_format},
      {"command", h.command},
      {"world_file", h.world_file},
      {"mode", h.mode},
      {"dt", h.dt},
      {"until", h.until ? nlohmann::ordered_json(*h.until) : nlohmann::ordered_json(nullptr)},
      {"keyframes", {{"every_seconds", h.keyframes.seconds}, {"every_events", h.keyframes.events}}},
      {"world", h.world},
  };
  if (h.plugins.is_array() && !h.plugins.empty()) header["plugins"] = h.plugins;
  buf_ = header.dump();
  buf_ += '\n';
  put();
}

void RecordingWriter::events(std::span<const turtle::LogEvent> events) {
  buf_.clear();
  for (const turtle::LogEvent& e : events) append_event(buf_, event_line(e));
  lines_ += events.size();
  put();
}

void RecordingWriter::input(std::string_view line) {
  buf_.assign(line);
  put();
}

void RecordingWriter::put() {
  out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
  offset_ += buf_.size();
}

bool RecordingWriter::keyframe_due(std::uint64_t engine_events) const {
  if (index_.empty()) return true;
  return policy_.events > 0 && engine_events - last_events_ >= policy_.events;
}

void RecordingWriter::keyframe(const sim::World& world, const RunNames& names) {
  if (!index_.empty() && world.time() == index_.back().t) return;  // one keyframe a time
  std::ostringstream state;
  write_state(state, world, names);
  std::string text = state.str();
  // The state file's layout has newlines between bodies; a recording has one line a keyframe.
  // (Ids are JSON strings, whose control characters are escaped, so every raw newline is layout.)
  std::erase(text, '\n');
  const std::vector<sim::WallDef>& walls = world.walls();
  if (!base_walls_) base_walls_ = walls.size();
  buf_ = "{\"keyframe\": " + std::to_string(index_.size()) + ", \"t\": ";
  append_number(buf_, world.time());
  buf_ += ", \"events\": " + std::to_string(world.stats().events) + ", \"lines\": " + std::to_string(lines_) +
          ", \"walls\": " + std::to_string(walls.size()) + ", \"added_walls\": [";
  for (std::size_t i = *base_walls_; i < walls.size(); ++i) {
    if (i > *base_walls_) buf_ += ", ";
    buf_ += '[';
    append_number(buf_, walls[i].from.x);
    buf_ += ", ";
    append_number(buf_, walls[i].from.y);
    buf_ += ", ";
    append_number(buf_, walls[i].to.x);
    buf_ += ", ";
    append_number(buf_, walls[i].to.y);
    buf_ += ']';
  }
  buf_ += "], \"state\": " + text + "}\n";
  index_.push_back({world.time(), offset_, lines_, world.stats().events});
  last_events_ = world.stats().events;
  put();
  out_.flush();
}

void RecordingWriter::finish(double t, const std::string& stopped) {
  using ojson = nlohmann::ordered_json;
  ojson entries = ojson::array();
  for (const Entry& e : index_) entries.push_back({{"t", e.t}, {"offset", e.offset}, {"lines", e.lines}, {"events", e.events}});
  const std::uint64_t at = offset_;
  buf_ = ojson{{"index", entries}, {"end", t}, {"lines", lines_}, {"stopped", stopped}}.dump() + "\n";
  buf_ += "{\"end_of_recording\": " + std::to_string(at) + "}\n";
  put();
  out_.flush();
}

namespace {

/// json::parse, with a line nested deeper than turtle::max_json_depth thrown out as damaged: it
/// throws json::parse_error as an unfinished line does (the readers treat both alike).
json parse_capped(const std::string& line) {
  if (turtle::json_too_deep(line)) return json::parse("[");
  return json::parse(line);
}

RecordingHeader parse_header(const std::string& line, const std::string& path) {
  const std::string where = path + ": ";
  if (const auto deep = turtle::json_too_deep(line))
    throw std::invalid_argument(where + "its header (the first line) is " + *deep);
  nlohmann::ordered_json h;
  try {
    h = nlohmann::ordered_json::parse(line);
  } catch (const json::exception&) {
    throw std::invalid_argument(where + "not a recording (its first line is not JSON); write one with `turtlegas run "
                                        "WORLD --until T --record R.tgrec`");
  }
  if (!h.is_object() || h.value("format", std::string()) != recording_format)
    throw std::invalid_argument(where + "not a recording: /format must be \"" + std::string(recording_format) +
                                "\" (write one with `turtlegas run WORLD --until T --record R.tgrec`)");
  RecordingHeader r;
  try {
    r.world_file = h.at("world_file").get<std::string>();
    r.world = h.at("world");
    r.mode = h.at("mode").get<std::string>();
    r.dt = h.at("dt").get<double>();
    if (!h.at("until").is_null()) r.until = h.at("until").get<double>();
    r.command = h.value("command", std::string("run"));
    r.keyframes.seconds = h.at("keyframes").at("every_seconds").get<double>();
    r.keyframes.events = h.at("keyframes").at("every_events").get<std::uint64_t>();
    if (const auto p = h.find("plugins"); p != h.end()) {
      for (const auto& e : *p) (void)e.at("file").get<std::string>(), (void)e.at("controllers").get<std::vector<std::string>>();
      r.plugins = *p;
    }
  } catch (const json::exception& e) {
    throw std::invalid_argument(where + "the header (line 1) lacks a key or has one of the wrong type (" +
                                std::string(e.what()) + "); the recording is damaged");
  }
  if (!r.world.is_object()) throw std::invalid_argument(where + "/world: not an object; the recording is damaged");
  return r;
}

Keyframe parse_keyframe(const json& j) {
  Keyframe k;
  k.t = j.at("t").get<double>();
  k.events = j.at("events").get<std::uint64_t>();
  k.lines = j.at("lines").get<std::uint64_t>();
  return k;
}

std::string human_bytes(std::uint64_t b) {
  std::ostringstream s;
  if (b < 10000) s << b << " bytes";
  else s << (b + 512) / 1024 << " KiB";
  return s.str();
}

}  // namespace

Recording read_recording(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": no such file, or it cannot be read");
  Recording r;
  in.seekg(0, std::ios::end);
  r.bytes = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  std::string line;
  // Every line of a recording opens with '{': anything else (a zero-filled tail a crash left) is not
  // read as a line, which for an unterminated tail of GB took all memory.
  if (in.peek() != '{' || !std::getline(in, line) || in.eof())
    throw std::invalid_argument(path + ": not a recording, or cut before the end of its header (line 1)");
  r.header = parse_header(line, path);
  const std::uint64_t header_end = line.size() + 1;

  // The fast way: the last line names the index's offset.
  if (r.bytes > header_end) {
    const std::uint64_t tail = std::min<std::uint64_t>(r.bytes - header_end, 64);
    std::string last(tail, '\0');
    in.clear();
    in.seekg(static_cast<std::streamoff>(r.bytes - tail));
    in.read(last.data(), static_cast<std::streamsize>(tail));
    if (!last.empty() && last.back() == '\n') {
      last.pop_back();
      const std::size_t nl = last.rfind('\n');
      const std::string end_line = nl == std::string::npos ? last : last.substr(nl + 1);
      if (starts_with(end_line, "{\"end_of_recording\":")) {
        try {
          const std::uint64_t at = parse_capped(end_line).at("end_of_recording").get<std::uint64_t>();
          in.clear();
          in.seekg(static_cast<std::streamoff>(at));
          std::string index_line;
          std::getline(in, index_line);
          const json idx = parse_capped(index_line);
          for (const json& e : idx.at("index")) {
            Keyframe k;
            k.t = e.at("t").get<double>();
            k.offset = e.at("offset").get<std::uint64_t>();
            k.lines = e.at("lines").get<std::uint64_t>();
            k.events = e.at("events").get<std::uint64_t>();
            r.keyframes.push_back(std::move(k));
          }
          r.end = idx.at("end").get<double>();
          r.stopped = idx.value("stopped", std::string());
          r.complete = true;
        } catch (const json::exception&) {
          r.keyframes.clear();  // a damaged index: the scan below
        }
      }
    }
  }
  if (r.complete && !r.keyframes.empty()) return r;

  // The slow way: every line, keeping what precedes the last whole keyframe.
  r.complete = false;
  in.clear();
  in.seekg(static_cast<std::streamoff>(header_end));
  std::uint64_t offset = header_end, lines = 0;
  while (in.peek() == '{' && std::getline(in, line)) {
    const bool whole = !in.eof();  // a last line without its newline was cut
    if (!whole) break;
    if (starts_with(line, "{\"keyframe\":")) {
      try {
        Keyframe k = parse_keyframe(parse_capped(line));
        k.offset = offset;
        r.keyframes.push_back(std::move(k));
      } catch (const json::exception&) {
        break;  // a damaged keyframe: nothing after it is vouched for
      }
    } else if (starts_with(line, "{\"t\":")) {
      ++lines;
    } else if (starts_with(line, "{\"step\":") || starts_with(line, "{\"index\":") ||
               starts_with(line, "{\"end_of_recording\":")) {
      // A served run's input; or the index or end line of a finished recording whose end is
      // damaged (what precedes is whole).
    } else {
      break;
    }
    offset += line.size() + 1;
  }
  if (r.keyframes.empty())
    throw std::invalid_argument(path + ": the recording has no whole keyframe (it was cut before the first, at t = 0); "
                                       "record the run again");
  const Keyframe& last = r.keyframes.back();
  r.end = last.t;
  r.dropped_events = lines - last.lines;
  r.dropped_bytes = r.bytes - last.offset;
  std::ostringstream w;
  w << path << ": the recording is incomplete (no index at its end: the run was killed, or the file was cut); "
    << "recovered " << r.keyframes.size() << " keyframe" << (r.keyframes.size() == 1 ? "" : "s") << ", t = 0 to "
    << last.t << " s and " << last.lines << " events; dropped what follows the last keyframe (" << r.dropped_events
    << " events, " << human_bytes(r.dropped_bytes) << " including the keyframe line's own state)";
  r.warning = w.str();
  return r;
}

Keyframe read_keyframe(const std::string& path, const Keyframe& at) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  in.seekg(static_cast<std::streamoff>(at.offset));
  std::string line;
  std::getline(in, line);
  try {
    const json j = parse_capped(line);
    Keyframe k = parse_keyframe(j);
    k.offset = at.offset;
    k.state = j.at("state");
    k.walls = j.at("walls").get<std::uint64_t>();
    k.added_walls = j.at("added_walls");
    return k;
  } catch (const json::exception& e) {
    throw std::invalid_argument(path + ": the keyframe at byte " + std::to_string(at.offset) + " is damaged (" + e.what() +
                                ")");
  }
}

namespace {

/// The first place where a and b differ, as a path of keys and indices ("" when equal); an array
/// element with an "id" is named by it too.
std::optional<std::string> first_difference(const json& a, const json& b, const std::string& at) {
  if (a == b) return std::nullopt;
  if (a.is_object() && b.is_object()) {
    for (const auto& [key, value] : b.items()) {
      if (!a.contains(key)) return at + key + ": missing here";
      if (auto d = first_difference(a.at(key), value, at + key + "/")) return d;
    }
    for (const auto& [key, value] : a.items())
      if (!b.contains(key)) return at + key + ": not in the recording";
  } else if (a.is_array() && b.is_array()) {
    if (a.size() != b.size())
      return at.substr(0, at.size() - (at.empty() ? 0 : 1)) + ": " + std::to_string(a.size()) + " here, " +
             std::to_string(b.size()) + " in the recording";
    for (std::size_t i = 0; i < a.size(); ++i) {
      std::string place = at + std::to_string(i);
      if (b[i].is_object() && b[i].contains("id") && b[i]["id"].is_string()) place += " '" + b[i]["id"].get<std::string>() + "'";
      if (auto d = first_difference(a[i], b[i], place + "/")) return d;
    }
  }
  return at.substr(0, at.size() - (at.empty() ? 0 : 1)) + ": " + a.dump() + " here, " + b.dump() + " in the recording";
}

}  // namespace

std::optional<std::string> keyframe_difference(const Keyframe& whole, const sim::World& world, const RunNames& names) {
  std::ostringstream out;
  write_state(out, world, names);
  const json here = parse_capped(out.str());
  return first_difference(here, whole.state, "");
}

std::string recording_inputs(const std::string& path, std::uint64_t offset, std::string_view world_name, double dt) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::string line, out = input_header_line(world_name, dt);
  std::getline(in, line);  // the header
  std::uint64_t at = line.size() + 1;
  while (at < offset && std::getline(in, line)) {
    at += line.size() + 1;
    if (!starts_with(line, "{\"step\":")) continue;
    out += line;
    out += '\n';
  }
  return out;
}

std::string recording_events(const std::string& path, std::uint64_t lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::string line, out;
  std::getline(in, line);  // the header
  std::uint64_t n = 0;
  while (n < lines && std::getline(in, line)) {
    if (!starts_with(line, "{\"t\":")) continue;
    out += line;
    out += '\n';
    ++n;
  }
  return out;
}

}  // namespace turtlegas::formats
