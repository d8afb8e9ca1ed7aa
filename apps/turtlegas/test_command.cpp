// SPDX-License-Identifier: MIT
#include "test_command.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output_file.hpp"
#include "child_processes.hpp"
#include "cli_common.hpp"
#include "turtlegas/sim/mode_names.hpp"
#include "turtlegas/world/expect.hpp"
#include "turtlegas/world/scenario.hpp"
#include "turtlegas/world/world_file.hpp"

namespace turtlegas::apps {
namespace {

namespace tw = turtlegas::world;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

const char* mode_name(sim::Mode m) { return sim::to_string(m).data(); }

/// One world's outcome, as the child reports it and the parent prints it.
struct Outcome {
  enum class Status { pass, fail, error } status = Status::error;
  std::string message;  ///< what failed, or why it could not run; for a pass, "(3 assertions, 0.01 s)"
  std::size_t assertions = 0;
  double seconds = 0.0;
  std::string log;      ///< the child's stdout and stderr
  std::string type = "expect";  ///< JUnit's failure type: expect, crash or timeout
};

const char* status_word(Outcome::Status s) {
  return s == Outcome::Status::pass ? "pass" : s == Outcome::Status::fail ? "fail" : "error";
}

/// Runs one world in this process: the child's whole job.
Outcome test_one(const std::string& file, const TestOptions& options, const turtle::Registry& registry) {
  Outcome o;
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
  std::string failures;
  for (sim::Mode mode : modes) {
    tw::ExpectResult r;
    try {
      r = tw::run_expectations(scene, registry, mode, server_options);
    } catch (const std::invalid_argument& e) {
      o.message = file + ": " + mode_name(mode) + " mode: " + e.what();
      return o;
    }
    o.assertions += r.assertions;
    for (const std::string& f : r.failures) {
      failures += failures.empty() ? "" : "; ";
      if (modes.size() > 1) failures += std::string(mode_name(mode)) + " mode: ";
      failures += f;
    }
  }
  o.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!failures.empty()) {
    o.status = Outcome::Status::fail;
    o.message = failures;
    return o;
  }
  o.status = Outcome::Status::pass;
  char line[160];
  std::snprintf(line, sizeof line, "(%s%zu assertion%s, %.2f s)", modes.size() > 1 ? "exact and step, " : "",
                o.assertions, o.assertions == 1 ? "" : "s", o.seconds);
  o.message = line;
  return o;
}

/// The child's side: runs its world, writes the outcome as one JSON line on descriptor 3.
int child_main(const TestOptions& options, const turtle::Registry& registry) {
  if (options.worlds.size() != 1 || ::fcntl(3, F_GETFD) == -1)
    throw BadInput("test --child is for turtlegas itself: it runs one world and reports on descriptor 3");
  Outcome o = test_one(options.worlds.front(), options, registry);
  const std::string line =
      json{{"status", status_word(o.status)}, {"message", o.message}, {"assertions", o.assertions},
           {"seconds", o.seconds}}
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

/// The parent's reading of how a child ended.
Outcome outcome_of(const std::string& file, const TestOptions& options, ChildResult&& r) {
  Outcome o;
  o.seconds = r.seconds;
  o.log = std::move(r.out);
  o.log += r.err;
  if (r.timed_out) {
    char msg[200];
    std::snprintf(msg, sizeof msg, "still running after --timeout %g s; killed", options.timeout);
    o.status = Outcome::Status::fail;
    o.message = msg;
    o.type = "timeout";
    return o;
  }
  try {
    const json j = json::parse(r.report);
    const std::string s = j.at("status").get<std::string>();
    o.status = s == "pass" ? Outcome::Status::pass : s == "fail" ? Outcome::Status::fail : Outcome::Status::error;
    o.message = j.at("message").get<std::string>();
    o.assertions = j.at("assertions").get<std::size_t>();
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

std::string seconds_text(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", s);
  return b;
}

/// JUnit XML as Jenkins, GitLab and the GitHub test-report actions read it: one <testsuite>, one
/// <testcase> per world (name: the file as given), <failure> for a failed world, <error> for one
/// that could not run, its log in <system-err>.
std::string junit_xml(const std::vector<std::string>& files, const std::vector<Outcome>& outcomes, double seconds) {
  std::size_t failures = 0, errors = 0;
  for (const Outcome& o : outcomes) {
    failures += o.status == Outcome::Status::fail ? 1 : 0;
    errors += o.status == Outcome::Status::error ? 1 : 0;
  }
  const std::string counts = "tests=\"" + std::to_string(files.size()) + "\" failures=\"" + std::to_string(failures) +
                             "\" errors=\"" + std::to_string(errors) + "\"";
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites name=\"turtlegas test\" " + counts + " time=\"" + seconds_text(seconds) + "\">\n";
  x += "  <testsuite name=\"turtlegas test\" " + counts + " skipped=\"0\" time=\"" + seconds_text(seconds) + "\">\n";
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Outcome& o = outcomes[i];
    x += "    <testcase classname=\"turtlegas.test\" name=\"" + xml_text(files[i]) + "\" file=\"" + xml_text(files[i]) +
         "\" time=\"" + seconds_text(o.seconds) + "\"";
    if (o.status == Outcome::Status::pass && o.log.empty()) {
      x += "/>\n";
      continue;
    }
    x += ">\n";
    if (o.status != Outcome::Status::pass) {
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
                  "Wall-clock seconds a world may take before it is killed and fails (0: no limit)")
      ->capture_default_str()
      ->check(real_in(0, 1e9, "seconds"));
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
  if (!options.junit.empty()) junit.emplace(options.junit, "--junit");

  std::vector<std::vector<std::string>> args;
  for (const std::string& file : options.worlds) {
    std::vector<std::string> a = {"test", file, "--child", "--program-budget", json(options.program_budget).dump(),
                                  "--stack-kib", std::to_string(options.stack_kib)};
    if (options.mode) a.insert(a.end(), {"--mode", *options.mode});
    for (const std::string& p : plugins) a.insert(a.end(), {"--plugin", p});
    args.push_back(std::move(a));
  }

  const auto start = Clock::now();
  const std::size_t n = options.worlds.size();
  if (options.tap) std::printf("TAP version 13\n1..%zu\n", n);
  std::fflush(stdout);
  std::vector<std::optional<Outcome>> done(n);
  std::size_t printed = 0;
  std::size_t passed = 0, failed = 0, bad = 0;
  run_children(args, options.jobs, options.timeout, [&](std::size_t i, ChildResult&& r) {
    done[i] = outcome_of(options.worlds[i], options, std::move(r));
    // In the order given, whatever order they end in.
    for (; printed < n && done[printed]; ++printed) {
      const Outcome& o = *done[printed];
      const std::string& file = options.worlds[printed];
      if (!options.quiet && !o.log.empty()) {
        std::fputs(o.log.c_str(), stderr);
        if (o.log.back() != '\n') std::fputc('\n', stderr);
        std::fflush(stderr);
      }
      const std::string line = options.tap ? tap_line(printed + 1, file, o) : result_line(file, o);
      std::fputs(line.c_str(), stdout);
      std::fflush(stdout);
      (o.status == Outcome::Status::pass ? passed : o.status == Outcome::Status::fail ? failed : bad) += 1;
    }
  });
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (n > 1 || options.tap)
    std::printf("%s%zu passed, %zu failed, %zu could not run\n", options.tap ? "# " : "", passed, failed, bad);
  if (junit) {
    std::vector<Outcome> outcomes;
    outcomes.reserve(done.size());
    for (auto& o : done) outcomes.push_back(std::move(*o));
    junit->stream() << junit_xml(options.worlds, outcomes, seconds);
    junit->commit();
  }
  // Bad input outranks a failure: a world that cannot run is a broken test, not a result.
  return bad > 0 ? exit_bad_input : failed > 0 ? exit_failure : exit_ok;
}

}  // namespace turtlegas::apps
