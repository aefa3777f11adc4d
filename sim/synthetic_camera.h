#pragma once

/// \file
/// \brief A camera with no hardware behind it: test patterns, moving content and scripted
/// faults (signal lost, resolution change, stall, unplug, a corrupt JPEG), produced on the show's
/// Clock, in any raw format Basalt handles or as MJPEG (like a USB webcam's large sizes).

#include <memory>
#include <optional>
#include <vector>

#include "devices/video_source.h"
#include "runtime/test_pattern.h"
#include "sim/jpeg_encoder.h"
#include "sim/synthetic_dial.h"

namespace basalt::sim {

/// \brief Something that goes wrong with a synthetic camera, at `time` after opening.
struct CameraFault {
  enum class Kind : std::uint8_t {
    kSignalLost,        ///< no signal for `duration`, then it renegotiates by itself (HDMI)
    kResolutionChange,  ///< from now on frames are `width` x `height` (a source change)
    kStall,             ///< no frames for `duration`, state still live until the stall timeout
    kUnplug,            ///< the device vanishes: lost until the DeviceManager reopens it
    kCorrupt,           ///< MJPEG: the first frame due at or after `time` is a damaged JPEG
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
  int jpegQuality = 85;  ///< MJPEG: 1-100, as IJG's cjpeg takes it
};

/// \brief Delivers frame n at `open time + n / fps`, drawn in the configured format, from
/// service(): exact and reproducible under a ManualClock. Frames carry pts = captureTime = their
/// due time, and sequence = n. MJPEG frames are the pattern drawn in 4:2:2 and encoded as one
/// complete baseline JPEG each (sim/jpeg_encoder.h), bytesUsed its length; the width must be even and the
/// picture at least 64x32.
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
  /// MJPEG: draws frame `n` in 4:2:2 and encodes it into `out` (damaged when `corrupt`); false
  /// when the JPEG does not fit the frame.
  bool encodeFrame(std::uint64_t n, bool corrupt, Frame& out);

  SyntheticCameraConfig config_;
  PresenceFlag present_;
  std::shared_ptr<FramePool> pool_;
  FrameRef background_;  // the pattern without the moving box, drawn once per mode
  // MJPEG: the picture is drawn as YUYV (background_ and scratch_ from rawPool_), split into
  // planes_ and encoded into jpeg_; allocated once per mode.
  std::shared_ptr<FramePool> rawPool_;
  FrameRef scratch_;
  Yuv422Planes planes_;
  std::vector<std::uint8_t> jpeg_;
  std::optional<JpegEncoder> encoder_;
  devices::VideoMode current_;
  Nanos origin_{0};
  std::uint64_t nextFrame_ = 0;
  std::size_t nextFault_ = 0;
  Nanos quietUntil_{0};  // no frames before this (signal lost or stall)
  bool signalLost_ = false;
  bool corruptNext_ = false;  // a corrupt fault is due: the next frame is damaged
};

}  // namespace basalt::sim
