// SPDX-License-Identifier: MIT
// Controllers loaded from shared-library plugins (`--plugin`), built by CMake with
// turtlegas_add_plugin: the example of docs/controllers.md, and a busy loop.
#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace turtlegas::test;

namespace {

const std::string feeler_world = std::string(TURTLEGAS_SOURCE_DIR) + "/controllers/examples/feeler.json";

}  // namespace

TEST_CASE("plugins: a plugin's controllers are listed and run") {
  TempDir dir;
  const Result list = run(dir.path, {"controllers", "--plugin", FEELER_PLUGIN});
  INFO(list.err);
  REQUIRE(list.code == 0);
  CHECK(contains(list.out, "feeler"));
  CHECK(contains(list.out, "wander"));

  const Result check = run(dir.path, {"check", feeler_world, "--plugin", FEELER_PLUGIN});
  INFO(check.err);
  CHECK(check.code == 0);
  CHECK(contains(check.out, "controllers: feeler"));

  const fs::path events = dir.path / "e.jsonl", state = dir.path / "s.json";
  const Result r = run(dir.path, {"run", feeler_world, "--until", "120", "--plugin", FEELER_PLUGIN, "--events",
                                  events.string(), "--state-out", state.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(contains(r.err, "turtle 'feeler'"));  // its t.log lines
  std::ifstream in(events);
  std::string line;
  std::size_t touches = 0;
  while (std::getline(in, line)) touches += json::parse(line).at("kind") == "touch" ? 1 : 0;
  CHECK(touches > 20);
  CHECK(json::parse(read(state)).at("turtles").size() == 1);

  // Without the plugin the world names an unknown controller.
  const Result without = run(dir.path, {"run", feeler_world, "--until", "1"});
  CHECK(without.code == 2);
  CHECK(contains(without.err, "controller 'feeler' is not registered"));
}

namespace {

/// A walled room with a gas (so that the event log has lines) and one turtle running `controller`.
std::string busy_world(const std::string& controller) {
  return R"({"format": "turtlegas-world/1", "arena": {"width": 100, "height": 100, "boundary": "walls"},
    "gas": [{"count": 40, "radius": 1, "speed": 40, "seed": 3}],
    "turtles": [{"id": "spin", "pos": [50, 50], "controller": ")" +
         controller + R"("}]})";
}

/// turtlegas with `args`, killed (SIGKILL, which no handler delays) after `bound` seconds: code 137.
Result run_bounded(const TempDir& dir, const std::vector<std::string>& args, int bound) {
  std::string cmd = "timeout -s KILL " + std::to_string(bound) + " " + quote(TURTLEGAS_BIN);
  for (const auto& a : args) {
    cmd += ' ';
    cmd += quote(a);
  }
  const fs::path out = dir.path / "stdout.txt", err = dir.path / "stderr.txt";
  cmd += " >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read(out), read(err)};
}

/// The lines of an event log, each checked to be a whole JSON object.
std::size_t whole_lines(const fs::path& log) {
  std::ifstream in(log);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    const json j = json::parse(line, nullptr, false);
    if (!j.is_object()) FAIL("a cut line in the kept event log: " << line);
    ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("plugins: a busy loop that never calls the API ends the process, naming the turtle; the event log is kept") {
  TempDir dir;
  const fs::path world = dir.write("spin.json", busy_world("spinner"));
  const fs::path events = dir.path / "e.jsonl";
  std::ofstream(events) << "previous\n";
  const Result r = run_bounded(dir, {"run", world.string(), "--until", "5", "--plugin", TEST_PLUGIN, "--program-budget",
                                     "0.2", "--events", events.string()},
                               60);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(contains(r.err, "turtle 'spin' (controller 'spinner')"));
  CHECK(contains(r.err, "busy loop"));
  CHECK(contains(r.err, "the event log is kept up to t = "));
  // Before: the event log was deleted (its temporary removed, the old file left).
  REQUIRE(fs::exists(events));
  CHECK(read(events) != "previous\n");
  whole_lines(events);
}

TEST_CASE("plugins: a busy loop that allocates never hangs: 20 runs in 20 end with the busy-loop message") {
  // Before: the watchdog jumped out of the SIGALRM handler wherever the program was; inside
  // malloc the arena's lock stayed held and the next allocation waited for ever (5 runs in 12
  // hung, measured on 18732e7 with a budget of 0.1 s).
  TempDir dir;
  const fs::path world = dir.write("alloc.json", busy_world("allocator"));
  const fs::path events = dir.path / "e.jsonl";
  int hung = 0, other = 0;
  for (int k = 0; k < 20; ++k) {
    const Result r = run_bounded(dir, {"run", world.string(), "--until", "5", "--plugin", TEST_PLUGIN, "--program-budget",
                                       "0.05", "--events", events.string()},
                                 30);
    if (r.code == 137) ++hung;
    else if (r.code != 1 || !contains(r.err, "turtle 'spin'") || !contains(r.err, "busy loop")) {
      ++other;
      UNSCOPED_INFO("run " << k << ": exit " << r.code << ": " << r.err);
    }
  }
  CHECK(hung == 0);
  CHECK(other == 0);
  REQUIRE(fs::exists(events));
  whole_lines(events);
}

TEST_CASE("plugins: a busy loop that calls the API stops there; the run fails and keeps its event log up to the stop") {
  TempDir dir;
  const fs::path world = dir.write("poll.json", busy_world("poller"));
  const fs::path events = dir.path / "e.jsonl", state = dir.path / "s.json";
  const Result r = run_bounded(dir, {"run", world.string(), "--until", "5", "--plugin", TEST_PLUGIN, "--program-budget",
                                     "0.2", "--events", events.string(), "--state-out", state.string()},
                               60);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(contains(r.err, "turtle 'spin': its program ran for more than"));
  CHECK(contains(r.err, "busy loop"));
  CHECK_FALSE(contains(r.err, "cannot be stopped safely"));  // stopped at its call of t.time()
  REQUIRE(fs::exists(events));  // before: deleted
  CHECK(whole_lines(events) > 0);
  CHECK_FALSE(fs::exists(state));  // the other outputs are not written
}

TEST_CASE("plugins: a file that is not a plugin is bad input") {
  TempDir dir;
  const Result missing = run(dir.path, {"controllers", "--plugin", (dir.path / "nope.so").string()});
  CHECK(missing.code == 2);
  CHECK(contains(missing.err, "cannot open it: No such file"));
  const Result not_plugin = run(dir.path, {"controllers", "--plugin", feeler_world});
  CHECK(not_plugin.code == 2);
  CHECK(contains(not_plugin.err, "--plugin " + feeler_world + ": not a shared library (no ELF header)"));
}

TEST_CASE("plugins: a truncated plugin, a FIFO and a directory are refused by name, without a crash or a wait") {
  TempDir dir;
  // Before: the cut copy crashed every command with SIGBUS and no word (dlopen maps the segments
  // past the file's end), and the FIFO blocked for ever.
  const std::string plugin = read(TEST_PLUGIN);
  const fs::path cut = dir.write("cut.so", plugin.substr(0, plugin.size() / 2));
  const Result truncated = run_bounded(dir, {"controllers", "--plugin", cut.string()}, 30);
  INFO(truncated.err);
  CHECK(truncated.code == 2);
  CHECK(contains(truncated.err, "--plugin " + cut.string() + ": truncated: a loadable segment ends at byte"));
  const fs::path fifo = dir.path / "fifo.so";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  const Result from_fifo = run_bounded(dir, {"check", feeler_world, "--plugin", fifo.string()}, 30);
  INFO(from_fifo.err);
  CHECK(from_fifo.code == 2);
  CHECK(contains(from_fifo.err, "--plugin " + fifo.string() + ": not a regular file (a FIFO)"));
  const Result from_dir = run(dir, {"controllers", "--plugin", dir.path.string()});
  CHECK(from_dir.code == 2);
  CHECK(contains(from_dir.err, "not a regular file (a directory)"));
}

TEST_CASE("plugins: a registration that throws, or that takes a taken name, is named") {
  TempDir dir;
  ::setenv("TURTLEGAS_TEST_PLUGIN_THROW", "1", 1);
  const Result threw = run(dir, {"controllers", "--plugin", TEST_PLUGIN});
  ::unsetenv("TURTLEGAS_TEST_PLUGIN_THROW");
  INFO(threw.err);
  CHECK(threw.code == 2);  // before: exit 1, "asked to throw" alone
  CHECK(contains(threw.err, std::string("--plugin ") + TEST_PLUGIN + ": its turtlegas_register threw: asked to throw"));
  for (const std::string name : {"wander", "remote"}) {
    ::setenv("TURTLEGAS_TEST_PLUGIN_CLASH", name.c_str(), 1);
    const Result clash = run(dir, {"controllers", "--plugin", TEST_PLUGIN});
    ::unsetenv("TURTLEGAS_TEST_PLUGIN_CLASH");
    INFO(clash.err);
    CHECK(clash.code == 2);  // before: 0, the built-in silently replaced
    CHECK(contains(clash.err, std::string("--plugin ") + TEST_PLUGIN + ": it registers"));
    CHECK(contains(clash.err, "'" + name + "'"));
    CHECK(contains(clash.err, "built-in"));
  }
  // Two plugins with one name: both named.
  ::setenv("TURTLEGAS_TEST_PLUGIN_CLASH", "feeler", 1);
  const Result two = run(dir, {"controllers", "--plugin", FEELER_PLUGIN, "--plugin", TEST_PLUGIN});
  ::unsetenv("TURTLEGAS_TEST_PLUGIN_CLASH");
  INFO(two.err);
  CHECK(two.code == 2);
  CHECK(contains(two.err, std::string("--plugin ") + TEST_PLUGIN + ": it registers the controller 'feeler', which --plugin " +
                              FEELER_PLUGIN + " registered already"));
}

TEST_CASE("plugins: TURTLEGAS_PLUGIN_PATH names plugin files and directories, for every command") {
  TempDir dir;
  const std::string path = fs::path(FEELER_PLUGIN).parent_path().string() + ":" + TEST_PLUGIN;
  ::setenv("TURTLEGAS_PLUGIN_PATH", path.c_str(), 1);
  const Result list = run(dir, {"controllers"});
  const Result check = run(dir, {"check", feeler_world});
  // The same file on the path and after --plugin is loaded once (no clash with itself).
  const Result twice = run(dir, {"run", feeler_world, "--until", "1", "--plugin", FEELER_PLUGIN});
  ::unsetenv("TURTLEGAS_PLUGIN_PATH");
  INFO(list.err << check.err << twice.err);
  CHECK(list.code == 0);
  CHECK(contains(list.out, "feeler"));
  CHECK(contains(list.out, "spinner"));
  CHECK(check.code == 0);
  CHECK(twice.code == 0);
}

TEST_CASE("plugins: a world file's \"plugins\" key, relative to the world file (issue 32)") {
  TempDir dir;
  fs::create_directories(dir.path / "lib");
  fs::create_directories(dir.path / "worlds");
  fs::copy_file(FEELER_PLUGIN, dir.path / "lib" / "libfeeler.so");
  json w = json::parse(read(feeler_world));
  w["plugins"] = {"../lib/libfeeler.so"};  // from the world file's directory, not the working one
  const fs::path world = dir.write("worlds/feeler.json", w.dump());
  const Result check = run(dir.path, {"check", world.string()});
  INFO(check.err);
  CHECK(check.code == 0);
  CHECK(contains(check.out, "controllers: feeler"));
  const fs::path events = dir.path / "e.jsonl";
  const Result r = run(dir.path, {"run", world.string(), "--until", "20", "--events", events.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(contains(read(events), "\"touch\""));
  // The same file by --plugin as well is loaded once (no clash with itself).
  CHECK(run(dir.path, {"run", world.string(), "--until", "1", "--plugin", (dir.path / "lib" / "libfeeler.so").string()}).code == 0);

  // A sweep of that world (its children too) loads them as well.
  dir.write("worlds/sweep.json", R"({"format": "turtlegas-sweep/1", "world": "feeler.json", "until": 2, "seeds": [1, 2]})");
  const Result sweep = run(dir.path, {"sweep", (dir.path / "worlds" / "sweep.json").string(), "--jobs", "2", "--out",
                                      (dir.path / "results.jsonl").string()});
  INFO(sweep.err);
  CHECK(sweep.code == 0);

  w["plugins"] = {"../lib/libnothere.so"};
  const fs::path missing = dir.write("worlds/missing.json", w.dump());
  const Result bad = run(dir.path, {"check", missing.string()});
  CHECK(bad.code == 2);
  CHECK(contains(bad.err, "libnothere.so"));
  CHECK(contains(bad.err, "/plugins of " + missing.string()));
  w["plugins"] = "../lib/libfeeler.so";
  const fs::path not_list = dir.write("worlds/not_list.json", w.dump());
  const Result bad2 = run(dir.path, {"run", not_list.string(), "--until", "1"});
  CHECK(bad2.code == 2);
  CHECK(contains(bad2.err, "/plugins"));
}

TEST_CASE("plugins: a recording names its plugins; render loads them, names one missing, and is quiet (issue 32)") {
  TempDir dir;
  fs::create_directories(dir.path / "lib");
  const fs::path plugin = dir.path / "lib" / "libfeeler.so";
  fs::copy_file(FEELER_PLUGIN, plugin);
  const fs::path rec = dir.path / "r.tgrec";
  const Result r = run(dir.path, {"run", feeler_world, "--until", "120", "--plugin", plugin.string(), "--record", rec.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(contains(r.err, "turtle 'feeler'"));  // the run prints its program's log lines
  std::string header;
  {
    std::ifstream in(rec);
    std::getline(in, header);
  }
  const json h = json::parse(header);
  REQUIRE(h.contains("plugins"));
  CHECK(h.at("plugins") == json::array({{{"file", fs::canonical(plugin).string()}, {"controllers", {"feeler"}}}}));

  // No --plugin: the recording's own is loaded; its log lines are not printed again unless asked.
  const Result draw = run(dir.path, {"render", rec.string(), "--at", "110", "--out", (dir.path / "a.png").string()});
  INFO(draw.err);
  CHECK(draw.code == 0);
  CHECK_FALSE(contains(draw.err, "turtle 'feeler'"));
  const Result loud = run(dir.path, {"render", rec.string(), "--at", "110", "--out", (dir.path / "b.png").string(), "--program-logs"});
  CHECK(loud.code == 0);
  CHECK(contains(loud.err, "turtle 'feeler'"));

  // Gone: render names the plugin and its controller; given another way, it is found.
  fs::remove(plugin);
  const Result gone = run(dir.path, {"render", rec.string(), "--at", "110", "--out", (dir.path / "c.png").string()});
  CHECK(gone.code == 2);
  CHECK(contains(gone.err, "the recording's programs need the plugin " + fs::canonical(dir.path).string() + "/lib/libfeeler.so"));
  CHECK(contains(gone.err, "'feeler'"));
  const Result replaced = run(dir.path, {"render", rec.string(), "--at", "110", "--out", (dir.path / "d.png").string(), "--plugin", FEELER_PLUGIN});
  INFO(replaced.err);
  CHECK(replaced.code == 0);
}

// `turtlegas test` runs each world in a process of its own (the test plugin's misbehaving
// programs), a few at a time, and reports in JUnit XML and TAP 13.
namespace {

/// A test world of one turtle running `controller`, passing when the turtle stays in the room.
std::string one_turtle_test(const std::string& controller) {
  return R"({"format": "turtlegas-world/1", "arena": {"width": 100, "height": 100, "boundary": "walls"},
    "turtles": [{"id": "t", "pos": [50, 50], "controller": ")" +
         controller + R"("}],
    "expect": [{"until": 5}, {"inside": [[0, 0], [100, 100]], "who": "*"}]})";
}

/// Runs python3 on `script` with `arg`; its exit code (0: the script's checks held).
int python(const TempDir& dir, const std::string& script, const std::string& arg) {
  const fs::path py = dir.write("check.py", script);
  const std::string cmd = "python3 " + quote(py.string()) + " " + quote(arg) + " >" +
                          quote((dir.path / "py.txt").string()) + " 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("test: a crash, an abort and an exit fail their own world by name; the others go on") {
  TempDir dir;
  std::vector<std::string> args = {"test"};
  for (const char* c : {"chatty", "segfaulter", "aborter", "exiter", "back_and_forth"}) {
    const std::string name = std::string(c) + ".json";
    dir.write(name, one_turtle_test(c == std::string("back_and_forth") ? "chatty" : c));
    args.push_back((dir.path / name).string());
  }
  args.insert(args.end(), {"--jobs", "2", "--plugin", TEST_PLUGIN});
  const Result r = run(dir.path, args);
  INFO(r.out << r.err);
  CHECK(r.code == 1);
  // In the order given, whatever order the processes end in.
  const std::size_t chatty = r.out.find("PASS " + (dir.path / "chatty.json").string());
  const std::size_t seg = r.out.find("FAIL " + (dir.path / "segfaulter.json").string() + ": its process ended");
  const std::size_t abrt = r.out.find("FAIL " + (dir.path / "aborter.json").string() + ": its process ended");
  const std::size_t ex = r.out.find("FAIL " + (dir.path / "exiter.json").string() + ": its process ended");
  const std::size_t last = r.out.find("PASS " + (dir.path / "back_and_forth.json").string());
  REQUIRE(chatty != std::string::npos);
  REQUIRE(seg != std::string::npos);
  REQUIRE(abrt != std::string::npos);
  REQUIRE(ex != std::string::npos);
  REQUIRE(last != std::string::npos);
  CHECK((chatty < seg && seg < abrt && abrt < ex && ex < last));
  CHECK(contains(r.out, "exit code 7"));
#if !defined(__SANITIZE_ADDRESS__)  // AddressSanitizer turns the fault into its own report and exit
  CHECK(contains(r.out, "killed by signal 11"));
  CHECK(contains(r.out, "killed by signal 6"));
#endif
  CHECK(contains(r.out, "2 passed, 3 failed, 0 could not run"));
  // The passing worlds' log lines come through on stderr.
  CHECK(contains(r.err, "hello from chatty"));
}

TEST_CASE("test: --timeout kills a hung world; --quiet drops the log lines; --tap is TAP 13") {
  TempDir dir;
  const fs::path spin = dir.write("spinner.json", one_turtle_test("spinner"));
  const fs::path chatty = dir.write("chatty.json", one_turtle_test("chatty"));
  // A program budget far past the timeout: only --timeout can stop the busy loop.
  const Result r = run(dir.path, {"test", spin.string(), chatty.string(), "--timeout", "1", "--program-budget", "600",
                                  "--plugin", TEST_PLUGIN, "--quiet", "--tap", "--jobs", "2"});
  INFO(r.out << r.err);
  CHECK(r.code == 1);
  CHECK(r.out.rfind("TAP version 13\n1..2\n", 0) == 0);
  // It says how far the world got: its last progress line (t = the last control step reached).
  CHECK(contains(r.out,
                 "not ok 1 - " + spin.string() + "\n  ---\n  message: \"still running after --timeout 1 s at t = "));
  CHECK(contains(r.out, " / 5 s; killed\"\n"));
  CHECK(contains(r.out, "  severity: fail\n"));
  CHECK(contains(r.out, "ok 2 - " + chatty.string() + " (1 assertion"));
  CHECK(contains(r.out, "# 1 passed, 1 failed, 0 could not run"));
  CHECK_FALSE(contains(r.err, "hello from chatty"));
}

TEST_CASE("test: --junit writes JUnit XML that python3's xml parser reads, one testcase per world") {
  TempDir dir;
  const fs::path chatty = dir.write("chatty.json", one_turtle_test("chatty"));
  const fs::path seg = dir.write("seg.json", one_turtle_test("segfaulter"));
  const fs::path broken = dir.write("broken.json", R"({"format": "turtlegas-world/1", "bals": []})");
  const fs::path xml = dir.path / "report.xml";
  const Result r = run(dir.path, {"test", chatty.string(), seg.string(), broken.string(), "--plugin", TEST_PLUGIN,
                                  "--junit", xml.string()});
  INFO(r.out << r.err);
  CHECK(r.code == 2);  // a world that cannot run outranks a failure
  REQUIRE(fs::exists(xml));
  const std::string script = R"(import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == "testsuites", root.tag
suites = root.findall("testsuite")
assert len(suites) == 1
s = suites[0]
assert (s.get("tests"), s.get("failures"), s.get("errors")) == ("3", "1", "1"), s.attrib
cases = s.findall("testcase")
assert [c.get("name").rsplit("/", 1)[-1] for c in cases] == ["chatty.json", "seg.json", "broken.json"]
for c in cases:
    float(c.get("time"))
assert cases[0].find("failure") is None and cases[0].find("error") is None
assert "hello from chatty & <friends>" in cases[0].find("system-err").text
f = cases[1].find("failure")
assert f is not None and "its process ended without a result" in f.get("message"), f
assert f.get("type") == "crash", f.get("type")
e = cases[2].find("error")
assert e is not None and "unknown key" in e.get("message"), e
print("ok")
)";
  CHECK(python(dir, script, xml.string()) == 0);
  INFO(read(dir.path / "py.txt"));
  CHECK(contains(read(dir.path / "py.txt"), "ok"));
}

TEST_CASE("test: numeric options out of range are bad input") {
  TempDir dir;
  const fs::path chatty = dir.write("chatty.json", one_turtle_test("chatty"));
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--jobs", "0"}, "--jobs: must be a whole number of processes from 1 to 1024 (got 0)"},
      {{"--jobs", "-1"}, "--jobs: must be a whole number of processes from 1 to 1024 (got -1)"},
      {{"--timeout", "-1"}, "--timeout: must be a number of seconds from 0 to"},
      {{"--timeout", "nan"}, "--timeout: must be a number of seconds from 0 to"},
      {{"--stack-kib", "4"}, "--stack-kib: must be a whole number of KiB from 16 to 1048576 (got 4)"},
      {{"--program-budget", "0"}, "--program-budget: must be a number of seconds from 0 (exclusive) to"},
  };
  for (const auto& [opts, message] : cases) {
    std::vector<std::string> args = {"test", chatty.string(), "--plugin", TEST_PLUGIN};
    args.insert(args.end(), opts.begin(), opts.end());
    const Result r = run(dir.path, args);
    INFO(opts.front() << ": " << r.err);
    CHECK(r.code == 2);
    CHECK(contains(r.err, message));
  }
}
