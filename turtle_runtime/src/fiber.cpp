// SPDX-License-Identifier: MIT
#include "fiber.hpp"

#include <csetjmp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <pthread.h>
#include <unistd.h>
#include <thread>
#include <vector>

#include <boost/context/fiber.hpp>
#include <boost/context/protected_fixedsize_stack.hpp>

// AddressSanitizer keeps shadow state per stack and must be told about every switch between them;
// Boost's fcontext switches do not tell it, so we do, around each resume and suspend. GCC says it
// is on with __SANITIZE_ADDRESS__, clang (14) only through __has_feature.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TURTLEGAS_FIBER_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(TURTLEGAS_FIBER_ASAN)
#include <sanitizer/common_interface_defs.h>
#define TURTLEGAS_ASAN_SWITCH(save, bottom, size) __sanitizer_start_switch_fiber(save, bottom, size)
#define TURTLEGAS_ASAN_ARRIVE(save, bottom, size) __sanitizer_finish_switch_fiber(save, bottom, size)
#else
#define TURTLEGAS_ASAN_SWITCH(save, bottom, size) ((void)0)
#define TURTLEGAS_ASAN_ARRIVE(save, bottom, size) ((void)0)
#endif

namespace turtlegas::turtle::detail {
namespace ctx = boost::context;

namespace {

// Where the running slice started, and which stack it is on. The scheduler is single-threaded:
// only one fiber runs at a time, so plain globals suffice; the signal handlers only read them.
sigjmp_buf g_slice_start;
Fiber::Impl* volatile g_running = nullptr;
char* volatile g_guard_lo = nullptr;
char* volatile g_guard_hi = nullptr;
// The busy-loop watchdog's view of the running slice (see watchdog()).
std::atomic<std::uint64_t> g_slice{0};          // odd while a slice with a budget runs
std::atomic<std::int64_t> g_budget_ns{0};
std::atomic<std::uint64_t> g_doomed_slice{0};   // the slice the watchdog condemned
pthread_t g_scheduler_thread;
// What a condemned slice that reaches no safe point ends in (set_busy_loop_exit()).
std::atomic<BusyLoopExit> g_busy_loop_exit{nullptr};
// Leaves the running slice for resume(). (AddressSanitizer cannot follow this jump from a signal
// handler across stacks; the tests of fault recovery are skipped in sanitizer builds.)
[[noreturn]] void jump_back(int code) { siglongjmp(g_slice_start, code); }

// A stack overflow that lands within this distance below the guard page is still ours (a frame
// larger than a page can step over it).
constexpr std::size_t kGuardSlack = 64 * 1024;
const std::size_t kPage = boost::context::stack_traits::page_size();

struct sigaction g_previous_segv{}, g_previous_bus{}, g_previous_alarm{};
// SIGALRMs the watchdog has sent and the handler has not yet seen: any other SIGALRM is someone
// else's (an alarm() of the program's own) and goes to the handler that was there before ours.
std::atomic<int> g_alarms_in_flight{0};

void on_segv(int sig, siginfo_t* info, void* uctx) {
  char* addr = static_cast<char*>(info->si_addr);
  if (g_running != nullptr && addr >= g_guard_lo - kGuardSlack && addr < g_guard_hi) jump_back(1);
  // Not a fiber's guard page: hand it to whoever handled it before us, or die of it.
  const struct sigaction& prev = sig == SIGBUS ? g_previous_bus : g_previous_segv;
  if ((prev.sa_flags & SA_SIGINFO) && prev.sa_sigaction) {
    prev.sa_sigaction(sig, info, uctx);
    return;
  }
  if (prev.sa_handler != SIG_DFL && prev.sa_handler != SIG_IGN && prev.sa_handler != nullptr) {
    prev.sa_handler(sig);
    return;
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

[[noreturn]] void default_busy_loop_exit(double) {
  static const char line[] =
      "turtlegas: a turtle program ran past its budget without issuing a command or calling the Turtle API (a busy "
      "loop?); the process stops\n";
  [[maybe_unused]] const ssize_t r = ::write(STDERR_FILENO, line, sizeof line - 1);
  ::_exit(1);
}

void on_alarm(int sig, siginfo_t* info, void* uctx) {
  int ours = g_alarms_in_flight.load(std::memory_order_relaxed);
  while (ours > 0 && !g_alarms_in_flight.compare_exchange_weak(ours, ours - 1, std::memory_order_relaxed)) {
  }
  if (ours > 0) {
    // Ours, sent to the scheduler's thread only, when a condemned slice ran a further budget
    // without reaching a safe point. It may be anywhere (inside malloc, holding the arena's lock):
    // jumping out would leave that lock held and the next allocation would wait for ever. So the
    // process ends here, by async-signal-safe calls only. A late one, for a slice that has since
    // left, is dropped.
    if (g_running != nullptr && pthread_equal(pthread_self(), g_scheduler_thread) &&
        g_slice.load(std::memory_order_relaxed) == g_doomed_slice.load(std::memory_order_relaxed)) {
      const double budget = static_cast<double>(g_budget_ns.load(std::memory_order_relaxed)) * 1e-9;
      if (BusyLoopExit f = g_busy_loop_exit.load(std::memory_order_relaxed)) f(budget);
      default_busy_loop_exit(budget);
    }
    return;
  }
  const struct sigaction& prev = g_previous_alarm;
  if ((prev.sa_flags & SA_SIGINFO) && prev.sa_sigaction) {
    prev.sa_sigaction(sig, info, uctx);
  } else if (prev.sa_handler == SIG_DFL) {
    // What the alarm would have done without us: end the process.
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  } else if (prev.sa_handler != SIG_IGN && prev.sa_handler != nullptr) {
    prev.sa_handler(sig);
  }
}

// (Re)installs the handlers. Called whenever a fiber is made, so that a handler someone else
// installed in between (a test framework, say) does not swallow our faults; theirs is chained.
void install_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    // The SIGSEGV handler must run on a stack of its own: the faulting stack is full.
    static char alt_stack[64 * 1024];
    stack_t ss{};
    ss.ss_sp = alt_stack;
    ss.ss_size = sizeof alt_stack;
    sigaltstack(&ss, nullptr);
  });
  struct sigaction current{};
  sigaction(SIGSEGV, nullptr, &current);
  if (current.sa_sigaction == on_segv) return;
  struct sigaction sa{};
  sa.sa_sigaction = on_segv;
  sa.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGSEGV, &sa, &g_previous_segv);
  sigaction(SIGBUS, &sa, &g_previous_bus);
  struct sigaction al{};
  al.sa_sigaction = on_alarm;
  al.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&al.sa_mask);
  struct sigaction current_alarm{};
  sigaction(SIGALRM, nullptr, &current_alarm);
  if (current_alarm.sa_sigaction != on_alarm) sigaction(SIGALRM, &al, &g_previous_alarm);
}

// Boost's protected stack, remembering where its guard page is.
class GuardedStack {
 public:
  GuardedStack(std::size_t size, char** guard_lo, std::size_t* reserved)
      : inner_(size), guard_lo_(guard_lo), reserved_(reserved) {}
  ctx::stack_context allocate() {
    ctx::stack_context sc = inner_.allocate();
    // Boost maps size + one page and protects the lowest page: [sp - size, sp - size + page).
    *guard_lo_ = static_cast<char*>(sc.sp) - sc.size;
    *reserved_ = sc.size;
    return sc;
  }
  void deallocate(ctx::stack_context& sc) noexcept { inner_.deallocate(sc); }

 private:
  ctx::protected_fixedsize_stack inner_;
  char** guard_lo_;
  std::size_t* reserved_;
};

// The busy-loop watchdog. A resume costs two relaxed stores (no system call): the slice's number
// and its budget. A thread of our own samples them a few times per budget. When the same slice has
// been running longer than its budget it condemns it (a relaxed store): the program's next call of
// the Turtle API (Fiber::safe_point()) leaves the slice there, a point where our own code runs and
// no lock is held. A slice still running one more budget later never calls the API (a pure busy
// loop): the watchdog sends SIGALRM to the scheduler's thread, whose handler ends the process
// (on_alarm) if that slice is still the one running. Nothing ever jumps out of arbitrary code.

void watchdog() {
  using namespace std::chrono;
  // A process-wide SIGALRM (someone's alarm()) must not land on this thread: the handler reads
  // the scheduler's slice, which only makes sense on the scheduler's thread.
  sigset_t alarm;
  sigemptyset(&alarm);
  sigaddset(&alarm, SIGALRM);
  pthread_sigmask(SIG_BLOCK, &alarm, nullptr);
  std::uint64_t watched = 0;
  steady_clock::time_point since = steady_clock::now();
  for (;;) {
    const std::int64_t budget = std::max<std::int64_t>(g_budget_ns.load(std::memory_order_relaxed), 1'000'000);
    std::this_thread::sleep_for(nanoseconds(std::clamp<std::int64_t>(budget / 8, 1'000'000, 100'000'000)));
    const std::uint64_t slice = g_slice.load(std::memory_order_relaxed);
    const auto now = steady_clock::now();
    if (slice != watched) {
      watched = slice;
      since = now;
      continue;
    }
    if ((slice & 1) && duration_cast<nanoseconds>(now - since).count() > budget) {
      if (g_doomed_slice.load(std::memory_order_relaxed) != slice) {
        g_doomed_slice.store(slice, std::memory_order_relaxed);  // first: stop at the next safe point
      } else {
        g_alarms_in_flight.fetch_add(1, std::memory_order_relaxed);  // a budget later: end the process
        if (pthread_kill(g_scheduler_thread, SIGALRM) != 0) g_alarms_in_flight.fetch_sub(1, std::memory_order_relaxed);
      }
      since = now;
    }
  }
}

void start_slice(double budget_seconds) {
  if (budget_seconds <= 0) return;
  static std::once_flag once;
  g_scheduler_thread = pthread_self();
  std::call_once(once, [] { std::thread(watchdog).detach(); });
  g_budget_ns.store(static_cast<std::int64_t>(budget_seconds * 1e9), std::memory_order_relaxed);
  // Only this thread writes the counter (the watchdog reads it): a plain load and store, not a
  // locked add, which costs ~20 cycles twice per resume.
  g_slice.store(g_slice.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);  // now odd: running
}

void end_slice(double budget_seconds) {
  if (budget_seconds <= 0) return;
  g_slice.store(g_slice.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);  // even again: idle
}

}  // namespace

// What resume(), suspend() and prefetch_stack() read comes first, in one cache line (the one
// prefetch_record() asks for); the body and the rest follow.
class alignas(64) Fiber::Impl {
 public:
  ctx::fiber self;    // the suspended body, seen from outside
  ctx::fiber caller;  // whoever resumed it, seen from inside
  char* guard_lo = nullptr;
  char* suspended_at = nullptr;  // the frame of the last suspend(), for prefetch_stack()
  char* entry = nullptr;         // the frame that calls the body, for prefetch_stack()
  std::size_t reserved = 0;
  bool started = false;
  bool finished = false;
  bool abandoned = false;  // a fault left its stack mid-flight: never resume or unwind it
  bool stopping = false;   // stop() has resumed it to unwind
  bool over_budget = false;  // it left its slice at a safe point, condemned by the watchdog
  double last_budget = 0.0;
  std::function<void()> body;
  std::exception_ptr error;
  // For AddressSanitizer: the resumer's stack as seen from inside, and fake-stack handles.
  const void* outer_bottom = nullptr;
  std::size_t outer_size = 0;
  void* outer_fake = nullptr;
  void* inner_fake = nullptr;
};

namespace {
Fiber* g_current = nullptr;
}

Fiber::Fiber(std::function<void()> body, std::size_t stack_bytes) : impl_(std::make_unique<Impl>()) {
  install_handlers();
  impl_->body = std::move(body);
  Impl* impl = impl_.get();
  impl_->self = ctx::fiber(std::allocator_arg, GuardedStack(stack_bytes, &impl_->guard_lo, &impl_->reserved),
                           [impl](ctx::fiber&& caller) {
                             TURTLEGAS_ASAN_ARRIVE(nullptr, &impl->outer_bottom, &impl->outer_size);
                             impl->caller = std::move(caller);
                             impl->entry = static_cast<char*>(__builtin_frame_address(0));
                             try {
                               impl->body();
                             } catch (const ctx::detail::forced_unwind&) {
                               // The fiber is being destroyed before it ever ran: let it unwind.
                               TURTLEGAS_ASAN_SWITCH(nullptr, impl->outer_bottom, impl->outer_size);
                               throw;
                             } catch (const Stop&) {
                               // stop(): the body has unwound, as asked.
                             } catch (...) {
                               impl->error = std::current_exception();
                             }
                             impl->finished = true;
                             TURTLEGAS_ASAN_SWITCH(nullptr, impl->outer_bottom, impl->outer_size);
                             return std::move(impl->caller);
                           });
}

Fiber::~Fiber() {
  if (impl_->self && !impl_->abandoned && !impl_->finished) {
    if (impl_->started) {
      stop(impl_->last_budget);
    } else {
      // Never resumed: destroying the handle unwinds Boost's entry frame only; no code of ours runs.
      TURTLEGAS_ASAN_SWITCH(&impl_->outer_fake, impl_->guard_lo + kPage, impl_->reserved - kPage);
      impl_->self = ctx::fiber{};
      TURTLEGAS_ASAN_ARRIVE(impl_->outer_fake, nullptr, nullptr);
    }
  }
  if (impl_->abandoned) {
    // A fault, or a body that would not stop, left the body mid-flight: `caller` may still name
    // the resume() we jumped out of, and destroying `self` would unwind a body that refuses to
    // be unwound. Let both handles go without touching them; the fiber's stack is leaked with
    // them (kept reachable, so that leak checkers do not report it as lost).
    // Out of memory for that list (a destructor must not throw), the whole record is let go
    // instead, unreachable but never destroyed.
    try {
      static std::vector<ctx::fiber>* const leaked = new std::vector<ctx::fiber>;
      if (leaked->capacity() - leaked->size() < 2) leaked->reserve(2 * leaked->size() + 2);  // (the moves cannot fail then)
      leaked->push_back(std::move(impl_->caller));
      if (impl_->self) leaked->push_back(std::move(impl_->self));
    } catch (const std::bad_alloc&) {
      static_cast<void>(impl_.release());
    }
  }
}

Fiber::Outcome Fiber::stop(double budget_seconds) {
  if (impl_->finished || impl_->abandoned) return Outcome::finished;
  if (!impl_->started) return Outcome::finished;  // the destructor lets an unstarted body go
  impl_->stopping = true;
  const Outcome outcome = resume(budget_seconds);
  if (outcome == Outcome::suspended) {
    // The body caught Stop and suspended again (a command issued from a catch (...) that did
    // not rethrow): it is never resumed again.
    impl_->abandoned = true;
    return Outcome::suspended;
  }
  return outcome;
}

bool Fiber::stopping() const { return impl_->stopping; }

Fiber::Outcome Fiber::resume(double budget_seconds) {
  if (impl_->finished || impl_->abandoned) return Outcome::finished;
  Fiber* const outer = g_current;
  g_current = this;
  // Not saving the signal mask keeps this free of system calls; the rare jump back from a handler
  // unblocks the signal itself.
  const int jumped = sigsetjmp(g_slice_start, 0);
  if (jumped != 0) {
    // Back from the SIGSEGV handler: the body ran into its guard page mid-slice.
    sigset_t handled;
    sigemptyset(&handled);
    sigaddset(&handled, SIGSEGV);
    sigaddset(&handled, SIGBUS);
    sigprocmask(SIG_UNBLOCK, &handled, nullptr);
    end_slice(budget_seconds);
    g_running = nullptr;
    g_current = outer;
    impl_->abandoned = true;
    return Outcome::stack_overflow;
  }
  impl_->started = true;
  impl_->last_budget = budget_seconds;
  g_guard_lo = impl_->guard_lo;
  g_guard_hi = impl_->guard_lo + kPage;
  g_running = impl_.get();
  start_slice(budget_seconds);
  TURTLEGAS_ASAN_SWITCH(&impl_->outer_fake, impl_->guard_lo + kPage,
                        impl_->reserved - kPage);
  impl_->self = std::move(impl_->self).resume();
  TURTLEGAS_ASAN_ARRIVE(impl_->outer_fake, nullptr, nullptr);
  end_slice(budget_seconds);
  g_running = nullptr;
  g_current = outer;
  if (!impl_->self) impl_->finished = true;
  if (impl_->over_budget) [[unlikely]] {
    impl_->abandoned = true;  // left at a safe point: never resumed or unwound again
    return Outcome::over_budget;
  }
  return impl_->finished ? Outcome::finished : Outcome::suspended;
}

void Fiber::suspend() {
  impl_->suspended_at = static_cast<char*>(__builtin_frame_address(0));
  const bool was_stopping = impl_->stopping;
  TURTLEGAS_ASAN_SWITCH(&impl_->inner_fake, impl_->outer_bottom, impl_->outer_size);
  impl_->caller = std::move(impl_->caller).resume();
  TURTLEGAS_ASAN_ARRIVE(impl_->inner_fake, &impl_->outer_bottom, &impl_->outer_size);
  // Resumed by stop(): unwind the body. (A body that suspends again while stopping is abandoned
  // by stop() and never comes back here.)
  if (impl_->stopping && !was_stopping) throw Stop{};
}

void Fiber::safe_point() {
  const std::uint64_t slice = g_slice.load(std::memory_order_relaxed);
  if (slice != g_doomed_slice.load(std::memory_order_relaxed) || (slice & 1) == 0) [[likely]] return;
  Fiber* const self = g_current;
  if (self == nullptr) return;
  // Condemned: back to resume() for good, by the ordinary switch. The body's frames stay as they
  // are (never unwound: a program that loops without commands may not unwind cleanly either).
  Impl& impl = *self->impl_;
  impl.over_budget = true;
  TURTLEGAS_ASAN_SWITCH(&impl.inner_fake, impl.outer_bottom, impl.outer_size);
  impl.caller = std::move(impl.caller).resume();
  std::abort();  // never resumed again
}

void set_busy_loop_exit(BusyLoopExit exit) { g_busy_loop_exit.store(exit, std::memory_order_relaxed); }

void Fiber::prefetch_record() const { __builtin_prefetch(impl_.get()); }

void Fiber::prefetch_stack() const {
  // A resume first pops the context saved just below suspend()'s frame (about 100 bytes down:
  // suspend's locals, then the registers jump_fcontext pushed), then returns through the
  // program's frames above it, at most up to the frame that called the body; the entry frames
  // and Boost's record above that are not touched until the body ends. At most 2 KiB: a deeper
  // program returns through a few frames between two commands, not all of them.
  const char* at = impl_->suspended_at;
  if (at == nullptr || impl_->finished || impl_->abandoned) return;
  constexpr std::ptrdiff_t kBelow = 128, kAbove = 2048, kLine = 64;
  const char* from = at - kBelow;
  const char* to = std::min<const char*>(impl_->entry, at + kAbove);
  for (const char* p = from; p < to; p += kLine) __builtin_prefetch(p);
}

bool Fiber::done() const { return impl_->finished || impl_->abandoned; }
std::size_t Fiber::reserved_bytes() const { return impl_->reserved; }
std::exception_ptr Fiber::error() const { return impl_->error; }
Fiber* Fiber::current() { return g_current; }

}  // namespace turtlegas::turtle::detail
