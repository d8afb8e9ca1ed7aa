// SPDX-License-Identifier: MIT
// libFuzzer harness for the world server's protocol (docs/protocol.md): the messages of a session
// handed to a served world's host in-process, as a connection would hand them over (no sockets).
// The input is lines:
//   the first line  words choosing the host: `replay` (a recording of a gas) or `replay-turtles`
//                   (of a script turtle) instead of a live world; `bodies` (tests/server/worlds/
//                   bodies_room.json instead of protocol_room.json), `step`, `realtime`, `paused`,
//                   `binary` (the connection takes binary frames), `token` (the server has one);
//   then            one message per line, parsed as Session::received parses a line (not JSON:
//                   skipped, the session's own bad_json), or `@2 MESSAGE` from a second
//                   connection, `@drop` (the first connection goes), `@state` (GET /api/state).
// The host runs at full speed (--speed max) to at most 2 simulated seconds (200 control steps), with
// a 50 ms lockstep timeout; a watchdog stops it (as SIGINT does) once it has sent nothing but
// frames for 30 ms, or after 300 ms. Every reply and JSON frame must be a JSON object with a
// string "type"; anything else, an exception out of the host, a sanitizer report or a hang is a
// finding. save and load are confined to a private temporary directory.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>

#include "cli.hpp"
#include "cli_common.hpp"
#include "fuzz_common.hpp"
#include "turtlegas/server/client.hpp"
#include "turtlegas/server/world_host.hpp"

namespace {

namespace fs = std::filesystem;
using namespace turtlegas;
using Clock = std::chrono::steady_clock;

/// The time of the host's last message other than a frame, for the watchdog.
std::atomic<std::int64_t> g_last_send{0};

std::int64_t ticks() { return Clock::now().time_since_epoch().count(); }

class FuzzClient : public server::Client {
 public:
  explicit FuzzClient(bool binary) : binary_(binary) {}
  void send(std::shared_ptr<const std::string> message) override {
    g_last_send.store(ticks());
    check(*message, "message");
  }
  void send_frame(std::shared_ptr<const std::string> frame, bool binary) override {
    if (binary && !binary_) fuzz::finding("protocol", "a binary frame sent to a connection that cannot take one");
    if (!binary) check(*frame, "frame");
  }
  void close_after_send() override {}
  bool binary_capable() const override { return binary_; }

 private:
  static void check(const std::string& text, const char* what) {
    const nlohmann::json m = nlohmann::json::parse(text, nullptr, false);
    if (m.is_discarded() || !m.is_object() || !m.contains("type") || !m["type"].is_string())
      fuzz::finding(what, ("not a JSON object with a string \"type\": " + text.substr(0, 300)).c_str());
  }
  bool binary_;
};

struct Sandbox {
  fs::path dir, save_dir;
  std::string protocol_room, bodies_room;
  apps::PreparedServe replay_gas, replay_turtles;
};

apps::PreparedServe record_and_prepare(const fs::path& world, const std::string& name) {
  apps::CommandLine line;
  const std::string w = world.string();
  const std::string rec = name + ".tgrec";
  const char* argv[] = {"turtlegas", "run", w.c_str(), "--until", "2", "--record", rec.c_str()};
  std::ostringstream out, err;
  if (apps::parse(line, 7, argv, out, err)) std::abort();
  apps::RunOptions o = line.run_line.options();
  o.signal_handlers = false;
  if (apps::run_command(o, fuzz::registry()) != 0) std::abort();
  apps::ServeCommandOptions s;
  s.replay = rec;
  return apps::prepare_serve(s, fuzz::registry());
}

Sandbox& sandbox() {
  static Sandbox s = [] {
    Sandbox b;
    b.dir = fuzz::make_sandbox("turtlegas-protocol-fuzz");
    b.save_dir = b.dir / "saves";
    fs::create_directories(b.save_dir);
    fs::current_path(b.dir);
    const fs::path src = TURTLEGAS_SOURCE_DIR;
    b.protocol_room = (src / "tests/server/worlds/protocol_room.json").string();
    b.bodies_room = (src / "tests/server/worlds/bodies_room.json").string();
    b.replay_gas = record_and_prepare(src / "worlds/tests/box_bounce.json", "gas");
    b.replay_turtles = record_and_prepare(src / "worlds/tests/controller_script.json", "turtles");
    std::fprintf(stderr, "protocol_fuzz: sandbox %s\n", b.dir.c_str());
    std::atexit([] { std::error_code ec; fs::remove_all(sandbox().dir, ec); });
    return b;
  }();
  return s;
}

bool has_word(std::string_view line, std::string_view word) {
  std::size_t at = 0;
  while ((at = line.find(word, at)) != std::string_view::npos) {
    const bool start = at == 0 || line[at - 1] == ' ';
    const bool end = at + word.size() == line.size() || line[at + word.size()] == ' ';
    if (start && end) return true;
    at += word.size();
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("turtlegas", std::make_shared<spdlog::sinks::null_sink_st>()));
  // The sandbox (and its recording, made by running a turtle world) comes with the first input,
  // not here: libFuzzer installs its SIGALRM handler (-timeout) after this function and keeps a
  // handler it finds, so the runtime's (turtle_runtime/src/fiber.cpp, chaining to the default
  // action) would kill the process at libFuzzer's first timer tick; and the parent of -fork
  // runs no input, so it stays in its directory, where its relative paths point.
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::size_t first_nl = text.find('\n');
  const std::string_view header = text.substr(0, first_nl);
  text = first_nl == std::string_view::npos ? std::string_view() : text.substr(first_nl + 1);
  Sandbox& box = sandbox();
  {
    std::error_code ec;
    for (const fs::directory_entry& e : fs::directory_iterator(box.save_dir, ec)) fs::remove_all(e.path(), ec);
  }

  server::HostOptions h;
  world::Scene scene;
  const bool replay_turtles = has_word(header, "replay-turtles");
  if (replay_turtles || has_word(header, "replay")) {
    const apps::PreparedServe& p = replay_turtles ? box.replay_turtles : box.replay_gas;
    h = p.options.host;
    scene = p.scene;
  } else {
    h.world_file = has_word(header, "bodies") ? box.bodies_room : box.protocol_room;
    try {
      scene = apps::load(h.world_file, fuzz::registry());
    } catch (const apps::BadInput& e) {
      fuzz::finding("a test world does not load", e.what());
    }
    h.world_text = "{}";
    h.mode = has_word(header, "step") ? sim::Mode::step : sim::Mode::exact;
    h.realtime = has_word(header, "realtime");
    h.until = std::min(2.0, 200 * scene.def.dt);
    h.save_dir = fs::canonical(box.save_dir);
  }
  h.speed = 0.0;
  h.paused = has_word(header, "paused");
  if (has_word(header, "token")) h.token = "secret";
  h.lockstep_timeout = 0.05;
  h.program_budget = 0.5;
  const bool binary = has_word(header, "binary");

  std::optional<server::WorldHost> host;
  try {
    host.emplace(std::move(h), fuzz::registry(), std::move(scene));
  } catch (const std::exception& e) {
    fuzz::finding("the host refused a test world", e.what());
  }
  auto one = std::make_shared<FuzzClient>(binary);
  std::shared_ptr<FuzzClient> two;
  one->id = host->next_client_id();
  host->connected(one);
  bool one_open = true;
  int lines = 0;
  while (!text.empty() && ++lines <= 256) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    if (line == "@state") {
      host->request_state([](std::string state) {
        if (state.empty()) fuzz::finding("state", "GET /api/state gave nothing");
      });
      continue;
    }
    if (line == "@drop") {
      if (one_open) host->disconnected(one);
      one_open = false;
      continue;
    }
    std::shared_ptr<FuzzClient> from = one;
    std::string_view message = line;
    if (line.substr(0, 3) == "@2 ") {
      if (!two) {
        two = std::make_shared<FuzzClient>(!binary);
        two->id = host->next_client_id();
        host->connected(two);
      }
      from = two;
      message.remove_prefix(3);
    } else if (!one_open) {
      continue;  // a closed connection says nothing more
    }
    nlohmann::json m = nlohmann::json::parse(message, nullptr, false);
    if (m.is_discarded()) continue;  // the session answers bad_json itself
    host->post(from, std::move(m));
  }

  // The watchdog: stops the host once it has only sent frames for 30 ms, or after 300 ms.
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
  g_last_send.store(ticks());
  std::thread watchdog([&] {
    const auto start = Clock::now();
    std::unique_lock lock(mutex);
    while (!done) {
      cv.wait_for(lock, std::chrono::milliseconds(5));
      const auto quiet = Clock::duration(ticks() - g_last_send.load());
      if (!done && (quiet > std::chrono::milliseconds(30) || Clock::now() - start > std::chrono::milliseconds(300))) {
        host->request_stop("fuzz");
        break;
      }
    }
  });
  try {
    (void)host->run();
  } catch (const std::exception& e) {
    fuzz::finding("an exception out of the host's loop", e.what());
  }
  {
    std::lock_guard lock(mutex);
    done = true;
  }
  cv.notify_one();
  watchdog.join();
  return 0;
}
