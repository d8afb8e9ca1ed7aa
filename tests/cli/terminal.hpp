// SPDX-License-Identifier: MIT
// A turtlegas process on a pseudo-terminal, as in a shell: for the progress lines, which appear only
// when stderr is a terminal. Waits are bounded: the process is killed after 60 s.
#pragma once

#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "run_cli.hpp"

namespace turtlegas::test {

/// What turtlegas wrote to its terminal, run with `args` in `dir` on a pseudo-terminal (as in a
/// shell), and how it ended: killed after 60 s.
struct OnTerminal {
  std::string seen;
  bool ended = false;
  int status = 0;
};

inline OnTerminal run_on_terminal(const fs::path& dir, const std::vector<std::string>& args) {
  std::vector<std::string> argv_s{TURTLEGAS_BIN};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  int master = -1;
  const pid_t pid = ::forkpty(&master, nullptr, nullptr, nullptr);
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::chdir(dir.c_str());
    std::vector<char*> argv;
    argv.reserve(argv_s.size() + 1);
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  OnTerminal r;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    pollfd pfd{master, POLLIN, 0};
    if (::poll(&pfd, 1, 100) > 0) {
      char buf[4096];
      const ssize_t n = ::read(master, buf, sizeof buf);
      if (n > 0) r.seen.append(buf, static_cast<std::size_t>(n));
      if (n <= 0 && ::waitpid(pid, &r.status, WNOHANG) == pid) {
        r.ended = true;
        break;
      }
    } else if (::waitpid(pid, &r.status, WNOHANG) == pid) {
      r.ended = true;
      break;
    }
  }
  if (!r.ended) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &r.status, 0);
  }
  ::close(master);
  return r;
}

}  // namespace turtlegas::test
