#include "runtime/event_loop.h"

#include <signal.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <string_view>

#include "runtime/log.h"

namespace basalt::runtime {
namespace {

// epoll data values reserved for the loop's own descriptors; user handles start at 1 and
// count up, so they never reach these.
constexpr std::uint64_t kWakeTag = UINT64_MAX;
constexpr std::uint64_t kTimerTag = UINT64_MAX - 1;
constexpr std::uint64_t kSignalTag = UINT64_MAX - 2;

BASALT_LOG_CATEGORY(Runtime, "runtime");

// Which wait call the process uses. epoll_pwait2 (Linux 5.11) takes a timespec; where it is
// missing (older kernels, valgrind) epoll_pwait with whole milliseconds does. Decided by the
// first wait and kept for the life of the process.
enum class WaitCall : int { kUndecided, kPwait2, kPwait };
std::atomic<WaitCall> gWaitCall{WaitCall::kUndecided};

bool pwait2DisabledByEnvironment() {
  const char* value = std::getenv("BASALT_NO_EPOLL_PWAIT2");
  return value != nullptr && std::string_view(value) == "1";
}

// Rounded up: a wait cut short by rounding down would return before the deadline and make
// the caller spin until it arrives.
int timeoutMilliseconds(Nanos wait) {
  if (wait <= Nanos{0}) return 0;
  const std::int64_t ms = (wait.count() + 999'999) / 1'000'000;
  return ms > INT_MAX ? INT_MAX : static_cast<int>(ms);
}

int waitForEvents(int epollFd, epoll_event* events, int maxEvents, Nanos wait) {
  WaitCall call = gWaitCall.load(std::memory_order_relaxed);
  if (call == WaitCall::kUndecided && pwait2DisabledByEnvironment()) {
    call = WaitCall::kPwait;
    gWaitCall.store(call, std::memory_order_relaxed);
    log::info(kLogRuntime, "the event loop waits with epoll_pwait (BASALT_NO_EPOLL_PWAIT2=1)");
  }
  if (call != WaitCall::kPwait) {
    timespec timeout{};
    timeout.tv_sec = static_cast<time_t>(wait.count() / 1'000'000'000);
    timeout.tv_nsec = static_cast<long>(wait.count() % 1'000'000'000);
    const int n = epoll_pwait2(epollFd, events, maxEvents, &timeout, nullptr);
    if (n >= 0 || errno != ENOSYS) {
      if (call == WaitCall::kUndecided && n >= 0) gWaitCall.store(WaitCall::kPwait2, std::memory_order_relaxed);
      return n;
    }
    gWaitCall.store(WaitCall::kPwait, std::memory_order_relaxed);
    static log::Once said;
    if (said.first()) {
      log::info(kLogRuntime,
                "epoll_pwait2 is not available (Linux before 5.11?); the event loop waits with "
                "epoll_pwait, to the millisecond");
    }
  }
  return epoll_pwait(epollFd, events, maxEvents, timeoutMilliseconds(wait), nullptr);
}

Result<void> addToEpoll(int epollFd, int fd, std::uint32_t events, std::uint64_t tag) {
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = tag;
  if (epoll_ctl(epollFd, EPOLL_CTL_ADD, fd, &ev) != 0) {
    return fail(Errc::kIo, systemErrorText("epoll_ctl(ADD)", errno));
  }
  return {};
}

}  // namespace

Result<std::unique_ptr<EventLoop>> EventLoop::create(const Clock& clock) {
  UniqueFd epollFd{epoll_create1(EPOLL_CLOEXEC)};
  if (!epollFd) return fail(Errc::kIo, systemErrorText("epoll_create1", errno));
  UniqueFd wakeFd{eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)};
  if (!wakeFd) return fail(Errc::kIo, systemErrorText("eventfd", errno));
  UniqueFd timerFd{timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK)};
  if (!timerFd) return fail(Errc::kIo, systemErrorText("timerfd_create", errno));
  if (auto r = addToEpoll(epollFd.get(), wakeFd.get(), EPOLLIN, kWakeTag); !r) return std::unexpected(r.error());
  if (auto r = addToEpoll(epollFd.get(), timerFd.get(), EPOLLIN, kTimerTag); !r) return std::unexpected(r.error());
  return std::unique_ptr<EventLoop>(new EventLoop(clock, std::move(epollFd), std::move(wakeFd), std::move(timerFd)));
}

const char* EventLoop::waitCallName() {
  return gWaitCall.load(std::memory_order_relaxed) == WaitCall::kPwait ? "epoll_pwait" : "epoll_pwait2";
}

EventLoop::EventLoop(const Clock& clock, UniqueFd epoll, UniqueFd wakeFd, UniqueFd timerFd)
    : clock_(clock), epoll_(std::move(epoll)), wakeFd_(std::move(wakeFd)), timerFd_(std::move(timerFd)), ready_(32) {}

EventLoop::~EventLoop() = default;

Result<EventLoop::Handle> EventLoop::watchFd(int fd, std::uint32_t events, FdCallback callback) {
  const Handle handle = nextHandle_++;
  if (auto r = addToEpoll(epoll_.get(), fd, events, handle); !r) return std::unexpected(r.error());
  fds_.emplace(handle, std::make_shared<FdCallback>(std::move(callback)));
  fdOfHandle_.emplace(handle, fd);
  return handle;
}

void EventLoop::unwatch(Handle handle) {
  auto it = fdOfHandle_.find(handle);
  if (it == fdOfHandle_.end()) return;
  // The fd may already be closed (a vanished device); epoll forgets closed fds by itself.
  epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, it->second, nullptr);
  fdOfHandle_.erase(it);
  fds_.erase(handle);
}

EventLoop::Handle EventLoop::addTimer(Nanos deadline, TimerCallback callback, Nanos period) {
  const Handle handle = nextHandle_++;
  timers_.emplace(handle, Timer{deadline, period, std::make_shared<TimerCallback>(std::move(callback))});
  armTimerFd();
  return handle;
}

void EventLoop::cancelTimer(Handle handle) {
  timers_.erase(handle);
  armTimerFd();
}

Result<void> EventLoop::watchSignals(std::initializer_list<int> signals, SignalCallback callback) {
  sigset_t mask;
  sigemptyset(&mask);
  for (int s : signals) sigaddset(&mask, s);
  if (pthread_sigmask(SIG_BLOCK, &mask, nullptr) != 0) {
    return fail(Errc::kIo, "cannot block signals for signalfd");
  }
  UniqueFd fd{signalfd(-1, &mask, SFD_CLOEXEC | SFD_NONBLOCK)};
  if (!fd) return fail(Errc::kIo, systemErrorText("signalfd", errno));
  if (auto r = addToEpoll(epoll_.get(), fd.get(), EPOLLIN, kSignalTag); !r) return r;
  signalFd_ = std::move(fd);
  signalCallback_ = std::move(callback);
  return {};
}

void EventLoop::wake() {
  const std::uint64_t one = 1;
  // EAGAIN means the counter is already non-zero: a wake-up is pending anyway.
  [[maybe_unused]] ssize_t n = ::write(wakeFd_.get(), &one, sizeof one);
}

Nanos EventLoop::nextDeadline() const {
  Nanos next = Nanos::max();
  for (const auto& [handle, timer] : timers_) next = std::min(next, timer.deadline);
  return next;
}

void EventLoop::armTimerFd() {
  // Only a system clock is backed by the kernel's timer; manual timers fire from dispatch().
  itimerspec spec{};
  const Nanos next = nextDeadline();
  if (!clock_.isManual() && next != Nanos::max()) {
    const Nanos at = std::max(next, Nanos{1});
    spec.it_value.tv_sec = static_cast<time_t>(at.count() / 1'000'000'000);
    spec.it_value.tv_nsec = static_cast<long>(at.count() % 1'000'000'000);
  }
  timerfd_settime(timerFd_.get(), TFD_TIMER_ABSTIME, &spec, nullptr);
}

int EventLoop::runDueTimers() {
  int ran = 0;
  const Nanos now = clock_.now();
  // Collect first: callbacks may add or cancel timers.
  for (;;) {
    Handle due = 0;
    Nanos earliest = Nanos::max();
    for (const auto& [handle, timer] : timers_) {
      if (timer.deadline <= now && timer.deadline < earliest) {
        earliest = timer.deadline;
        due = handle;
      }
    }
    if (due == 0) break;
    auto it = timers_.find(due);
    std::shared_ptr<TimerCallback> callback = it->second.callback;
    if (it->second.period.count() > 0) {
      // Skip missed periods instead of firing a burst after a stall.
      const Nanos period = it->second.period;
      Nanos next = it->second.deadline + period;
      if (next <= now) next = now + period - (now - it->second.deadline) % period;
      it->second.deadline = next;
    } else {
      timers_.erase(it);
    }
    (*callback)();
    ++ran;
  }
  armTimerFd();
  return ran;
}

Result<int> EventLoop::dispatch(Nanos maxWait) {
  int ran = runDueTimers();
  Nanos wait = ran > 0 ? Nanos{0} : maxWait;
  if (!clock_.isManual()) {
    const Nanos next = nextDeadline();
    if (next != Nanos::max()) wait = std::min(wait, std::max(Nanos{0}, next - clock_.now()));
  }
  const int n = waitForEvents(epoll_.get(), ready_.data(), static_cast<int>(ready_.size()), wait);
  if (n < 0) {
    if (errno == EINTR) return ran;
    return fail(Errc::kIo, systemErrorText(waitCallName(), errno));
  }
  for (int i = 0; i < n; ++i) {
    const epoll_event& ev = ready_[static_cast<std::size_t>(i)];
    const std::uint64_t tag = ev.data.u64;
    if (tag == kWakeTag) {
      std::uint64_t count = 0;
      [[maybe_unused]] ssize_t r = ::read(wakeFd_.get(), &count, sizeof count);
      ++ran;
    } else if (tag == kTimerTag) {
      std::uint64_t expirations = 0;
      [[maybe_unused]] ssize_t r = ::read(timerFd_.get(), &expirations, sizeof expirations);
    } else if (tag == kSignalTag) {
      signalfd_siginfo info{};
      while (::read(signalFd_.get(), &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
        if (signalCallback_) signalCallback_(static_cast<int>(info.ssi_signo));
        ++ran;
      }
    } else {
      auto it = fds_.find(tag);
      if (it != fds_.end()) {
        // Copy: the callback may unwatch itself.
        std::shared_ptr<FdCallback> callback = it->second;
        (*callback)(ev.events);
        ++ran;
      }
    }
  }
  ran += runDueTimers();
  return ran;
}

}  // namespace basalt::runtime
