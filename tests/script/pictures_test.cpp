// Pictures a script makes: save_image writes the frame drawn last (LAVA's ras.im32 by default,
// or the name given), a jitter loop averages its passes into one antialiased picture, and Save
// Model brings back the same picture bit for bit.
// Example failures: save_image writing the next frame instead of the last one drawn; jitter
// passes drawn without their sub-pixel offsets (the average would equal one pass); a saved
// model that reloads with a one-bit difference in a matrix.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "media/image_io.h"
#include "play_support.h"
#include "runtime/script/save_model.h"
#include "script_support.h"
#include "support/test_paths.h"

namespace basalt::script {
namespace {

class Pictures : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    stage_ = test::Stage::open({160, 120}, why);
    if (!stage_) GTEST_SKIP() << "no headless EGL here: " << why;
  }
  std::filesystem::path writeScript(const std::string& name, std::string_view text) {
    dir_ = basalt::test::scratchDir("script-" + name);
    std::ofstream(dir_ / (name + ".mdl")) << text;
    return dir_ / (name + ".mdl");
  }
  std::unique_ptr<test::Stage> stage_;
  std::filesystem::path dir_;
};

TEST_F(Pictures, JitterAveragesItsPassesAndSaveImageWritesThem) {
  const auto script = writeScript("jitter", R"(position.global_y_rotate = 10
jitter 8
  draw
end_jitter
save_image "avg.png"
draw
save_image "single.png"
save_image
quit
)");
  kiosk::ScriptPlayerOptions options;
  options.outputDir = dir_ / "out";
  const auto played = stage_->play(script, 100, {}, {0, 1, 2, 3, 4, 5, 6, 7, 8}, options);
  ASSERT_EQ(played.stats.frames, 9);
  ASSERT_EQ(played.imagesWritten.size(), 3u);

  // The passes differ: each is drawn with its own sub-pixel offset.
  EXPECT_FALSE(played.at(0).image.pixels == played.at(1).image.pixels);
  // avg.png is the rounded mean of the eight passes, exactly.
  auto average = media::readImage(dir_ / "out/avg.png");
  ASSERT_TRUE(average) << average.error().describe();
  const Image& first = played.at(0).image;
  ASSERT_EQ(average->pixels.size(), first.pixels.size());
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < first.pixels.size(); ++i) {
    unsigned sum = 0;
    for (std::int64_t f = 0; f < 8; ++f) sum += played.at(f).image.pixels[i];
    mismatches += average->pixels[i] == (sum + 4) / 8 ? 0u : 1u;
  }
  EXPECT_EQ(mismatches, 0u);
  // single.png is the frame drawn after the loop, not a later one.
  auto single = media::readImage(dir_ / "out/single.png");
  ASSERT_TRUE(single);
  EXPECT_TRUE(single->pixels == played.at(8).image.pixels);
  // The averaged edges are soft: values between the object's and the background's.
  const ImageDifference d = compareImages(*average, *single, 0);
  EXPECT_GT(d.pixelsOverTolerance, 0u);
  EXPECT_LT(d.pixelsOverTolerance, first.width * first.height / 10) << "only the edges change";

  // A bare save_image: LAVA's ras.im32, in the output folder (as PNG beside it until media/
  // writes Sun rasterfiles, and the author is told so).
  const auto& last = played.imagesWritten.back();
  EXPECT_EQ(last.parent_path(), dir_ / "out");
  EXPECT_EQ(last.filename().string().rfind("ras.im32", 0), 0u) << last;
  EXPECT_TRUE(std::filesystem::exists(last));
  if (last.extension() == ".png") {
    EXPECT_EQ(played.count(Severity::kWarning, "Sun rasterfiles"), 1u);
  }
}

TEST_F(Pictures, SaveImageBeforeAnyDrawIsReported) {
  const auto script = writeScript("early", "save_image \"x.png\"\ndraw\nquit\n");
  kiosk::ScriptPlayerOptions options;
  options.outputDir = dir_ / "out";
  const auto played = stage_->play(script, 10, {}, {}, options);
  EXPECT_EQ(played.count(Severity::kError, "nothing has been drawn yet"), 1u);
  EXPECT_EQ(played.stats.frames, 1) << "the show went on to the draw and the quit";
}

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST_F(Pictures, SaveModelGivesTheSamePictureBitForBit) {
  // Render, save, reload into a fresh show, render again: the same pixels. Then both go on
  // (the motion left running) for 30 frames, and again the same pixels.
  for (const char* name : {"rich_state.mdl", "example_motion.mdl"}) {
    auto original = test::run(readText(basalt::test::sourceDir() / "tests/script/scripts" / name));
    ASSERT_EQ(original.count(Severity::kError), 0u) << name;
    const std::string saved = saveModel(original.show, original.object);
    auto restored = test::run(saved);
    ASSERT_EQ(restored.count(Severity::kError), 0u) << name;
    const Image a = stage_->render(original.show);
    const Image b = stage_->render(restored.show);
    EXPECT_GT(test::coverage(a), 0.01) << name << ": nothing drawn";
    EXPECT_TRUE(a.pixels == b.pixels) << name << ": the reloaded model looks different";
    for (int i = 0; i < 30; ++i) {
      original.show.advanceFrame();
      restored.show.advanceFrame();
    }
    EXPECT_TRUE(stage_->render(original.show).pixels == stage_->render(restored.show).pixels) << name << " + 30 frames";
  }
}


TEST_F(Pictures, LoadObjectShowsAModelWithItsMaterials) {
  // The Cornell box from the shared test data (tinyobjloader's), beside its material library.
  const auto source = basalt::test::testdataDir() / "models/obj/tinyobjloader";
  if (!std::filesystem::exists(source / "cornell_box.obj")) GTEST_SKIP() << "no shared test data at " << source;
  const auto script = writeScript("cornell", R"(load_object "cornell_box.obj"
position.global_y_rotate = 180
draw
render.prim_type red_wall = wireframe
draw
quit
)");
  std::filesystem::copy_file(source / "cornell_box.obj", dir_ / "cornell_box.obj");
  std::filesystem::copy_file(source / "cornell_box.mtl", dir_ / "cornell_box.mtl");
  const auto played = stage_->play(script, 10, {0, 1}, {0, 1});
  EXPECT_EQ(played.count(Severity::kError), 0u) << "the model loads without errors";
  ASSERT_EQ(played.stats.frames, 2);
  const runtime::Show& shown = played.at(0).show;
  EXPECT_EQ(shown.partCount(), 8u) << "the box's eight objects with faces become parts (front_wall has none)";
  const auto redWall = shown.findPart("red_wall");
  ASSERT_TRUE(redWall.has_value()) << "parts are named after the file's objects";
  EXPECT_EQ(played.at(1).show.part(*redWall).own.render.primType, runtime::PrimType::kWireframe);
  // The materials colour the picture: somewhere a red pixel (the red wall) and a green one.
  const Image& image = played.at(0).image;
  bool red = false;
  bool green = false;
  for (std::uint32_t y = 0; y < image.height; ++y) {
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const int r = image.at(x, y, 0), g = image.at(x, y, 1), b = image.at(x, y, 2);
      red = red || (r > 80 && g < r / 3 && b < r / 3);
      green = green || (g > 80 && r < g / 3 && b < g / 3);
    }
  }
  EXPECT_TRUE(red) << "no pixel of the red wall";
  EXPECT_TRUE(green) << "no pixel of the green wall";
  EXPECT_FALSE(played.at(0).image.pixels == played.at(1).image.pixels) << "the wireframe wall changes the picture";
}

}  // namespace
}  // namespace basalt::script
