// SyntheticCamera: the simulated twin of a webcam or capture card.
//
// Serves tests, demos and benchmarks: a test pattern (colour bars, gradient, checker, solid) in
// any raw format Basalt handles, a moving box so that stalls and repeats show, and a script of
// faults. Limits: raw formats only (no MJPEG); frames are produced from service(), so a frame is
// never late under a ManualClock and at most one service() period late under a SystemClock.

#include "sim/synthetic_camera.h"

#include <fmt/format.h>

namespace basalt::sim {

devices::DeviceInfo SyntheticCamera::defaultInfo() {
  return devices::DeviceInfo{"Synthetic camera", "synthetic", "virtual", 0, 0, "synthetic:camera", ""};
}

SyntheticCamera::SyntheticCamera(devices::DeviceInfo info, SyntheticCameraConfig config, const Clock& clock,
                                 PresenceFlag present)
    : VideoSource(std::move(info), clock), config_(std::move(config)), present_(std::move(present)) {
  setModes({config_.mode});
}

Result<void> SyntheticCamera::doOpen() {
  if (present_ && !present_->load()) return fail(Errc::kNotFound, "the synthetic camera is unplugged", info().path);
  if (config_.mode.format == PixelFormat::kMjpeg || config_.mode.format == PixelFormat::kUnknown ||
      config_.mode.width == 0 || config_.mode.height == 0 || !(config_.mode.fps > 0)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("the synthetic camera cannot make {}; choose a raw format, a size and a frame rate",
                            devices::describeMode(config_.mode)),
                info().path);
  }
  current_ = config_.mode;
  makePool();
  origin_ = clock().now();
  nextFrame_ = 0;
  nextFault_ = 0;
  quietUntil_ = Nanos{0};
  signalLost_ = false;
  setMode(current_);
  setStallTimeout(std::max<Nanos>(std::chrono::milliseconds(500), fromSeconds(10.0 / current_.fps)));
  return {};
}

void SyntheticCamera::doClose() {
  background_.reset();
  pool_.reset();
}

void SyntheticCamera::makePool() {
  background_.reset();
  pool_ = FramePool::create({current_.format, current_.width, current_.height, config_.poolSize + 1, 1, true});
  background_ = pool_->acquire();
  drawTestPattern(*background_, config_.pattern, 0, false);
}

void SyntheticCamera::doService(Nanos now) {
  if (present_ && !present_->load()) {
    reportLost(Error(Errc::kDeviceLost, "unplugged while streaming", info().path));
    return;
  }
  for (;;) {
    const Nanos due = origin_ + frameTime(static_cast<std::int64_t>(nextFrame_), current_.fps);
    // Faults that start before this frame take effect first.
    while (nextFault_ < config_.faults.size() && origin_ + config_.faults[nextFault_].time <= std::min(due, now)) {
      const CameraFault& f = config_.faults[nextFault_++];
      const Nanos at = origin_ + f.time;
      switch (f.kind) {
        case CameraFault::Kind::kSignalLost:
          quietUntil_ = at + f.duration;
          signalLost_ = true;
          reportLost(Error(Errc::kUnavailable, "no signal", info().path), true);
          break;
        case CameraFault::Kind::kResolutionChange:
          current_.width = f.width;
          current_.height = f.height;
          makePool();
          setMode(current_);
          break;
        case CameraFault::Kind::kStall: quietUntil_ = at + f.duration; break;
        case CameraFault::Kind::kUnplug:
          reportLost(Error(Errc::kDeviceLost, "unplugged while streaming", info().path));
          return;
      }
    }
    if (signalLost_ && now >= quietUntil_) {
      signalLost_ = false;
      reportRecovered();  // the signal is back: renegotiated
    }
    if (due > now) return;
    ++nextFrame_;
    if (due < quietUntil_) continue;  // no signal or stalled: this frame never comes
    FrameRef frame = pool_->acquire();
    if (!frame) {
      countDrop();  // the show holds every frame: drop this one, like a real driver
      continue;
    }
    if (config_.moving) {
      drawMovingBoxOver(*frame, *background_, config_.pattern, nextFrame_ - 1);
    } else {
      drawTestPattern(*frame, config_.pattern, nextFrame_ - 1, false);
    }
    frame->pts = due;
    frame->captureTime = due;
    frame->sequence = nextFrame_ - 1;
    deliver(std::move(frame));
  }
}

}  // namespace basalt::sim
