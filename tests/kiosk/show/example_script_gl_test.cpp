// The manual's example motion script (LAVA section 10, "EXAMPLE", tests/runtime/script/scripts/
// example_motion.mdl, verbatim) played headless through the frame loop under a ManualClock:
// 1001 draws are 1001 frames, and chosen frames are checked against the object's position and
// attributes worked out from the manual's text, and against pictures of those states.
// Example failures: a draw that does not end a frame; loops run one pass too few; the
// translate and rotate of a pass applied once per loop instead of once per pass; lines not
// getting fatter; a frame drawn with the state of the next one.

#include <gtest/gtest.h>

#include <cmath>

#include "play_support.h"
#include "runtime/script/interpreter.h"
#include "support/test_paths.h"

namespace basalt::script {
namespace {

using runtime::PrimType;

/// What the manual's text says frame `frame` shows.
struct ExampleState {
  Mat4 local;
  Mat4 global;
  PrimType prim = PrimType::kSolid;
  float width = 1;
};

ExampleState expectedExample(std::int64_t frame) {
  ExampleState s;
  if (frame == 0) return s;  // after both resets, before anything moved
  if (frame <= 600) {
    // Three times: 100 passes moving right 0.002 while turning 1 degree, then 100 turning.
    // Moves and turns are about the same (local X) axis, so they commute.
    const std::int64_t n = frame;
    const std::int64_t moves = (n - 1) / 200 * 100 + std::min<std::int64_t>((n - 1) % 200 + 1, 100);
    s.local = Mat4::translation({0.002f * static_cast<float>(moves), 0, 0}) * Mat4::rotationX(static_cast<float>(n));
    return s;
  }
  // Then five times: 40 passes shrinking by 0.95 while turning 2 degrees, lines one wider,
  // 40 growing by 1.0526, lines one wider again. Uniform scales commute with rotations.
  const std::int64_t m = std::min<std::int64_t>(frame, 1000) - 601;
  const std::int64_t pass = m / 80;
  const std::int64_t within = m % 80;
  const std::int64_t shrinks = pass * 40 + std::min<std::int64_t>(within + 1, 40);
  const std::int64_t grows = pass * 40 + std::max<std::int64_t>(within + 1 - 40, 0);
  const double scale = std::pow(0.95, static_cast<double>(shrinks)) * std::pow(1.0526, static_cast<double>(grows));
  s.global = Mat4::rotationX(2.0f * static_cast<float>(m + 1)) *
             Mat4::scaling({static_cast<float>(scale), static_cast<float>(scale), static_cast<float>(scale)});
  s.prim = PrimType::kWireframe;
  s.width = static_cast<float>(1 + 2 * pass + (within >= 40 ? 1 : 0));
  if (frame > 1000) s.width = 11;  // the last `lines.line_width += 1.0` after the last draw
  return s;
}

void expectNear(const Mat4& actual, const Mat4& expected, std::int64_t frame, const char* which) {
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_NEAR(actual.m[i], expected.m[i], 2e-4f) << which << " matrix, element " << i << ", frame " << frame;
  }
}

/// The expected state built by hand on the start-up show, without the interpreter.
runtime::Show handBuilt(const ExampleState& e) {
  runtime::Show show = startupShow();
  show.position().local = e.local;
  show.position().global = e.global;
  show.editGlobalStyle([&](runtime::PartStyle& s) {
    s.render.primType = e.prim;
    s.lines.width = e.width;
  });
  return show;
}

class ExampleScript : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    stage_ = test::Stage::open({160, 160}, why);
    if (!stage_) GTEST_SKIP() << "no headless EGL here: " << why;
  }
  std::unique_ptr<test::Stage> stage_;
};

TEST_F(ExampleScript, PlaysFrameByFrameAsTheManualDescribes) {
  const std::set<std::int64_t> states = {0,   1,   2,   99,  100, 101, 150, 200, 201,  300,  599,
                                         600, 601, 602, 640, 641, 680, 700, 900, 1000, 1001, 1050};
  const std::set<std::int64_t> images = {0, 150, 600, 700, 1000};
  const auto played =
      stage_->play(basalt::test::sourceDir() / "tests/runtime/script/scripts/example_motion.mdl", 1051, states, images);
  EXPECT_TRUE(played.messages.empty()) << played.messages[0].describe();
  EXPECT_EQ(played.stats.frames, 1051);
  EXPECT_TRUE(played.finished) << "1001 draws, then the script ends and the show goes on";
  EXPECT_FALSE(played.quit);

  for (std::int64_t frame : states) {
    const test::KeptFrame& kept = played.at(frame);
    const ExampleState e = expectedExample(frame);
    expectNear(kept.show.position().local, e.local, frame, "local");
    expectNear(kept.show.position().global, e.global, frame, "global");
    EXPECT_EQ(kept.show.globalStyle().render.primType, e.prim) << "frame " << frame;
    EXPECT_FLOAT_EQ(kept.show.globalStyle().lines.width, e.width) << "frame " << frame;
    if (frame <= 1000) {
      EXPECT_EQ(kept.step.stop, StepStop::kDraw) << "frame " << frame << " is a draw";
    } else {
      EXPECT_EQ(kept.step.stop, StepStop::kEnd) << "frame " << frame << " comes after the script";
    }
  }

  for (std::int64_t frame : images) {
    const Image& picture = played.at(frame).image;
    ASSERT_FALSE(picture.empty()) << "frame " << frame;
    const Image expected = stage_->render(handBuilt(expectedExample(frame)));
    const ImageDifference d = compareImages(picture, expected, 8);
    EXPECT_TRUE(d.sameShape);
    // The script reaches its matrices by hundreds of small steps, the hand-built state in one:
    // the last bits differ, and an edge pixel of an 11-pixel line may fall the other way.
    EXPECT_LE(d.pixelsOverTolerance, picture.width * picture.height / 100)
        << "frame " << frame << " does not look like the state the manual describes (max delta " << d.maxChannelDelta
        << ")";
  }
  // Solid for the first part, then wireframe: far fewer pixels lit.
  const double solid = test::coverage(played.at(150).image);
  const double wire = test::coverage(played.at(700).image);
  EXPECT_GT(solid, 0.1);
  EXPECT_LT(wire, solid / 3) << "frame 700 should be a wireframe";
  // Frame 0 faces the viewer square on: one face, red (face 1), fills the middle.
  const Image& first = played.at(0).image;
  const std::uint32_t c = first.width / 2;
  EXPECT_GT(first.at(c, c, 0), 100);
  EXPECT_LT(first.at(c, c, 1), 40);
  EXPECT_LT(first.at(c, c, 2), 40);
}

TEST_F(ExampleScript, FatterLinesLightMorePixels) {
  // The same wireframe state at the widths the script reaches: the renderer draws line_width.
  ExampleState e = expectedExample(1000);
  e.width = 1;
  const double thin = test::coverage(stage_->render(handBuilt(e)));
  e.width = 11;
  const double fat = test::coverage(stage_->render(handBuilt(e)));
  EXPECT_GT(fat, thin * 2);
}

}  // namespace
}  // namespace basalt::script
