// SPDX-License-Identifier: MIT
// `turtlegas tag` as a user runs it: the table, the JSON, determinism and bad input.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {

struct Result {
  int code = -1;
  std::string out, err;
};

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

Result run(const fs::path& dir, const std::vector<std::string>& args) {
  std::string cmd = quote(TURTLEGAS_BIN);
  for (const auto& a : args) cmd += " " + quote(a);
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  cmd += " >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read(out), read(err)};
}

}  // namespace

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
