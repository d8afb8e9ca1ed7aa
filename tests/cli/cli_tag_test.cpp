// SPDX-License-Identifier: MIT
// `turtlegas tag` as a user runs it: the table, the JSON, determinism and bad input.
#include <filesystem>
#include <string>
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
  CHECK(bad.err.find("controller 'wandr' is not registered") != std::string::npos);
  const Result missing = run(dir, {"tag", "worlds/nope.json", "--controllers", "tag_chaser"});
  CHECK(missing.code == 2);
  fs::remove_all(dir);
}
