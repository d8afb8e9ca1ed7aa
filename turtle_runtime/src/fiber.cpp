// SPDX-License-Identifier: MIT
#include "fiber.hpp"

#include <csetjmp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <sys/time.h>

#include <boost/context/fiber.hpp>
#include <boost/context/protected_fixedsize_stack.hpp>

namespace turtlegas::turtle::detail {
namespace ctx = boost::context;

namespace {

// Where the running slice started, and which stack it is on. The scheduler is single-threaded:
// only one fiber runs at a time, so plain globals suffice; the signal handlers only read them.
sigjmp_buf g_slice_start;
Fiber::Impl* volatile g_running = nullptr;
char* volatile g_guard_lo = nullptr;
char* volatile g_guard_hi = nullptr;

// A stack overflow that lands within this distance below the guard page is still ours (a frame
// larger than a page can step over it).
constexpr std::size_t kGuardSlack = 64 * 1024;

struct sigaction g_previous_segv{}, g_previous_bus{};

void on_segv(int sig, siginfo_t* info, void* uctx) {
  char* addr = static_cast<char*>(info->si_addr);
  if (g_running != nullptr && addr >= g_guard_lo - kGuardSlack && addr < g_guard_hi) siglongjmp(g_slice_start, 1);
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
  if (g_running != nullptr) siglongjmp(g_slice_start, 2);
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

void set_timer(double seconds) {
  itimerval tv{};
  if (seconds > 0) {
    tv.it_value.tv_sec = static_cast<time_t>(seconds);
    tv.it_value.tv_usec = static_cast<suseconds_t>((seconds - static_cast<double>(tv.it_value.tv_sec)) * 1e6);
    if (tv.it_value.tv_sec == 0 && tv.it_value.tv_usec == 0) tv.it_value.tv_usec = 1;
  }
  setitimer(ITIMER_REAL, &tv, nullptr);
}

}  // namespace

class Fiber::Impl {
 public:
  std::function<void()> body;
  ctx::fiber self;    // the suspended body, seen from outside
  ctx::fiber caller;  // whoever resumed it, seen from inside
  char* guard_lo = nullptr;
  std::size_t reserved = 0;
  bool started = false;
  bool finished = false;
  bool abandoned = false;  // a fault left its stack mid-flight: never resume or unwind it
  std::exception_ptr error;
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
                             impl->caller = std::move(caller);
                             try {
                               impl->body();
                             } catch (const ctx::detail::forced_unwind&) {
                               throw;  // the fiber is being destroyed while suspended: let it unwind
                             } catch (...) {
                               impl->error = std::current_exception();
                             }
                             impl->finished = true;
                             return std::move(impl->caller);
                           });
}

Fiber::~Fiber() {
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
  const int jumped = sigsetjmp(g_slice_start, 1);
  if (jumped != 0) {
    // Back from a signal handler: the body faulted mid-slice.
    set_timer(0);
    g_running = nullptr;
    g_current = outer;
    impl_->abandoned = true;
    return jumped == 1 ? Outcome::stack_overflow : Outcome::over_budget;
  }
  g_guard_lo = impl_->guard_lo;
  g_guard_hi = impl_->guard_lo + ctx::stack_traits::page_size();
  g_running = impl_.get();
  set_timer(budget_seconds);
  impl_->self = std::move(impl_->self).resume();
  set_timer(0);
  g_running = nullptr;
  g_current = outer;
  if (!impl_->self) impl_->finished = true;
  return impl_->finished ? Outcome::finished : Outcome::suspended;
}

void Fiber::suspend() {
  // The guard range was set on allocation, which happens on the first resume.
  impl_->caller = std::move(impl_->caller).resume();
}

bool Fiber::done() const { return impl_->finished || impl_->abandoned; }
std::size_t Fiber::reserved_bytes() const { return impl_->reserved; }
std::exception_ptr Fiber::error() const { return impl_->error; }
Fiber* Fiber::current() { return g_current; }

}  // namespace turtlegas::turtle::detail
