// `basalt run SHOW.mdl`, `basalt check SHOW.mdl` and `basalt help script` as a user runs them.
// Example failures: `quit` not ending the run; a bad line stopping the show or going unreported;
// `check` passing a script with errors or naming the wrong line; the printed reference differing
// from the generated page; a saved model that reloads into a different picture.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "media/image_io.h"
#include "runtime/script/reference.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

test::ProcessResult basalt(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return test::run(argv);
}

std::filesystem::path write(const std::filesystem::path& dir, const std::string& name, std::string_view text) {
  std::ofstream(dir / name) << text;
  return dir / name;
}

bool eglAvailable(std::string& why) {
  // A folder of this test's own: ctest runs the tests of this file in parallel processes.
  const auto dir = test::scratchDir(std::string("script-cli-probe-") +
                                    ::testing::UnitTest::GetInstance()->current_test_info()->name());
  const auto probe = basalt({"run", "--frames", "1", "--headless", "--output-dir", dir.string()});
  why = probe.output;
  return probe.exitCode == 0;
}

std::size_t countLines(const std::string& text, std::string_view needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

TEST(ScriptCli, RunPlaysAScriptUntilQuit) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("script-cli-quit");
  const auto script = write(dir, "three.mdl", "loop 3\n  position.global_y_rotate = 10\n  draw\nend_loop\nquit\n");
  const auto r = basalt({"run", script.string(), "--headless", "--output-dir", (dir / "out").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("3 frames"), std::string::npos) << "quit ends the run on the last draw:\n" << r.output;
  EXPECT_NE(r.output.find("manual clock"), std::string::npos) << "a script that quits runs as fast as it can";
  EXPECT_NE(r.output.find("script quit"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": 3 draws,"), std::string::npos) << "three draws, three frames:\n" << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "out/snapshot.png"));
}

// Each draw ends one frame (LAVA manual §10, draw: "Draw the object once."), so a run stopped
// after 30 frames reports 30 draws, not the one the script reached for a 31st frame never drawn.
TEST(ScriptCli, TheDrawCountIsTheFramesDrawn) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("script-cli-draws");
  const auto script = write(dir, "spin.mdl", "loop 1000\n  position.global_y_rotate = 1\n  draw\nend_loop\n");
  const auto r =
      basalt({"run", script.string(), "--headless", "--frames", "30", "--output-dir", (dir / "out").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("30 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": 30 draws,"), std::string::npos) << r.output;
}

TEST(ScriptCli, BadLinesAreReportedAndTheShowGoesOn) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("script-cli-bad");
  const auto script = write(dir, "bad.mdl",
                            "rendr.prim_type = wireframe\nloop 5\n  lines.line_width /= 0\n  draw\nend_loop\n"
                            "render.prim_type \"face 9\" = markers\ndraw\nquit\n");
  const auto r = basalt({"run", script.string(), "--headless", "--output-dir", (dir / "out").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("basalt: error: " + script.string() +
                          ":1: unknown command 'rendr.prim_type'; did you mean 'render.prim_type'?"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(countLines(r.output, script.string() + ":3: lines.line_width /= 0: division by zero"), 1u)
      << "once, not once per pass:\n"
      << r.output;
  EXPECT_NE(r.output.find(script.string() + ":6: render.prim_type: the object has no part 'face 9'"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("6 frames"), std::string::npos) << r.output;
}

TEST(ScriptCli, SaveImageAndSaveModel) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("script-cli-save");
  const auto script = write(dir, "pose.mdl",
                            "render.prim_type \"face 1\" = wireframe\nlines.line_width = 3\n"
                            "position.global_x_rotate = 20\nlighting.color [1] = 1 0.5 0.5\ndraw\nsave_image\nquit\n");
  const auto first = basalt({"run", script.string(), "--headless", "--output-dir", (dir / "a").string(), "--save-image",
                             "pose.png", "--save-model", (dir / "saved.mdl").string()});
  ASSERT_EQ(first.exitCode, 0) << first.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "a/pose.png")) << first.output;
  EXPECT_NE(first.output.find("model saved to"), std::string::npos);
  // The saved model, run on a fresh show, draws the same picture.
  const auto second = basalt(
      {"run", (dir / "saved.mdl").string(), "--frames", "1", "--headless", "--output-dir", (dir / "b").string()});
  ASSERT_EQ(second.exitCode, 0) << second.output;
  auto a = media::readImage(dir / "a/snapshot.png");
  auto b = media::readImage(dir / "b/snapshot.png");
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->pixels == b->pixels) << "the reloaded model draws a different picture";
  auto saved = media::readImage(dir / "a/pose.png");
  ASSERT_TRUE(saved);
  EXPECT_TRUE(saved->pixels == a->pixels) << "save_image wrote the frame that was drawn";
}

TEST(ScriptCli, RunRefusesWhatItCannotPlay) {
  const auto dir = test::scratchDir("script-cli-refuse");
  const auto missing = basalt({"run", (dir / "missing.mdl").string(), "--headless", "--output-dir", dir.string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.output.find("basalt: error: cannot start"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("missing.mdl"), std::string::npos) << missing.output;
  const auto other = basalt({"run", "show.xyz"});
  EXPECT_EQ(other.exitCode, 2);
  EXPECT_NE(other.output.find("plays show manifests and LAVA scripts (.mdl)"), std::string::npos) << other.output;
  const auto two = basalt({"run", "a.mdl", "b.mdl"});
  EXPECT_EQ(two.exitCode, 2);
}

TEST(ScriptCli, CheckListsEveryErrorWithoutRunning) {
  const auto dir = test::scratchDir("script-cli-check");
  const auto bad = write(dir, "bad.mdl",
                         "render.prim_type = wirefame\n! fine\nlines.line_color = 1 0\nloop 2\n draw\n"
                         "part.select face1\nload_texture \"missing.png\"\nmotion.global_x_rotate += 1\n");
  const auto r = basalt({"check", bad.string()});
  EXPECT_EQ(r.exitCode, 1);
  const std::string b = bad.string();
  for (const std::string& expected :
       {b + ":1: error: render.prim_type takes one of: wireframe, markers, solid; not "
            "'wirefame' (did you mean 'wireframe'?)",
        b + ":3: error: lines.line_color needs 3 numbers, found 2", b + ":4: error: this loop has no end_loop",
        b + ":6: error: part.select: the start-up cube has no part 'face1'; did you mean "
            "'face 1'?",
        b + ":7: error: load_texture: there is no file", b + ":8: error: motion.global_x_rotate does not take '+='",
        std::string("basalt: ") + b + ": 6 errors"}) {
    EXPECT_NE(r.output.find(expected), std::string::npos) << "missing: " << expected << "\nin:\n" << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "check runs nothing";

  const auto good = write(dir, "good.mdl", "render.prim_type \"face 2\" = wireframe\nloop 2\n draw\nend_loop\nquit\n");
  const auto ok = basalt({"check", good.string()});
  EXPECT_EQ(ok.exitCode, 0) << ok.output;
  EXPECT_NE(ok.output.find("no errors (5 commands checked)"), std::string::npos) << ok.output;
  const auto example =
      basalt({"check", (test::sourceDir() / "tests/runtime/script/scripts/example_motion.mdl").string()});
  EXPECT_EQ(example.exitCode, 0) << example.output;

  const auto unknown = basalt({"check", "show.xyz"});
  EXPECT_EQ(unknown.exitCode, 2);
  EXPECT_NE(unknown.output.find(".mdl (LAVA script)"), std::string::npos) << unknown.output;
  EXPECT_EQ(basalt({"check"}).exitCode, 2);
}

/// Colours in `image`, each channel cut to 3 bits (lighting and filtering blur the rest).
std::size_t coarseColours(const Image& image) {
  std::set<std::uint32_t> seen;
  for (std::size_t i = 0; i + 2 < image.pixels.size(); i += image.channels) {
    seen.insert((image.pixels[i] >> 5) << 6 | (image.pixels[i + 1] >> 5) << 3 | (image.pixels[i + 2] >> 5));
  }
  return seen.size();
}

// LAVA §7.1, Camera: "LAVA expects to see a video signal when "Camera" is activated". A script
// run directly shows the camera named with --camera on the parts whose texture is video: the
// synthetic camera's eight colour bars put colours on the cube that the run without a camera
// does not have, and that run says it has no camera.
// Example failures: --camera is refused or ignored; tv.camera = on still says "this show has no
// camera"; the camera opens but its frames never reach the video texture.
TEST(ScriptCli, TheCameraOptionIsWhatTvCameraShows) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("script-cli-camera");
  const auto script =
      write(dir, "camera.mdl", "texture.switch = video\ntv.camera = on\nloop 20\n  draw\nend_loop\nquit\n");
  const auto with = basalt(
      {"run", script.string(), "--headless", "--camera", "synthetic", "--snapshot", (dir / "with.png").string()});
  ASSERT_EQ(with.exitCode, 0) << with.output;
  EXPECT_EQ(with.output.find("has no camera"), std::string::npos) << with.output;
  const auto without = basalt({"run", script.string(), "--headless", "--snapshot", (dir / "without.png").string()});
  ASSERT_EQ(without.exitCode, 0) << without.output;
  EXPECT_NE(without.output.find("has no camera"), std::string::npos) << without.output;
  auto a = media::readImage(dir / "with.png");
  auto b = media::readImage(dir / "without.png");
  ASSERT_TRUE(a && b);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a->pixels.size() && i < b->pixels.size(); ++i) differing += a->pixels[i] != b->pixels[i];
  EXPECT_GT(differing, a->pixels.size() / 20) << "the camera's picture is on the cube";
  EXPECT_GE(coarseColours(*a), coarseColours(*b) + 4) << "the colour bars bring colours the plain cube lacks";

  // A camera spec that cannot be one is refused, naming the option's forms.
  const auto bad = basalt({"run", script.string(), "--headless", "--camera", "hid:077d:0410"});
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_NE(bad.output.find("v4l2:/dev/videoN"), std::string::npos) << bad.output;
  const auto missing =
      basalt({"run", script.string(), "--headless", "--camera", "replay:" + (dir / "none.trace").string()});
  EXPECT_NE(missing.exitCode, 0);
  EXPECT_NE(missing.output.find("none.trace"), std::string::npos) << missing.output;
}

// The same with a real V4L2 camera, in the virtual lab: vivid's webcam input through the V4L2
// backend (`--camera v4l2:/dev/videoN`). Its default test pattern is colour bars too.
// Example failure: the v4l2 form parsed but the camera never opened (wrong match field).
TEST(ScriptCliLab, TheCameraOptionOpensAV4l2Camera) {
  const char* node = std::getenv("BASALT_VLAB_V4L2_WEBCAM");
  if (node == nullptr || *node == '\0') {
    GTEST_SKIP() << "needs the virtual lab (make vlab): BASALT_VLAB_V4L2_WEBCAM (vivid webcam input)";
  }
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("script-cli-lab-camera");
  const auto script =
      write(dir, "camera.mdl", "texture.switch = video\ntv.camera = on\nloop 30\n  draw\nend_loop\nquit\n");
  const auto with = basalt({"run", script.string(), "--headless", "--camera", std::string("v4l2:") + node, "--snapshot",
                            (dir / "with.png").string()});
  ASSERT_EQ(with.exitCode, 0) << with.output;
  EXPECT_EQ(with.output.find("has no camera"), std::string::npos) << with.output;
  const auto without = basalt({"run", script.string(), "--headless", "--snapshot", (dir / "without.png").string()});
  ASSERT_EQ(without.exitCode, 0) << without.output;
  auto a = media::readImage(dir / "with.png");
  auto b = media::readImage(dir / "without.png");
  ASSERT_TRUE(a && b);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a->pixels.size() && i < b->pixels.size(); ++i) differing += a->pixels[i] != b->pixels[i];
  EXPECT_GT(differing, a->pixels.size() / 20) << "vivid's picture is on the cube:\n" << with.output;
}

TEST(ScriptCli, HelpScriptPrintsTheReference) {
  const auto r = basalt({"help", "script"});
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_TRUE(r.output == script::scriptReference()) << "basalt help script differs from the generated reference";
  const auto overview = basalt({"--help"});
  EXPECT_NE(overview.output.find("check"), std::string::npos);
  EXPECT_NE(overview.output.find("help script"), std::string::npos);
}

}  // namespace
}  // namespace basalt
