// SPDX-License-Identifier: MIT
// Running the turtlegas program from a test as a user would: a scratch directory, the command's
// exit code and output. TURTLEGAS_BIN (the binary's path) comes from the test's compile definitions.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace turtlegas::test {

namespace fs = std::filesystem;

/// A fresh directory for one test case, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() / ("turtlegas-cli-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return path / name;
  }
};

inline std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// A word for the shell, in single quotes.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct Result {
  int code = -1;
  std::string out, err;
};

/// Runs turtlegas with `args` (stdin empty), its output captured in files in dir.
inline Result run(const fs::path& dir, const std::vector<std::string>& args) {
  std::string cmd = quote(TURTLEGAS_BIN);
  // Appended piecewise: GCC 12 gives a false -Wrestrict for "literal" + std::string (bug 105329).
  for (const auto& a : args) {
    cmd += ' ';
    cmd += quote(a);
  }
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  cmd += " >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read(out), read(err)};
}

inline Result run(const TempDir& dir, const std::vector<std::string>& args) { return run(dir.path, args); }

}  // namespace turtlegas::test
