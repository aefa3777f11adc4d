// LAVA manual section 11, the demo sequence (tests/runtime/script/scripts/demo_section11.mdl), played
// headless under a ManualClock. Chosen frames are checked against the Show and pictures: the
// cube turns and stops, goes wireframe and solid, the bones model that cannot be loaded is
// reported while the show goes on, the VCR plays a real movie (../shared/testdata/video/mpeg1)
// onto the cube with texture.switch = video, the camera is reported absent (a script run has no
// manifest camera), and the transparency and texture steps are stored.
// Example failures: a failed load_object that stops the show or changes the object; the VCR
// lines silently ignored or the movie not reaching the picture; load_color_cube not giving back the start-up state; the
// texture put on parts that were not displayed; the run not ending at `quit`.

#include <gtest/gtest.h>

#include <fstream>

#include "media/image_io.h"
#include "play_support.h"
#include "runtime/script/interpreter.h"
#include "support/test_paths.h"

namespace basalt::script {
namespace {

using runtime::PrimType;

void expectNear(const Mat4& a, const Mat4& b, std::int64_t frame) {
  for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(a.m[i], b.m[i], 1e-5f) << "element " << i << ", frame " << frame;
}

/// The demo script in a folder of its own, with the files it names: the texture (a small
/// checkerboard), a stand-in for the bones model and a real MPEG-1 movie (empty when the testdata
/// is missing).
std::filesystem::path stageDemo() {
  const auto dir = basalt::test::scratchDir("script-demo");
  std::filesystem::copy_file(basalt::test::sourceDir() / "tests/runtime/script/scripts/demo_section11.mdl",
                             dir / "demo_section11.mdl");
  std::filesystem::create_directories(dir / "Face");
  Image texture = Image::make(8, 8, 3);
  for (std::uint32_t y = 0; y < 8; ++y) {
    for (std::uint32_t x = 0; x < 8; ++x) {
      for (std::uint32_t c = 0; c < 3; ++c) texture.row(y)[x * 3 + c] = ((x + y) % 2) ? 230 : 30;
    }
  }
  EXPECT_TRUE(media::writeImage(dir / "Face/madona.png", texture));
  std::ofstream(dir / "foot_bones.obj") << "# a stand-in with nothing to draw: its load fails at its line\n";
  const auto movie = basalt::test::testdataDir() / "video/mpeg1/pypy_test.mpg";
  if (!basalt::test::testdataDir().empty() && std::filesystem::exists(movie)) {
    std::filesystem::copy_file(movie, dir / "movie.mpg");
  } else {
    std::ofstream(dir / "movie.mpg") << "a stand-in movie\n";
  }
  return dir / "demo_section11.mdl";
}

class DemoScript : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    stage_ = test::Stage::open({160, 160}, why);
    if (!stage_) GTEST_SKIP() << "no headless EGL here: " << why;
  }
  std::unique_ptr<test::Stage> stage_;
};

TEST_F(DemoScript, PlaysTheManualsDemoSequence) {
  std::set<std::int64_t> all;
  for (std::int64_t f = 0; f <= 88; ++f) all.insert(f);
  const auto script = stageDemo();
  if (std::filesystem::file_size(script.parent_path() / "movie.mpg") < 100) {
    GTEST_SKIP() << "../shared/testdata/video/mpeg1/pypy_test.mpg is missing: the VCR steps need a real movie";
  }
  kiosk::ScriptPlayerOptions options;
  options.manualClock = true;
  const auto played = stage_->play(script, 500, all, {19, 20, 42, 43, 47, 48}, options);
  EXPECT_TRUE(played.quit);
  EXPECT_EQ(played.stats.frames, 89) << "89 draws, then quit ends the run on the last one";

  // Rotate slightly (1 and 3 degrees a frame), wireframe while turning, stop, solid.
  const runtime::Show start = startupShow();
  runtime::Show turning = start;
  for (std::int64_t f = 0; f <= 39; ++f) {
    expectNear(played.at(f).show.position().global, turning.position().global, f);
    EXPECT_EQ(played.at(f).show.globalStyle().render.primType, f < 20 ? PrimType::kSolid : PrimType::kWireframe);
    turning.rotateGlobal({1, 3, 0});
  }
  expectNear(played.at(40).show.position().global, played.at(39).show.position().global, 40);
  EXPECT_EQ(played.at(40).show.globalStyle().render.primType, PrimType::kSolid);

  // The stand-in bones model has nothing to draw: reported at its line; the cube stays, unchanged.
  EXPECT_EQ(played.count(Severity::kError, "load_object"), 1u);
  EXPECT_EQ(played.at(41).show.partCount(), 6u);
  EXPECT_EQ(played.at(41).show.position(), played.at(40).show.position());

  // Load Color Cube: the start-up state again, picture included.
  EXPECT_EQ(played.at(42).show.position(), start.position());
  EXPECT_EQ(played.at(42).show.motion(), start.motion());
  EXPECT_EQ(played.at(42).show.globalStyle(), start.globalStyle());
  EXPECT_TRUE(played.at(42).image.pixels == stage_->render(start).pixels) << "frame 42 is not the start-up cube";

  // Video texture mapping and the camera: the settings are stored; the VCR lines are reported.
  EXPECT_EQ(played.at(43).show.texture().source, runtime::TextureSource::kVideo);
  const auto& front45 = played.at(45).show.globalStyle().front;
  EXPECT_EQ(front45.transparencyMethod, runtime::TransparencyMethod::kBlended);
  EXPECT_EQ(front45.transparencyBlend, runtime::TransparencyBlend::kConstantBackground);
  EXPECT_FLOAT_EQ(front45.transparency, 0.45f);
  EXPECT_EQ(played.at(46).show.globalStyle().front.transparencyMethod, runtime::TransparencyMethod::kNone);
  EXPECT_EQ(played.count(Severity::kError, "movie player is not available"), 0u)
      << "tv.movie, repeat, play x2, stop, unload all reach the movie player";
  EXPECT_EQ(played.count(Severity::kError, "tv."), 1u) << "only tv.camera = on: this run has no camera";
  EXPECT_EQ(played.count(Severity::kError, "has no camera"), 1u);
  EXPECT_EQ(played.count(Severity::kNote, "not rendered yet"), 0u) << "the renderer draws all the demo uses";
  EXPECT_EQ(played.count(Severity::kError), 2u) << "the bones and the camera, nothing else";
  // The movie plays on the cube: frame 43 differs from the cube drawn without it.
  EXPECT_FALSE(played.at(43).image.pixels == stage_->render(played.at(43).show).pixels)
      << "frame 43 shows no movie on the cube";

  // Texture mapping: faces 3 and 6 alone, textured; then everything shown again.
  const runtime::Show& single = played.at(48).show;
  for (runtime::PartId id = 0; id < single.partCount(); ++id) {
    const std::string& name = single.part(id).name;
    const bool chosen = name == "face 3" || name == "face 6";
    EXPECT_EQ(single.part(id).selected, chosen) << name;
    EXPECT_EQ(single.part(id).texture, chosen ? "Face/madona.png" : "") << name;
  }
  EXPECT_LT(test::coverage(played.at(48).image), test::coverage(played.at(47).image)) << "four faces hidden";
  for (runtime::PartId id = 0; id < 6; ++id) EXPECT_TRUE(played.at(68).show.part(id).selected);

  // Spinning about Z from frame 68, then Reset Global Matrix.
  runtime::Show spin = played.at(67).show;
  spin.rotateGlobal({0.25f, 0.5f, 2});
  expectNear(played.at(68).show.position().global, spin.position().global, 68);
  EXPECT_EQ(played.at(88).show.position().global, Mat4{});

  // Solid, then wireframe.
  EXPECT_LT(test::coverage(played.at(20).image), test::coverage(played.at(19).image) / 2);
}

}  // namespace
}  // namespace basalt::script
