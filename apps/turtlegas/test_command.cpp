// SPDX-License-Identifier: MIT
#include "test_command.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_processes.hpp"
#include "cli_common.hpp"
#include "output_file.hpp"
#include "run3d.hpp"
#include "run_loop.hpp"
#include "signals.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/expect.hpp"
#include "turtlegas/world/expect3.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::apps {
namespace {

namespace tw = turtlegas::world;
using nlohmann::json;

constexpr int progress_fd = 4;  // the child's progress lines (child_processes.hpp)

const char* mode_name(sim::Mode m) { return sim::to_string(m).data(); }

/// One world's outcome, as the child reports it and the parent prints it.
struct Outcome {
  /// not_run: the suite was stopped (SIGINT, SIGTERM) before the world ended.
  enum class Status { pass, fail, error, not_run } status = Status::error;
  std::string message;  ///< what failed, or why it could not run; for a pass, "(3 assertions, 0.01 s)"
  std::size_t assertions = 0;
  double seconds = 0.0;
  std::string log;      ///< the child's stdout and stderr
  std::string type = "expect";  ///< JUnit's failure type: expect, crash, timeout or limit
};

const char* status_word(Outcome::Status s) {
  return s == Outcome::Status::pass ? "pass" : s == Outcome::Status::fail ? "fail" : "error";
}

/// How far a world's process has got: the line it writes on descriptor 4 now and then.
struct WorldProgress {
  double t = 0.0, until = 0.0;
  std::size_t part = 0, parts = 1;  ///< the mode being run (exact, then step), of how many
  std::string mode;

  std::string line() const {
    return json{{"t", t}, {"until", until}, {"part", part}, {"parts", parts}, {"mode", mode}}.dump() + "\n";
  }
  /// nullopt when there is none yet.
  static std::optional<WorldProgress> parse(const std::string& line) {
    const json j = json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return std::nullopt;
    WorldProgress p;
    p.t = j.value("t", 0.0);
    p.until = j.value("until", 0.0);
    p.part = j.value("part", std::size_t{0});
    p.parts = std::max<std::size_t>(1, j.value("parts", std::size_t{1}));
    p.mode = j.value("mode", "");
    return p;
  }
  /// "t = 31.4 / 1e+12 s", "step mode, t = 2 / 10 s" when the world runs in both.
  std::string text() const {
    char b[128];
    std::snprintf(b, sizeof b, "%s%st = %.6g / %.6g s", parts > 1 ? mode.c_str() : "", parts > 1 ? " mode, " : "", t,
                  until);
    return b;
  }
  /// Simulated seconds done and to do, over every mode.
  double done() const { return static_cast<double>(part) * until + t; }
  double total() const { return static_cast<double>(parts) * until; }
};

/// The child's side of the progress: a WorldProgress line on descriptor 4 at most five times a
/// second, never waiting for the parent (a line the pipe has no room for is dropped).
class ProgressReports {
 public:
  ProgressReports() : open_(::fcntl(progress_fd, F_GETFD) != -1) {
    if (open_) ::fcntl(progress_fd, F_SETFL, ::fcntl(progress_fd, F_GETFL) | O_NONBLOCK);
  }
  void report(const WorldProgress& p) {
    if (!open_ || Clock::now() - last_ < std::chrono::milliseconds(200)) return;
    last_ = Clock::now();
    const std::string line = p.line();  // shorter than PIPE_BUF: written whole or not at all
    [[maybe_unused]] const ssize_t n = ::write(progress_fd, line.data(), line.size());
  }

 private:
  bool open_;
  Clock::time_point last_{};
};

/// A world stopped by --max-wall-seconds or --max-events: it fails, as type "limit".
Outcome stopped_by_limit(const std::string& limit, const WorldProgress& at, std::uint64_t events) {
  Outcome o;
  o.status = Outcome::Status::fail;
  o.type = "limit";
  o.message = "stopped by " + limit + " at " + at.text() + " (" + std::to_string(events) + " events)";
  return o;
}

std::string read_text(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// One mode's run of a world's expect list, added to its outcome: the assertions, and each failure
/// named by its mode when the world runs in both.
void tally_mode(Outcome& o, std::string& failures, std::size_t assertions, const std::vector<std::string>& found,
                sim::Mode mode, bool both) {
  o.assertions += assertions;
  for (const std::string& f : found) {
    failures += failures.empty() ? "" : "; ";
    if (both) failures += std::string(mode_name(mode)) + " mode: ";
    failures += f;
  }
}

/// The outcome of a world whose modes all ran: failed with their failures, or passed with a summary.
Outcome finish_modes(Outcome o, const std::string& failures, Clock::time_point start, bool both, bool three_d) {
  o.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!failures.empty()) {
    o.status = Outcome::Status::fail;
    o.message = failures;
    return o;
  }
  o.status = Outcome::Status::pass;
  char line[160];
  std::snprintf(line, sizeof line, "(%s%s%zu assertion%s, %.2f s)", three_d ? "3-D, " : "", both ? "exact and step, " : "",
                o.assertions, o.assertions == 1 ? "" : "s", o.seconds);
  o.message = line;
  return o;
}

/// Runs one 3-D world ("dimensions": 3) against its `expect` list (world/expect3.hpp).
Outcome test_one_3d(const std::string& file, const tw::World3File& world3, const TestOptions& options) {
  Outcome o;
  tw::Expectations3 expect;
  try {
    expect = tw::parse_expect3(read_text(file), file, world3);
  } catch (const tw::WorldFileError& e) {
    o.message = e.what();
    return o;
  }
  if (!expect.present) {
    o.message = file + ": no \"expect\" list; a test world needs one, e.g. \"expect\": [{\"until\": 10}, ...]";
    return o;
  }
  if (expect.until < 0.0) {
    o.message = file + ": /expect: no {\"until\": T}; add one to say how long the test runs";
    return o;
  }
  std::vector<sim::Mode> modes = expect.modes;
  if (options.mode) {
    const std::optional<sim::Mode> mode = sim::mode_from_string(*options.mode);
    if (!mode) {
      o.message = file + ": --mode " + *options.mode + ": exact or step";
      return o;
    }
    modes = {*mode};
  }
  if (modes.empty()) modes = {sim::Mode::exact};
  const auto start = Clock::now();
  const std::optional<double> wall = options.limits.wall_seconds();
  const std::optional<std::uint64_t> max_events = options.limits.events();
  ProgressReports reports;
  WorldProgress at;
  at.until = expect.until;
  at.parts = modes.size();
  std::uint64_t events_before = 0;  // of the modes run before this one: --max-events counts the world's
  std::string failures;
  for (sim::Mode mode : modes) {
    tw::World3File w = world3;
    w.def.mode = mode;
    at.mode = mode_name(mode);
    at.t = 0.0;
    std::uint64_t events = 0;
    tw::Expect3Result r;
    try {
      r = tw::run_expect3(w, expect, [&](const sim::World3& world) {
        at.t = world.time();
        events = world.events();
        if (wall && seconds_since(start) >= *wall) throw sim::StopRequested("--max-wall-seconds");
        if (max_events && events_before + events >= *max_events) throw sim::EventLimitReached("--max-events");
        reports.report(at);
      });
    } catch (const std::invalid_argument& e) {
      o.message = file + ": " + mode_name(mode) + " mode: " + e.what();
      return o;
    } catch (const sim::StopRequested&) {
      return stopped_by_limit("--max-wall-seconds " + fmt(*wall), at, events_before + events);
    } catch (const sim::EventLimitReached&) {
      return stopped_by_limit("--max-events " + std::to_string(*max_events), at, *max_events);
    }
    events_before += events;
    ++at.part;
    tally_mode(o, failures, r.assertions, r.failures, mode, modes.size() > 1);
  }
  return finish_modes(o, failures, start, modes.size() > 1, true);
}

/// Runs one world in this process: the child's whole job.
Outcome test_one(const std::string& file, const TestOptions& options, const turtle::Registry& registry) {
  Outcome o;
  try {
    if (const std::optional<tw::World3File> w3 = load_world3_if_3d(file)) return test_one_3d(file, *w3, options);
  } catch (const BadInput& e) {
    o.message = e.what();
    return o;
  }
  tw::Scene scene;
  try {
    scene = tw::load_scene(file, registry);
  } catch (const tw::WorldFileError& e) {
    o.message = e.what();
    return o;
  }
  const tw::Expectations& expect = scene.expect;
  if (!expect.present) {
    o.message = file + ": no \"expect\" list; a test world needs one, e.g. \"expect\": [{\"until\": 10}, ...]";
    return o;
  }
  if (!expect.until) {
    o.message = file + ": /expect: no {\"until\": T}; add one to say how long the test runs";
    return o;
  }
  std::vector<sim::Mode> modes = expect.modes;
  if (options.mode) modes = {sim::mode_from_string(*options.mode).value_or(sim::Mode::exact)};  // CLI11 checked it
  if (modes.empty()) modes = {sim::Mode::exact};

  turtle::ServerOptions server_options;
  server_options.program_budget = options.program_budget;
  server_options.stack_bytes = options.stack_kib * 1024;
  const auto start = Clock::now();
  Limits limits;
  limits.max_wall_seconds = options.limits.wall_seconds();
  limits.max_events = options.limits.events();
  ProgressReports reports;
  WorldProgress at;
  at.until = *expect.until;
  at.parts = modes.size();
  std::uint64_t events_before = 0;  // of the modes run before this one: --max-events counts the world's
  std::string failures;
  for (sim::Mode mode : modes) {
    std::uint64_t events = 0;
    at.mode = mode_name(mode);
    at.t = 0.0;
    tw::ExpectHooks hooks;
    hooks.on_start = [&](turtle::WorldServer& server) { stop_inside_steps(server, limits, start, events_before); };
    hooks.on_step = [&](const turtle::WorldServer& server) {
      at.t = server.time();
      events = server.world().stats().events;
      // Also here, not only every 4096 events: a world may take many steps for few events.
      if (limits.max_wall_seconds && seconds_since(start) >= *limits.max_wall_seconds)
        throw sim::StopRequested("--max-wall-seconds");
      reports.report(at);
    };
    tw::ExpectResult r;
    try {
      r = tw::run_expectations(scene, registry, mode, server_options, hooks);
    } catch (const std::invalid_argument& e) {
      o.message = file + ": " + mode_name(mode) + " mode: " + e.what();
      return o;
    } catch (const sim::StopRequested&) {
      return stopped_by_limit("--max-wall-seconds " + fmt(*limits.max_wall_seconds), at, events_before + events);
    } catch (const sim::EventLimitReached&) {
      return stopped_by_limit("--max-events " + std::to_string(*limits.max_events), at, *limits.max_events);
    }
    events_before += events;
    ++at.part;
    tally_mode(o, failures, r.assertions, r.failures, mode, modes.size() > 1);
  }
  return finish_modes(o, failures, start, modes.size() > 1, false);
}

/// The child's side: runs its world, writes the outcome as one JSON line on descriptor 3.
int child_main(const TestOptions& options, const turtle::Registry& registry) {
  if (options.worlds.size() != 1 || ::fcntl(3, F_GETFD) == -1)
    throw BadInput("test --child is for turtlegas itself: it runs one world and reports on descriptor 3");
  Outcome o = test_one(options.worlds.front(), options, registry);
  const std::string line =
      json{{"status", status_word(o.status)}, {"message", o.message}, {"assertions", o.assertions},
           {"seconds", o.seconds}, {"type", o.type}}
          .dump() +
      "\n";
  std::fflush(stdout);
  for (std::size_t done = 0; done < line.size();) {
    const ssize_t n = ::write(3, line.data() + done, line.size() - done);
    if (n <= 0) return exit_failure;
    done += static_cast<std::size_t>(n);
  }
  return o.status == Outcome::Status::pass ? exit_ok : o.status == Outcome::Status::fail ? exit_failure : exit_bad_input;
}

std::string seconds_text(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", s);
  return b;
}

/// A world that has not stopped itself this long after its --max-wall-seconds is killed.
constexpr double grace_seconds = 10.0;

/// Wall-clock seconds a world's process gets before the parent kills it (0: no end): --timeout,
/// or --max-wall-seconds and the grace when that comes first.
double kill_after(const TestOptions& options) {
  const std::optional<double> wall = options.limits.wall_seconds();
  const double backstop = wall ? *wall + grace_seconds : 0.0;
  if (options.timeout > 0.0 && (backstop == 0.0 || options.timeout <= backstop)) return options.timeout;
  return backstop;
}

std::string timeout_text(const TestOptions& options) {
  if (options.timeout > 0.0 && kill_after(options) == options.timeout)
    return "--timeout " + fmt(options.timeout) + " s";
  return fmt(kill_after(options)) + " s (--max-wall-seconds and " + fmt(grace_seconds) + " s more)";
}

/// The parent's reading of how a child ended.
Outcome outcome_of(const std::string& file, const TestOptions& options, ChildResult&& r) {
  Outcome o;
  o.seconds = r.seconds;
  o.log = std::move(r.out);
  o.log += r.err;
  const std::optional<WorldProgress> at = WorldProgress::parse(r.status);
  const std::string where = at ? " at " + at->text() : std::string();
  if (r.stopped) {
    o.status = Outcome::Status::not_run;
    o.message = std::string("stopped by ") + signal_name(stop_signal()) + " after " + seconds_text(r.seconds) + " s" +
                where + ", before it ended";
    return o;
  }
  if (r.timed_out) {
    o.status = Outcome::Status::fail;
    o.message = "still running after " + timeout_text(options) + where + "; killed";
    o.type = "timeout";
    return o;
  }
  try {
    const json j = json::parse(r.report);
    const std::string s = j.at("status").get<std::string>();
    o.status = s == "pass" ? Outcome::Status::pass : s == "fail" ? Outcome::Status::fail : Outcome::Status::error;
    o.message = j.at("message").get<std::string>();
    o.assertions = j.at("assertions").get<std::size_t>();
    o.type = j.value("type", o.type);
    return o;
  } catch (const json::exception&) {
    // No report: the world's process crashed, or a program ended it (exit, abort).
    o.status = Outcome::Status::fail;
    o.type = "crash";
    o.message = "its process ended without a result: " + r.how_it_ended() + " (" + file + " ran in a process of its own)";
    return o;
  }
}

/// Text that XML 1.0 accepts: escaped, control characters and bytes that are not UTF-8 replaced
/// by '?'.
std::string xml_text(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    std::size_t len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    bool ok = len > 0 && i + len <= s.size();
    for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 2;
    if (!ok) {
      out += '?';
      ++i;
      continue;
    }
    if (len > 1) {
      out.append(s, i, len);
      i += len;
      continue;
    }
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += (c < 0x20 && c != '\t' && c != '\n' && c != '\r') ? '?' : static_cast<char>(c);
    }
    ++i;
  }
  return out;
}

/// A log cut to its first and last lines when long, for the reports.
std::string capped(const std::string& log) {
  constexpr std::size_t cap = 64 * 1024;
  if (log.size() <= cap) return log;
  return log.substr(0, cap / 2) + "\n... (" + std::to_string(log.size() - cap) + " bytes left out) ...\n" +
         log.substr(log.size() - cap / 2);
}

/// JUnit XML as Jenkins, GitLab and the GitHub test-report actions read it: one <testsuite>, one
/// <testcase> per world (name: the file as given), <failure> for a failed world, <error> for one
/// that could not run, <skipped> for one that a stopped suite did not finish, its log in
/// <system-err>.
std::string junit_xml(const std::vector<std::string>& files, const std::vector<Outcome>& outcomes, double seconds) {
  std::size_t failures = 0, errors = 0, skipped = 0;
  for (const Outcome& o : outcomes) {
    failures += o.status == Outcome::Status::fail ? 1 : 0;
    errors += o.status == Outcome::Status::error ? 1 : 0;
    skipped += o.status == Outcome::Status::not_run ? 1 : 0;
  }
  const std::string counts = "tests=\"" + std::to_string(files.size()) + "\" failures=\"" + std::to_string(failures) +
                             "\" errors=\"" + std::to_string(errors) + "\"";
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites name=\"turtlegas test\" " + counts + " time=\"" + seconds_text(seconds) + "\">\n";
  x += "  <testsuite name=\"turtlegas test\" " + counts + " skipped=\"" + std::to_string(skipped) + "\" time=\"" +
       seconds_text(seconds) + "\">\n";
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Outcome& o = outcomes[i];
    x += "    <testcase classname=\"turtlegas.test\" name=\"" + xml_text(files[i]) + "\" file=\"" + xml_text(files[i]) +
         "\" time=\"" + seconds_text(o.seconds) + "\"";
    if (o.status == Outcome::Status::pass && o.log.empty()) {
      x += "/>\n";
      continue;
    }
    x += ">\n";
    if (o.status == Outcome::Status::not_run) {
      x += "      <skipped message=\"" + xml_text(o.message) + "\"/>\n";
    } else if (o.status != Outcome::Status::pass) {
      const char* tag = o.status == Outcome::Status::fail ? "failure" : "error";
      x += std::string("      <") + tag + " message=\"" + xml_text(o.message) + "\" type=\"" +
           (o.status == Outcome::Status::fail ? o.type : std::string("bad-input")) + "\">" + xml_text(o.message) + "</" + tag +
           ">\n";
    }
    if (!o.log.empty()) x += "      <system-err>" + xml_text(capped(o.log)) + "</system-err>\n";
    x += "    </testcase>\n";
  }
  x += "  </testsuite>\n</testsuites>\n";
  return x;
}

/// A string for a YAML block of TAP 13: double-quoted, JSON escapes (a YAML subset).
std::string yaml_string(const std::string& s) { return json(s).dump(-1, ' ', false, json::error_handler_t::replace); }

std::string tap_line(std::size_t n, const std::string& file, const Outcome& o) {
  if (o.status == Outcome::Status::pass) return "ok " + std::to_string(n) + " - " + file + " " + o.message + "\n";
  if (o.status == Outcome::Status::not_run)
    return "ok " + std::to_string(n) + " - " + file + " # SKIP " + o.message + "\n";
  std::string s = "not ok " + std::to_string(n) + " - " + file + "\n";
  s += "  ---\n";
  s += "  message: " + yaml_string(o.message) + "\n";
  s += std::string("  severity: ") + (o.status == Outcome::Status::fail ? "fail" : "error") + "\n";
  s += "  duration_ms: " + seconds_text(o.seconds * 1000.0) + "\n";
  s += "  ...\n";
  return s;
}

std::string result_line(const std::string& file, const Outcome& o) {
  switch (o.status) {
    case Outcome::Status::pass: return "PASS " + file + " " + o.message + "\n";
    case Outcome::Status::fail: return "FAIL " + file + ": " + o.message + "\n";
    case Outcome::Status::error: return "ERROR " + o.message + "\n";  // the message names the file
    case Outcome::Status::not_run: return "NOT RUN " + file + ": " + o.message + "\n";
  }
  return {};
}

}  // namespace

CLI::App* add_test_command(CLI::App& app, TestOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "test", "Run scripted test worlds headless against their \"expect\" lists, each in its own process; one line "
              "per world, exit 1 on a failure");
  cmd->add_option("worlds", options.worlds, "World files with an \"expect\" list")->required();
  cmd->add_option("--mode", options.mode, "exact or step: overrides each world's own {\"mode\": ...}")
      ->check(CLI::IsMember(sim::mode_names));
  add_program_budget_option(*cmd, options.program_budget, "its world fails");
  add_stack_kib_option(*cmd, options.stack_kib);
  cmd->add_option("--jobs,-j", options.jobs, "Worlds run at once, each in its own process")
      ->capture_default_str()
      ->check(integer_in(1, 1024, "processes"));
  cmd->add_option("--timeout", options.timeout,
                  "Wall-clock seconds a world's process may take before it is killed and fails (0: no limit)")
      ->capture_default_str()
      ->check(real_in(0, 1e9, "seconds"));
  options.limits.add_to(*cmd, "each world", "saying how far it got", "it fails as type \"limit\"");
  cmd->add_option("--junit", options.junit, "Write a JUnit XML report here (for CI)");
  cmd->add_flag("--tap", options.tap, "Print TAP 13 on stdout instead of PASS/FAIL lines");
  cmd->add_flag("--quiet,-q", options.quiet, "Leave out the worlds' log lines; print only the results");
  cmd->add_flag("--child", options.child, "(internal) run one world in this process, report on descriptor 3")
      ->group("");
  return cmd;
}

int test_command(const TestOptions& options, const turtle::Registry& registry, const std::vector<std::string>& plugins) {
  if (options.child) return child_main(options, registry);

  // Opened first, so that a bad path costs nothing; renamed into place when written whole.
  std::optional<OutputFile> junit;
  std::vector<NamedPath> inputs;
  for (const std::string& w : options.worlds) inputs.push_back({w, "a world file"});
  for (const std::string& p : plugins) inputs.push_back({p, "--plugin"});
  check_outputs({{options.junit, "--junit"}}, inputs);
  if (!options.junit.empty()) junit.emplace(options.junit, "--junit");
  install_stop_signals("stopping the worlds that run and writing what they did");

  std::vector<std::vector<std::string>> args;
  for (const std::string& file : options.worlds) {
    std::vector<std::string> a = {"test", file, "--child", "--program-budget", json(options.program_budget).dump(),
                                  "--stack-kib", std::to_string(options.stack_kib)};
    if (options.mode) a.insert(a.end(), {"--mode", *options.mode});
    if (const auto wall = options.limits.wall_seconds()) a.insert(a.end(), {"--max-wall-seconds", json(*wall).dump()});
    if (const auto events = options.limits.events()) a.insert(a.end(), {"--max-events", std::to_string(*events)});
    for (const std::string& p : plugins) a.insert(a.end(), {"--plugin", p});
    args.push_back(std::move(a));
  }

  const auto start = Clock::now();
  const std::size_t n = options.worlds.size();
  if (options.tap) std::printf("TAP version 13\n1..%zu\n", n);
  std::fflush(stdout);
  std::vector<std::optional<Outcome>> done(n);
  std::size_t printed = 0, finished = 0;
  std::size_t passed = 0, failed = 0, bad = 0, not_run = 0;
  StatusLine status;
  // Prints the outcomes from `printed` on in the order given, whatever order they end in, up to
  // the first not there yet.
  auto print = [&] {
    for (; printed < n && done[printed]; ++printed) {
      const Outcome& o = *done[printed];
      const std::string& file = options.worlds[printed];
      status.clear();
      if (!options.quiet && !o.log.empty()) {
        std::fputs(o.log.c_str(), stderr);
        if (o.log.back() != '\n') std::fputc('\n', stderr);
        std::fflush(stderr);
      }
      const std::string line = options.tap ? tap_line(printed + 1, file, o) : result_line(file, o);
      std::fputs(line.c_str(), stdout);
      std::fflush(stdout);
      (o.status == Outcome::Status::pass   ? passed
       : o.status == Outcome::Status::fail ? failed
       : o.status == Outcome::Status::error ? bad
                                            : not_run) += 1;
    }
  };
  // "2 of 5 worlds done; running: a.json 12 s, t = 31 / 1e+12 s, ETA 9.2 years; b.json 3 s".
  auto show = [&](const std::vector<RunningChild>& running) {
    if (!status.due()) return;
    std::string text = std::to_string(finished) + " of " + std::to_string(n) + " worlds done; running:";
    for (std::size_t k = 0; k < running.size(); ++k) {
      if (k == 3) {
        text += " and " + std::to_string(running.size() - k) + " more";
        break;
      }
      const RunningChild& c = running[k];
      text += (k > 0 ? "; " : " ") + options.worlds[c.index] + " " + human_duration(c.seconds);
      if (const auto at = WorldProgress::parse(c.status))
        text += ", " + at->text() + ", " + eta_text(at->done(), at->total(), c.seconds);
    }
    status.show(text);
  };
  const int stopped_by = run_children(args, options.jobs, kill_after(options),
                                      {[&](std::size_t i, ChildResult&& r) {
                                         done[i] = outcome_of(options.worlds[i], options, std::move(r));
                                         ++finished;
                                         print();
                                       },
                                       show});
  status.clear();
  if (stopped_by != 0) {
    for (std::optional<Outcome>& o : done) {
      if (o) continue;
      o.emplace();
      o->status = Outcome::Status::not_run;
      o->message = std::string("not started: the suite was stopped by ") + signal_name(stopped_by);
    }
    print();
  }
  const double seconds = seconds_since(start);
  if (n > 1 || options.tap || stopped_by != 0) {
    std::printf("%s%zu passed, %zu failed, %zu could not run", options.tap ? "# " : "", passed, failed, bad);
    if (stopped_by != 0) std::printf(", %zu not run: stopped by %s", not_run, signal_name(stopped_by));
    std::printf("\n");
  }
  if (options.tap && stopped_by != 0) std::printf("Bail out! stopped by %s\n", signal_name(stopped_by));
  std::fflush(stdout);
  if (junit) {
    std::vector<Outcome> outcomes;
    outcomes.reserve(done.size());
    for (auto& o : done) outcomes.push_back(std::move(*o));
    junit->stream() << junit_xml(options.worlds, outcomes, seconds);
    junit->commit();
  }
  if (stopped_by != 0) return exit_code_for(stopped_by);
  // Bad input outranks a failure: a world that cannot run is a broken test, not a result.
  return bad > 0 ? exit_bad_input : failed > 0 ? exit_failure : exit_ok;
}

}  // namespace turtlegas::apps
