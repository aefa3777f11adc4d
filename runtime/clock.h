#pragma once

/// \file
/// \brief Injected time. Everything time-dependent takes a Clock; nothing else reads the system
/// clock, so a simulated week runs in seconds and a replay is exact.

#include <atomic>
#include <chrono>
#include <cstdint>

namespace basalt {

using Nanos = std::chrono::nanoseconds;
using WallTime = std::chrono::system_clock::time_point;

/// \brief A source of monotonic time (frame pacing, time-outs, media) and of calendar time
/// (schedules). Implementations are safe to read from any thread.
class Clock {
 public:
  virtual ~Clock() = default;
  /// \brief Monotonic time since an arbitrary epoch fixed for the life of the clock.
  [[nodiscard]] virtual Nanos now() const = 0;
  /// \brief Calendar time, for opening hours and log stamps.
  [[nodiscard]] virtual WallTime wallNow() const = 0;
  /// \brief True for clocks that only move when told to (the frame loop then never sleeps).
  [[nodiscard]] virtual bool isManual() const = 0;
};

/// \brief CLOCK_MONOTONIC and the system's calendar clock.
class SystemClock final : public Clock {
 public:
  [[nodiscard]] Nanos now() const override;
  [[nodiscard]] WallTime wallNow() const override;
  [[nodiscard]] bool isManual() const override { return false; }
};

/// \brief A clock that moves only when advanced. Calendar time is `wallOrigin + now()`.
///
/// Threading: `now()` may be read from any thread; `advance()`/`set()` are called by the one
/// thread that owns the simulation (the frame loop).
class ManualClock final : public Clock {
 public:
  explicit ManualClock(Nanos start = Nanos{0}, WallTime wallOrigin = WallTime{});

  [[nodiscard]] Nanos now() const override { return Nanos{now_.load(std::memory_order_acquire)}; }
  [[nodiscard]] WallTime wallNow() const override;
  [[nodiscard]] bool isManual() const override { return true; }

  void advance(Nanos step);
  /// \brief Moves to `t`; moving backwards is a bug (monotonic time) and is ignored.
  void set(Nanos t);
  void setWallOrigin(WallTime origin);

 private:
  std::atomic<std::int64_t> now_;         // nanoseconds; release on write, acquire on read
  std::atomic<std::int64_t> wallOrigin_;  // system_clock ticks at now() == 0
};

/// \brief Seconds as a double, for printing and for rates.
inline double toSeconds(Nanos t) { return std::chrono::duration<double>(t).count(); }
/// \brief Nanoseconds from seconds, rounded to the nearest nanosecond.
inline Nanos fromSeconds(double s) { return Nanos{static_cast<std::int64_t>(s * 1e9 + (s >= 0 ? 0.5 : -0.5))}; }

/// \brief The duration of frame `n` start at `fps` frames per second, exactly (no drift).
inline Nanos frameTime(std::int64_t n, double fps) { return fromSeconds(static_cast<double>(n) / fps); }

}  // namespace basalt
