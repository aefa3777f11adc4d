// `basalt run` with movies and recording, as a user runs it: the README's run command records
// the default show to a playable file; a movie plays as a part's texture and as the Zoom picture
// in the snapshot; a missing or unsupported movie and a full disk each give one clear line
// naming the file and the cause while the show runs to its end.
// Example failures: a recording with no index (MP4 not finalised) or the wrong frame count; a
// bad movie that stops the show or crashes it; a full disk that hangs the encoder.

#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "media/image_io.h"
#include "media/movie_player.h"
#include "support/movie_playback.h"
#include "support/numbered_clip.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

test::ProcessResult runBasalt(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return test::run(argv, {}, std::chrono::seconds(120));
}

bool eglAvailable(std::string& why) {
  const auto probe = runBasalt(
      {"run", "--frames", "1", "--headless", "--snapshot", (test::scratchDir("video-cli-probe") / "p.png").string()});
  if (probe.exitCode == 0) return true;
  why = probe.output;
  return false;
}

/// Opens a recording with Basalt's own player and counts its frames.
std::int64_t countFrames(const std::filesystem::path& file, media::MovieInfo& info) {
  auto player = media::MoviePlayer::create({});
  if (!player || !(*player)->load(file)) return -1;
  auto loaded = (*player)->waitUntilLoaded(std::chrono::seconds(20));
  if (!loaded) {
    ADD_FAILURE() << loaded.error().describe();
    return -1;
  }
  info = *loaded;
  (*player)->play();
  Nanos t{0};
  const auto run = test::playFor(**player, t, info.frameDuration, 10000);
  return static_cast<std::int64_t>(run.frames.size());
}

TEST(VideoCli, RecordsTheDefaultShow) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("video-cli-record");
  for (const char* name : {"show.mp4", "show.mkv", "show.avi"}) {
    const auto file = dir / name;
    const auto r = runBasalt({"run", "--frames", "24", "--fps", "24", "--size", "320x240", "--record", file.string(),
                              "--snapshot", (dir / "last.png").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("recorded 24 frames to " + file.string()), std::string::npos) << r.output;
    media::MovieInfo info;
    EXPECT_EQ(countFrames(file, info), 24) << name;
    EXPECT_EQ(info.width, 320u);
    EXPECT_EQ(info.height, 240u);
    EXPECT_NEAR(info.fps, 24, 0.01);
  }
}

TEST(VideoCli, RecordFramesStopsTheRecordingNotTheShow) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto file = test::scratchDir("video-cli-record-frames") / "rec.mkv";
  const auto r = runBasalt(
      {"run", "--frames", "40", "--record", file.string(), "--record-frames", "10", "--record-codec", "mjpeg"});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("40 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("recorded 10 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Motion-JPEG in Matroska"), std::string::npos) << r.output;
}

TEST(VideoCli, RecordsUntilStoppedAndFinishesTheFile) {
  // LAVA's "Rec" until stopped: a live show recorded with no frame limit, ended by Ctrl-C, leaves
  // a finished MP4 (its index written) holding every frame it says it recorded.
  // Example failure: an MP4 cut off at the signal, which no player opens.
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto file = test::scratchDir("video-cli-record-stop") / "live.mp4";
  test::Process p = test::Process::start({(test::binaryDir() / "basalt").string(), "run", "--headless", "--size",
                                          "160x120", "--fps", "15", "--record", file.string()});
  ASSERT_TRUE(p.started());
  ASSERT_TRUE(test::waitUntilSignalBlocked(p.pid(), SIGINT)) << p.outputSoFar();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  p.signal(SIGINT);
  const auto r = p.wait(std::chrono::seconds(60));
  ASSERT_FALSE(r.timedOut) << r.output;
  ASSERT_EQ(r.exitCode, 0) << r.output;
  std::smatch recorded;
  ASSERT_TRUE(std::regex_search(r.output, recorded, std::regex("recorded ([0-9]+) frames to ")))
      << "says how much it recorded: " << r.output;
  const std::int64_t frames = std::stoll(recorded[1]);
  EXPECT_GT(frames, 5) << r.output;
  media::MovieInfo info;
  EXPECT_EQ(countFrames(file, info), frames) << "the file holds what was recorded";
  EXPECT_EQ(info.width, 160u);
  EXPECT_NEAR(info.fps, 15, 0.01);
}

TEST(VideoCli, FullDiskIsAClearErrorAndTheShowGoesOn) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  if (access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full to stand for a full disk";
  // /dev/full takes the open and fails every write with ENOSPC, as a full disk does.
  const std::filesystem::path full = test::scratchDir("video-cli-full") / "full.mkv";
  std::filesystem::create_symlink("/dev/full", full);
  const auto r = runBasalt({"run", "--frames", "60", "--record", full.string()});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("60 frames"), std::string::npos) << "the show ran to its end: " << r.output;
  EXPECT_NE(r.output.find(full.string()), std::string::npos) << "names the file: " << r.output;
  EXPECT_NE(r.output.find("space"), std::string::npos) << "says the disk is full: " << r.output;
}

TEST(VideoCli, MovieOnAPartAndAsTheZoomPicture) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("video-cli-movie");
  auto clip = test::makeNumberedClip(dir / "numbers.mkv", 30, 30, media::VideoCodec::kH264);
  ASSERT_TRUE(clip) << clip.error().describe();
  const auto snapshot = dir / "last.png";
  // 40 show frames at 30 fps: the last shows movie frame 39 - 30 = 9 (it loops).
  const auto r = runBasalt({"run", "--frames", "40", "--fps", "30", "--movie", "face 1=" + clip->string(), "--zoom",
                            "face 1=1@20,30", "--snapshot", snapshot.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("converted in the shader"), std::string::npos) << "the upload path is reported";
  EXPECT_EQ(r.output.find("no part of that name"), std::string::npos) << "'face 1' is a part of the cube";
  auto image = media::readImage(snapshot);
  ASSERT_TRUE(image) << image.error().describe();
  EXPECT_EQ(test::readImageNumber(*image, 20, 30, 160, 120), 9);
}

TEST(VideoCli, AMistypedPartNameSaysWhichPartsThereAre) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::scratchDir("video-cli-part-typo");
  auto clip = test::makeNumberedClip(dir / "numbers.mkv", 5, 30, media::VideoCodec::kH264);
  ASSERT_TRUE(clip) << clip.error().describe();
  // The start-up cube's parts are 'face 1' to 'face 6' (LAVA's colour cube).
  for (const auto& [typed, meant] :
       std::vector<std::pair<std::string, std::string>>{{"fcae 2", "face 2"}, {"Face 3", "face 3"}}) {
    const auto r = runBasalt(
        {"run", "--frames", "3", "--movie", typed + "=" + clip->string(), "--snapshot", (dir / "s.png").string()});
    EXPECT_EQ(r.exitCode, 0) << "a texture nobody shows is a warning, the show goes on: " << r.output;
    EXPECT_NE(r.output.find("movie '" + typed +
                            "': the show has no part of that name (its parts: 'face 1', 'face 2', "
                            "'face 3', 'face 4', 'face 5', 'face 6'; did you mean '" +
                            meant + "'?)"),
              std::string::npos)
        << r.output;
  }
}

TEST(VideoCli, BadMoviesAreReportedAndTheShowGoesOn) {
  std::string why;
  if (!eglAvailable(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  std::vector<std::pair<std::string, std::string>> cases = {{"/nonexistent/clip.mp4", "no such movie file"}};
  const auto data = test::testdataDir();
  if (!data.empty()) {
    cases.emplace_back((data / "video/negative/broken.mp4").string(), "moov");
    cases.emplace_back((data / "video/negative/stub_mp4v.mp4").string(), "unsupported video codec");
  }
  for (const auto& [file, cause] : cases) {
    const auto r = runBasalt({"run", "--frames", "20", "--movie", "front=" + file, "--snapshot",
                              (test::scratchDir("video-cli-bad") / "s.png").string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("20 frames"), std::string::npos) << "the show went on: " << r.output;
    EXPECT_NE(r.output.find(file), std::string::npos) << "names the file: " << r.output;
    EXPECT_NE(r.output.find(cause), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("fallback"), std::string::npos) << r.output;
  }
}

TEST(VideoCli, UsageErrorsNameTheOption) {
  for (const auto& [args, needle] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"run", "--movie", "nofile"}, "--movie needs PART=FILE"},
           {{"run", "--zoom", "x=0.5"}, "no movie of that name"},
           {{"run", "--record-codec", "divx"}, "unknown video codec"},
           {{"run", "--zoom", "x=big"}, "--zoom needs"}}) {
    const auto r = runBasalt(args);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << r.output;
  }
  const auto r = runBasalt({"run", "--frames", "2", "--record", "/tmp/x.flv"});
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find(".mkv, .mp4"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace basalt
