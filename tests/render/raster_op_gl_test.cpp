// LAVA's sixteen raster operations (render.raster_op) on OpenGL ES, which has no logic ops:
// each one drawn over a known background and compared with the operation computed here on the
// 8-bit channels, both where the GL offers framebuffer fetch (exact) and where it does not (the
// destination read from a copy of the frame). The copy path must say so, once per operation.
// Example failures: and_reverse and and_inverted swapped; a result off by one from float rounding;
// the warning repeated every frame, or missing.

#include <gtest/gtest.h>

#include "render/attribute_tables.h"
#include "runtime/log.h"
#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using runtime::PartStyle;
using runtime::RasterOp;
using runtime::Show;

constexpr std::uint8_t kDst[3] = {0x5A, 0xC3, 0x0F};
constexpr std::uint8_t kSrc[3] = {0x3C, 0x96, 0xF0};

Show rasterScene(RasterOp op) {
  Show show = showOf(makeQuad(0.5f, 0.0f, 1));
  show.global().background = {kDst[0] / 255.0f, kDst[1] / 255.0f, kDst[2] / 255.0f};
  show.editGlobalStyle([&](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {kSrc[0] / 255.0f, kSrc[1] / 255.0f, kSrc[2] / 255.0f};
    s.render.rasterOp = op;
  });
  return show;
}

constexpr RasterOp kAllOps[] = {RasterOp::kClear,  RasterOp::kSet, RasterOp::kCopy,       RasterOp::kCopyInverted,
                                RasterOp::kInvert, RasterOp::kAnd, RasterOp::kAndReverse, RasterOp::kAndInverted,
                                RasterOp::kNand,   RasterOp::kOr,  RasterOp::kOrReverse,  RasterOp::kOrInverted,
                                RasterOp::kNor,    RasterOp::kXor, RasterOp::kEquiv,      RasterOp::kNoop};

class RasterOps : public RenderTest {
 protected:
  /// Draws each of the sixteen operations and compares the centre pixel with the table.
  void checkAll(render::Renderer& r) {
    for (const RasterOp op : kAllOps) {
      SCOPED_TRACE(std::string(render::rasterOpName(op)));
      const Show show = rasterScene(op);
      ASSERT_TRUE(output().beginFrame());
      r.draw(show, testCamera(), output().size());
      Image image;
      ASSERT_TRUE(output().readBack(image));
      for (std::uint32_t c = 0; c < 3; ++c) {
        EXPECT_EQ(image.at(128, 128, c), render::applyRasterOp(op, kSrc[c], kDst[c])) << "channel " << c;
        EXPECT_EQ(image.at(5, 5, c), kDst[c]) << "the background must stay";
      }
    }
  }
};

TEST_F(RasterOps, ExactWithFramebufferFetch) {
  if (!renderer().capabilities().framebufferFetch) {
    GTEST_SKIP() << "this GL has no GL_EXT_shader_framebuffer_fetch; ExactFromACopyOfTheFrame covers the operations";
  }
  checkAll(renderer());
}

TEST_F(RasterOps, ExactFromACopyOfTheFrame) {
  auto noFetch = render::Renderer::create({.allowFramebufferFetch = false});
  ASSERT_TRUE(noFetch) << noFetch.error().describe();
  ASSERT_FALSE((*noFetch)->capabilities().framebufferFetch);
  checkAll(**noFetch);
}

TEST(RasterOpTable, MatchesTheXglDefinitions) {
  // Spot checks against X11/XGL truth tables on single bits.
  EXPECT_EQ(render::applyRasterOp(RasterOp::kAndReverse, 0xF0, 0xCC), 0xF0 & ~0xCC & 0xFF);
  EXPECT_EQ(render::applyRasterOp(RasterOp::kAndInverted, 0xF0, 0xCC), ~0xF0 & 0xCC & 0xFF);
  EXPECT_EQ(render::applyRasterOp(RasterOp::kOrReverse, 0xF0, 0xCC), (0xF0 | ~0xCC) & 0xFF);
  EXPECT_EQ(render::applyRasterOp(RasterOp::kOrInverted, 0xF0, 0xCC), (~0xF0 | 0xCC) & 0xFF);
  EXPECT_EQ(render::applyRasterOp(RasterOp::kEquiv, 0xF0, 0xCC), ~(0xF0 ^ 0xCC) & 0xFF);
  EXPECT_EQ(render::applyRasterOp(RasterOp::kNoop, 0xF0, 0xCC), 0xCC);
  EXPECT_EQ(render::rasterOpName(RasterOp::kAndInverted), "and_inv");
}

class RasterOpWarning : public RenderTest {};

TEST_F(RasterOpWarning, CopyPathWarnsOncePerOperation) {
  auto r = render::Renderer::create({.allowFramebufferFetch = false});
  ASSERT_TRUE(r) << r.error().describe();
  auto ring = std::make_shared<log::RingSink>(64);
  log::addSink(ring);
  for (int frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(output().beginFrame());
    (*r)->draw(rasterScene(RasterOp::kXor), testCamera(), output().size());
    (*r)->draw(rasterScene(RasterOp::kCopy), testCamera(), output().size());
  }
  log::removeSink(ring);
  int xorWarnings = 0, other = 0;
  for (const log::Record& rec : ring->snapshot(log::Level::kWarn)) {
    if (rec.message.find("render.raster_op = xor") != std::string::npos) {
      ++xorWarnings;
    } else if (rec.message.find("raster_op") != std::string::npos) {
      ++other;
    }
  }
  EXPECT_EQ(xorWarnings, 1) << "the copy path is announced once, naming the operation";
  EXPECT_EQ(other, 0) << "copy needs no warning";
}

}  // namespace
}  // namespace basalt::test
