#pragma once

/// \file
/// \brief A camera or capture card (LAVA §7): the interface every video backend implements. A
/// VideoSource is a FrameSource, so a texture stream reads it like a movie; its health() says
/// whether it is live, waiting or lost, so that the stream can show its fallback.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "devices/device.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/frame.h"
#include "runtime/frame_queue.h"

namespace basalt::devices {

/// \brief A picture format a source delivers.
struct VideoMode {
  PixelFormat format = PixelFormat::kUnknown;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double fps = 0;  ///< nominal frames per second (0: unknown or variable)
  friend bool operator==(const VideoMode&, const VideoMode&) = default;
};

/// \brief "YUYV 640x480 @ 30 fps".
std::string describeMode(const VideoMode& mode);

/// \brief LAVA's "Hardware" panel: what an operator may change on a video source. Values left at
/// their defaults keep what the device does.
struct VideoControls {
  bool mirror = false;  ///< flip left-right (hardware flip where the device has it, else the renderer's)
  double maxFps = 0;    ///< deliver at most this many frames per second, dropping the rest (0: all)
  int quality = -1;     ///< compression quality 0..100 for MJPEG/JPEG devices (-1: the device's)
  int input = -1;       ///< input (port) index for capture cards with several (-1: the current one)
  friend bool operator==(const VideoControls&, const VideoControls&) = default;
};

/// \brief What a lost or absent source's texture shows (the show manifest chooses).
struct VideoFallback {
  enum class Kind : std::uint8_t { kLastFrame, kTestPattern, kColour };
  Kind kind = Kind::kLastFrame;
  float colour[4] = {0, 0, 0, 1};
};

/// \brief Receives every frame a source delivers, on the producer's thread (trace recording).
class FrameTap {
 public:
  virtual ~FrameTap() = default;
  virtual void onFrame(DeviceId device, const FrameRef& frame) = 0;
};

/// \brief A camera or capture card, whatever its backend. Non-virtual public API (NVI) owning the
/// state machine and the frame queue; backends implement the hooks.
///
/// Threading: open(), close(), service() and setControls() are called by the thread that owns
/// the device (the DeviceManager's). frameAt() is called by the frame loop; health(), state(),
/// mode() and the counters may be read from any thread. Backends deliver frames from their
/// capture thread (or from doService) with deliver(), and report a lost signal or device with
/// reportLost() from any thread.
class VideoSource : public FrameSource {
 public:
  ~VideoSource() override;
  VideoSource(const VideoSource&) = delete;
  VideoSource& operator=(const VideoSource&) = delete;

  /// \brief Starts streaming; frames then queue up for frameAt(). Allowed when absent or lost.
  [[nodiscard]] Result<void> open(DeviceId id = 0);
  /// \brief Stops streaming and releases the device. Safe in any state.
  void close();
  /// \brief Notices a loss the backend reported and lets service-driven backends (simulated
  /// ones) produce the frames due by `now`. Never blocks.
  void service(Nanos now);

  /// \brief The newest frame due at `showTime` (never one from the future); empty when none is
  /// new. Frame loop thread; never blocks, never allocates.
  FrameRef frameAt(Nanos showTime) override;
  [[nodiscard]] SourceHealth health() const override;

  [[nodiscard]] DeviceState state() const { return state_.load(std::memory_order_acquire); }
  /// \brief Clock time of the last state change.
  [[nodiscard]] Nanos stateSince() const { return Nanos{since_.load(std::memory_order_acquire)}; }
  /// \brief True while the device is lost but the backend recovers by itself (an HDMI signal
  /// gone; it renegotiates when the signal returns), so the DeviceManager need not reopen it.
  [[nodiscard]] bool recovering() const { return recovering_.load(std::memory_order_acquire); }
  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  [[nodiscard]] std::optional<Error> lostReason() const;
  /// \brief The mode frames are delivered in now (changes on renegotiation).
  [[nodiscard]] VideoMode mode() const;
  /// \brief The modes the device offers (filled by the backend on open; may be empty).
  [[nodiscard]] std::vector<VideoMode> modes() const;

  [[nodiscard]] VideoControls controls() const;
  /// \brief Applies LAVA's hardware controls; mirror falls back to the renderer when the device
  /// cannot flip (see mirrorInRenderer()).
  [[nodiscard]] Result<void> setControls(const VideoControls& controls);
  /// \brief Whether the renderer must flip the picture (mirror asked, the device cannot).
  [[nodiscard]] bool mirrorInRenderer() const { return mirrorInRenderer_.load(std::memory_order_acquire); }

  void setFrameTap(FrameTap* tap) { tap_.store(tap, std::memory_order_release); }
  [[nodiscard]] std::uint64_t framesDelivered() const { return delivered_.load(std::memory_order_relaxed); }
  /// \brief Frames dropped by the frame-rate limit, the queue or the backend.
  [[nodiscard]] std::uint64_t framesDropped() const;

 protected:
  VideoSource(DeviceInfo info, const Clock& clock, std::size_t queueDepth = 4);

  /// \brief Hands a frame to the show (any thread). Frames arriving faster than maxFps are
  /// dropped; a full queue drops its oldest. Returns whether the frame was kept.
  bool deliver(FrameRef frame);
  /// \brief The device or its signal is gone (any thread). With `recovering` the backend
  /// renegotiates by itself and calls reportRecovered(); otherwise the DeviceManager reopens it.
  void reportLost(Error why, bool recovering = false);
  /// \brief The signal is back (after reportLost(..., true)); state returns to live.
  void reportRecovered();
  /// \brief Records the mode frames now come in (on open and on renegotiation).
  void setMode(const VideoMode& mode);
  void setModes(std::vector<VideoMode> modes);
  /// \brief Backends that flip in hardware say so from doApplyControls().
  void setMirrorInRenderer(bool value) { mirrorInRenderer_.store(value, std::memory_order_release); }
  void countDrop() { backendDrops_.fetch_add(1, std::memory_order_relaxed); }
  /// \brief A live source that delivers nothing for this long counts as stalled: lost (recovering
  /// by itself) until frames come again. Default 2 s.
  void setStallTimeout(Nanos timeout) { stallTimeout_.store(timeout.count(), std::memory_order_relaxed); }
  [[nodiscard]] const Clock& clock() const { return clock_; }
  [[nodiscard]] DeviceId id() const { return id_; }

 private:
  [[nodiscard]] virtual Result<void> doOpen() = 0;
  virtual void doClose() = 0;
  virtual void doService(Nanos now) { (void)now; }
  /// \brief Applies the controls the device can apply; returns an error for impossible values.
  [[nodiscard]] virtual Result<void> doApplyControls(const VideoControls& controls);

  void setState(DeviceState state);

  DeviceInfo info_;
  const Clock& clock_;
  FrameQueue queue_;
  DeviceId id_ = 0;
  std::atomic<DeviceState> state_{DeviceState::kAbsent};
  std::atomic<std::int64_t> since_{0};
  std::atomic<bool> lost_{false};  // a loss reported by the backend, not yet handled by service()
  std::atomic<bool> recovering_{false};
  std::atomic<bool> mirrorInRenderer_{false};
  std::atomic<FrameTap*> tap_{nullptr};
  std::atomic<std::uint64_t> delivered_{0};
  std::atomic<std::uint64_t> rateDrops_{0};
  std::atomic<std::uint64_t> backendDrops_{0};
  std::atomic<std::int64_t> lastKeptPts_{INT64_MIN};  // for the frame-rate limit (one producer)
  std::atomic<std::int64_t> minInterval_{0};          // ns between kept frames (0: keep all)
  std::atomic<std::int64_t> lastDelivery_{0};         // Clock time of the last frame delivered
  std::atomic<std::int64_t> stallTimeout_{2'000'000'000};
  std::atomic<bool> stalled_{false};  // lost because nothing came for stallTimeout_
  mutable std::mutex mutex_;          // guards the fields below
  VideoMode mode_;
  std::vector<VideoMode> modes_;
  VideoControls controls_;
  std::optional<Error> lostReason_;
};

}  // namespace basalt::devices
