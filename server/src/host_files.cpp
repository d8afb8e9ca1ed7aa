// SPDX-License-Identifier: MIT
// The world host's files: save and load (docs/protocol.md, "Save and load"), done between steps
// in the save directory only; and the input log that makes a served run replayable.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include <spdlog/spdlog.h>

#include "host_text.hpp"
#include "turtlegas/formats/input_log.hpp"
#include "turtlegas/formats/state_file.hpp"
#include "turtlegas/server/protocol.hpp"
#include "turtlegas/server/world_host.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::server {

using nlohmann::json;

void WorldHost::on_file(ClientState& c, const json& m, const std::string& type) {
  const json id = message_id(m);
  if (type == "save") require_live();
  if (options_.save_dir.empty())
    throw RequestError("no_save_dir", "save and load need a directory: start the server with --save-dir DIR");
  const std::string file = string_field(m, "file", type == "save" ? R"({"type": "save", "file": "snap.json"})" : R"({"type": "load", "file": "room.json"})");
  check_plain_name(file);
  file_requests_.push_back({c.client->id, id, type == "load", file});
}

void WorldHost::do_file_requests() {
  while (!file_requests_.empty()) {
    const FileRequest f = file_requests_.front();
    file_requests_.pop_front();
    auto it = clients_.find(f.client);
    auto fail = [&](const char* code, const std::string& message) {
      if (it == clients_.end()) return;
      ++it->second.errors;
      reply_text(it->second, error_text(code, message, &f.id, f.load ? "load" : "save", "/file"));
    };
    const std::filesystem::path path = options_.save_dir / f.file;
    std::error_code ec;
    const auto st = std::filesystem::symlink_status(path, ec);
    if (!ec && std::filesystem::is_symlink(st)) {
      fail("bad_path", "/file: '" + f.file + "' is a symlink; save and load touch only plain files in the save directory");
      continue;
    }
    if (!f.load) {
      if (const std::string what = in_use(path); !what.empty()) {
        fail("bad_path", "/file: '" + f.file + "' is " + what + ", in use by the server; save under another name");
        continue;
      }
      if (ended_) {
        fail("ended", "the world has ended (" + *ended_ + ")");
        continue;
      }
      const std::filesystem::path tmp = options_.save_dir / ("." + f.file + ".tmp-" + std::to_string(::getpid()));
      {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (out) formats::write_state(out, server_->world(), formats::RunNames{ball_ids_, scene_.def, server_->world()});
        if (!out) {
          std::filesystem::remove(tmp, ec);
          fail("bad_path", "/file: cannot write '" + f.file + "' in the save directory");
          continue;
        }
      }
      std::filesystem::rename(tmp, path, ec);
      if (ec) {
        std::filesystem::remove(tmp, ec);
        fail("bad_path", "/file: cannot write '" + f.file + "' in the save directory");
        continue;
      }
      if (it != clients_.end()) {
        json m = {{"id", f.id}};
        json r = ok(m, "save");
        r["file"] = f.file;
        reply(it->second, r);
      }
      continue;
    }
    if (!std::filesystem::is_regular_file(path, ec)) {
      fail("not_found", "/file: no file '" + f.file + "' in the save directory");
      continue;
    }
    world::Scene scene;
    std::string text;
    try {
      std::ifstream in(path, std::ios::binary);
      std::ostringstream buf;
      buf << in.rdbuf();
      text = buf.str();
      scene = world::parse_scene(text, f.file, registry_);
      // Built before anything is let go: a world the runtime refuses changes nothing.
      turtle::ServerOptions probe;
      probe.mode = options_.mode;
      (void)world::make_server(scene, registry_, probe);
    } catch (const std::exception& e) {
      fail("bad_world", e.what());
      continue;
    }
    for (auto& [cid, c] : clients_) release_all(c, "load");
    fan_out_events();
    if (events_file_) events_file_->flush();
    if (inputs_file_) inputs_file_->flush();
    events_writer_.reset();
    events_file_.reset();
    inputs_file_.reset();
    if (recorder_) finish_recording("load");
    build_world(std::move(scene));
    served_file_ = path;
    {
      std::lock_guard lock(text_mutex_);
      options_.world_text = std::move(text);
    }
    std::map<std::string, FrameStream> fresh;
    for (auto& [key, s] : streams_) fresh.try_emplace(key, s.kind(), *server_).first->second.next_due = now();
    streams_ = std::move(fresh);
    spdlog::info("loaded '{}'", f.file);
    if (it != clients_.end()) reply(it->second, ok(json{{"id", f.id}}, "load"));
    broadcast(dump({{"type", "world"}, {"world", world_json()}}));
    for (auto& [cid, c] : clients_)
      if (c.stream) reply_text(c, snapshot_text(*server_, ball_ids_, claimed(), clock(), nullptr, world_json()["arena"], looks_));
  }
}

std::string WorldHost::input_line(std::string line) const {
  if (!waiting_) return line;
  const Slot& s = slots_[*waiting_];
  return formats::input_while_waiting(std::move(line), scene_.def.turtles[*waiting_].id,
                                      s.taken_step == server_->step() ? s.taken : 0);
}

void WorldHost::write_input(const std::string& raw) {
  const std::string line = input_line(raw);
  if (inputs_file_) {
    *inputs_file_ << line;
    inputs_file_->flush();  // on disk as it is taken (the header is, too: host_world.cpp)
    if (!*inputs_file_) output_failed("--inputs-out", options_.inputs_path);
  }
  if (recorder_) recorder_->input(line);
}

void WorldHost::output_failed(const char* option, const std::string& path) {
  const int e = errno;
  if (std::string(option) == "--events") events_writer_.reset(), events_file_.reset();
  if (std::string(option) == "--inputs-out") inputs_file_.reset();
  if (!output_error_.empty()) return;
  output_error_ = std::string(option) + ": writing '" + path + "' failed" + (e ? " (" + std::string(std::strerror(e)) + ")" : "");
  spdlog::error("{}; the server stops", output_error_);
  stopping_ = true;
  stop_reason_ = "error";
}

void WorldHost::check_outputs() {
  if (events_file_ && !*events_file_) output_failed("--events", options_.events_path);
  if (inputs_file_ && !*inputs_file_) output_failed("--inputs-out", options_.inputs_path);
  if (record_file_ && !*record_file_ && output_error_.empty()) output_failed("--record", options_.record_path);
}

std::string WorldHost::in_use(const std::filesystem::path& path) const {
  const std::pair<const std::string*, const char*> files[] = {
      {nullptr, "the served world"},
      {&options_.events_path, "the live event log (--events)"},
      {&options_.inputs_path, "the live input log (--inputs-out)"},
      {&options_.record_path, "the live recording (--record)"}};
  for (const auto& [name, what] : files) {
    const std::filesystem::path other = name ? std::filesystem::path(*name) : served_file_;
    if (other.empty()) continue;
    std::error_code ec;
    // The same file by any name: a hard link or a symlinked directory is caught by `equivalent`.
    if (std::filesystem::equivalent(path, other, ec) && !ec) return what;
    ec.clear();
    const auto a = std::filesystem::weakly_canonical(path, ec);
    if (ec) continue;
    const auto b = std::filesystem::weakly_canonical(other, ec);
    if (!ec && a == b) return what;
  }
  return {};
}

}  // namespace turtlegas::server
