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

TEST_P(StreamLayouts, ConvertsToTheRightColours) {
  const LayoutCase& c = GetParam();
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(c.format, c.colorimetry, pool);
  auto changed = stream_->update(frame);
  ASSERT_TRUE(changed) << changed.error().describe();
  EXPECT_TRUE(*changed);
  EXPECT_EQ(stream_->uploadPath(), UploadPath::kPlanes);
  const bool asIs = c.format == PixelFormat::kRgba8;
  EXPECT_NE(stream_->describe().find(asIs ? "uploaded as is" : "converted in the shader"), std::string::npos)
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

TEST_P(StreamLayouts, AMirroredStreamShowsTheBandsRightToLeft) {
  const LayoutCase& c = GetParam();
  std::shared_ptr<FramePool> pool;
  FrameRef frame = bandFrame(c.format, c.colorimetry, pool);
  stream_->setMirror(true);
  ASSERT_TRUE(stream_->update(frame));
  EXPECT_NE(stream_->describe().find("mirrored"), std::string::npos) << stream_->describe();
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
  ASSERT_TRUE(stream_->readPixels(out));
  EXPECT_NEAR(out.at(kWidth / 8, kHeight / 2, 1), kBands.front().g * 255, 3);
}

constexpr Colorimetry k601Limited{Colorimetry::Matrix::kBt601, Colorimetry::Range::kLimited};
constexpr Colorimetry k709Limited{Colorimetry::Matrix::kBt709, Colorimetry::Range::kLimited};
constexpr Colorimetry k709Full{Colorimetry::Matrix::kBt709, Colorimetry::Range::kFull};
constexpr Colorimetry k601Full{Colorimetry::Matrix::kBt601, Colorimetry::Range::kFull};
constexpr Colorimetry k2020Limited{Colorimetry::Matrix::kBt2020, Colorimetry::Range::kLimited};

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
  // Read back, a picture-only stream converts on demand: the same texture as the other.
  Image a, b;
  ASSERT_TRUE(stream_->readPixels(a));
  ASSERT_TRUE((*direct)->readPixels(b));
  EXPECT_EQ(compareImages(a, b, 0).pixelsOverTolerance, 0u);
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

}  // namespace
}  // namespace basalt::render
