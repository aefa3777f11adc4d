// SyntheticCamera: the simulated twin of a webcam or capture card.
//
// Serves tests, demos and benchmarks: a test pattern (colour bars, gradient, checker, solid) in
// any raw format Basalt handles or as MJPEG (drawn in YUYV, split into 4:2:2 planes, encoded by
// sim/jpeg_encoder on the producing thread), a moving box so that stalls and repeats show, and
// a script of faults. Limits: frames are produced from service(), so a frame is never late under
// a ManualClock and at most one service() period late under a SystemClock; MJPEG costs a
// software encode per frame on the thread that services the camera (tests and demos, not 4K).

#include "sim/synthetic_camera.h"

#include <cstring>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace basalt::sim {
namespace {

/// A JPEG no decoder can read, though whole (SOI to EOI): the code counts of its first Huffman
/// table are overwritten (libjpeg: "Bogus Huffman table definition").
void damageJpeg(std::vector<std::uint8_t>& jpeg) {
  for (std::size_t i = 2; i + 21 < jpeg.size(); ++i) {
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xC4) {  // DHT: length (2), class and id (1), 16 counts
      std::memset(jpeg.data() + i + 5, 0xFF, 16);
      break;
    }
  }
}

}  // namespace

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
  if (config_.mode.format == PixelFormat::kUnknown || config_.mode.width == 0 || config_.mode.height == 0 ||
      !(config_.mode.fps > 0)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("the synthetic camera cannot make {}; choose a format, a size and a frame rate",
                            devices::describeMode(config_.mode)),
                info().path);
  }
  // A JPEG's headers alone are about 600 bytes, and MJPEG frames hold what the raw 4:2:2
  // picture would (2 bytes a pixel).
  if (config_.mode.format == PixelFormat::kMjpeg &&
      (config_.mode.width % 2 != 0 || std::size_t{config_.mode.width} * config_.mode.height < 2048)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("the synthetic camera cannot make {}: MJPEG (4:2:2) needs an even width and at least "
                            "2048 pixels (64x32)",
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
  corruptNext_ = false;
  setMode(current_);
  setStallTimeout(std::max<Nanos>(std::chrono::milliseconds(500), fromSeconds(10.0 / current_.fps)));
  return {};
}

void SyntheticCamera::doClose() {
  background_.reset();
  scratch_.reset();
  pool_.reset();
  rawPool_.reset();
}

void SyntheticCamera::makePool() {
  background_.reset();
  scratch_.reset();
  if (current_.format == PixelFormat::kMjpeg) {
    // The JPEGs go out in frames sized for the raw 4:2:2 picture (never reached at quality
    // 85); the picture is drawn in YUYV frames of a pool of two that never leave the camera.
    pool_ = FramePool::create({PixelFormat::kMjpeg, current_.width, current_.height, config_.poolSize, 1, true});
    rawPool_ = FramePool::create({PixelFormat::kYuyv, current_.width, current_.height, 2, 1, true});
    background_ = rawPool_->acquire();
    scratch_ = rawPool_->acquire();
    planes_.resize(current_.width, current_.height);
    jpeg_.reserve(std::size_t{current_.width} * current_.height);
    if (!encoder_ || encoder_->quality() != config_.jpegQuality) encoder_.emplace(config_.jpegQuality);
  } else {
    rawPool_.reset();
    pool_ = FramePool::create({current_.format, current_.width, current_.height, config_.poolSize + 1, 1, true});
    background_ = pool_->acquire();
  }
  drawTestPattern(*background_, config_.pattern, 0, false);
}

bool SyntheticCamera::encodeFrame(std::uint64_t n, bool corrupt, Frame& out) {
  Frame& picture = *scratch_;
  if (config_.moving) {
    drawMovingBoxOver(picture, *background_, config_.pattern, n);
  } else {
    drawTestPattern(picture, config_.pattern, n, false);
  }
  const Plane& packed = picture.planes[0];
  const std::uint32_t halfWidth = current_.width / 2;
  for (std::uint32_t y = 0; y < current_.height; ++y) {
    const std::uint8_t* row = packed.data + std::size_t{y} * packed.stride;
    std::uint8_t* luma = planes_.y.data() + std::size_t{y} * current_.width;
    std::uint8_t* cb = planes_.cb.data() + std::size_t{y} * halfWidth;
    std::uint8_t* cr = planes_.cr.data() + std::size_t{y} * halfWidth;
    for (std::size_t x = 0; x < halfWidth; ++x) {  // Y0 Cb Y1 Cr
      luma[2 * x] = row[4 * x];
      cb[x] = row[4 * x + 1];
      luma[2 * x + 1] = row[4 * x + 2];
      cr[x] = row[4 * x + 3];
    }
  }
  expandToFullRange(planes_);
  encoder_->encode(planes_, jpeg_);
  if (corrupt) damageJpeg(jpeg_);
  if (jpeg_.size() > out.planes[0].size) return false;
  std::memcpy(out.planes[0].data, jpeg_.data(), jpeg_.size());
  out.bytesUsed = jpeg_.size();
  out.colorimetry = Colorimetry{Colorimetry::Matrix::kBt601, Colorimetry::Range::kFull};  // JFIF
  return true;
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
        case CameraFault::Kind::kCorrupt: corruptNext_ = true; break;
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
    if (current_.format == PixelFormat::kMjpeg) {
      const bool corrupt = std::exchange(corruptNext_, false);
      if (!encodeFrame(nextFrame_ - 1, corrupt, *frame)) {
        countDrop();  // larger than the raw picture: not a JPEG a camera would send
        continue;
      }
    } else if (config_.moving) {
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
