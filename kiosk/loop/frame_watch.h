#pragma once

/// \file
/// \brief How far the frame loop has got, for watchers on other threads: the status server
/// reports a frame that has been running too long (a stuck participant) as a problem.

#include <atomic>
#include <cstdint>
#include <optional>

#include "runtime/clock.h"

namespace basalt::kiosk {

/// \brief The frame in progress and since when.
///
/// Threading: frameBegan() and frameEnded() on the frame loop's thread; busy() from any thread
/// (two atomics; a reader may pair a frame number with the next frame's start, which only
/// shortens the time it reports by one frame).
class FrameWatch {
 public:
  struct Busy {
    std::int64_t frame = 0;
    Nanos since{0};  ///< SystemClock time the frame began
  };

  void frameBegan(std::int64_t frame, Nanos now) {
    frame_.store(frame, std::memory_order_relaxed);
    began_.store(now.count(), std::memory_order_release);
  }
  void frameEnded() { began_.store(kIdle, std::memory_order_release); }

  /// \brief The frame being made now, or nothing while the loop waits between frames.
  [[nodiscard]] std::optional<Busy> busy() const {
    const std::int64_t began = began_.load(std::memory_order_acquire);
    if (began == kIdle) return std::nullopt;
    return Busy{frame_.load(std::memory_order_relaxed), Nanos{began}};
  }

 private:
  static constexpr std::int64_t kIdle = INT64_MIN;
  std::atomic<std::int64_t> frame_{0};
  std::atomic<std::int64_t> began_{kIdle};
};

}  // namespace basalt::kiosk
