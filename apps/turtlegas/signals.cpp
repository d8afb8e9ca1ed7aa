// SPDX-License-Identifier: MIT
#include "signals.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "output_file.hpp"
#include "turtlegas/turtle/world_server.hpp"

namespace turtlegas::apps {
namespace {

volatile sig_atomic_t g_stop = 0;
const char* g_stop_doing = "stopping at the next control step and writing the outputs";
constexpr std::size_t max_child_groups = 1024;  // test's and sweep's --jobs are at most 1024
std::atomic<pid_t> g_child_groups[max_child_groups];
char g_world[512] = "";
std::atomic<double> g_run_time{0.0};

// What a signal handler may build a line with: a fixed buffer, no allocation, write(2) only.
class Line {
 public:
  Line& operator<<(const char* s) {
    while (s && *s && n_ < sizeof buf_ - 1) buf_[n_++] = *s++;
    return *this;
  }
  /// Six significant digits, "%.6g"-like, without the C library.
  Line& operator<<(double v) {
    if (std::isnan(v)) return *this << "nan";
    if (v < 0) {
      *this << "-";
      v = -v;
    }
    if (std::isinf(v)) return *this << "inf";
    if (v == 0) return *this << "0";
    int exp10 = 0;
    while (v >= 10.0) v /= 10.0, ++exp10;
    while (v < 1.0) v *= 10.0, --exp10;
    auto digits = static_cast<std::uint64_t>(std::llround(v * 1e5));  // 6 digits, d.ddddd
    if (digits >= 1000000) digits /= 10, ++exp10;
    char d[7];
    for (int k = 5; k >= 0; --k) d[k] = static_cast<char>('0' + digits % 10), digits /= 10;
    d[6] = '\0';
    int last = 5;  // trailing zeros go
    while (last > 0 && d[last] == '0') --last;
    if (exp10 >= -4 && exp10 < 6) {
      // Fixed: the point after digit exp10 (or leading zeros for a negative exponent).
      if (exp10 < 0) {
        *this << "0.";
        for (int k = -1; k > exp10; --k) *this << "0";
        for (int k = 0; k <= last; ++k) put(d[k]);
      } else {
        for (int k = 0; k <= std::max(last, exp10); ++k) {
          put(d[k]);
          if (k == exp10 && k < last) put('.');
        }
      }
      return *this;
    }
    put(d[0]);
    if (last > 0) {
      put('.');
      for (int k = 1; k <= last; ++k) put(d[k]);
    }
    put('e');
    if (exp10 < 0) put('-'), exp10 = -exp10;
    else put('+');
    char e[4];
    int ne = 0;
    do e[ne++] = static_cast<char>('0' + exp10 % 10), exp10 /= 10;
    while (exp10 > 0);
    if (ne == 1) put('0');
    while (ne > 0) put(e[--ne]);
    return *this;
  }
  void write() const { [[maybe_unused]] const ssize_t r = ::write(STDERR_FILENO, buf_, n_); }

 private:
  void put(char c) {
    if (n_ < sizeof buf_ - 1) buf_[n_++] = c;
  }
  char buf_[1024];
  std::size_t n_ = 0;
};

/// SIGKILL to every noted child group: async-signal-safe (kill only).
void kill_child_groups() {
  for (std::atomic<pid_t>& g : g_child_groups)
    if (const pid_t group = g.load(std::memory_order_relaxed); group > 0) ::kill(-group, SIGKILL);
}

void on_stop(int sig) {
  if (g_stop != 0) {
    // The second one: the run did not get to a consistent point soon enough for the user.
    kill_child_groups();
    remove_temporaries();
    (Line() << "turtlegas: " << signal_name(sig) << " again: stopping at once; outputs are not written\n").write();
    ::signal(sig, SIG_DFL);
    ::raise(sig);
    return;
  }
  g_stop = sig;
  (Line() << "turtlegas: " << signal_name(sig) << ": " << g_stop_doing << " (again to quit at once)\n").write();
}

/// "in the program of turtle 't1' (controller 'wander') at t = 12.5 s" or "at t = 12.5 s (no
/// turtle program was running)".
Line& where(Line& line) {
  const turtle::ProgramInFlight& p = turtle::program_in_flight();
  const char* turtle = p.turtle;
  const char* controller = p.controller;
  if (turtle != nullptr) {
    line << " in the program of turtle '" << turtle << "' (controller '" << (controller ? controller : "?")
         << "') at t = " << static_cast<double>(p.t) << " s";
  } else {
    line << " at t = " << g_run_time.load(std::memory_order_relaxed) << " s (in no turtle's program)";
  }
  return line;
}

const char* describe(int sig) {
  switch (sig) {
    case SIGSEGV: return "a segmentation fault (a bad pointer?)";
    case SIGBUS: return "a bus error (a bad pointer?)";
    case SIGFPE: return "an arithmetic fault (an integer division by zero?)";
    case SIGILL: return "an illegal instruction";
    case SIGABRT: return "an abort (abort(), a failed assert, or an uncaught exception)";
  }
  return "a fatal signal";
}

/// What a lost run leaves: nothing, or the outputs put in place before (a periodic checkpoint,
/// render's frames), which are whole.
const char* outputs_so_far() {
  return any_output_committed() ? "the outputs put in place before now (a periodic --checkpoint, frames) are whole, "
                                  "the others were not written"
                                : "no outputs were written";
}

void on_fatal(int sig) {
  Line line;
  line << "turtlegas: " << signal_name(sig) << ", " << describe(sig);
  where(line) << ", world " << g_world << "; the run is lost: " << outputs_so_far() << "\n";
  line.write();
  kill_child_groups();
  remove_temporaries();
  // The default action, as if we had not been here: the process dies of the signal. Returning
  // re-runs the faulting instruction (SIGSEGV) or, for a raised signal, delivers it now.
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void on_exit() {
  if (turtle::program_in_flight().turtle == nullptr) return;  // turtlegas's own exit
  Line line;
  line << "turtlegas: exit() was called";
  where(line) << ", world " << g_world << "; the run is lost: " << outputs_so_far() << "\n";
  line.write();
  remove_temporaries();
  ::_exit(1);
}

/// After the runtime's line naming the busy-looping turtle (turtle::set_busy_loop_last_words).
void on_busy_loop_exit() {
  kill_child_groups();
  Line line;
  if (keep_temporaries() > 0)
    line << "turtlegas: the event log is kept up to t = " << g_run_time.load(std::memory_order_relaxed)
         << " s (the last chunk written); the other outputs are not written\n";
  else
    line << "turtlegas: outputs are not written\n";
  line.write();
}

}  // namespace

void install_stop_signals(const char* doing) {
  if (doing != nullptr) g_stop_doing = doing;
  struct sigaction sa{};
  sa.sa_handler = on_stop;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int stop_signal() { return g_stop; }
int exit_code_for(int sig) { return 128 + sig; }

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGABRT: return "SIGABRT";
  }
  return "a signal";
}

void install_crash_report(const std::string& world) {
  std::strncpy(g_world, world.c_str(), sizeof g_world - 1);
  // A stack of its own for the handler: a fault may come from a full stack.
  static char alt_stack[64 * 1024];
  stack_t current{};
  if (sigaltstack(nullptr, &current) == 0 && (current.ss_flags & SS_DISABLE)) {
    stack_t ss{};
    ss.ss_sp = alt_stack;
    ss.ss_size = sizeof alt_stack;
    sigaltstack(&ss, nullptr);
  }
  struct sigaction sa{};
  sa.sa_handler = on_fatal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_ONSTACK | SA_RESETHAND;
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) sigaction(sig, &sa, nullptr);
  turtle::set_busy_loop_last_words(&on_busy_loop_exit);
  static bool once = [] { return std::atexit(on_exit) == 0; }();
  (void)once;
}

void note_child_group(pid_t group) {
  for (std::atomic<pid_t>& g : g_child_groups) {
    pid_t empty = 0;
    if (g.compare_exchange_strong(empty, group)) return;
  }
}

void forget_child_group(pid_t group) {
  for (std::atomic<pid_t>& g : g_child_groups) {
    pid_t same = group;
    if (g.compare_exchange_strong(same, 0)) return;
  }
}

void note_run_time(double t) { g_run_time.store(t, std::memory_order_relaxed); }

}  // namespace turtlegas::apps
