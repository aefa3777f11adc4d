// The default show rendered headless through EGL (Mesa llvmpipe here): golden images of frames
// 0 and 60, bit-exact determinism under a ManualClock, and the lighting that tells the faces
// apart. Skips with the reason when no EGL is available.
// Example failures: a renderer change that shifts colours or geometry; frame n depending on
// anything but n (time, uninitialised memory); a face rendered unlit.

#include <gtest/gtest.h>

#include <memory>
#include <set>

#include "render/output.h"
#include "render/renderer.h"
#include "runtime/show/show.h"
#include "support/golden.h"
#include "support/test_paths.h"

namespace basalt::render {
namespace {

class DefaultShow : public ::testing::Test {
 protected:
  void SetUp() override {
    auto output = createHeadlessOutput({500, 500});
    if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
    output_ = std::move(*output);
    auto renderer = Renderer::create();
    ASSERT_TRUE(renderer) << renderer.error().describe();
    renderer_ = std::move(*renderer);
  }

  /// Renders frame `n` of a fresh default show.
  Image renderFrame(int n) {
    runtime::Show show = runtime::Show::makeDefault();
    for (int i = 0; i < n; ++i) show.advanceFrame();
    EXPECT_TRUE(output_->beginFrame());
    renderer_->draw(show, runtime::computeView(show, 1.0f), output_->size());
    Image image;
    auto r = output_->readBack(image);
    EXPECT_TRUE(r) << (r ? "" : r.error().describe());
    return image;
  }

  std::unique_ptr<Output> output_;
  std::unique_ptr<Renderer> renderer_;
};

TEST_F(DefaultShow, Frame0MatchesGolden) {
  const Image frame = renderFrame(0);
  const std::string problem =
      test::compareWithGolden(frame, test::sourceDir() / "tests/render/golden/default_show_f0.png");
  EXPECT_TRUE(problem.empty()) << problem;
}

TEST_F(DefaultShow, Frame60MatchesGolden) {
  const Image frame = renderFrame(60);
  const std::string problem =
      test::compareWithGolden(frame, test::sourceDir() / "tests/render/golden/default_show_f60.png");
  EXPECT_TRUE(problem.empty()) << problem;
}

TEST_F(DefaultShow, SameFrameSamePixels) {
  const Image a = renderFrame(30);
  const Image b = renderFrame(30);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_TRUE(a.pixels == b.pixels) << "frame 30 rendered twice differs: the show is not deterministic";
  const Image c = renderFrame(31);
  EXPECT_FALSE(a.pixels == c.pixels) << "frame 31 equals frame 30: the cube does not turn";
}

TEST_F(DefaultShow, CubeOnBlackWithLitFaces) {
  const Image f = renderFrame(0);
  // Corners are background: black.
  for (auto [x, y] : {std::pair{0u, 0u}, {499u, 0u}, {0u, 499u}, {499u, 499u}}) {
    EXPECT_EQ(f.at(x, y, 0) + f.at(x, y, 1) + f.at(x, y, 2), 0) << "corner " << x << "," << y;
  }
  // The centre is the cube, lit: neither black nor saturated white.
  const int centre = f.at(250, 250, 0) + f.at(250, 250, 1) + f.at(250, 250, 2);
  EXPECT_GT(centre, 30);
  EXPECT_LT(centre, 3 * 255);
  // Three faces show and the lights tell them apart: count distinct colours on a cross
  // through the centre.
  std::set<std::uint32_t> colours;
  for (std::uint32_t i = 150; i < 350; i += 10) {
    for (auto [x, y] : {std::pair{i, 250u}, {250u, i}}) {
      if (f.at(x, y, 0) + f.at(x, y, 1) + f.at(x, y, 2) == 0) continue;
      colours.insert(std::uint32_t{f.at(x, y, 0)} << 16 | std::uint32_t{f.at(x, y, 1)} << 8 | f.at(x, y, 2));
    }
  }
  EXPECT_GE(colours.size(), 3u) << "fewer than three differently lit faces visible";
}

}  // namespace
}  // namespace basalt::render
