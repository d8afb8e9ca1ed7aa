// SPDX-License-Identifier: MIT
#include "child_processes.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "signals.hpp"

namespace turtlegas::apps {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int report_fd = 3;
constexpr int status_fd = 4;
constexpr int pipes = 4;  // stdout, stderr, report, status

struct Pipe {
  int read = -1, write = -1;
};

Pipe make_pipe() {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(errno));
  return {fds[0], fds[1]};
}

void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

/// One running child: its pid and the pipes it writes.
struct Running {
  std::size_t index = 0;
  pid_t pid = -1;
  int fds[pipes] = {-1, -1, -1, -1};
  Clock::time_point start;
  bool killed = false;
  bool reaped = false;
  int status = 0;
  ChildResult result;
  std::string status_tail;  // descriptor 4 after its last newline

  void append(int k, const char* data, std::size_t n) {
    if (k < 3) {
      (k == 0 ? result.out : k == 1 ? result.err : result.report).append(data, n);
      return;
    }
    // Only the last whole line matters: the child's latest progress.
    status_tail.append(data, n);
    const std::size_t end = status_tail.rfind('\n');
    if (end == std::string::npos) {
      if (status_tail.size() > 4096) status_tail.clear();
      return;
    }
    const std::size_t before = end == 0 ? std::string::npos : status_tail.rfind('\n', end - 1);
    const std::size_t begin = before == std::string::npos ? 0 : before + 1;
    result.status = status_tail.substr(begin, end - begin);
    status_tail.erase(0, end + 1);
  }
  bool open() const {
    for (int fd : fds)
      if (fd >= 0) return true;
    return false;
  }
};

/// In the child, after fork: wire the pipes and exec the program. Only async-signal-safe calls.
[[noreturn]] void exec_child(const std::string& exe, const std::vector<std::string>& args, const Pipe (&p)[pipes],
                             pid_t parent) {
  ::setpgid(0, 0);  // its own group, so a timeout kills whatever it started too
  // Dies with the parent, however the parent dies (SIGKILL, SIGHUP): never an orphan running on.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);  // the parent died before the prctl
  const int devnull = ::open("/dev/null", O_RDONLY);
  if (devnull >= 0) ::dup2(devnull, 0);
  ::dup2(p[0].write, 1);
  ::dup2(p[1].write, 2);
  ::dup2(p[2].write, report_fd);  // dup2 clears O_CLOEXEC on the copy
  ::dup2(p[3].write, status_fd);
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(exe.c_str(), argv.data());
  const char msg[] = "turtlegas: cannot start a child process (execv failed)\n";
  [[maybe_unused]] ssize_t n = ::write(2, msg, sizeof msg - 1);
  ::_exit(127);
}

Running start(std::size_t index, const std::string& exe, const std::vector<std::string>& args) {
  Pipe p[pipes] = {make_pipe(), make_pipe(), make_pipe(), make_pipe()};
  Running r;
  r.index = index;
  r.start = Clock::now();
  const pid_t parent = ::getpid();
  r.pid = ::fork();
  if (r.pid < 0) {
    for (Pipe& q : p) close_fd(q.read), close_fd(q.write);
    throw std::runtime_error(std::string("cannot start a child process: ") + std::strerror(errno));
  }
  if (r.pid == 0) exec_child(exe, args, p, parent);
  ::setpgid(r.pid, r.pid);  // also here, so that a kill right away finds the group
  note_child_group(r.pid);
  for (int k = 0; k < pipes; ++k) {
    close_fd(p[k].write);
    r.fds[k] = p[k].read;
    ::fcntl(r.fds[k], F_SETFL, ::fcntl(r.fds[k], F_GETFL) | O_NONBLOCK);
  }
  return r;
}

/// Reads what is there on every open pipe of r; closes those at their end.
void drain(Running& r) {
  char buf[65536];
  for (int k = 0; k < pipes; ++k) {
    while (r.fds[k] >= 0) {
      const ssize_t n = ::read(r.fds[k], buf, sizeof buf);
      if (n > 0) {
        r.append(k, buf, static_cast<std::size_t>(n));
      } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
        close_fd(r.fds[k]);
      } else {
        break;
      }
    }
  }
}

std::string signal_text(int sig) {
  const char* d = ::strsignal(sig);
  return std::to_string(sig) + (d ? std::string(" (") + d + ")" : std::string());
}

}  // namespace

std::string ChildResult::how_it_ended() const {
  char secs[32];
  std::snprintf(secs, sizeof secs, "%g", seconds);
  if (timed_out) return std::string("killed after its timeout, ") + secs + " s";
  if (stopped) return std::string("killed after ") + secs + " s, when turtlegas was stopped";
  if (!exited) return "killed by signal " + signal_text(signal);
  return "exit code " + std::to_string(exit_code);
}

std::string self_executable() {
  std::vector<char> buf(4096);
  const ssize_t n = ::readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  if (n <= 0) throw std::runtime_error("cannot find the program's own executable (/proc/self/exe)");
  return std::string(buf.data(), static_cast<std::size_t>(n));
}

int run_children(const std::vector<std::vector<std::string>>& args, std::size_t jobs, double timeout_seconds,
                 const ChildCallbacks& callbacks) {
  if (jobs < 1) jobs = 1;
  const std::string exe = self_executable();
  // A child that dies while we write to it must not kill us; we write nothing, but be safe.
  ::signal(SIGPIPE, SIG_IGN);
  std::vector<Running> running;
  std::size_t next = 0;
  const auto timeout = std::chrono::duration<double>(timeout_seconds);
  auto last_tick = Clock::now();
  int stopped_by = 0;
  while ((next < args.size() && stopped_by == 0) || !running.empty()) {
    while (stopped_by == 0 && running.size() < jobs && next < args.size()) {
      running.push_back(start(next, exe, args[next]));
      ++next;
    }
    // Wait for output or the nearest timeout, but wake up now and then to reap children that
    // closed their pipes and to notice exits (a child's grandchild may hold a pipe open). A
    // signal cuts the poll short (poll is never restarted).
    std::vector<pollfd> polls;
    for (Running& r : running)
      for (int fd : r.fds)
        if (fd >= 0) polls.push_back({fd, POLLIN, 0});
    int wait_ms = 100;
    if (timeout_seconds > 0.0) {
      for (const Running& r : running) {
        if (r.killed) continue;
        const auto left = std::chrono::duration<double>(r.start + std::chrono::duration_cast<Clock::duration>(timeout) -
                                                        Clock::now()).count();
        wait_ms = std::min(wait_ms, std::max(0, static_cast<int>(left * 1000.0) + 1));
      }
    }
    if (!polls.empty()) {
      ::poll(polls.data(), polls.size(), wait_ms);
    } else {
      ::usleep(static_cast<useconds_t>(std::min(wait_ms, 10)) * 1000);
    }
    if (stopped_by == 0 && stop_signal() != 0) {
      stopped_by = stop_signal();
      for (Running& r : running) {
        if (r.reaped || r.killed) continue;
        ::kill(-r.pid, SIGKILL);
        ::kill(r.pid, SIGKILL);
        r.killed = r.result.stopped = true;
      }
    }
    for (std::size_t k = 0; k < running.size();) {
      Running& r = running[k];
      drain(r);
      if (!r.reaped) {
        const pid_t w = ::waitpid(r.pid, &r.status, WNOHANG);
        if (w == r.pid) r.reaped = true;
      }
      if (!r.reaped && !r.killed && timeout_seconds > 0.0 && Clock::now() - r.start >= timeout) {
        ::kill(-r.pid, SIGKILL);
        ::kill(r.pid, SIGKILL);
        r.killed = true;
      }
      if (r.reaped) {
        // Gone: what is left in the pipes is all there is (a grandchild holding one is killed).
        if (r.open()) ::kill(-r.pid, SIGKILL);
        for (int i = 0; i < 50 && r.open(); ++i) {
          drain(r);
          if (r.open()) ::usleep(1000);
        }
        for (int& fd : r.fds) close_fd(fd);
        forget_child_group(r.pid);
        r.result.seconds = std::chrono::duration<double>(Clock::now() - r.start).count();
        // A child that used up its time fails as timed out even if it ended before the kill came:
        // under load the parent may look late, and the outcome must not depend on when it looked.
        r.result.timed_out =
            !r.result.stopped && (r.killed || (timeout_seconds > 0.0 && r.result.seconds >= timeout_seconds));
        if (WIFEXITED(r.status)) {
          r.result.exited = true;
          r.result.exit_code = WEXITSTATUS(r.status);
        } else if (WIFSIGNALED(r.status)) {
          r.result.signal = WTERMSIG(r.status);
        }
        const std::size_t index = r.index;
        ChildResult result = std::move(r.result);
        running.erase(running.begin() + static_cast<std::ptrdiff_t>(k));
        callbacks.on_done(index, std::move(result));
        continue;
      }
      ++k;
    }
    if (callbacks.on_tick && !running.empty() && Clock::now() - last_tick >= std::chrono::milliseconds(200)) {
      last_tick = Clock::now();
      std::vector<RunningChild> now;
      now.reserve(running.size());
      for (const Running& r : running)
        now.push_back({r.index, std::chrono::duration<double>(last_tick - r.start).count(), r.result.status});
      callbacks.on_tick(now);
    }
  }
  return stopped_by;
}

}  // namespace turtlegas::apps
