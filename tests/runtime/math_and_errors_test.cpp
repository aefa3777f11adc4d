// Math, errors, images and logging: the vocabulary every folder uses.
// Example failures: a wrong matrix multiplication order (rotations compose backwards); an
// error message that loses its location; the image comparison passing different images.

#include <gtest/gtest.h>

#include "runtime/error.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "runtime/math.h"

namespace basalt {
namespace {

void expectNear(const Vec3& a, const Vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-5f);
  EXPECT_NEAR(a.y, b.y, 1e-5f);
  EXPECT_NEAR(a.z, b.z, 1e-5f);
}

TEST(Math, RotationsAreCounterClockwiseAndComposeRightToLeft) {
  expectNear(Mat4::rotationZ(90).transformPoint({1, 0, 0}), {0, 1, 0});
  expectNear(Mat4::rotationX(90).transformPoint({0, 1, 0}), {0, 0, 1});
  expectNear(Mat4::rotationY(90).transformPoint({0, 0, 1}), {1, 0, 0});
  const Mat4 m = Mat4::translation({5, 0, 0}) * Mat4::rotationZ(90);  // rotate, then translate
  expectNear(m.transformPoint({1, 0, 0}), {5, 1, 0});
  expectNear(Mat4::rotation(90, {0, 0, 1}).transformPoint({1, 0, 0}), {0, 1, 0});
}

TEST(Math, InverseUndoes) {
  const Mat4 m = Mat4::translation({1, 2, 3}) * Mat4::rotationY(30) * Mat4::scaling({2, 3, 4});
  const Mat4 i = m * m.inverted();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(i(r, c), r == c ? 1.0f : 0.0f, 1e-5f);
  EXPECT_EQ(Mat4::scaling({0, 1, 1}).inverted(), Mat4{}) << "singular matrices invert to identity";
}

TEST(Math, PerspectiveMapsNearAndFarToTheDepthRange) {
  const Mat4 p = Mat4::perspective(90, 1, 1, 10);
  const Vec4 nearPoint = p * Vec4{0, 0, -1, 1};
  const Vec4 farPoint = p * Vec4{0, 0, -10, 1};
  EXPECT_NEAR(nearPoint.z / nearPoint.w, -1, 1e-5f);
  EXPECT_NEAR(farPoint.z / farPoint.w, 1, 1e-5f);
}

TEST(Error, CarriesCodeLocationAndContext) {
  const Error e = Error(Errc::kParse, "expected a number", "scene.sce:3:14").withContext("loading scene");
  EXPECT_EQ(e.code(), Errc::kParse);
  EXPECT_EQ(e.describe(), "scene.sce:3:14: loading scene: expected a number");
  EXPECT_EQ(Error(Errc::kIo, "x").at("a.obj").at("b.obj").where(), "a.obj") << "the first location wins";
  Result<int> r = failf(Errc::kNotFound, "no part named '{}'", "wheel");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message(), "no part named 'wheel'");
  EXPECT_EQ(errcName(Errc::kDeviceLost), "device lost");
}

TEST(Image, ComparisonFindsEveryDifferingPixel) {
  Image a = Image::make(4, 4, 4);
  Image b = a;
  b.pixels[5] = 10;                   // pixel 1, channel 1
  b.pixels[std::size_t{4} * 15] = 3;  // pixel 15, channel 0, within tolerance 3
  Image diff;
  const ImageDifference d = compareImages(a, b, 3, &diff);
  EXPECT_TRUE(d.sameShape);
  EXPECT_EQ(d.maxChannelDelta, 10);
  EXPECT_EQ(d.pixelsOverTolerance, 1u);
  EXPECT_EQ(diff.at(1, 0, 0), 255) << "the diff image marks the differing pixel red";
  EXPECT_FALSE(compareImages(a, Image::make(4, 5, 4), 0).sameShape);
}

TEST(Log, SpecSetsCategoryThresholds) {
  static log::Category cat("test-spec");
  ASSERT_TRUE(log::configure("test-spec=error"));
  EXPECT_FALSE(cat.enabled(log::Level::kWarn));
  EXPECT_TRUE(cat.enabled(log::Level::kError));
  ASSERT_TRUE(log::configure("info"));
  EXPECT_TRUE(cat.enabled(log::Level::kInfo));
  EXPECT_FALSE(log::configure("test-spec=loud")) << "unknown level names are reported";
}

TEST(Log, RingKeepsTheNewestRecords) {
  static log::Category cat("test-ring");
  auto ring = std::make_shared<log::RingSink>(3);
  log::addSink(ring);
  log::setStderrEnabled(false);
  for (int i = 0; i < 5; ++i) log::warn(cat, "message {}", i);
  log::info(cat, "quiet");
  log::setStderrEnabled(true);
  log::removeSink(ring);
  const auto all = ring->snapshot();
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].message, "message 3");
  EXPECT_EQ(all[2].message, "quiet");
  EXPECT_EQ(ring->snapshot(log::Level::kWarn).size(), 2u);
}

TEST(Log, OnceIsOnce) {
  log::Once once;
  EXPECT_TRUE(once.first());
  EXPECT_FALSE(once.first());
}

}  // namespace
}  // namespace basalt
