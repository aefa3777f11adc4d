// `basalt run [DISPLAY.cave] [SCENE.sce | MODEL.obj]`, the thesis' command line (Appendix B:
// "3Deng [ cavefile(.cave) ] [ scenefiles(.sce) ] [ modelfiles(.obj) ]"), run as a user runs
// it: a scene plays from its own camera without a manifest, and with a display file on the
// facet the file names. Runs the real binary headless.
//
// The scene: the camera at the origin looking down -Z with fov[90] (vertical; the output is
// square, so 45 degrees each way), a white box whose front face is the square x 1..3, y -1..1
// at z = -2 (its back at -3). By the pinhole model the face spans x / 2 = 0.5..1.5 in normalised coordinates:
// the right quarter of the picture, clipped at its edge; its left side (x = 1, z -2..-3) shows
// from x / 3 = 0.33 on; the centre is black. Fitted into
// LAVA's window instead, the box would be centred.
//
// Example failures: the positional files taken as a script and refused; the scene fitted to the
// window; the display file ignored (the facet's black border missing).

#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "media/image_io.h"
#include "support/kiosk_process.h"
#include "support/polyhedra.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

test::ProcessResult runBasalt(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return test::run(argv);
}

bool eglAvailable(std::string& why) {
  const auto probe = runBasalt({"run", "--frames", "1", "--headless", "--snapshot",
                                (test::scratchDir("thesis-cli-probe") / "probe.png").string()});
  if (probe.exitCode == 0) return true;
  why = probe.output;
  return false;
}

std::filesystem::path writeScene(const std::string& name, const std::string& box) {
  const auto dir = test::scratchDir(name);
  std::ofstream(dir / "box.obj") << box;
  std::ofstream(dir / "scene.sce") << "projection fov[90] nearclip[0.1] farclip[100]\n"
                                      "ambient[0,0,0]\ndiffuse[0,0,0]\nspecular[0,0,0]\nemission[255,255,255]\n"
                                      "import box.obj\n";
  return dir;
}

std::string boxObj(double x0, double y0, double z0, double x1, double y1, double z1) {
  std::string obj = "o box\n";
  for (int i = 0; i < 8; ++i) {
    obj += "v " + std::to_string((i & 1) ? x1 : x0) + " " + std::to_string((i & 2) ? y1 : y0) + " " +
           std::to_string((i & 4) ? z1 : z0) + "\n";
  }
  return obj + "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
}

TEST(ThesisCommandLine, ASceneFileAlonePlaysFromItsOwnCamera) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = writeScene("thesis-cli-scene", boxObj(1, -1, -3, 3, 1, -2));
  const auto snapshot = dir / "frame.png";
  const auto r = runBasalt({"run", "--frames", "2", "--headless", "--size", "200x200", "--snapshot", snapshot.string(),
                            (dir / "scene.sce").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  auto image = media::readImage(snapshot);
  ASSERT_TRUE(image) << image.error().describe();
  ASSERT_EQ(image->width, 200u);
  // Normalised x 0.5 is pixel 150; y -0.5..0.5 is rows 50..150.
  EXPECT_GT(image->at(175, 100, 0), 200) << "inside the face, right of the centre";
  EXPECT_GT(image->at(155, 55, 0), 200);
  EXPECT_LT(image->at(100, 100, 0), 20) << "the centre is empty";
  // The box's left side (x = 1, z -2..-3) faces the camera: it reaches x / 3 = 0.33, pixel 133.
  EXPECT_GT(image->at(140, 100, 0), 200) << "the box's left side";
  EXPECT_LT(image->at(128, 100, 0), 20) << "left of the box";
  EXPECT_LT(image->at(175, 45, 0), 20) << "above the face";
}

TEST(ThesisCommandLine, ADisplayFileShowsTheSceneThroughItsFacet) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  // A box straight ahead, seen through the cube display's front wall (facet 5, one unit away,
  // one unit to each side: a 90-degree square filling the square output); the display's
  // geometry wider than the output's aspect would leave black bars: 300 x 200 shows them.
  const auto dir = writeScene("thesis-cli-cave", boxObj(-0.5, -0.5, -5, 0.5, 0.5, -4));
  std::ofstream(dir / "display.obj") << test::cubeDisplayObj();
  std::ofstream(dir / "display.cave") << "model display.obj\nfacet[5]\n";
  const auto snapshot = dir / "frame.png";
  const auto r = runBasalt({"run", "--frames", "2", "--headless", "--size", "300x200", "--snapshot", snapshot.string(),
                            (dir / "display.cave").string(), (dir / "scene.sce").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  auto image = media::readImage(snapshot);
  ASSERT_TRUE(image) << image.error().describe();
  // The facet: the middle 200 x 200. The box's face, 0.5 / 4 of the half-width: 12.5 pixels
  // each side of the centre.
  EXPECT_GT(image->at(150, 100, 0), 200) << "the box ahead";
  EXPECT_LT(image->at(150, 80, 0), 20) << "beside the box, inside the facet";
  EXPECT_LT(image->at(20, 100, 0), 20) << "outside the facet";
}

TEST(ThesisCommandLine, OneDisplayAndOneSceneOnly) {
  const auto dir = writeScene("thesis-cli-usage", boxObj(-1, -1, -3, 1, 1, -2));
  const auto scene = (dir / "scene.sce").string();
  auto r = runBasalt({"run", scene, scene});
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("one display file"), std::string::npos) << r.output;
  r = runBasalt({"run", (dir / "missing.sce").string(), "--frames", "1", "--headless"});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("no such file"), std::string::npos) << r.output;
}

// The set-up toggles for a kiosk without a keyboard: POST /control/setup with the toggle's name
// and the control token, as the keys do. Example failures: the request refused as an unknown
// path; a toggle that answers but changes nothing on screen; an unknown name taken as another.
TEST(ThesisCommandLine, SetUpTogglesAsControlRequests) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::writeShow("thesis-setup-control", R"(
[show]
entry = "scene.sce"
fps = 30

[output]
kind = "headless"
size = "160x120"

[status]
listen = "127.0.0.1:0"
token_file = "token"
)");
  const std::string token = "0123456789abcdef0123456789abcdef";
  std::ofstream(dir / "token") << token << "\n";
  std::ofstream(dir / "box.obj") << boxObj(-1, -1, -6, 1, 1, -4);
  std::ofstream(dir / "scene.sce") << "projection fov[60]\nfog start[1] end[8] color[0,0,255] function[linear]\n"
                                      "import box.obj\n";
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  const std::string bearer = "Bearer " + token;
  const auto before = show->get("/snapshot.png");
  ASSERT_EQ(before.status, 200);
  auto r = show->post("/control/setup", "fog", bearer);
  EXPECT_EQ(r.status, 200) << r.body;
  EXPECT_NE(r.body.find("fog off"), std::string::npos) << r.body;
  r = show->post("/control/setup", "wireframe", bearer);
  EXPECT_EQ(r.status, 200) << r.body;
  EXPECT_NE(r.body.find("surfaces drawn as wireframe"), std::string::npos) << r.body;
  // The status server keeps a snapshot for a second.
  std::this_thread::sleep_for(std::chrono::milliseconds(1300));
  const auto after = show->get("/snapshot.png");
  ASSERT_EQ(after.status, 200);
  EXPECT_NE(before.body, after.body) << "the toggles changed nothing on screen";
  r = show->post("/control/setup", "cave", bearer);
  EXPECT_EQ(r.status, 200) << r.body;
  EXPECT_NE(r.body.find("no facet views"), std::string::npos) << r.body;
  r = show->post("/control/setup", "fogg", bearer);
  EXPECT_EQ(r.status, 400) << r.body;
  r = show->post("/control/setup", "fog");
  EXPECT_NE(r.status, 200) << "the control token is needed";
  show->process().signal(SIGTERM);
  EXPECT_EQ(show->process().wait().exitCode, 0);
}

}  // namespace
}  // namespace basalt
