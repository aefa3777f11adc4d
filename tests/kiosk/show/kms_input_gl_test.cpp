// Keyboards on a KMS kiosk, end to end: `basalt run` on the KMS output (virtio-gpu in the virtual
// lab, BASALT_VLAB_DRM) with a keyboard made through uinput (BASALT_VLAB_UINPUT). A technician's
// calibration keys typed on it must reach the facet view as they do in a window
// (tests/render/window_output_gl_test.cpp), which the control server then reports. Outside the
// lab it skips, saying so. Example failure: the evdev reader runs but the director never takes
// its events, so on KMS the thesis' keys need the control server.

#include <gtest/gtest.h>
#include <linux/input.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include "support/kiosk_process.h"
#include "support/polyhedra.h"
#include "support/uinput_device.h"

namespace basalt::render {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : "";
}

TEST(KmsInput, CalibrationKeysTypedOnAKeyboardCalibrateTheFacetView) {
  const std::string drm = env("BASALT_VLAB_DRM");
  const std::string uinput = env("BASALT_VLAB_UINPUT");
  if (drm.empty() || uinput.empty()) {
    GTEST_SKIP() << "needs the virtual lab (make vlab): BASALT_VLAB_DRM (a KMS display) and BASALT_VLAB_UINPUT "
                    "(/dev/uinput for a virtual keyboard)";
  }
  std::string why;
  auto keyboard =
      test::UinputDevice::create(uinput, "Basalt Lab Kiosk Keyboard", test::UinputDevice::keyboardKeys(), false, why);
  ASSERT_TRUE(keyboard) << why;
  const auto dir = test::writeShow("kms-keys", R"(
[show]
name = "KMS keys"
entry = "default"
fps = 30

[output]
kind = "kms"
device = ")" + drm + R"("

[[views]]
name = "front"
kind = "facet"
cave = "display.cave"

[input]
names = ["Basalt Lab Kiosk Keyboard"]

[status]
listen = "127.0.0.1:0"
token_file = "token"
)");
  const std::string token = "0123456789abcdef0123456789abcdef";
  std::ofstream(dir / "token") << token << "\n";
  std::ofstream(dir / "display.obj") << test::cubeDisplayObj();
  std::ofstream(dir / "display.cave") << "model display.obj\nfacet[5]\n";
  // Snapshots go to the show's scratch folder: the lab's working folder is read-only.
  auto show = test::RunningShow::start(
      {(dir / "show.toml").string(), "--no-resume", "--output-dir", (dir / "out").string()}, {}, why);
  ASSERT_TRUE(show) << why;
  // A key pressed before the reader opened the keyboard never reaches it (evdev delivers to the
  // open handles only): wait for the reader, then for the first frame on the display.
  ASSERT_TRUE(show->process().waitForOutput("reading keyboard 'Basalt Lab Kiosk Keyboard'", std::chrono::seconds(60)))
      << show->process().outputSoFar();
  ASSERT_TRUE(show->process().waitForOutput("first frame", std::chrono::seconds(60))) << show->process().outputSoFar();
  // The thesis' Xskew small step up is Shift and ':' (the ';' key); Shift and 'S' turn the side.
  ASSERT_TRUE(keyboard->key(KEY_LEFTSHIFT, 1));
  ASSERT_TRUE(keyboard->key(KEY_SEMICOLON, 1));
  ASSERT_TRUE(keyboard->key(KEY_SEMICOLON, 0));
  ASSERT_TRUE(keyboard->key(KEY_S, 1));
  ASSERT_TRUE(keyboard->key(KEY_S, 0));
  ASSERT_TRUE(keyboard->key(KEY_LEFTSHIFT, 0));
  const std::string bearer = "Bearer " + token;
  std::string settings;
  int status = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const auto answer = show->post("/control/calibrate", "", bearer);
    status = answer.status;
    settings = answer.body;
    if (settings.find("side[1]") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(status, 200) << settings;
  EXPECT_NE(settings.find("Xskew[0.5]"), std::string::npos) << settings << "\n" << show->process().outputSoFar();
  EXPECT_NE(settings.find("side[1]"), std::string::npos) << settings;
  EXPECT_NE(show->process().outputSoFar().find("reading keyboard 'Basalt Lab Kiosk Keyboard'"), std::string::npos)
      << show->process().outputSoFar();
  show->process().signal(SIGTERM);
  EXPECT_EQ(show->process().wait(std::chrono::seconds(20)).exitCode, 0);
}

}  // namespace
}  // namespace basalt::render
