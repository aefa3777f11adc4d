// The synthetic camera's MJPEG frames, the twin of a webcam's: each frame one complete baseline
// JPEG of the camera's size (bytesUsed its length), decoded by media::MjpegDecoder to the colour
// bars the camera draws in raw formats; a corrupt fault damages exactly the frame due then, which
// the decoder counts and drops while the next frame decodes; MJPEG needs an even width and
// room for a JPEG's headers.
// Example failures: a frame cut short or padded past its JPEG; a JPEG of the wrong size; bars in
// the wrong order or colours (chroma planes swapped, limited range sent as full); a corrupt frame
// that decodes anyway, or that stops the frames after it.

#include <gtest/gtest.h>

#include <cstdlib>
#include <span>
#include <utility>
#include <vector>

#include "media/mjpeg_decoder.h"
#include "runtime/clock.h"
#include "runtime/test_pattern.h"
#include "sim/jpeg_encoder.h"
#include "sim/synthetic_camera.h"

namespace basalt::sim {
namespace {

using namespace std::chrono_literals;

constexpr std::uint32_t kW = 160, kH = 120;

SyntheticCameraConfig mjpegConfig() {
  SyntheticCameraConfig config;
  config.mode = {PixelFormat::kMjpeg, kW, kH, 30};
  config.moving = false;
  config.poolSize = 12;  // the tests hold every frame
  return config;
}

/// The frames the camera delivers up to `until`, serviced frame by frame.
std::vector<FrameRef> framesUntil(SyntheticCamera& camera, ManualClock& clock, Nanos until) {
  std::vector<FrameRef> frames;
  for (Nanos t{0}; t <= until; t += 33'333'334ns) {
    clock.set(t);
    camera.service(t);
    if (FrameRef f = camera.frameAt(t)) frames.push_back(std::move(f));
  }
  return frames;
}

TEST(SyntheticMjpeg, EveryFrameIsACompleteJpegOfTheCamerasSize) {
  ManualClock clock(Nanos{0});
  SyntheticCamera camera(SyntheticCamera::defaultInfo(), mjpegConfig(), clock);
  ASSERT_TRUE(camera.open()) << "MJPEG is a format the synthetic camera makes";
  const std::vector<FrameRef> frames = framesUntil(camera, clock, 300ms);
  ASSERT_GE(frames.size(), 9u);
  for (const FrameRef& f : frames) {
    ASSERT_EQ(f->format, PixelFormat::kMjpeg);
    EXPECT_EQ(f->width, kW);
    EXPECT_EQ(f->height, kH);
    ASSERT_GT(f->bytesUsed, 0u);
    ASSERT_LE(f->bytesUsed, f->planes[0].size);
    const auto info = inspectJpeg(std::span<const std::uint8_t>(f->planes[0].data, f->bytesUsed));
    ASSERT_TRUE(info) << "frame " << f->sequence << " is not a JPEG";
    EXPECT_TRUE(info->complete) << "frame " << f->sequence << " ends without EOI";
    EXPECT_TRUE(info->baseline);
    EXPECT_EQ(info->width, kW);
    EXPECT_EQ(info->height, kH);
  }
}

TEST(SyntheticMjpeg, FramesDecodeToTheColourBarsAndACorruptOneIsDropped) {
  ManualClock clock(Nanos{0});
  SyntheticCameraConfig config = mjpegConfig();
  config.faults.push_back({95ms, CameraFault::Kind::kCorrupt, Nanos{0}, 0, 0});  // frame 3 (100 ms)
  SyntheticCamera camera(SyntheticCamera::defaultInfo(), config, clock);
  ASSERT_TRUE(camera.open());
  const std::vector<FrameRef> frames = framesUntil(camera, clock, 210ms);
  ASSERT_EQ(frames.size(), 7u);
  // The bars as the camera draws them raw, in limited range: the JPEG carries them full range.
  auto rawPool = FramePool::create({PixelFormat::kYuyv, kW, kH, 1, 1, true});
  FrameRef raw = rawPool->acquire();
  ASSERT_TRUE(drawTestPattern(*raw, TestPattern::kColourBars, 0, false));

  auto decoder = media::MjpegDecoder::create({4, "synthetic camera"});
  ASSERT_TRUE(decoder) << decoder.error().describe();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE(i);
    const FrameRef& jpeg = frames[i];
    EXPECT_EQ(jpeg->sequence, i);
    const auto info = inspectJpeg(std::span<const std::uint8_t>(jpeg->planes[0].data, jpeg->bytesUsed));
    EXPECT_TRUE(info && info->complete) << "a damaged JPEG is still whole: its Huffman table is bad";
    ASSERT_TRUE((*decoder)->push(jpeg));
    ASSERT_TRUE((*decoder)->waitForFinished(i + 1, 10s))
        << "decoded " << (*decoder)->decoded() << ", corrupt " << (*decoder)->corrupt();
    FrameRef decoded = (*decoder)->frameAt(jpeg->pts);
    if (i == 3) {
      EXPECT_FALSE(decoded) << "the corrupt JPEG decoded";
      EXPECT_EQ((*decoder)->corrupt(), 1u);
      continue;
    }
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->format, PixelFormat::kI420);
    EXPECT_EQ(decoded->width, kW);
    EXPECT_EQ(decoded->height, kH);
    EXPECT_EQ(decoded->sequence, i);
    // The middle of each of the eight bars: the decoded luma is the raw luma in full range.
    for (std::uint32_t bar = 0; bar < 8; ++bar) {
      const std::uint32_t x = bar * kW / 8 + kW / 16;
      const int limited = samplePixel(*raw, x, kH / 2).r;
      const int expected = (limited - 16) * 255 / 219;
      const int got = decoded->planes[0].data[std::size_t{kH / 2} * decoded->planes[0].stride + x];
      EXPECT_NEAR(got, expected, 6) << "bar " << bar;
    }
  }
  EXPECT_EQ((*decoder)->decoded(), 6u);
  EXPECT_EQ((*decoder)->corrupt(), 1u);
}

TEST(SyntheticMjpeg, NeedsAnEvenWidthAndRoomForTheHeaders) {
  ManualClock clock(Nanos{0});
  for (const auto& [w, h] : {std::pair{161u, 120u}, std::pair{32u, 16u}}) {
    SyntheticCameraConfig config = mjpegConfig();
    config.mode.width = w;
    config.mode.height = h;
    SyntheticCamera camera(SyntheticCamera::defaultInfo(), config, clock);
    auto r = camera.open();
    ASSERT_FALSE(r) << w << "x" << h;
    EXPECT_NE(r.error().describe().find("needs an even width and at least 2048 pixels"), std::string::npos)
        << r.error().describe();
  }
}

}  // namespace
}  // namespace basalt::sim
