#pragma once

/// \file
/// \brief Handing video frames from a producer thread (a decoder, a camera) to the frame loop,
/// which shows the newest frame that is due and never one from the future.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

#include "runtime/clock.h"
#include "runtime/frame.h"

namespace basalt {

/// \brief Whether a source is delivering pictures, for the fallback a texture stream shows.
enum class SourceState : std::uint8_t {
  kLive,     ///< frames flow (or may flow: a paused movie is live)
  kWaiting,  ///< not delivered yet: the device is absent or opening
  kLost,     ///< was delivering and stopped: unplugged, signal lost, stalled; reopening by itself
};

/// \brief A source's state and the Clock time it entered it ("lost since 12:03:07").
struct SourceHealth {
  SourceState state = SourceState::kLive;
  Nanos since{0};
};

/// \brief A stream of frames the renderer can show: a movie, a camera, a capture card.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// \brief The source's state, so that a texture stream can show its configured fallback (last
  /// frame, a test pattern or a colour) while it is not live. Any thread; never blocks.
  [[nodiscard]] virtual SourceHealth health() const { return {}; }
  /// \brief The frame to show at `showTime`: the newest frame whose pts is at or before it, or
  /// an empty ref when no new frame is due (keep showing the last one). Called on the frame
  /// loop's thread; never blocks.
  virtual FrameRef frameAt(Nanos showTime) = 0;
};

/// \brief A fixed-capacity queue of frames in presentation order.
///
/// Producers either wait for room (a movie decoder that runs ahead of the show) or drop the
/// oldest frame (a live camera that must never lag). The consumer takes the newest due frame
/// and releases the older due ones. Threading: any producer thread, one consumer thread;
/// `mutex_` guards the ring; `room_` signals producers waiting for space.
class FrameQueue {
 public:
  explicit FrameQueue(std::size_t capacity);
  FrameQueue(const FrameQueue&) = delete;
  FrameQueue& operator=(const FrameQueue&) = delete;

  /// \brief Adds a frame if there is room; false when full.
  bool tryPush(FrameRef frame);
  /// \brief Adds a frame, dropping (and counting) the oldest when full. Never blocks.
  void pushDroppingOldest(FrameRef frame);
  /// \brief Waits until there is room or `timeout` passes or close() is called; true if room.
  bool waitForRoom(std::chrono::nanoseconds timeout);
  /// \brief The newest frame with pts <= `now`, releasing older ones; empty if none is due.
  FrameRef takeDue(Nanos now);
  /// \brief The pts of the oldest queued frame, if any (for pre-roll and gap checks).
  [[nodiscard]] bool frontPts(Nanos& pts) const;
  /// \brief The oldest queued frame, left in the queue (a consumer looking for a frame by its
  /// number); empty when none is queued.
  [[nodiscard]] FrameRef peekFront() const;
  /// \brief Takes the oldest queued frame out, counted as passed over when `passOver` (it is
  /// dropped rather than shown); empty when none is queued.
  FrameRef takeFront(bool passOver = false);
  /// \brief Drops every queued frame (on seek, stop, source change).
  void clear();
  /// \brief Wakes waiting producers for good (shutdown); later waits return false at once.
  void close();
  void reopen();

  [[nodiscard]] std::size_t size() const;
  [[nodiscard]] std::size_t capacity() const { return slots_.size(); }
  /// \brief Frames dropped: pushed out when full, or passed over because a newer one was due.
  [[nodiscard]] std::uint64_t dropped() const;

 private:
  FrameRef popFrontLocked();

  mutable std::mutex mutex_;
  std::condition_variable room_;
  std::vector<FrameRef> slots_;  // guarded by mutex_
  std::size_t head_ = 0;         // guarded by mutex_
  std::size_t size_ = 0;         // guarded by mutex_
  std::uint64_t dropped_ = 0;    // guarded by mutex_
  bool closed_ = false;          // guarded by mutex_
};

}  // namespace basalt
