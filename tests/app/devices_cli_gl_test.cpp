// `basalt devices`, `basalt record` and `basalt run --replay` as a user runs them: the device list
// with the simulated twins and recordings, a demo trace recorded without hardware, and the same
// trace under the same show giving the same frames bit for bit (and different frames from a show
// without it, so the dials really drove the show); camera video recorded in Matroska by default,
// as .bvraw with --raw-video, and both replay.
// Example failures: `basalt devices` failing on a machine with nothing plugged in; a recording
// that writes no trace.toml; a replay that depends on wall-clock timing and so renders
// differently from run to run; a camera recorded in the old format only, or a .bvraw trace that no
// longer replays.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim/raw_video.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

test::ProcessResult runBasalt(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return test::run(argv, {}, std::chrono::seconds(120));
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

TEST(DevicesCli, ListsWhatIsThereOrSaysNothingIs) {
  const auto r = runBasalt({"devices"});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const bool listed = r.output.find("Dial boxes:") != std::string::npos ||
                      r.output.find("Video sources:") != std::string::npos ||
                      r.output.find("cannot be opened") != std::string::npos;
  EXPECT_TRUE(listed || r.output.find("No dial box, camera or capture card found") != std::string::npos) << r.output;
}

TEST(DevicesCli, ListsSimulatedTwinsAndRecordings) {
  const auto dir = test::testdataDir();
  std::vector<std::string> args{"devices", "--synthetic"};
  if (!dir.empty()) {
    args.push_back("--replay");
    args.push_back((dir / "hid" / "udev-hid-bpf" / "huion_dial2_q630m_rdescs.hid").string());
  }
  const auto r = runBasalt(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("Synthetic dial box"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Synthetic camera"), std::string::npos) << r.output;
  if (!dir.empty()) {
    EXPECT_NE(r.output.find("HUION Huion Tablet_Q630M"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("declares no dial"), std::string::npos) << "the vendor node says why it is not used";
  }
  const auto bad = runBasalt({"devices", "--replay", "/no/such/trace"});
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.output.find("/no/such/trace"), std::string::npos) << bad.output;
}

TEST(DevicesCli, RecordRefusesBadRequestsWithOneLine) {
  auto r = runBasalt({"record", "--synthetic"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.output.find("--output"), std::string::npos) << r.output;
  r = runBasalt({"record", "--output", "x.trace", "--dial", "toaster:1"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.output.find("backend"), std::string::npos) << r.output;
  r = runBasalt({"record", "--output", "x.trace", "--dial", "hid", "--fast", "--seconds", "1"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.output.find("real device"), std::string::npos) << r.output;
}

TEST(DevicesCli, RecordedTraceReplaysBitForBit) {
  const auto dir = test::scratchDir("devices-cli");
  const auto trace = dir / "demo.trace";
  auto r = runBasalt({"record", "--synthetic", "--fast", "--seconds", "2", "--output", trace.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(trace / "trace.toml"));
  EXPECT_TRUE(std::filesystem::exists(trace / "dials.hid"));
  EXPECT_TRUE(std::filesystem::exists(trace / "camera.mkv")) << "camera video is recorded in Matroska";
  EXPECT_NE(r.output.find("recorded 2 device(s)"), std::string::npos) << r.output;
  const auto raw = dir / "raw.trace";
  r = runBasalt({"record", "--synthetic", "--fast", "--seconds", "1", "--raw-video", "--output", raw.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(raw / "camera.bvraw")) << "--raw-video keeps the uncompressed format";
  r = runBasalt({"record", "--synthetic", "--fast", "--seconds", "1", "--output", trace.string()});
  EXPECT_EQ(r.exitCode, 1) << "recording over a trace must be refused";
  EXPECT_NE(r.output.find("holds a finished trace"), std::string::npos) << r.output;

  const auto probe = runBasalt({"run", "--frames", "1", "--headless", "--snapshot", (dir / "probe.png").string()});
  if (probe.exitCode != 0) GTEST_SKIP() << "no headless EGL here: " << probe.output;
  const auto a = dir / "a.png", b = dir / "b.png", plain = dir / "plain.png";
  r = runBasalt({"run", "--frames", "90", "--headless", "--replay", trace.string(), "--snapshot", a.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("replayed trace " + trace.string() + " ("), std::string::npos) << r.output;
  r = runBasalt({"run", "--frames", "90", "--headless", "--replay", trace.string(), "--snapshot", b.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = runBasalt({"run", "--frames", "30", "--headless", "--replay", raw.string()});
  EXPECT_EQ(r.exitCode, 0) << ".bvraw traces still replay: " << r.output;
  r = runBasalt({"run", "--frames", "90", "--headless", "--snapshot", plain.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::string pa = slurp(a), pb = slurp(b), pp = slurp(plain);
  ASSERT_FALSE(pa.empty());
  EXPECT_EQ(pa, pb) << "the same trace under the same show must give the same frame";
  EXPECT_NE(pa, pp) << "the replayed dial turn did not change the show";
}

// Makes sure `run --replay` says once, at the end, what it replayed: the trace, its devices, and
// the input reports and video frames they played, counted here from the trace's own files.
// Example failure: one line per device and none with the counts, or the summary printed twice.
TEST(DevicesCli, ReplaySaysWhatItReplayedOnce) {
  const auto dir = test::scratchDir("devices-cli-replay-report");
  const auto trace = dir / "site.trace";
  auto r = runBasalt({"record", "--synthetic", "--fast", "--seconds", "2", "--raw-video", "--output", trace.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  // What the trace holds: its E: lines and its video frames.
  std::size_t reports = 0;
  std::istringstream hid(slurp(trace / "dials.hid"));
  for (std::string line; std::getline(hid, line);) reports += line.starts_with("E: ") ? 1u : 0u;
  auto video = sim::RawVideoReader::open(trace / "camera.bvraw");
  ASSERT_TRUE(video) << video.error().describe();
  std::size_t frames = 0;
  for (auto f = (*video)->next(); f && *f; f = (*video)->next()) ++frames;
  ASSERT_GT(reports, 0u);
  ASSERT_GT(frames, 0u);

  const auto probe = runBasalt({"run", "--frames", "1", "--headless", "--snapshot", (dir / "probe.png").string()});
  if (probe.exitCode != 0) GTEST_SKIP() << "no headless EGL here: " << probe.output;
  // Once through, with time to spare: 240 frames at 60 fps are 4 s of show time.
  r = runBasalt({"run", "--frames", "240", "--fps", "60", "--headless", "--replay", trace.string(), "--replay-once",
                 "--snapshot", (dir / "s.png").string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::string said = fmt::format("basalt: replayed trace {} (2.0 s recorded on ", trace.string());
  const auto at = r.output.find(said);
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find(said, at + 1), std::string::npos) << "said once: " << r.output;
  EXPECT_NE(r.output.find(fmt::format("): 2 devices, {} input reports and {} video frames over 4.0 s of show time\n",
                                      reports, frames)),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("did not play"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace basalt
