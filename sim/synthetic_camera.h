#pragma once

/// \file
/// \brief A camera with no hardware behind it: test patterns, moving content and scripted
/// faults (signal lost, resolution change, stall, unplug), produced on the show's Clock.

#include <memory>
#include <vector>

#include "devices/video_source.h"
#include "runtime/test_pattern.h"
#include "sim/synthetic_dial.h"

namespace basalt::sim {

/// \brief Something that goes wrong with a synthetic camera, at `time` after opening.
struct CameraFault {
  enum class Kind : std::uint8_t {
    kSignalLost,        ///< no signal for `duration`, then it renegotiates by itself (HDMI)
    kResolutionChange,  ///< from now on frames are `width` x `height` (a source change)
    kStall,             ///< no frames for `duration`, state still live until the stall timeout
    kUnplug,            ///< the device vanishes: lost until the DeviceManager reopens it
  };
  Nanos time{0};
  Kind kind = Kind::kSignalLost;
  Nanos duration{0};
  std::uint32_t width = 0;
  std::uint32_t height = 0;
};

struct SyntheticCameraConfig {
  devices::VideoMode mode{PixelFormat::kYuyv, 640, 360, 30};
  TestPattern pattern = TestPattern::kColourBars;
  bool moving = true;
  std::vector<CameraFault> faults;
  std::size_t poolSize = 6;
};

/// \brief Delivers frame n at `open time + n / fps`, drawn in the configured format, from
/// service(): exact and reproducible under a ManualClock. Frames carry pts = captureTime = their
/// due time, and sequence = n.
class SyntheticCamera final : public devices::VideoSource {
 public:
  SyntheticCamera(devices::DeviceInfo info, SyntheticCameraConfig config, const Clock& clock,
                  PresenceFlag present = nullptr);
  static devices::DeviceInfo defaultInfo();

 private:
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;
  void makePool();

  SyntheticCameraConfig config_;
  PresenceFlag present_;
  std::shared_ptr<FramePool> pool_;
  FrameRef background_;  // the pattern without the moving box, drawn once per mode
  devices::VideoMode current_;
  Nanos origin_{0};
  std::uint64_t nextFrame_ = 0;
  std::size_t nextFault_ = 0;
  Nanos quietUntil_{0};  // no frames before this (signal lost or stall)
  bool signalLost_ = false;
};

}  // namespace basalt::sim
