// SPDX-License-Identifier: MIT
// `turtlegas tag` as a user runs it: the table, the JSON, determinism and bad input.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "run_cli.hpp"

namespace fs = std::filesystem;
using namespace turtlegas::test;

TEST_CASE("turtlegas tag prints a ranking and writes it as JSON, the same every time", "[cli][tag]") {
  const fs::path dir = fs::temp_directory_path() / ("turtlegas-cli-tag-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<std::string> args = {"tag", "worlds/tag.json", "--controllers", "tag_chaser,tag_evader,tag_random",
                                         "--rounds", "6", "--until", "20"};
  auto with_json = [&](const std::string& name) {
    auto a = args;
    a.push_back("--json");
    a.push_back((dir / name).string());
    return a;
  };
  const Result a = run(dir, with_json("a.json"));
  const Result b = run(dir, with_json("b.json"));
  REQUIRE(a.code == 0);
  CHECK(a.out == b.out);
  CHECK(read(dir / "a.json") == read(dir / "b.json"));
  CHECK(a.out.find("rank") != std::string::npos);
  for (const char* name : {"tag_chaser", "tag_evader", "tag_random"}) CHECK(a.out.find(name) != std::string::npos);
  const auto j = nlohmann::json::parse(read(dir / "a.json"));
  CHECK(j.at("rounds") == 6);
  CHECK(j.at("ranking").size() == 3);
  CHECK(j.at("ranking")[0].contains("mean_time_it"));

  const Result bad = run(dir, {"tag", "worlds/tag.json", "--controllers", "tag_chaser,wandr"});
  CHECK(bad.code == 2);
  CHECK(bad.err.find("--controllers: controller 'wandr' is not registered; known: braitenberg, epuck_swarm, mirror, script, ") != std::string::npos);
  CHECK(bad.err.find("wander; did you mean 'wander'?") != std::string::npos);
  const Result missing = run(dir, {"tag", "worlds/nope.json", "--controllers", "tag_chaser"});
  CHECK(missing.code == 2);
  fs::remove_all(dir);
}

TEST_CASE("turtlegas tag --json checks its path before playing, and leaves no file behind a failure", "[cli][tag]") {
  const fs::path dir = fs::temp_directory_path() / ("turtlegas-cli-tag-json-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // A directory that does not exist: bad input, found before a single round is played (the
  // ranking table is never printed).
  const Result no_dir = run(dir, {"tag", "worlds/tag.json", "--controllers", "tag_chaser,tag_evader", "--json",
                                  (dir / "nowhere" / "t.json").string()});
  CHECK(no_dir.code == 2);
  CHECK(no_dir.err.find("--json: directory") != std::string::npos);
  CHECK(no_dir.out.find("rank") == std::string::npos);
  // A bad world after a good path: no file, and no temporary file, is left.
  const Result bad_world = run(dir, {"tag", "worlds/nope.json", "--controllers", "tag_chaser", "--json",
                                     (dir / "t.json").string()});
  CHECK(bad_world.code == 2);
  for (const auto& entry : fs::directory_iterator(dir)) {  // only run()'s captures of the output
    const std::string name = entry.path().filename().string();
    CHECK((name == "stdout.txt" || name == "stderr.txt"));
  }
  fs::remove_all(dir);
}

TEST_CASE("turtlegas tag: intervals, the pairwise table, notes, --params and range checks", "[cli][tag]") {
  const fs::path dir = fs::temp_directory_path() / ("turtlegas-cli-tag-stats-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Result r = run(dir, {"tag", "worlds/tag.json", "--controllers", "tag_chaser,tag_evader", "--rounds", "5",
                             "--until", "10", "--params", "tag_chaser.lunge=25", "--params", "tag_evader.flee=true",
                             "--stack-kib", "64", "--program-budget", "5"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("+/- 95%") != std::string::npos);
  CHECK(r.out.find("row minus column") != std::string::npos);
  // 5 rounds, 2 controllers: a warning on stderr, and the note under the table.
  CHECK(r.err.find("5 rounds do not divide among 2 controllers") != std::string::npos);
  CHECK(r.out.find("note: 5 rounds do not divide") != std::string::npos);
  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{"--params", "lunge=25"}, "--params lunge=25: write controller.key=value"},
      {{"--params", "wander.step=3"}, "'wander' is not one of --controllers"},
      {{"--stack-kib", "8"}, "--stack-kib: must be a whole number of KiB from 16 to 1048576 (got 8)"},
      {{"--program-budget", "-1"}, "--program-budget: must be a number of seconds from 0 (exclusive) to"},
      {{"--rounds", "0"}, "--rounds: must be a whole number of rounds from 1 to 100000000 (got 0)"},
      // The text as typed: a check after CLI11's conversion said "(got 18446744073709551615)".
      {{"--rounds", "-1"}, "--rounds: must be a whole number of rounds from 1 to 100000000 (got -1)"},
      {{"--until", "0"}, "--until: must be a number of seconds > 0 (got 0)"},
      {{"--until", "inf"}, "--until: must be a number of seconds > 0 (got inf)"},
  };
  for (const auto& [extra, message] : bad) {
    std::vector<std::string> args = {"tag", "worlds/tag.json", "--controllers", "tag_chaser,tag_evader"};
    args.insert(args.end(), extra.begin(), extra.end());
    const Result b = run(dir, args);
    INFO(extra.front() << ": " << b.err);
    CHECK(b.code == 2);
    CHECK(b.err.find(message) != std::string::npos);
  }
  fs::remove_all(dir);
}
