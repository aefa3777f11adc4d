// The VideoSource contract, run against every backend: open/close and the state machine,
// frames that are well formed, in order and never from the future, the health a texture stream
// reads, frames that stay valid after the source is closed, and the frame-rate limit and mirror
// of LAVA's Hardware panel. Instantiated for the synthetic and replay backends always; for V4L2
// (vivid's webcam and HDMI inputs, a UVC gadget) in the virtual lab and libcamera where it sees
// a camera, skipping with the reason elsewhere.
// Example failures: a V4L2 buffer unmapped while the renderer still reads it; a frame whose
// planes do not match its mode; a camera whose health says live while nothing arrives; a closed
// source that still delivers.

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <thread>

#include "devices/libcamera/libcamera_camera.h"
#include "devices/v4l2/v4l2_camera.h"
#include "devices/video_source.h"
#include "sim/raw_video.h"
#include "sim/replay.h"
#include "sim/synthetic_camera.h"
#include "support/test_paths.h"
#include "vlab.h"
#include "vlab_uvc.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

struct VideoBackend {
  std::string name;
  std::function<std::shared_ptr<VideoSource>(const Clock&, std::string& skipReason)> make;
  bool threaded = false;
};

void PrintTo(const VideoBackend& backend, std::ostream* os) { *os << backend.name; }

std::shared_ptr<VideoSource> makeSynthetic(const Clock& clock, std::string&) {
  sim::SyntheticCameraConfig config;
  config.mode = {PixelFormat::kNv12, 160, 90, 30};
  return std::make_shared<sim::SyntheticCamera>(sim::SyntheticCamera::defaultInfo(), config, clock);
}

std::shared_ptr<VideoSource> makeReplay(const Clock& clock, std::string& reason) {
  // Record two seconds of a synthetic camera into a .bvraw file, then replay it.
  const auto dir = test::scratchDir("video_contract_replay");
  const VideoMode mode{PixelFormat::kYuyv, 96, 54, 25};
  auto writer = sim::RawVideoWriter::create(dir / "camera.bvraw", mode);
  if (!writer) {
    reason = writer.error().describe();
    return nullptr;
  }
  auto pool = FramePool::create({mode.format, mode.width, mode.height, 1, 1, true});
  for (int i = 0; i < 50; ++i) {
    FrameRef f = pool->acquire();
    drawTestPattern(*f, TestPattern::kGradient, static_cast<std::uint64_t>(i), true);
    f->sequence = static_cast<std::uint64_t>(i);
    if (!(*writer)->write(*f, frameTime(i, mode.fps))) return nullptr;
  }
  if (!(*writer)->finish()) return nullptr;
  auto reader = sim::RawVideoReader::open(dir / "camera.bvraw");
  if (!reader) {
    reason = reader.error().describe();
    return nullptr;
  }
  return std::make_shared<sim::ReplayCamera>(
      DeviceInfo{"Recorded camera", "replay", "virtual", 0, 0, "camera.bvraw", ""}, std::move(*reader), clock, true);
}

std::shared_ptr<VideoSource> makeV4l2(const char* variable, const char* what, const Clock& clock, std::string& reason) {
  const bool uvc = std::string(variable) == "BASALT_VLAB_V4L2_UVC";
  const auto node = uvc ? test::labUvcNode() : test::vlabEnv(variable);
  if (!node) {
    reason = uvc && test::vlabEnv(variable)
                 ? "the lab's UVC camera (USB 1209:0002) is at no /dev/video node: a case before unplugged it and "
                   "it did not come back"
                 : test::needsVlab(std::string(variable) + " (" + what + ")");
    return nullptr;
  }
  V4l2Options options;
  options.width = 640;
  options.height = 360;
  if (std::string(variable) == "BASALT_VLAB_V4L2_HDMI") options.width = options.height = 0;  // the timings decide
  return makeV4l2Camera(*node, options, clock);
}

std::shared_ptr<VideoSource> makeLibcamera(const Clock& clock, std::string& reason) {
  LibcameraProvider provider;
  if (!provider.startError().empty()) {
    reason = provider.startError();
    return nullptr;
  }
  auto cameras = provider.enumerate();
  if (cameras.empty()) {
    reason =
        "libcamera sees no camera here (it needs a CSI sensor or a UVC camera that udev has processed; the "
        "virtual lab has one: make vlab)";
    return nullptr;
  }
  DeviceRequest r;
  r.name = "camera";
  r.kind = DeviceKind::kVideoSource;
  auto source = provider.openVideoSource(cameras.front(), r, clock);
  if (!source) {
    reason = source.error().describe();
    return nullptr;
  }
  return *source;
}

class VideoSourceContract : public ::testing::TestWithParam<VideoBackend> {
 protected:
  void SetUp() override {
    std::string reason;
    source_ = GetParam().make(clock_, reason);
    if (!source_) GTEST_SKIP() << GetParam().name << " backend cannot run here: " << reason;
  }
  void TearDown() override {
    if (source_) source_->close();
  }
  void tick() {
    clock_.advance(10ms);
    if (GetParam().threaded) std::this_thread::sleep_for(3ms);
    source_->service(clock_.now());
  }

  ManualClock clock_{Nanos{std::chrono::seconds(1)}};
  std::shared_ptr<VideoSource> source_;
};

TEST_P(VideoSourceContract, OpensLiveAndClosesAbsent) {
  EXPECT_EQ(source_->state(), DeviceState::kAbsent);
  EXPECT_EQ(source_->health().state, SourceState::kWaiting);
  ASSERT_TRUE(source_->open(5)) << "open failed";
  EXPECT_EQ(source_->state(), DeviceState::kLive);
  EXPECT_EQ(source_->health().state, SourceState::kLive);
  EXPECT_NE(source_->mode().format, PixelFormat::kUnknown);
  EXPECT_GT(source_->mode().width, 0u);
  EXPECT_TRUE(source_->open(5)) << "opening a live source is a no-op";
  source_->close();
  EXPECT_EQ(source_->state(), DeviceState::kAbsent);
  EXPECT_EQ(source_->health().state, SourceState::kWaiting);
  source_->close();
}

TEST_P(VideoSourceContract, FramesAreWellFormedInOrderAndNeverEarly) {
  ASSERT_TRUE(source_->open(5));
  const VideoMode mode = source_->mode();
  int frames = 0;
  std::uint64_t lastSequence = 0;
  Nanos lastPts{-1};
  for (int step = 0; step < 300 && frames < 10; ++step) {
    tick();
    FrameRef f = source_->frameAt(clock_.now());
    if (!f) continue;
    ++frames;
    EXPECT_LE(f->pts, clock_.now()) << "a frame from the future";
    EXPECT_GT(f->pts, lastPts) << "frames out of order";
    if (frames > 1) {
      // The sequence is the driver's count, passed on as it is: it never goes back, but a driver
      // may repeat one (vivid's HDMI input under emulation numbered two buffers 0, 9 ms apart,
      // when its thread caught up; interlaced fields share theirs). The presentation time is
      // Basalt's and strictly rises (above).
      EXPECT_GE(f->sequence, lastSequence) << "the sequence went back";
    }
    lastPts = f->pts;
    lastSequence = f->sequence;
    EXPECT_EQ(f->format, mode.format);
    EXPECT_EQ(f->width, mode.width);
    EXPECT_EQ(f->height, mode.height);
    EXPECT_EQ(f->planeCount, mode.format == PixelFormat::kMjpeg ? 1 : planeCount(mode.format));
    for (int p = 0; p < f->planeCount; ++p) {
      const Plane& plane = f->planes[static_cast<std::size_t>(p)];
      EXPECT_TRUE(plane.data || plane.dmabufFd >= 0) << "plane " << p << " has no memory";
      if (mode.format != PixelFormat::kMjpeg) {
        EXPECT_GT(plane.stride, 0u);
      }
    }
  }
  EXPECT_GE(frames, 3) << "fewer than 3 frames in 3 s";
  EXPECT_GE(source_->framesDelivered(), static_cast<std::uint64_t>(frames));
}

TEST_P(VideoSourceContract, FramesOutliveClose) {
  ASSERT_TRUE(source_->open(5));
  FrameRef held;
  for (int step = 0; step < 300 && !held; ++step) {
    tick();
    held = source_->frameAt(clock_.now());
  }
  ASSERT_TRUE(held);
  source_->close();
  EXPECT_FALSE(source_->frameAt(clock_.now())) << "a closed source delivers nothing";
  // The frame's memory is still readable (AddressSanitizer checks this in `make sanitize`).
  if (held->planes[0].data) {
    unsigned sum = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(held->planes[0].size, 4096); ++i) sum += held->planes[0].data[i];
    (void)sum;
  }
  held.reset();  // returns the buffer to a source that is gone: must not crash
  ASSERT_TRUE(source_->open(5)) << "reopening after close";
}

TEST_P(VideoSourceContract, FrameRateLimitIsKept) {
  VideoControls c;
  c.maxFps = 5;
  ASSERT_TRUE(source_->setControls(c));
  ASSERT_TRUE(source_->open(5));
  EXPECT_EQ(source_->controls().maxFps, 5);
  const double nominal = source_->mode().fps;
  if (nominal > 0 && nominal <= 5.0 + 1e-6) {
    // The device took the limit as its own rate (V4L2's S_PARM): nothing to drop, and no more
    // than five frames a second arrive.
    if (!GetParam().threaded) return;
    const std::uint64_t before = source_->framesDelivered();
    const auto start = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - start < 2s) {
      tick();
      (void)source_->frameAt(clock_.now());
    }
    const std::uint64_t arrived = source_->framesDelivered() - before;
    EXPECT_LE(arrived, 12u) << "a source limited to 5 fps delivered " << arrived << " frames in 2 s";
    EXPECT_GE(arrived, 6u) << "frames still flow at the limited rate";
    return;
  }
  // The device runs faster: the source drops what comes early.
  for (int step = 0; step < 200; ++step) {
    tick();
    (void)source_->frameAt(clock_.now());
  }
  EXPECT_GT(source_->framesDropped(), 0u) << "a 5 fps limit on a " << nominal << " fps source dropped nothing";
}

TEST_P(VideoSourceContract, MirrorIsAppliedByTheDeviceOrTheRenderer) {
  ASSERT_TRUE(source_->open(5));
  VideoControls c;
  c.mirror = true;
  ASSERT_TRUE(source_->setControls(c));
  EXPECT_TRUE(source_->controls().mirror);
  c.mirror = false;
  ASSERT_TRUE(source_->setControls(c));
  EXPECT_FALSE(source_->mirrorInRenderer());
  c.quality = 101;
  EXPECT_FALSE(source_->setControls(c)) << "quality is 0..100";
}

INSTANTIATE_TEST_SUITE_P(
    Backends, VideoSourceContract,
    ::testing::Values(VideoBackend{"synthetic", makeSynthetic}, VideoBackend{"replay", makeReplay},
                      VideoBackend{"v4l2_webcam",
                                   [](const Clock& c, std::string& r) {
                                     return makeV4l2("BASALT_VLAB_V4L2_WEBCAM", "vivid's webcam input", c, r);
                                   },
                                   true},
                      VideoBackend{"v4l2_hdmi",
                                   [](const Clock& c, std::string& r) {
                                     return makeV4l2("BASALT_VLAB_V4L2_HDMI", "a vivid HDMI input", c, r);
                                   },
                                   true},
                      VideoBackend{"v4l2_uvc",
                                   [](const Clock& c, std::string& r) {
                                     return makeV4l2("BASALT_VLAB_V4L2_UVC", "the lab's UVC camera", c, r);
                                   },
                                   true},
                      VideoBackend{"libcamera", makeLibcamera, true}),
    [](const ::testing::TestParamInfo<VideoBackend>& param) { return param.param.name; });

}  // namespace
}  // namespace basalt::devices
