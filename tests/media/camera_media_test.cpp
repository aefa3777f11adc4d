// What media/ gives the camera and trace work: the MJPEG decoder (camera JPEGs to I420 on its
// own thread, timestamps and sequence kept, damaged JPEGs dropped without ending the stream)
// and the Matroska trace video (frames written as the device gave them with their original,
// irregular timestamps and read back identical).
// Example failures: timestamps rounded to a frame rate on the way through the file; MJPEG
// re-encoded (bytes differ); a damaged JPEG that stops every later frame; a decoder that loses
// the camera's sequence numbers.

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "media/image_io.h"
#include "media/mjpeg_decoder.h"
#include "media/trace_video.h"
#include "support/numbered_clip.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

constexpr std::uint32_t kW = 160, kH = 120;

/// JPEG bytes of numbered image `n`, made through Basalt's image writer.
std::vector<std::uint8_t> numberedJpeg(int n) {
  const auto path = test::binaryDir() / "test-scratch" / "jpegs" / fmt::format("n{}-{}.jpg", n, ::getpid());
  std::filesystem::create_directories(path.parent_path());
  auto r = writeImage(path, test::numberedImage(kW, kH, n));
  EXPECT_TRUE(r) << r.error().describe();
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

FrameRef mjpegFrame(FramePool& pool, const std::vector<std::uint8_t>& bytes, std::int64_t ptsMs, std::uint64_t seq) {
  FrameRef f = pool.acquire();
  EXPECT_TRUE(f);
  EXPECT_LE(bytes.size(), f->storageSize());
  std::memcpy(f->planes[0].data, bytes.data(), bytes.size());
  f->bytesUsed = bytes.size();
  f->pts = std::chrono::milliseconds(ptsMs);
  f->captureTime = f->pts + Nanos{7};
  f->sequence = seq;
  return f;
}

TEST(MjpegDecoder, DecodesCameraFramesKeepingTimeAndSequence) {
  auto decoder = MjpegDecoder::create({4, "test camera"});
  ASSERT_TRUE(decoder) << decoder.error().describe();
  auto pool = FramePool::create({PixelFormat::kMjpeg, kW, kH, 4, 1, true});
  for (int n = 0; n < 6; ++n) {
    const std::int64_t ptsMs = 1000 + n * 37;  // an irregular camera clock
    ASSERT_TRUE((*decoder)->push(mjpegFrame(*pool, numberedJpeg(n), ptsMs, 500 + static_cast<std::uint64_t>(n))));
    ASSERT_TRUE((*decoder)->waitForDecoded(static_cast<std::uint64_t>(n) + 1, std::chrono::seconds(10)));
    FrameRef f = (*decoder)->frameAt(std::chrono::milliseconds(ptsMs));
    ASSERT_TRUE(f) << "frame " << n;
    EXPECT_EQ(f->format, PixelFormat::kI420);
    EXPECT_EQ(f->width, kW);
    EXPECT_EQ(test::readFrameNumber(*f), n);
    EXPECT_EQ(f->pts, std::chrono::milliseconds(ptsMs));
    EXPECT_EQ(f->sequence, 500u + static_cast<std::uint64_t>(n));
    EXPECT_EQ(f->captureTime, f->pts + Nanos{7});
  }
  EXPECT_FALSE((*decoder)->frameAt(std::chrono::milliseconds(5000))) << "nothing new is due";
}

TEST(MjpegDecoder, DamagedJpegIsDroppedAndTheStreamGoesOn) {
  auto decoder = MjpegDecoder::create({4, "test camera"});
  ASSERT_TRUE(decoder);
  auto pool = FramePool::create({PixelFormat::kMjpeg, kW, kH, 4, 1, true});
  std::vector<std::uint8_t> garbage = numberedJpeg(3);
  garbage.resize(garbage.size() / 3);  // a USB transfer cut short
  for (std::size_t i = 200; i < garbage.size(); i += 7) garbage[i] = 0xA5;
  EXPECT_FALSE((*decoder)->push(mjpegFrame(*pool, garbage, 0, 1))) << "no end-of-image marker";
  EXPECT_EQ((*decoder)->corrupt(), 1u) << "counted at once, not left waiting in the parser";
  // A whole JPEG padded with zeros after its end marker, as cameras send them, is fine.
  std::vector<std::uint8_t> padded = numberedJpeg(42);
  padded.resize(padded.size() + 300, 0);
  ASSERT_TRUE((*decoder)->push(mjpegFrame(*pool, padded, 40, 2)));
  ASSERT_TRUE((*decoder)->waitForDecoded(1, std::chrono::seconds(10)));
  FrameRef f = (*decoder)->frameAt(std::chrono::milliseconds(40));
  ASSERT_TRUE(f);
  EXPECT_EQ(test::readFrameNumber(*f), 42);
  EXPECT_EQ(f->sequence, 2u);
  EXPECT_EQ((*decoder)->corrupt(), 1u) << "the damaged JPEG is counted";
}

TEST(MjpegDecoder, RefusesFramesThatAreNotJpeg) {
  auto decoder = MjpegDecoder::create({});
  ASSERT_TRUE(decoder);
  auto pool = FramePool::create({PixelFormat::kYuyv, 16, 16, 1, 1, true});
  EXPECT_FALSE((*decoder)->push(pool->acquire()));
  EXPECT_EQ((*decoder)->dropped(), 1u);
}

/// A raw frame of `format` showing `n` (luma from the numbered image, neutral chroma).
FrameRef rawFrame(FramePool& pool, PixelFormat format, int n) {
  FrameRef f = pool.acquire();
  const Image img = test::numberedImage(kW, kH, n);
  for (std::uint32_t y = 0; y < kH; ++y) {
    for (std::uint32_t x = 0; x < kW; ++x) {
      const std::uint8_t luma = img.at(x, y, 1);
      Plane& p0 = f->planes[0];
      if (format == PixelFormat::kYuyv) {
        p0.data[y * p0.stride + 2 * x] = luma;
        p0.data[y * p0.stride + 2 * x + 1] = 128;
      } else {
        p0.data[y * p0.stride + x] = luma;
      }
    }
  }
  if (format == PixelFormat::kNv12) std::memset(f->planes[1].data, 128, f->planes[1].size);
  return f;
}

struct TraceCase {
  PixelFormat written;
  PixelFormat read;
};

class TraceVideo : public ::testing::TestWithParam<TraceCase> {};

TEST_P(TraceVideo, FramesComeBackWithTheirOriginalTimestamps) {
  const TraceCase c = GetParam();
  const auto path = test::scratchDir(fmt::format("trace-{}", pixelFormatName(c.written))) / "camera0.mkv";
  const Nanos origin = std::chrono::seconds(5000);
  // Irregular times, as a camera under load delivers them (microsecond precision).
  const std::vector<std::int64_t> micros = {0, 33'367, 66'701, 133'402, 166'770, 200'101, 266'800};
  std::vector<std::vector<std::uint8_t>> jpegs;
  {
    auto writer = TraceVideoWriter::create(path, c.written, kW, kH, origin);
    ASSERT_TRUE(writer) << writer.error().describe();
    auto pool = FramePool::create({c.written, kW, kH, 2, 4, true});
    for (std::size_t i = 0; i < micros.size(); ++i) {
      FrameRef f;
      if (c.written == PixelFormat::kMjpeg) {
        jpegs.push_back(numberedJpeg(static_cast<int>(i)));
        f = mjpegFrame(*pool, jpegs.back(), 0, i);
      } else {
        f = rawFrame(*pool, c.written, static_cast<int>(i));
      }
      f->pts = origin + std::chrono::microseconds(micros[i]);
      ASSERT_TRUE((*writer)->write(*f));
    }
    ASSERT_TRUE((*writer)->finish());
  }
  const Nanos replayOrigin = std::chrono::seconds(10);
  auto reader = TraceVideoReader::open(path, replayOrigin);
  ASSERT_TRUE(reader) << reader.error().describe();
  EXPECT_EQ((*reader)->format(), c.read);
  EXPECT_EQ((*reader)->width(), kW);
  for (std::size_t i = 0; i < micros.size(); ++i) {
    auto f = (*reader)->next();
    ASSERT_TRUE(f) << f.error().describe();
    ASSERT_TRUE(*f) << "frame " << i << " missing";
    EXPECT_EQ((*f)->pts, replayOrigin + std::chrono::microseconds(micros[i])) << "frame " << i;
    EXPECT_EQ((*f)->sequence, i);
    if (c.read == PixelFormat::kMjpeg) {
      ASSERT_EQ((*f)->bytesUsed, jpegs[i].size());
      EXPECT_EQ(std::memcmp((*f)->planes[0].data, jpegs[i].data(), jpegs[i].size()), 0) << "MJPEG kept byte for byte";
    } else {
      EXPECT_EQ(test::readFrameNumber(**f), static_cast<int>(i));
    }
  }
  auto end = (*reader)->next();
  ASSERT_TRUE(end);
  EXPECT_FALSE(*end) << "no frame after the last";
}

INSTANTIATE_TEST_SUITE_P(Formats, TraceVideo,
                         ::testing::Values(TraceCase{PixelFormat::kYuyv, PixelFormat::kYuyv},
                                           TraceCase{PixelFormat::kMjpeg, PixelFormat::kMjpeg},
                                           TraceCase{PixelFormat::kNv12, PixelFormat::kI420},
                                           TraceCase{PixelFormat::kI420, PixelFormat::kI420}),
                         [](const ::testing::TestParamInfo<TraceCase>& p) {
                           return std::string(pixelFormatName(p.param.written));
                         });

TEST(TraceVideoErrors, MissingAndDamagedFilesSayWhich) {
  auto missing = TraceVideoReader::open("/nonexistent/camera0.mkv");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().describe().find("/nonexistent/camera0.mkv"), std::string::npos);
  const auto damaged = test::scratchDir("trace-damaged") / "camera0.mkv";
  {
    std::ofstream out(damaged, std::ios::binary);
    out << "this is not a Matroska file at all, just text pretending";
  }
  auto r = TraceVideoReader::open(damaged);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().describe().find(damaged.string()), std::string::npos) << r.error().describe();
}

}  // namespace
}  // namespace basalt::media
