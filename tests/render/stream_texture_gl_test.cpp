// Stream textures on headless EGL (Mesa llvmpipe here): every YUV and RGB layout the decoders
// and cameras produce (I420, YV12, NV12, NV21, YUYV, UYVY, RGBA, BGRA, GRAY8) is uploaded as
// planes and converted in the shader with the stream's colorimetry (BT.601/709/2020, limited and
// full range) to the right colours; a frame is converted once however often it is offered; the
// fallback shows when a source fails; the dmabuf path says why it is not taken here; a
// mirrored stream (a camera that cannot flip in the device) shows every layout right to left.
// Example failures: U and V swapped (YV12, NV21), a wrong matrix (BT.601 used for HD), limited
// range shown as full (washed-out black), odd strides shearing the picture, packed 4:2:2
// showing every pixel twice, a conversion per part instead of per frame, a mirror that swaps the
// two pixels of a packed 4:2:2 texel wrongly or is ignored for RGBA.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <utility>

#include "render/egl.h"
#include "render/gl.h"
#include "render/output.h"
#include "render/stream_texture.h"
#include "render/texture_registry.h"
#include "runtime/frame.h"

namespace basalt::render {
namespace {

struct Rgb {
  double r, g, b;
};
constexpr std::array<Rgb, 4> kBands = {Rgb{1, 0, 0}, Rgb{0, 1, 0}, Rgb{0, 0, 1}, Rgb{0.5, 0.25, 0.75}};
constexpr std::uint32_t kWidth = 64, kHeight = 32;
constexpr Colorimetry k601Limited{Colorimetry::Matrix::kBt601, Colorimetry::Range::kLimited};
constexpr Colorimetry k709Limited{Colorimetry::Matrix::kBt709, Colorimetry::Range::kLimited};
constexpr Colorimetry k709Full{Colorimetry::Matrix::kBt709, Colorimetry::Range::kFull};
constexpr Colorimetry k601Full{Colorimetry::Matrix::kBt601, Colorimetry::Range::kFull};
constexpr Colorimetry k2020Limited{Colorimetry::Matrix::kBt2020, Colorimetry::Range::kLimited};

/// Reference RGB -> YUV (8-bit) for a colorimetry, computed independently of the shader.
std::array<int, 3> toYuv(Rgb c, const Colorimetry& m) {
  double kr = 0.299, kb = 0.114;
  if (m.matrix == Colorimetry::Matrix::kBt709) kr = 0.2126, kb = 0.0722;
  if (m.matrix == Colorimetry::Matrix::kBt2020) kr = 0.2627, kb = 0.0593;
  const double y = kr * c.r + (1 - kr - kb) * c.g + kb * c.b;
  const double u = (c.b - y) / (2 * (1 - kb)), v = (c.r - y) / (2 * (1 - kr));
  const bool limited = m.range == Colorimetry::Range::kLimited;
  auto q = [](double x) { return static_cast<int>(std::lround(std::clamp(x, 0.0, 255.0))); };
  return limited ? std::array<int, 3>{q(16 + 219 * y), q(128 + 224 * u), q(128 + 224 * v)}
                 : std::array<int, 3>{q(255 * y), q(128 + 255 * u), q(128 + 255 * v)};
}

/// A frame of four vertical colour bands in `format`, rows padded to 64 bytes.
FrameRef bandFrame(PixelFormat format, const Colorimetry& m, std::shared_ptr<FramePool>& pool) {
  pool = FramePool::create({format, kWidth, kHeight, 1, 64, true});
  FrameRef f = pool->acquire();
  f->colorimetry = m;
  for (std::uint32_t y = 0; y < kHeight; ++y) {
    for (std::uint32_t x = 0; x < kWidth; ++x) {
      const Rgb c = kBands[x * 4 / kWidth];
      const auto yuv = toYuv(c, m);
      auto px = [&](int plane, std::uint32_t col, std::uint32_t row) -> std::uint8_t* {
        const Plane& p = f->planes[static_cast<std::size_t>(plane)];
        return p.data + std::size_t{p.stride} * row + col;
      };
      const auto Y = static_cast<std::uint8_t>(yuv[0]), U = static_cast<std::uint8_t>(yuv[1]),
                 V = static_cast<std::uint8_t>(yuv[2]);
      const auto R = static_cast<std::uint8_t>(std::lround(c.r * 255)),
                 G = static_cast<std::uint8_t>(std::lround(c.g * 255)),
                 B = static_cast<std::uint8_t>(std::lround(c.b * 255));
      switch (format) {
        case PixelFormat::kI420:
        case PixelFormat::kYv12: {
          *px(0, x, y) = Y;
          const int uPlane = format == PixelFormat::kI420 ? 1 : 2;
          *px(uPlane, x / 2, y / 2) = U;
          *px(3 - uPlane, x / 2, y / 2) = V;
          break;
        }
        case PixelFormat::kNv12:
        case PixelFormat::kNv21:
          *px(0, x, y) = Y;
          *px(1, x / 2 * 2, y / 2) = format == PixelFormat::kNv12 ? U : V;
          *px(1, x / 2 * 2 + 1, y / 2) = format == PixelFormat::kNv12 ? V : U;
          break;
        case PixelFormat::kYuyv:
          *px(0, x * 2, y) = Y;
          *px(0, x / 2 * 4 + 1, y) = U;
          *px(0, x / 2 * 4 + 3, y) = V;
          break;
        case PixelFormat::kUyvy:
          *px(0, x * 2 + 1, y) = Y;
          *px(0, x / 2 * 4, y) = U;
          *px(0, x / 2 * 4 + 2, y) = V;
          break;
        case PixelFormat::kRgba8:
        case PixelFormat::kBgra8: {
          std::uint8_t* p = px(0, x * 4, y);
          p[0] = format == PixelFormat::kRgba8 ? R : B;
          p[1] = G;
          p[2] = format == PixelFormat::kRgba8 ? B : R;
          p[3] = 255;
          break;
        }
        case PixelFormat::kGray8: *px(0, x, y) = G; break;
        default: break;
      }
    }
  }
  f->sequence = 1;
  f->pts = Nanos{1};
  return f;
}

class StreamTextures : public ::testing::Test {
 protected:
  void SetUp() override {
    auto output = createHeadlessOutput({64, 64});
    if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
    output_ = std::move(*output);
    auto stream = StreamTexture::create("movie");
    ASSERT_TRUE(stream) << stream.error().describe();
    stream_ = std::move(*stream);
  }
  std::unique_ptr<Output> output_;
  std::unique_ptr<StreamTexture> stream_;
};

struct LayoutCase {
  PixelFormat format;
  Colorimetry colorimetry;
};

class StreamLayouts : public StreamTextures, public ::testing::WithParamInterface<LayoutCase> {};

bool fourTwoZero(PixelFormat f) {
  return f == PixelFormat::kI420 || f == PixelFormat::kYv12 || f == PixelFormat::kNv12 || f == PixelFormat::kNv21;
}

TEST_P(StreamLayouts, ConvertsToTheRightColours) {
  const LayoutCase& c = GetParam();
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(c.format, c.colorimetry, pool);
  // Both passes: one fragment a pixel, and eight (4:2:0 layouts only; the others ignore it).
  for (const ConversionPass pass : {ConversionPass::kPerPixel, ConversionPass::kPacked}) {
    const bool packed = pass == ConversionPass::kPacked;
    SCOPED_TRACE(packed ? "packed pass" : "per-pixel pass");
    stream_->setConversionPass(pass);
    frame->sequence = packed ? 2 : 1;
    auto changed = stream_->update(frame);
    ASSERT_TRUE(changed) << changed.error().describe();
    EXPECT_TRUE(*changed);
    EXPECT_EQ(stream_->uploadPath(), UploadPath::kPlanes);
    EXPECT_EQ(stream_->packedConversion(), packed && fourTwoZero(c.format));
    EXPECT_EQ(stream_->view().bottomUp, stream_->packedConversion()) << "the packed pass stores rows bottom first";
    const bool asIs = c.format == PixelFormat::kRgba8;
    EXPECT_NE(stream_->describe().find(asIs ? "uploaded as is" : "converted in the shader"), std::string::npos)
        << stream_->describe();
    EXPECT_EQ(stream_->describe().find("eight pixels a fragment") != std::string::npos, stream_->packedConversion())
        << stream_->describe();
    Image out;
    ASSERT_TRUE(stream_->readPixels(out));
    ASSERT_EQ(out.width, kWidth);
    for (std::size_t band = 0; band < kBands.size(); ++band) {
      const auto x = static_cast<std::uint32_t>(band * kWidth / 4 + kWidth / 8);
      for (std::uint32_t y : {1u, kHeight / 2, kHeight - 2}) {
        const Rgb want = kBands[band];
        const bool gray = c.format == PixelFormat::kGray8;
        const double wr = gray ? want.g : want.r, wg = want.g, wb = gray ? want.g : want.b;
        EXPECT_NEAR(out.at(x, y, 0), wr * 255, 3) << "band " << band << " row " << y << " red";
        EXPECT_NEAR(out.at(x, y, 1), wg * 255, 3) << "band " << band << " row " << y << " green";
        EXPECT_NEAR(out.at(x, y, 2), wb * 255, 3) << "band " << band << " row " << y << " blue";
      }
    }
  }
}

TEST_P(StreamLayouts, AMirroredStreamShowsTheBandsRightToLeft) {
  const LayoutCase& c = GetParam();
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(c.format, c.colorimetry, pool);
  stream_->setConversionPass(ConversionPass::kPacked);
  stream_->setMirror(true);
  ASSERT_TRUE(stream_->update(frame));
  EXPECT_NE(stream_->describe().find("mirrored"), std::string::npos) << stream_->describe();
  EXPECT_FALSE(stream_->packedConversion()) << "a mirrored stream takes the per-pixel pass";
  Image out;
  ASSERT_TRUE(stream_->readPixels(out));
  const bool gray = c.format == PixelFormat::kGray8;
  for (std::size_t band = 0; band < kBands.size(); ++band) {
    const auto x = static_cast<std::uint32_t>(band * kWidth / 4 + kWidth / 8);
    const Rgb want = kBands[kBands.size() - 1 - band];
    EXPECT_NEAR(out.at(x, kHeight / 2, 0), (gray ? want.g : want.r) * 255, 3) << "band " << band;
    EXPECT_NEAR(out.at(x, kHeight / 2, 1), want.g * 255, 3) << "band " << band;
    EXPECT_NEAR(out.at(x, kHeight / 2, 2), (gray ? want.g : want.b) * 255, 3) << "band " << band;
  }
  // The edge columns swap exactly (no half-pixel shift): column 0 shows the frame's last one.
  EXPECT_NEAR(out.at(0, 1, 1), kBands.back().g * 255, 3);
  // Mirror off again: the same frame is converted again, the right way round.
  stream_->setMirror(false);
  ASSERT_TRUE(stream_->update(frame));
  EXPECT_EQ(stream_->conversions(), 2u);
  EXPECT_EQ(stream_->packedConversion(), fourTwoZero(c.format));
  ASSERT_TRUE(stream_->readPixels(out));
  EXPECT_NEAR(out.at(kWidth / 8, kHeight / 2, 1), kBands.front().g * 255, 3);
}

// The packed pass gives the per-pixel pass's picture, pixel for pixel (within a rounding step),
// on a frame whose every sample differs from its neighbours: width not a multiple of four (the
// last fragment reads past the picture into the row padding), every 4:2:0 layout. An odd height
// takes the per-pixel pass. Example failures: even and odd rows swapped or the picture upside
// down after the copy through the pixel buffer; chroma taken from the wrong half of a texel or
// the wrong row pair; U and V swapped for YV12 or NV21.
class PackedPass : public StreamTextures, public ::testing::WithParamInterface<PixelFormat> {
 protected:
  static FrameRef noiseFrame(PixelFormat format, std::uint32_t width, std::uint32_t height,
                             std::shared_ptr<FramePool>& pool) {
    pool = FramePool::create({format, width, height, 1, 64, true});
    FrameRef f = pool->acquire();
    f->colorimetry = k709Limited;
    std::uint32_t state = 12345;
    for (int p = 0; p < f->planeCount; ++p) {
      Plane& plane = f->planes[static_cast<std::size_t>(p)];
      for (std::size_t i = 0; i < plane.size; ++i) {
        state = state * 1664525u + 1013904223u;
        plane.data[i] = static_cast<std::uint8_t>(16 + (state >> 24) % 224);
      }
    }
    // Frames of one test may reuse one address: the size tells them apart.
    f->sequence = std::uint64_t{width} * 1000 + height;
    f->pts = Nanos{1};
    return f;
  }
};

TEST_P(PackedPass, GivesThePerPixelPicture) {
  for (const auto& [width, height] : {std::pair{64u, 32u}, std::pair{66u, 18u}, std::pair{30u, 10u}}) {
    SCOPED_TRACE(testing::Message() << width << "x" << height);
    std::shared_ptr<FramePool> pool;
    FrameRef frame = noiseFrame(GetParam(), width, height, pool);
    auto reference = StreamTexture::create("reference");
    ASSERT_TRUE(reference);
    (*reference)->setConversionPass(ConversionPass::kPerPixel);
    stream_->setConversionPass(ConversionPass::kPacked);
    ASSERT_TRUE((*reference)->update(frame));
    ASSERT_TRUE(stream_->update(frame));
    EXPECT_TRUE(stream_->packedConversion());
    EXPECT_FALSE((*reference)->packedConversion());
    Image want, got;
    ASSERT_TRUE((*reference)->readPixels(want));
    ASSERT_TRUE(stream_->readPixels(got));
    const ImageDifference d = compareImages(got, want, 1);
    EXPECT_TRUE(d.sameShape);
    EXPECT_EQ(d.pixelsOverTolerance, 0u) << "max delta " << d.maxChannelDelta;
  }
  // An odd height: the per-pixel pass, the right way up.
  std::shared_ptr<FramePool> pool;
  FrameRef odd = bandFrame(GetParam(), k601Limited, pool);
  std::shared_ptr<FramePool> oddPool;
  FrameRef oddFrame = noiseFrame(GetParam(), 64, 31, oddPool);
  stream_->setConversionPass(ConversionPass::kPacked);
  ASSERT_TRUE(stream_->update(oddFrame));
  EXPECT_FALSE(stream_->packedConversion());
  EXPECT_FALSE(stream_->view().bottomUp);
  ASSERT_TRUE(stream_->update(odd));
  Image bands;
  ASSERT_TRUE(stream_->readPixels(bands));
  EXPECT_GT(bands.at(kWidth / 8, 1, 0), 200) << "red at the top left";
}

INSTANTIATE_TEST_SUITE_P(FourTwoZero, PackedPass,
                         ::testing::Values(PixelFormat::kI420, PixelFormat::kYv12, PixelFormat::kNv12,
                                           PixelFormat::kNv21),
                         [](const ::testing::TestParamInfo<PixelFormat>& p) {
                           return std::string(pixelFormatName(p.param));
                         });

INSTANTIATE_TEST_SUITE_P(
    Formats, StreamLayouts,
    ::testing::Values(LayoutCase{PixelFormat::kI420, k601Limited}, LayoutCase{PixelFormat::kI420, k709Limited},
                      LayoutCase{PixelFormat::kI420, k709Full}, LayoutCase{PixelFormat::kI420, k2020Limited},
                      LayoutCase{PixelFormat::kYv12, k601Limited}, LayoutCase{PixelFormat::kNv12, k709Limited},
                      LayoutCase{PixelFormat::kNv12, k601Full}, LayoutCase{PixelFormat::kNv21, k601Limited},
                      LayoutCase{PixelFormat::kYuyv, k601Limited}, LayoutCase{PixelFormat::kYuyv, k709Full},
                      LayoutCase{PixelFormat::kUyvy, k709Limited}, LayoutCase{PixelFormat::kRgba8, k601Limited},
                      LayoutCase{PixelFormat::kBgra8, k601Limited}, LayoutCase{PixelFormat::kGray8, k601Full}),
    [](const ::testing::TestParamInfo<LayoutCase>& p) {
      std::string name(pixelFormatName(p.param.format));
      name += p.param.colorimetry.matrix == Colorimetry::Matrix::kBt709    ? "_709"
              : p.param.colorimetry.matrix == Colorimetry::Matrix::kBt2020 ? "_2020"
                                                                           : "_601";
      name += p.param.colorimetry.range == Colorimetry::Range::kFull ? "_full" : "_limited";
      return name;
    });

TEST_F(StreamTextures, ConvertsOncePerNewFrameAndPublishesByName) {
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(PixelFormat::kI420, k601Limited, pool);
  TextureRegistry registry;
  ASSERT_TRUE(stream_->update(frame));
  stream_->publish(registry);
  const TextureView* view = registry.find("movie");
  ASSERT_NE(view, nullptr);
  EXPECT_EQ(view->id, stream_->view().id);
  EXPECT_EQ(view->size, (Size{kWidth, kHeight}));
  const std::uint64_t generation = view->generation;
  // Several parts (or views, or eyes) ask for the same frame: no new conversion.
  for (int part = 0; part < 5; ++part) {
    auto changed = stream_->update(frame);
    ASSERT_TRUE(changed);
    EXPECT_FALSE(*changed);
  }
  EXPECT_EQ(stream_->conversions(), 1u);
  stream_->publish(registry);
  EXPECT_EQ(registry.find("movie")->generation, generation);
  // An empty ref (no new frame due) keeps the picture.
  EXPECT_FALSE(*stream_->update(FrameRef{}));
  EXPECT_EQ(stream_->conversions(), 1u);
}

TEST_F(StreamTextures, FallbackShowsWhenTheSourceFails) {
  stream_->setFallbackColor(1.0f, 0.0f, 1.0f);
  EXPECT_TRUE(stream_->showingFallback());
  std::shared_ptr<FramePool> pool;
  ASSERT_TRUE(stream_->update(bandFrame(PixelFormat::kNv12, k601Limited, pool)));
  EXPECT_FALSE(stream_->showingFallback());
  stream_->showFallback();
  Image out;
  ASSERT_TRUE(stream_->readPixels(out));
  EXPECT_EQ(out.at(5, 5, 0), 255);
  EXPECT_EQ(out.at(5, 5, 1), 0);
  EXPECT_EQ(out.at(5, 5, 2), 255);
}

TEST_F(StreamTextures, CompressedFramesAreRefusedWithAMessage) {
  auto pool = FramePool::create({PixelFormat::kMjpeg, 16, 16, 1, 1, true});
  auto r = stream_->update(pool->acquire());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("MJPEG"), std::string::npos) << r.error().message();
}

TEST_F(StreamTextures, DmabufImportWhereEglOffersIt) {
  if (!stream_->dmabufImportOffered()) {
    GTEST_SKIP() << "this EGL (Mesa's surfaceless llvmpipe here) does not offer EGL_EXT_image_dma_buf_import; "
                    "frames are uploaded as planes instead";
  }
  GTEST_SKIP() << "EGL offers dmabuf import, but no dmabuf exporter (udmabuf, a camera) is available to this test";
}

// The Zoom picture drawn straight from the planes (a picture-only stream: one pass, no RGBA
// texture in between) looks like the picture drawn through the converted texture, for every
// planar layout, mirrored or not, at its own size and scaled; layouts it cannot draw that way,
// and translucent pictures, take the texture path. Example failures: the picture upside down or
// U and V swapped on the one-pass path; a picture-only stream whose texture is read back stale.
class DirectPictures : public StreamTextures, public ::testing::WithParamInterface<LayoutCase> {
 protected:
  Image drawn(StreamTexture& stream, PictureOverlay& overlay, const PictureRect& rect) {
    EXPECT_TRUE(output_->beginFrame());
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    stream.drawPicture(overlay, rect, output_->size());
    Image image;
    EXPECT_TRUE(output_->readBack(image));
    return image;
  }
};

TEST_P(DirectPictures, LookLikeThePictureThroughTheTexture) {
  const LayoutCase& c = GetParam();
  auto overlay = PictureOverlay::create();
  ASSERT_TRUE(overlay) << overlay.error().describe();
  auto direct = StreamTexture::create("direct");
  ASSERT_TRUE(direct);
  (*direct)->setPictureOnly(true);
  // The one-pass picture belongs to the per-pixel pass (the packed pass converts at update());
  // the reference takes the packed pass, so each is checked against the other.
  (*direct)->setConversionPass(ConversionPass::kPerPixel);
  stream_->setConversionPass(ConversionPass::kPacked);
  for (const bool mirrored : {false, true}) {
    SCOPED_TRACE(mirrored ? "mirrored" : "as is");
    stream_->setMirror(mirrored);
    (*direct)->setMirror(mirrored);
    std::shared_ptr<FramePool> pool;
    FrameRef frame = bandFrame(c.format, c.colorimetry, pool);
    frame->sequence = mirrored ? 2 : 1;
    ASSERT_TRUE(stream_->update(frame));
    ASSERT_TRUE((*direct)->update(frame));
    for (const PictureRect rect : {PictureRect{0, 16, 64, 32}, PictureRect{8, 4, 40, 52}}) {
      const std::uint64_t before = (*direct)->directPictures();
      const Image reference = drawn(*stream_, **overlay, rect);
      const Image oneResult = drawn(**direct, **overlay, rect);
      EXPECT_EQ((*direct)->directPictures(), before + 1) << "drawn from the planes";
      if (rect.width == kWidth && rect.height == kHeight) {
        // At its own size: texel by texel, the same picture.
        const ImageDifference d = compareImages(oneResult, reference, 6);
        EXPECT_LE(d.pixelsOverTolerance, 8u) << "max delta " << d.maxChannelDelta;
      } else {
        // Scaled, the planes are filtered before the conversion (the texture path filters after
        // it): the edges of the bands blend differently; the middle of each band is the same.
        for (int band = 0; band < 4; ++band) {
          const auto bx = static_cast<std::uint32_t>(rect.x + rect.width * (static_cast<float>(band) + 0.5f) / 4);
          const auto top = static_cast<std::uint32_t>(rect.y),
                     bottom = static_cast<std::uint32_t>(rect.y + rect.height);
          for (std::uint32_t by = top + 1; by + 1 < bottom; ++by) {
            for (std::uint32_t ch = 0; ch < 3; ++ch) {
              ASSERT_NEAR(oneResult.at(bx, by, ch), reference.at(bx, by, ch), 6) << "band " << band << " row " << by;
            }
          }
        }
      }
      // The bands run left to right (right to left mirrored): red at the left edge as is.
      const auto x = static_cast<std::uint32_t>(rect.x + 2), y = static_cast<std::uint32_t>(rect.y + rect.height / 2);
      if (mirrored) {
        EXPECT_LT(oneResult.at(x, y, 0), 200) << "mirrored: the left edge is not red";
      } else {
        EXPECT_GT(oneResult.at(x, y, 0), 200) << "the left edge is red";
        EXPECT_LT(oneResult.at(x, y, 1), 60);
      }
    }
  }
  EXPECT_EQ((*direct)->conversions(), 2u) << "frames counted as shown";
  // Read back, a picture-only stream converts on demand: the same texture as the other (within
  // a rounding step: the other took the packed pass).
  Image a, b;
  ASSERT_TRUE(stream_->readPixels(a));
  ASSERT_TRUE((*direct)->readPixels(b));
  EXPECT_EQ(compareImages(a, b, 1).pixelsOverTolerance, 0u);
}

INSTANTIATE_TEST_SUITE_P(
    Planar, DirectPictures,
    ::testing::Values(LayoutCase{PixelFormat::kI420, k709Limited}, LayoutCase{PixelFormat::kYv12, k601Limited},
                      LayoutCase{PixelFormat::kNv12, k601Full}, LayoutCase{PixelFormat::kNv21, k601Limited}),
    [](const ::testing::TestParamInfo<LayoutCase>& p) { return std::string(pixelFormatName(p.param.format)); });

TEST_F(StreamTextures, PackedLayoutsAndTranslucentPicturesTakeTheTexturePath) {
  auto overlay = PictureOverlay::create();
  ASSERT_TRUE(overlay);
  stream_->setPictureOnly(true);
  stream_->setConversionPass(ConversionPass::kPerPixel);
  std::shared_ptr<FramePool> pool;
  FrameRef packed = bandFrame(PixelFormat::kYuyv, k601Limited, pool);
  ASSERT_TRUE(stream_->update(packed));
  ASSERT_TRUE(output_->beginFrame());
  stream_->drawPicture(**overlay, {0, 0, 64, 64}, output_->size());
  EXPECT_EQ(stream_->directPictures(), 0u) << "YUYV is converted, then drawn as a texture";
  std::shared_ptr<FramePool> pool2;
  FrameRef planar = bandFrame(PixelFormat::kI420, k601Limited, pool2);
  planar->sequence = 7;
  ASSERT_TRUE(stream_->update(planar));
  stream_->drawPicture(**overlay, {0, 0, 64, 64}, output_->size(), 0.5f);
  EXPECT_EQ(stream_->directPictures(), 0u) << "a translucent picture blends the texture";
  Image image;
  ASSERT_TRUE(output_->readBack(image));
  EXPECT_GT(image.at(2, 32, 0), 60) << "the translucent picture was drawn";
}

// An opaque picture at the texture's own size is copied into the output by a framebuffer blit,
// from a texture stored either way up, and looks as the same picture drawn as a quad; a picture
// that is scaled, translucent or reaches past the output is drawn. Example failures: the blit
// upside down for one of the two row orders; the picture a row off its place.
TEST_F(StreamTextures, PicturesAtTheirOwnSizeAreCopiedAndLookTheSame) {
  auto overlay = PictureOverlay::create();
  ASSERT_TRUE(overlay);
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(PixelFormat::kI420, k709Limited, pool);
  auto picture = [&](auto draw) {
    EXPECT_TRUE(output_->beginFrame());
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    draw();
    Image image;
    EXPECT_TRUE(output_->readBack(image));
    return image;
  };
  for (const ConversionPass pass : {ConversionPass::kPerPixel, ConversionPass::kPacked}) {
    SCOPED_TRACE(pass == ConversionPass::kPacked ? "packed pass (bottom row first)" : "per-pixel pass (top row first)");
    stream_->setConversionPass(pass);
    frame->sequence += 1;
    ASSERT_TRUE(stream_->update(frame));
    EXPECT_EQ(stream_->view().bottomUp, pass == ConversionPass::kPacked);
    const PictureRect rect{0, 20, 64, 32};
    const std::uint64_t before = stream_->blitPictures();
    const Image copied = picture([&] { stream_->drawPicture(**overlay, rect, output_->size()); });
    EXPECT_EQ(stream_->blitPictures(), before + 1) << "copied, not drawn";
    const Image drawn = picture([&] { (*overlay)->draw(stream_->view(), rect, output_->size()); });
    const ImageDifference d = compareImages(copied, drawn, 0);
    EXPECT_EQ(d.pixelsOverTolerance, 0u) << "max delta " << d.maxChannelDelta;
    EXPECT_GT(copied.at(2, 21, 0), 200) << "red at the picture's top left";
    EXPECT_EQ(copied.at(2, 19, 0), 0) << "nothing above the picture";
    EXPECT_EQ(copied.at(2, 52, 0), 0) << "nothing below the picture";
    // Scaled, translucent or past the edge: drawn.
    stream_->drawPicture(**overlay, {0, 0, 32, 16}, output_->size());
    stream_->drawPicture(**overlay, rect, output_->size(), 0.5f);
    stream_->drawPicture(**overlay, {40, 20, 64, 32}, output_->size());
    EXPECT_EQ(stream_->blitPictures(), before + 1);
  }
}

// Stream textures and picture overlays made in one context share its programs: a movie item that
// starts again (a new stream texture and overlay each time) compiles nothing; a new context
// compiles its own.
// Example failure: every item start compiling the conversion again (tens of milliseconds of a
// software renderer's JIT, a hitch at every start, and its memory coming and going).
TEST_F(StreamTextures, StreamsInOneContextCompileTheConversionOnce) {
  EglContext* context = EglContext::current();
  ASSERT_NE(context, nullptr) << "the headless output's context is current";
  const std::string key =
      stream_->conversionPass() == ConversionPass::kPacked ? "stream_texture.yuv.3.packed" : "stream_texture.yuv.3";
  const std::uint32_t program = context->keptProgram(key);
  EXPECT_NE(program, 0u) << key;
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(PixelFormat::kI420, k601Limited, pool);
  for (int item = 0; item < 3; ++item) {
    auto again = StreamTexture::create("item");
    ASSERT_TRUE(again);
    frame->sequence = static_cast<std::uint64_t>(item + 1);
    ASSERT_TRUE((*again)->update(frame));
    Image out;
    ASSERT_TRUE((*again)->readPixels(out));
    EXPECT_GT(out.at(2, 2, 0), 200) << "red at the left";
    EXPECT_EQ(context->keptProgram(key), program) << "compiled again";
  }
  // Picture overlays (a movie item makes one each time it starts) share theirs too.
  auto first = PictureOverlay::create();
  ASSERT_TRUE(first);
  const std::uint32_t picture = context->keptProgram("stream_texture.picture");
  EXPECT_NE(picture, 0u);
  auto second = PictureOverlay::create();
  ASSERT_TRUE(second);
  EXPECT_EQ(context->keptProgram("stream_texture.picture"), picture) << "compiled again";
  first->reset();
  second->reset();
  // Another context: its own programs.
  stream_.reset();
  output_.reset();
  EXPECT_EQ(EglContext::current(), nullptr);
  auto other = createHeadlessOutput({16, 16});
  ASSERT_TRUE(other);
  ASSERT_NE(EglContext::current(), nullptr);
  EXPECT_EQ(EglContext::current()->keptProgram(key), 0u);
  auto fresh = StreamTexture::create("fresh");
  ASSERT_TRUE(fresh);
  EXPECT_NE(EglContext::current()->keptProgram(key), 0u);
}

}  // namespace
}  // namespace basalt::render
