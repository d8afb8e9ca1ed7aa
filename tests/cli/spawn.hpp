// SPDX-License-Identifier: MIT
// A turtlegas process a test can signal and wait for with a deadline: runs that must stop, or
// that used to hang, are spawned, never waited for without a bound.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "run_cli.hpp"

namespace turtlegas::test {

/// How a spawned process ended.
struct Ended {
  int code = -1;    ///< exit code, or -1 when killed by a signal
  int signal = 0;   ///< the signal that killed it, or 0
};

class Spawned {
 public:
  /// Starts turtlegas with `args` in `dir`, stdin from /dev/null, stdout and stderr to files there.
  Spawned(const fs::path& dir, const std::vector<std::string>& args)
      : out_(dir / "stdout.txt"), err_(dir / "stderr.txt") {
    std::vector<std::string> argv_s{TURTLEGAS_BIN};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      // The child: its own process group, so a signal to it reaches nothing else.
      ::setpgid(0, 0);
      const int in = ::open("/dev/null", O_RDONLY);
      const int out = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open(err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(in, 0);
      ::dup2(out, 1);
      ::dup2(err, 2);
      ::chdir(dir.c_str());
      std::vector<char*> argv;
      argv.reserve(argv_s.size() + 1);  // and the closing null
      for (std::string& a : argv_s) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ~Spawned() {
    if (pid_ > 0 && !ended_) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
  }
  Spawned(const Spawned&) = delete;
  Spawned& operator=(const Spawned&) = delete;

  void send(int sig) const { ::kill(pid_, sig); }

  /// Waits up to `seconds` for the process to end; nullopt if it is still running (it is then
  /// killed by the destructor).
  std::optional<Ended> wait_for(double seconds) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        ended_ = true;
        if (WIFEXITED(status)) return Ended{WEXITSTATUS(status), 0};
        return Ended{-1, WIFSIGNALED(status) ? WTERMSIG(status) : 0};
      }
      if (std::chrono::steady_clock::now() > deadline) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  /// Waits until `file` exists and holds at least `bytes` bytes, or `seconds` pass.
  static bool wait_for_file(const fs::path& file, std::uintmax_t bytes, double seconds) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < deadline) {
      std::error_code ec;
      if (fs::exists(file, ec) && fs::file_size(file, ec) >= bytes) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  /// Waits until a file in `dir` whose name begins with `prefix` holds at least `bytes` bytes, or
  /// `seconds` pass; `found` is its path.
  static bool wait_for_file_prefix(const fs::path& dir, const std::string& prefix, std::uintmax_t bytes,
                                   double seconds, fs::path& found) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < deadline) {
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.path().filename().string().rfind(prefix, 0) == 0 && fs::file_size(e.path(), ec) >= bytes && !ec) {
          found = e.path();
          return true;
        }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  std::string out() const { return read(out_); }
  std::string err() const { return read(err_); }

 private:
  fs::path out_, err_;
  pid_t pid_ = -1;
  bool ended_ = false;
};

}  // namespace turtlegas::test
