#pragma once

/// \file
/// \brief The frame loop's event loop: file descriptors, timers on the injected Clock,
/// POSIX signals and cross-thread wake-ups, on epoll.

#include <sys/epoll.h>

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <vector>

#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/unique_fd.h"

namespace basalt::runtime {

/// \brief Dispatches readiness of file descriptors, timers and signals on one thread.
///
/// Threading: everything except `wake()` must be called on the loop's thread. `wake()` may be
/// called from any thread (device and GStreamer threads call it after pushing into a queue);
/// it makes a pending or the next `dispatch()` return promptly.
///
/// Timers run on the injected Clock. With a SystemClock, `dispatch()` sleeps until the next
/// timer is due; with a ManualClock it fires the timers due at the clock's current time and
/// never waits for one in the future (the owner advances the clock).
class EventLoop {
 public:
  using Handle = std::uint64_t;
  using FdCallback = std::function<void(std::uint32_t epollEvents)>;
  using TimerCallback = std::function<void()>;
  using SignalCallback = std::function<void(int signal)>;

  static Result<std::unique_ptr<EventLoop>> create(const Clock& clock);
  ~EventLoop();
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  /// \brief Calls `callback` with the epoll event mask whenever `fd` is ready for `events`.
  /// The loop borrows `fd`; the caller keeps it open until `unwatch()`.
  [[nodiscard]] Result<Handle> watchFd(int fd, std::uint32_t events, FdCallback callback);
  void unwatch(Handle handle);

  /// \brief Calls `callback` at `deadline` (Clock time), then every `period` if non-zero.
  Handle addTimer(Nanos deadline, TimerCallback callback, Nanos period = Nanos{0});
  void cancelTimer(Handle handle);

  /// \brief Blocks `signals` for the process and delivers them through the loop (signalfd).
  /// Call before starting other threads so that they inherit the blocked mask.
  [[nodiscard]] Result<void> watchSignals(std::initializer_list<int> signals, SignalCallback callback);

  /// \brief Thread-safe: interrupts the current or next wait.
  void wake();

  /// \brief Runs what is ready, waiting at most `maxWait` for something to happen.
  /// \return the number of callbacks run (fds, timers, signals and wake-ups).
  Result<int> dispatch(Nanos maxWait);

  /// \brief The earliest pending timer deadline, or Nanos::max() when there is none.
  [[nodiscard]] Nanos nextDeadline() const;

  /// \brief The system call the loops of this process wait with: "epoll_pwait2", or
  /// "epoll_pwait" where that is missing (Linux before 5.11, valgrind) or
  /// BASALT_NO_EPOLL_PWAIT2=1 asks for it. Decided by the first wait of any loop.
  [[nodiscard]] static const char* waitCallName();

 private:
  EventLoop(const Clock& clock, UniqueFd epoll, UniqueFd wakeFd, UniqueFd timerFd);
  int runDueTimers();
  void armTimerFd();

  struct Timer {
    Nanos deadline;
    Nanos period;
    std::shared_ptr<TimerCallback> callback;  // shared so that dispatch copies without allocating
  };

  const Clock& clock_;
  UniqueFd epoll_;
  UniqueFd wakeFd_;   // eventfd; written by wake() from any thread
  UniqueFd timerFd_;  // timerfd on CLOCK_MONOTONIC, armed at the next deadline (system clock)
  UniqueFd signalFd_;
  SignalCallback signalCallback_;
  Handle nextHandle_ = 1;
  std::map<Handle, std::shared_ptr<FdCallback>> fds_;  // by handle; the fd's epoll data is the handle
  std::map<Handle, int> fdOfHandle_;
  std::map<Handle, Timer> timers_;
  std::vector<epoll_event> ready_;  // sized once; dispatch() allocates nothing
};

}  // namespace basalt::runtime
