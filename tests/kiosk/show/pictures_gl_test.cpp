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

TEST_F(Pictures, JitterAveragesItsPassesShowsAndSavesTheAverage) {
  // The frame presented at the end of the jitter loop is the average (LAVA showed the
  // accumulated picture), and save_image writes that average.
  // Failure caught: the average only written to files while the screen shows the last pass.
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
  const auto outDir = dir_ / "out";
  options.outputDir = outDir;
  const auto played = stage_->play(script, 100, {}, {0, 1, 2, 3, 4, 5, 6, 7, 8}, options);
  ASSERT_EQ(played.stats.frames, 9);
  ASSERT_EQ(played.imagesWritten.size(), 3u);
  // The raw passes: the offsets of pass i do not depend on the pass count, so a loop of nine
  // shows the eight passes above unaveraged as its frames 0 to 7.
  const auto nine = writeScript("jitter9", "position.global_y_rotate = 10\njitter 9\n  draw\nend_jitter\nquit\n");
  const auto passes = stage_->play(nine, 100, {}, {0, 1, 2, 3, 4, 5, 6, 7}, options);
  ASSERT_EQ(passes.stats.frames, 9);
  for (std::int64_t f = 0; f < 7; ++f) {
    EXPECT_TRUE(passes.at(f).image.pixels == played.at(f).image.pixels) << "pass " << f << " is the same in both";
  }

  // The passes differ: each is drawn with its own sub-pixel offset.
  EXPECT_FALSE(played.at(0).image.pixels == played.at(1).image.pixels);
  // avg.png is the rounded mean of the eight passes, exactly.
  auto average = media::readImage(outDir / "avg.png");
  ASSERT_TRUE(average) << average.error().describe();
  const Image& first = played.at(0).image;
  ASSERT_EQ(average->pixels.size(), first.pixels.size());
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < first.pixels.size(); ++i) {
    unsigned sum = 0;
    for (std::int64_t f = 0; f < 8; ++f) sum += passes.at(f).image.pixels[i];
    mismatches += average->pixels[i] == (sum + 4) / 8 ? 0u : 1u;
  }
  EXPECT_EQ(mismatches, 0u);
  // The frame shown after the loop (frame 7, the last pass's) is the average, bit for bit.
  EXPECT_TRUE(played.at(7).image.pixels == average->pixels) << "the screen shows the last pass, not the average";
  EXPECT_FALSE(played.at(7).image.pixels == passes.at(7).image.pixels);
  // single.png is the frame drawn after the loop, not a later one.
  auto single = media::readImage(outDir / "single.png");
  ASSERT_TRUE(single);
  EXPECT_TRUE(single->pixels == played.at(8).image.pixels);
  // The averaged edges are soft: values between the object's and the background's.
  const ImageDifference d = compareImages(*average, *single, 0);
  EXPECT_GT(d.pixelsOverTolerance, 0u);
  EXPECT_LT(d.pixelsOverTolerance, first.width * first.height / 10) << "only the edges change";

  // A bare save_image: LAVA's ras.im32, a Sun rasterfile in the output folder, holding the
  // frame drawn last (the single pass).
  const auto& last = played.imagesWritten.back();
  EXPECT_EQ(last, outDir / "ras.im32");
  std::ifstream raster(last, std::ios::binary);
  unsigned char magic[4] = {};
  raster.read(reinterpret_cast<char*>(magic), 4);
  EXPECT_EQ(magic[0], 0x59);  // the Sun rasterfile magic number 0x59a66a95, big-endian
  EXPECT_EQ(magic[1], 0xa6);
  EXPECT_EQ(magic[2], 0x6a);
  EXPECT_EQ(magic[3], 0x95);
  auto reread = media::readImage(last);
  ASSERT_TRUE(reread) << reread.error().describe();
  EXPECT_EQ(compareImages(*reread, *single, 0).pixelsOverTolerance, 0u) << "ras.im32 is the last frame drawn";
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
    auto original = test::run(readText(basalt::test::sourceDir() / "tests/runtime/script/scripts" / name));
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

TEST_F(Pictures, SaveModelOfATexturedModelReloadsToTheSamePicture) {
  // A model whose materials carry textures (assimp's spider, five JPEG maps named as
  // ".\\File.jpg" in its MTL), plus one texture the script maps itself. Saved next to the script
  // and played from there, the model gives the same picture bit for bit: the material textures
  // come back with the model (Save Model leaves them to it, rather than writing their resolved
  // paths, which a script may not name), the script's own texture by its own name.
  // Failure caught: `load_texture "/abs/path/SpiderTex.jpg"` in the saved model (refused on
  // reload), or a texture resolved twice (model folder + script folder).
  const auto source = basalt::test::testdataDir() / "models/obj/assimp";
  if (!std::filesystem::exists(source / "spider.obj")) GTEST_SKIP() << "no shared test data at " << source;
  const auto script = writeScript("spider", R"(load_object "spider.obj"
position.global_y_rotate = 30
position.global_x_rotate = 20
part.deselect_all
part.select "Auge"
load_texture "eye.jpg"
part.select_all
draw
quit
)");
  for (const char* file : {"spider.obj", "spider.mtl", "SpiderTex.jpg", "drkwood2.jpg", "engineflare1.jpg",
                           "wal67ar_small.jpg", "wal69ar_small.jpg"}) {
    std::filesystem::copy_file(source / file, dir_ / file);
  }
  std::filesystem::copy_file(source / "engineflare1.jpg", dir_ / "eye.jpg");
  const auto played = stage_->play(script, 10, {0}, {0});
  ASSERT_EQ(played.count(Severity::kError), 0u) << "the model and its textures load";
  ASSERT_EQ(played.stats.frames, 1);
  const runtime::Show& shown = played.at(0).show;
  std::size_t textured = 0;
  for (runtime::PartId id = 0; id < shown.partCount(); ++id) textured += shown.part(id).texture.empty() ? 0u : 1u;
  ASSERT_GE(textured, 2u) << "the spider's parts carry their material textures";

  const std::string saved = saveModel(played.finalShow, played.object);
  EXPECT_EQ(saved.find(dir_.string()), std::string::npos) << "no absolute path in the saved model:\n" << saved;
  EXPECT_NE(saved.find("load_texture \"eye.jpg\""), std::string::npos) << "the script's own texture is kept";
  const auto savedScript = dir_ / "saved.mdl";
  std::ofstream(savedScript) << saved << "draw\nquit\n";

  // The registry forgets the first run's textures, so the reload must bring them itself.
  for (runtime::PartId id = 0; id < shown.partCount(); ++id) {
    if (!shown.part(id).texture.empty()) stage_->renderer().textures().remove(shown.part(id).texture);
  }
  const auto reloaded = stage_->play(savedScript, 10, {0}, {0});
  EXPECT_EQ(reloaded.count(Severity::kError), 0u) << "the saved model plays without errors";
  EXPECT_EQ(reloaded.count(Severity::kWarning), 0u) << "... and without warnings";
  ASSERT_EQ(reloaded.stats.frames, 1);
  for (runtime::PartId id = 0; id < shown.partCount(); ++id) {
    EXPECT_EQ(reloaded.at(0).show.part(id).texture, shown.part(id).texture) << shown.part(id).name;
  }
  EXPECT_GT(test::coverage(played.at(0).image), 0.01) << "nothing drawn";
  EXPECT_TRUE(played.at(0).image.pixels == reloaded.at(0).image.pixels) << "the reloaded model looks different";
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
