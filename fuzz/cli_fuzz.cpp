// SPDX-License-Identifier: MIT
// libFuzzer harness for the command line: the input is an argument vector, one argument per line
// (docs/fuzzing.md), given to the real parser (apps/turtlegas/cli.hpp, the one main() uses) and
// then to the cheap part of the command it chose:
//   controllers, check      run as they are;
//   run                     run, bounded (at most fuzz::max_events engine events and 1 s of wall
//                           clock through its own --max-events / --max-wall-seconds, which it
//                           must honour);
//   serve, replay           everything before listening (prepare_serve: options, world, recording);
//   test, tag, render, sweep parsed only (test and sweep start processes of this program, tag and
//                           render have no bound to run under).
// Everything happens in a private temporary directory holding a few small worlds and a recording
// (gas.json, turtle.json, tag.json, walls.json, rec.tgrec), rewritten before every input; an
// argument with a '/' or starting with ".." and any --plugin are skipped, so nothing outside that
// directory is read or written, and nothing touches the network. An exception other than the
// command's own answer, a sanitizer report or a hang (libFuzzer's -timeout) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>

#include "cli.hpp"
#include "cli_common.hpp"
#include "fuzz_common.hpp"

namespace {

namespace fs = std::filesystem;
using namespace turtlegas;

/// The private directory and the files put back into it before every input.
struct Sandbox {
  fs::path dir;
  std::map<std::string, std::string> files;
};

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "cli_fuzz: cannot read %s\n", p.c_str());
    std::abort();
  }
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void restore(const Sandbox& s) {
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(s.dir, ec)) fs::remove_all(e.path(), ec);
  for (const auto& [name, text] : s.files) std::ofstream(s.dir / name, std::ios::binary) << text;
}

Sandbox& sandbox() {
  static Sandbox s = [] {
    Sandbox b;
    b.dir = fuzz::make_sandbox("turtlegas-cli-fuzz");
    const fs::path src = TURTLEGAS_SOURCE_DIR;
    b.files["gas.json"] = read_file(src / "worlds/tests/box_bounce.json");
    b.files["turtle.json"] = read_file(src / "worlds/tests/controller_script.json");
    b.files["tag.json"] = read_file(src / "worlds/tests/tag_it.json");
    b.files["walls.json"] = read_file(src / "worlds/tests/moving_wall.json");
    fs::current_path(b.dir);
    restore(b);
    // A recording for `replay` and `render`, made by the program itself.
    apps::CommandLine line;
    const char* argv[] = {"turtlegas", "run", "turtle.json", "--until", "2", "--record", "rec.tgrec"};
    std::ostringstream out, err;
    apps::parse(line, 7, argv, out, err);
    apps::RunOptions o = line.run_line.options();
    o.signal_handlers = false;
    if (apps::run_command(o, fuzz::registry()) != 0) std::abort();
    b.files["rec.tgrec"] = read_file(b.dir / "rec.tgrec");
    // Where the sandbox went, for a person reading the log; removed at exit.
    std::fprintf(stderr, "cli_fuzz: sandbox %s\n", b.dir.c_str());
    std::atexit([] { std::error_code ec; fs::remove_all(sandbox().dir, ec); });
    return b;
  }();
  return s;
}

/// The arguments of an input, or none when it must be skipped (a path out of the sandbox, a plugin).
bool split(std::string_view text, std::vector<std::string>& args) {
  args.assign(1, "turtlegas");
  for (;;) {
    const std::size_t nl = text.find('\n');
    std::string_view a = text.substr(0, nl);
    if (a.find('/') != std::string_view::npos || a.substr(0, 2) == ".." || a.find("--plugin") != std::string_view::npos)
      return false;
    args.emplace_back(a);
    if (args.size() > 64) return false;
    if (nl == std::string_view::npos) return true;
    text.remove_prefix(nl + 1);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Logs to nowhere (formatted all the same), standard output (`-`, --help) to /dev/null.
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("turtlegas", std::make_shared<spdlog::sinks::null_sink_st>()));
  std::fflush(stdout);
  if (std::freopen("/dev/null", "w", stdout) == nullptr) std::abort();
  // The sandbox (and its recording, made by running a turtle world) comes with the first input,
  // not here: libFuzzer installs its SIGALRM handler (-timeout) after this function and keeps a
  // handler it finds, so the runtime's (turtle_runtime/src/fiber.cpp, chaining to the default
  // action) would kill the process at libFuzzer's first timer tick; and the parent of -fork
  // runs no input, so it stays in its directory, where its relative paths point.
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> args;
  if (!split(text, args)) return 0;
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());

  restore(sandbox());
  apps::CommandLine line;
  std::ostringstream out, err;
  if (apps::parse(line, static_cast<int>(argv.size()), argv.data(), out, err)) return 0;
  if (!line.plugins.empty()) return 0;
  turtle::Registry registry = controllers::builtin_registry();
  try {
    switch (line.command()) {
      case apps::Command::controllers:
      case apps::Command::check: (void)apps::dispatch(line, registry); break;
      case apps::Command::run: {
        apps::RunOptions o = line.run_line.options();
        o.signal_handlers = false;
        if (!o.max_events || *o.max_events > fuzz::max_events) o.max_events = fuzz::max_events;
        if (!o.max_wall_seconds || *o.max_wall_seconds > 1.0) o.max_wall_seconds = 1.0;
        (void)apps::run_command(o, registry);
        break;
      }
      case apps::Command::serve: (void)apps::prepare_serve(line.serve_opt, registry); break;
      case apps::Command::replay: (void)apps::prepare_serve(line.replay_opt, registry); break;
      case apps::Command::test:
      case apps::Command::tag:
      case apps::Command::render:
      case apps::Command::sweep: break;
    }
  } catch (const apps::BadInput&) {
    // The documented answer to a bad command line or world: exit code 2 with its message.
  } catch (const std::logic_error& e) {
    // main() would print it as an error with exit code 1, but it is a bug, not an answer: an
    // out_of_range, an invalid_argument the command did not turn into BadInput, a length_error.
    fuzz::finding("std::logic_error", e.what());
  } catch (const nlohmann::json::exception& e) {
    fuzz::finding("nlohmann::json::exception", e.what());
  } catch (const std::runtime_error&) {
    // Exit code 1 with its message: a file that cannot be written, a world that ended.
  }
  return 0;
}
