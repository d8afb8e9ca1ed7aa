// SPDX-License-Identifier: MIT
#include "fiber.hpp"

#include <csetjmp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <pthread.h>
#include <thread>

#include <boost/context/fiber.hpp>
#include <boost/context/protected_fixedsize_stack.hpp>

// AddressSanitizer keeps shadow state per stack and must be told about every switch between them;
// Boost's fcontext switches do not tell it, so we do, around each resume and suspend.
#if defined(__SANITIZE_ADDRESS__)
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
// Leaves the running slice for resume(). (AddressSanitizer cannot follow this jump from a signal
// handler across stacks; the tests of fault recovery are skipped in sanitizer builds.)
[[noreturn]] void jump_back(int code) { siglongjmp(g_slice_start, code); }

// A stack overflow that lands within this distance below the guard page is still ours (a frame
// larger than a page can step over it).
constexpr std::size_t kGuardSlack = 64 * 1024;
const std::size_t kPage = boost::context::stack_traits::page_size();

struct sigaction g_previous_segv{}, g_previous_bus{};

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

void on_alarm(int) {
  if (g_running != nullptr && g_slice.load(std::memory_order_relaxed) == g_doomed_slice.load(std::memory_order_relaxed))
    jump_back(2);
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
  al.sa_handler = on_alarm;
  al.sa_flags = SA_ONSTACK;
  sigemptyset(&al.sa_mask);
  sigaction(SIGALRM, &al, nullptr);
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
// and its budget. A thread of our own samples them a few times per budget; when the same slice has
// been running longer than its budget it sends SIGALRM to the scheduler's thread, whose handler
// jumps out of the slice if (and only if) that slice is still the one running.

void watchdog() {
  using namespace std::chrono;
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
      g_doomed_slice.store(slice, std::memory_order_relaxed);
      pthread_kill(g_scheduler_thread, SIGALRM);
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
                               // The fiber is being destroyed while suspended: let it unwind.
                               TURTLEGAS_ASAN_SWITCH(nullptr, impl->outer_bottom, impl->outer_size);
                               throw;
                             } catch (...) {
                               impl->error = std::current_exception();
                             }
                             impl->finished = true;
                             TURTLEGAS_ASAN_SWITCH(nullptr, impl->outer_bottom, impl->outer_size);
                             return std::move(impl->caller);
                           });
}

Fiber::~Fiber() {
  if (impl_->self && !impl_->abandoned) {
    // Suspended mid-program: destroying the handle unwinds the body's stack, on that stack.
    TURTLEGAS_ASAN_SWITCH(&impl_->outer_fake, impl_->guard_lo + kPage,
                          impl_->reserved - kPage);
    impl_->self = ctx::fiber{};
    TURTLEGAS_ASAN_ARRIVE(impl_->outer_fake, nullptr, nullptr);
  }
  if (impl_->abandoned) {
    // A fault left the body mid-slice: `caller` still names the resume() we jumped out of, and
    // destroying it would switch into that dead context. Let the handle go without touching it;
    // the fiber's stack is leaked with it.
    new (std::malloc(sizeof(ctx::fiber))) ctx::fiber(std::move(impl_->caller));
  }
}

Fiber::Outcome Fiber::resume(double budget_seconds) {
  if (impl_->finished || impl_->abandoned) return Outcome::finished;
  Fiber* const outer = g_current;
  g_current = this;
  // Not saving the signal mask keeps this free of system calls; the rare jump back from a handler
  // unblocks the signal itself.
  const int jumped = sigsetjmp(g_slice_start, 0);
  if (jumped != 0) {
    // Back from a signal handler: the body faulted mid-slice.
    sigset_t handled;
    sigemptyset(&handled);
    sigaddset(&handled, jumped == 1 ? SIGSEGV : SIGALRM);
    sigaddset(&handled, SIGBUS);
    sigprocmask(SIG_UNBLOCK, &handled, nullptr);
    end_slice(budget_seconds);
    g_running = nullptr;
    g_current = outer;
    impl_->abandoned = true;
    return jumped == 1 ? Outcome::stack_overflow : Outcome::over_budget;
  }
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
  return impl_->finished ? Outcome::finished : Outcome::suspended;
}

void Fiber::suspend() {
  impl_->suspended_at = static_cast<char*>(__builtin_frame_address(0));
  TURTLEGAS_ASAN_SWITCH(&impl_->inner_fake, impl_->outer_bottom, impl_->outer_size);
  try {
    impl_->caller = std::move(impl_->caller).resume();
  } catch (const ctx::detail::forced_unwind&) {
    // Destroyed while suspended: we are back on this stack to unwind it.
    TURTLEGAS_ASAN_ARRIVE(impl_->inner_fake, &impl_->outer_bottom, &impl_->outer_size);
    throw;
  }
  TURTLEGAS_ASAN_ARRIVE(impl_->inner_fake, &impl_->outer_bottom, &impl_->outer_size);
}

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
