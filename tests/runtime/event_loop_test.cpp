// The event loop: timers on the injected clock, wake-ups from other threads, fds and signals.
// Example failures: a manual-clock timer firing before its time (replays run ahead), a wake-up
// from a device thread lost (the loop sleeps past an event), a signal killing the process
// instead of reaching the loop.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <thread>

#include "runtime/event_loop.h"

namespace basalt::runtime {
namespace {

TEST(EventLoop, ManualClockTimersFireOnlyWhenDue) {
  ManualClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop) << loop.error().describe();
  int fired = 0;
  (*loop)->addTimer(Nanos{1000}, [&] { ++fired; });
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(fired, 0);
  clock.set(Nanos{999});
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(fired, 0);
  clock.set(Nanos{1000});
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(fired, 1);
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(fired, 1) << "a one-shot timer fired twice";
}

TEST(EventLoop, PeriodicTimerSkipsMissedPeriods) {
  ManualClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop);
  int fired = 0;
  (*loop)->addTimer(Nanos{100}, [&] { ++fired; }, Nanos{100});
  clock.set(Nanos{1050});  // ten periods late
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(fired, 1) << "a stalled loop must not fire a burst of catch-up timers";
  EXPECT_EQ((*loop)->nextDeadline(), Nanos{1100});
}

TEST(EventLoop, CancelledTimerNeverFires) {
  ManualClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop);
  int fired = 0;
  const auto handle = (*loop)->addTimer(Nanos{10}, [&] { ++fired; });
  (*loop)->cancelTimer(handle);
  clock.set(Nanos{20});
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(fired, 0);
}

TEST(EventLoop, SystemClockTimerWakesTheWait) {
  SystemClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop);
  bool fired = false;
  (*loop)->addTimer(clock.now() + std::chrono::milliseconds(5), [&] { fired = true; });
  for (int i = 0; i < 100 && !fired; ++i) ASSERT_TRUE((*loop)->dispatch(std::chrono::milliseconds(50)));
  EXPECT_TRUE(fired);
}

TEST(EventLoop, WakeFromAnotherThreadEndsTheWait) {
  SystemClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop);
  std::thread waker([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    (*loop)->wake();
  });
  // Without the wake-up this would wait the full 30 s and the test would time out.
  auto ran = (*loop)->dispatch(std::chrono::seconds(30));
  waker.join();
  ASSERT_TRUE(ran);
  EXPECT_GE(*ran, 1);
}

TEST(EventLoop, WatchedFdCallsBackWithItsEvents) {
  ManualClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop);
  int fds[2];
  ASSERT_EQ(pipe2(fds, O_CLOEXEC | O_NONBLOCK), 0);
  UniqueFd readEnd(fds[0]), writeEnd(fds[1]);
  std::uint32_t seen = 0;
  auto handle = (*loop)->watchFd(readEnd.get(), EPOLLIN, [&](std::uint32_t events) {
    seen = events;
    char c;
    [[maybe_unused]] auto n = ::read(readEnd.get(), &c, 1);
  });
  ASSERT_TRUE(handle);
  ASSERT_EQ(::write(writeEnd.get(), "x", 1), 1);
  ASSERT_TRUE((*loop)->dispatch(std::chrono::milliseconds(100)));
  EXPECT_TRUE(seen & EPOLLIN);
  (*loop)->unwatch(*handle);
  seen = 0;
  ASSERT_EQ(::write(writeEnd.get(), "y", 1), 1);
  ASSERT_TRUE((*loop)->dispatch(Nanos{0}));
  EXPECT_EQ(seen, 0u) << "an unwatched fd still called back";
}

TEST(EventLoop, SignalsArriveAsCallbacks) {
  ManualClock clock;
  auto loop = EventLoop::create(clock);
  ASSERT_TRUE(loop);
  int got = 0;
  ASSERT_TRUE((*loop)->watchSignals({SIGUSR1}, [&](int s) { got = s; }));
  ASSERT_EQ(::kill(::getpid(), SIGUSR1), 0);
  for (int i = 0; i < 10 && got == 0; ++i) ASSERT_TRUE((*loop)->dispatch(std::chrono::milliseconds(100)));
  EXPECT_EQ(got, SIGUSR1);
}

}  // namespace
}  // namespace basalt::runtime
