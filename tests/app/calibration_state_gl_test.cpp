// `basalt run` as the service runs it, with systemd's STATE_DIRECTORY set: a facet view's
// calibration saved over HTTP (POST /control/calibrate?save=1) goes to the state folder, not to
// the show's folder (read-only under the unit), and the next start plays it.
// Example failures: the save written to the show's cave file (500 "Read-only file system" under
// the unit's ProtectSystem=strict); the saved calibration not read back, so that the restart
// systemd makes after a crash loses it.

#include <gtest/gtest.h>

#include <signal.h>

#include <fstream>
#include <sstream>

#include "support/kiosk_process.h"
#include "support/polyhedra.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

constexpr const char* kToken = "fedcba9876543210fedcba9876543210";

TEST(CalibrationUnderTheService, SavedInTheStateDirectoryAndPlayedAtTheNextStart) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::writeShow("calibration-state", R"(
[show]
name = "Calibration under the service"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "160x120"

[[views]]
name = "front"
kind = "facet"
cave = "display.cave"

[status]
listen = "127.0.0.1:0"
token_file = "token"
)");
  std::ofstream(dir / "token") << kToken << "\n";
  std::ofstream(dir / "display.obj") << test::cubeDisplayObj();
  const std::string caveText = "model display.obj\nfacet[5]\n";
  std::ofstream(dir / "display.cave") << caveText;
  const auto state = test::scratchDir("calibration-state-folder");
  // systemd may list several folders; the first is the service's.
  const std::map<std::string, std::string> env{{"STATE_DIRECTORY", state.string() + ":/nonexistent"}};
  const std::string bearer = std::string("Bearer ") + kToken;
  const std::vector<std::string> args{(dir / "show.toml").string(), "--realtime", "--no-resume"};

  {
    auto show = test::RunningShow::start(args, env, why);
    ASSERT_TRUE(show) << why;
    const auto saved = show->post("/control/calibrate?view=front&save=1", "Xscale[1.25]; Yskew[-2]", bearer);
    EXPECT_EQ(saved.status, 200) << saved.body;
    EXPECT_NE(saved.body.find("saved to " + (state / "calibration/front.cave").string()), std::string::npos)
        << saved.body;
    show->process().signal(SIGTERM);
    EXPECT_EQ(show->process().wait().exitCode, 0);
  }
  EXPECT_TRUE(std::filesystem::is_regular_file(state / "calibration/front.cave"));
  std::ifstream cave(dir / "display.cave");
  std::ostringstream caveNow;
  caveNow << cave.rdbuf();
  EXPECT_EQ(caveNow.str(), caveText) << "the show's folder is not written";

  // The next start, as after a restart: the view plays the saved calibration.
  auto show = test::RunningShow::start(args, env, why);
  ASSERT_TRUE(show) << why;
  const auto read = show->post("/control/calibrate?view=front", "", bearer);
  EXPECT_EQ(read.status, 200) << read.body;
  EXPECT_NE(read.body.find("view 'front': facet[5] side[0] Xscale[1.25] Yscale[1] Xskew[0] Yskew[-2]"),
            std::string::npos)
      << read.body;
}

}  // namespace
}  // namespace basalt
