// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <exception>
#include <functional>
#include <memory>

namespace turtlegas::turtle::detail {

/// A cooperative coroutine with its own stack and a guard page below it (Boost.Context's fiber on
/// a protected stack; this file pair is the only place that includes Boost.Context).
///
/// Two faults are contained rather than left to take the process down where that is safe:
/// - running into the guard page (a stack overflow) is caught by a SIGSEGV handler on an
///   alternate stack, which jumps back to the resume() that started the slice;
/// - running past a wall-clock budget without suspending (a busy loop) is caught by a watchdog
///   thread, which condemns the slice: the body's next call of safe_point() (every call of the
///   Turtle API makes one) switches back to resume() by the ordinary fiber switch. A body that
///   makes no such call for one more budget cannot be left safely (it may be inside malloc with
///   the arena's lock held, and no code may run on this thread after a jump out of it): SIGALRM's
///   handler then ends the process through set_busy_loop_exit()'s function (async-signal-safe).
/// Either way the fiber is then abandoned (its stack is leaked, never unwound) and resume()
/// reports what happened.
///
/// A body suspended mid-flight is ended by stop() (the destructor calls it): it resumes the body,
/// and suspend() then throws Stop, which unwinds the body's frames (running their destructors) up
/// to the fiber's entry. A body that catches Stop and suspends again (a `catch (...)` that does
/// not rethrow, around a command) cannot be unwound: it is abandoned there, its stack leaked.
///
/// One simulation thread per process: the running slice, its guard page and the watchdog's view
/// of it are process-wide (fiber.cpp), and the busy-loop signal goes to the thread that last
/// resumed a fiber. Every WorldServer of a process must therefore run its programs on one thread
/// (a network server gives all its worlds one simulation thread or strand, and its sessions other
/// threads). Worlds on several threads would first need thread_local slice state and a watchdog
/// per thread.
class Fiber {
 public:
  enum class Outcome {
    suspended,       ///< the body called suspend()
    finished,        ///< the body returned (or threw: see error())
    stack_overflow,  ///< the body ran into its guard page
    over_budget,     ///< the body ran past the budget without suspending
  };

  /// What suspend() throws to unwind a body that stop() ends. Not a std::exception, so that
  /// `catch (const std::exception&)` lets it through; a `catch (...)` must rethrow it.
  struct Stop {};

  Fiber(std::function<void()> body, std::size_t stack_bytes);
  /// Stops a body suspended mid-flight (stop(), with the budget of the last resume).
  ~Fiber();
  Fiber(const Fiber&) = delete;
  Fiber& operator=(const Fiber&) = delete;

  /// Runs the body until it suspends or ends. budget_seconds <= 0 means no budget.
  Outcome resume(double budget_seconds);
  /// From inside the body: back to whoever resumed it. Throws Stop when stop() resumes it.
  void suspend();
  /// Ends a suspended body: resumes it so that its suspend() throws Stop, within the budget.
  /// Returns finished when it unwound (or had ended); suspended when it caught Stop and suspended
  /// again, and stack_overflow or over_budget when it faulted while unwinding: in those three
  /// cases the body is abandoned, never resumed or unwound again.
  Outcome stop(double budget_seconds);
  /// Whether stop() has been called: from inside the body, a suspend() now abandons it for good.
  bool stopping() const;
  bool done() const;
  /// What the body threw, if it ended by throwing.
  std::exception_ptr error() const;
  /// Cache hints for a scheduler that knows which fiber it resumes next. A resume after a long
  /// while starts with cache misses on the fiber's record and on its stack; issued some time
  /// before resume(), first prefetch_record() and later (once the record has arrived)
  /// prefetch_stack() overlap those misses with other work. They change nothing else.
  void prefetch_record() const;
  void prefetch_stack() const;
  /// Bytes reserved for the stack, guard page included.
  std::size_t reserved_bytes() const;

  /// The fiber running now, if any.
  static Fiber* current();
  /// From inside a body (cheap: two relaxed loads): if the watchdog has condemned the running
  /// slice, leaves it for good; resume() returns over_budget. Otherwise returns at once.
  static void safe_point();

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Called from SIGALRM's handler, on the simulation thread, when a condemned slice has run a
/// further budget without reaching a safe point: async-signal-safe calls only, and it must not
/// return (it ends with _exit). The default writes one line on stderr and exits with code 1.
using BusyLoopExit = void (*)(double budget_seconds);
void set_busy_loop_exit(BusyLoopExit exit);

}  // namespace turtlegas::turtle::detail
