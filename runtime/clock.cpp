#include "runtime/clock.h"

#include <time.h>

namespace basalt {

Nanos SystemClock::now() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return Nanos{static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec};
}

WallTime SystemClock::wallNow() const { return std::chrono::system_clock::now(); }

ManualClock::ManualClock(Nanos start, WallTime wallOrigin)
    : now_(start.count()), wallOrigin_(wallOrigin.time_since_epoch().count()) {}

WallTime ManualClock::wallNow() const {
  const auto origin = WallTime::duration{wallOrigin_.load(std::memory_order_acquire)};
  return WallTime{origin} + std::chrono::duration_cast<WallTime::duration>(now());
}

void ManualClock::advance(Nanos step) {
  if (step.count() > 0) now_.fetch_add(step.count(), std::memory_order_acq_rel);
}

void ManualClock::set(Nanos t) {
  std::int64_t current = now_.load(std::memory_order_acquire);
  while (t.count() > current && !now_.compare_exchange_weak(current, t.count(), std::memory_order_acq_rel)) {
  }
}

void ManualClock::setWallOrigin(WallTime origin) {
  wallOrigin_.store(origin.time_since_epoch().count(), std::memory_order_release);
}

}  // namespace basalt
