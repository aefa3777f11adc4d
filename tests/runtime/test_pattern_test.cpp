// Test patterns, the synthetic camera's pictures and a lost camera's fallback: every raw format
// is drawn, colour bars sample to their BT.601 values, and the fast path (background copied, only
// the moving box redrawn) gives exactly the bytes of a full draw, so replays stay bit-exact.
// Example failures: a chroma sample at the box's edge that differs between the two paths; a
// pattern drawn past the end of a padded plane.

#include <gtest/gtest.h>

#include <cstring>

#include "runtime/test_pattern.h"

namespace basalt {
namespace {

bool samePixels(const Frame& a, const Frame& b) {
  for (int p = 0; p < a.planeCount; ++p) {
    const Plane& pa = a.planes[static_cast<std::size_t>(p)];
    const Plane& pb = b.planes[static_cast<std::size_t>(p)];
    if (pa.size != pb.size || std::memcmp(pa.data, pb.data, pa.size) != 0) return false;
  }
  return true;
}

TEST(TestPattern, FastMovingBoxMatchesAFullDrawInEveryFormat) {
  for (PixelFormat f :
       {PixelFormat::kRgba8, PixelFormat::kBgra8, PixelFormat::kRgb8, PixelFormat::kGray8, PixelFormat::kYuyv,
        PixelFormat::kUyvy, PixelFormat::kNv12, PixelFormat::kNv21, PixelFormat::kI420, PixelFormat::kYv12}) {
    for (auto [w, h] : {std::pair{64u, 36u}, std::pair{37u, 21u}}) {
      auto pool = FramePool::create({f, w, h, 3, 8, true});
      FrameRef background = pool->acquire(), fast = pool->acquire(), full = pool->acquire();
      ASSERT_TRUE(drawTestPattern(*background, TestPattern::kGradient, 0, false)) << pixelFormatName(f);
      for (std::uint64_t n : {0u, 5u, 16u, 17u, 100u}) {
        std::memset(full->storage(), 0, full->storageSize());
        ASSERT_TRUE(drawTestPattern(*full, TestPattern::kGradient, n, true));
        ASSERT_TRUE(drawMovingBoxOver(*fast, *background, TestPattern::kGradient, n));
        EXPECT_TRUE(samePixels(*fast, *full)) << pixelFormatName(f) << " " << w << "x" << h << " frame " << n;
      }
    }
  }
}

TEST(TestPattern, BarsHaveTheirColoursAndMjpegIsRefused) {
  auto pool = FramePool::create({PixelFormat::kRgba8, 80, 10, 1, 1, true});
  FrameRef f = pool->acquire();
  ASSERT_TRUE(drawTestPattern(*f, TestPattern::kColourBars, 0, false));
  EXPECT_EQ(samplePixel(*f, 5, 5), (Rgb8{191, 191, 191}));
  EXPECT_EQ(samplePixel(*f, 15, 5), (Rgb8{191, 191, 0}));
  EXPECT_EQ(samplePixel(*f, 75, 5), (Rgb8{0, 0, 0}));
  auto yuv = FramePool::create({PixelFormat::kYuyv, 80, 10, 1, 1, true});
  FrameRef y = yuv->acquire();
  ASSERT_TRUE(drawTestPattern(*y, TestPattern::kColourBars, 0, false));
  EXPECT_EQ(samplePixel(*y, 5, 5).r, 180) << "75% white is luma 180 in BT.601 limited range";
  auto mjpeg = FramePool::create({PixelFormat::kMjpeg, 16, 16, 1, 1, true});
  FrameRef m = mjpeg->acquire();
  EXPECT_FALSE(drawTestPattern(*m, TestPattern::kColourBars, 0, false));
}

}  // namespace
}  // namespace basalt
