// `basalt run` on show manifests as a user runs it: every example show plays headless (saying
// which parts this build lacks, and playing on without them); a broken manifest does not start under
// --strict and says why with file:line; a missing display is one clear line; the schedule follows the
// calendar time the run starts at.
// Example failures: an example that crashes because its scene reader is missing; a manifest
// error that starts the show anyway, or stops it without the line it is on.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "support/kiosk_process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

test::ProcessResult basalt(std::vector<std::string> args) {
  args.insert(args.begin(), {(test::binaryDir() / "basalt").string(), "run"});
  return test::run(args, {}, std::chrono::seconds(60));
}

class ExampleRun : public testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(ExampleRun, PlaysHeadless) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto& [folder, name] = GetParam();
  const auto out = test::scratchDir(std::string("kiosk-run-") + folder);
  const auto r = basalt({(test::sourceDir() / "configs/shows" / folder / "show.toml").string(), "--output", "headless",
                         "--frames", "30", "--no-resume", "--status", "127.0.0.1:0", "--output-dir", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find(std::string("played '") + name + "': 30 frames"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(out / "snapshot.png"));
  EXPECT_EQ(r.output.find("cannot play"), std::string::npos) << "every scripted and scene item plays: " << r.output;
}

INSTANTIATE_TEST_SUITE_P(Configs, ExampleRun,
                         testing::Values(std::pair{"default", "Default demo"}, std::pair{"video-wall", "Video wall"},
                                         std::pair{"camera-sculpture", "Camera sculpture"},
                                         std::pair{"lava-script", "LAVA tour"}),
                         [](const auto& p) { return test::caseName(p.param.first); });

TEST(KioskRun, AShowFolderPlaysItsShowToml) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  // The folder as a technician names it, with and without the trailing slash.
  for (const std::string& folder : {(test::sourceDir() / "configs/shows/default").string(),
                                    (test::sourceDir() / "configs/shows/default/").string()}) {
    const auto r = basalt({folder, "--output", "headless", "--frames", "3", "--no-resume", "--status", "127.0.0.1:0",
                           "--output-dir", test::scratchDir("kiosk-run-folder").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("played 'Default demo': 3 frames"), std::string::npos) << r.output;
  }
  // A folder without show.toml says so, and what it holds instead.
  const auto dir = test::scratchDir("kiosk-run-folder-without");
  std::ofstream(dir / "tour.mdl") << "draw\n";
  const auto r = basalt({dir.string(), "--frames", "1", "--headless"});
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("the folder " + dir.string() + " has no show.toml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("it holds tour.mdl"), std::string::npos) << r.output;
}

TEST(KioskRun, TheSceneEntryIsReadWithItsModels) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto r = basalt({(test::sourceDir() / "configs/shows/camera-sculpture/show.toml").string(), "--output",
                         "headless", "--frames", "5", "--no-resume", "--status", "127.0.0.1:0", "--output-dir",
                         test::scratchDir("kiosk-run-missing").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("show.toml:10: scene sculpture.sce: 1 models, 0 terrains, 0 warnings"), std::string::npos)
      << r.output;
}

TEST(KioskRun, ABrokenManifestDoesNotStartUnderStrict) {
  const auto dir = test::writeShow("kiosk-run-broken", "[show]\nentry = \"gone.mdl\"\n");
  const auto r = basalt({(dir / "show.toml").string(), "--frames", "1", "--headless", "--strict"});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("show.toml:2: show.entry: 'gone.mdl' does not exist"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("basalt: error: cannot start: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("has 1 problem (above)"), std::string::npos) << r.output;
  const auto usage = basalt({"show.txt"});
  EXPECT_EQ(usage.exitCode, 2);
  EXPECT_NE(usage.output.find("give a show manifest (show.toml)"), std::string::npos) << usage.output;
}

TEST(KioskRun, NoDisplayForKmsIsOneClearLine) {
  if (std::filesystem::exists("/dev/dri")) GTEST_SKIP() << "this machine has DRM devices; the lab tests them";
  const auto r = basalt({"--output", "kms", "--frames", "1"});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("basalt: error: cannot open the kms output: there is no DRM device"), std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(KioskRun, TheScheduleReadsTheCalendarTheRunStartsAt) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::writeShow("kiosk-run-schedule", R"(
[show]
entry = "default"
[kiosk.schedule]
timezone = "Europe/Paris"
daily = "10:00-18:00"
monday = "closed"
outside = "black"
)");
  // Monday 2026-03-23 at noon in Paris, then Tuesday 09:59:58 UTC (10:59:58 in Paris).
  const auto monday = basalt({(dir / "show.toml").string(), "--headless", "--frames", "3", "--no-resume",
                              "--clock-start", "2026-03-23T11:00:00Z", "--output-dir", (dir / "out").string()});
  ASSERT_EQ(monday.exitCode, 0) << monday.output;
  EXPECT_NE(monday.output.find("at the end: closed, closed: display black"), std::string::npos) << monday.output;
  const auto tuesday = basalt({(dir / "show.toml").string(), "--headless", "--frames", "3", "--no-resume",
                               "--clock-start", "2026-03-24T09:59:58Z", "--output-dir", (dir / "out").string()});
  ASSERT_EQ(tuesday.exitCode, 0) << tuesday.output;
  EXPECT_NE(tuesday.output.find("at the end: open, playing"), std::string::npos) << tuesday.output;
  const auto bad = basalt({"--clock-start", "tomorrow"});
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.output.find("--clock-start needs a UTC time"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace basalt
