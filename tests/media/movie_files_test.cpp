// Every movie under ../shared/testdata/video, each its own case: it opens with the expected
// size, pixel aspect and frame rate, plays through to its last frame in order (frame count
// exact), or fails with the expected message naming the file and the cause.
// Example failures: a container's text tracks stalling the pipeline (many_tracks.mp4); B-frame
// reordering showing frames out of order; an elementary stream with no duration reporting no
// frames; a truncated file hanging the player; an unsupported codec reaching the screen as a
// crash or a silent black texture.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cctype>
#include <sstream>
#include <string>
#include <vector>

#include "media/movie_player.h"
#include "support/movie_playback.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

struct MovieCase {
  const char* file;  // under testdata/video
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double fps = 0;
  std::int64_t frames = 0;  // frames in the file (last frame number + 1)
  double pixelAspect = 1;
  bool gapsAllowed = false;     // damaged frames the decoder drops
  const char* error = nullptr;  // for files that must fail: part of the message
};

void PrintTo(const MovieCase& c, std::ostream* os) { *os << c.file; }

class MovieFile : public ::testing::TestWithParam<MovieCase> {};

TEST_P(MovieFile, PlaysAsExpectedOrFailsClearly) {
  const MovieCase& c = GetParam();
  const std::filesystem::path data = test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "no ../shared/testdata here (set BASALT_TESTDATA)";
  const std::filesystem::path path = data / "video" / c.file;
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player) << player.error().describe();
  ASSERT_TRUE((*player)->load(path));
  auto info = (*player)->waitUntilLoaded(std::chrono::seconds(20));
  if (c.error) {
    ASSERT_FALSE(info) << c.file << " played but must fail";
    const std::string message = info.error().describe();
    EXPECT_NE(message.find(c.error), std::string::npos) << message;
    EXPECT_NE(message.find(path.string()), std::string::npos) << "the message must name the file: " << message;
    EXPECT_EQ((*player)->state(), MovieState::kFailed);
    // The player is reusable after a failure.
    ASSERT_TRUE((*player)->load(data / "video/h264/stub_h264.mp4"));
    EXPECT_TRUE((*player)->waitUntilLoaded(std::chrono::seconds(20)));
    return;
  }
  ASSERT_TRUE(info) << info.error().describe();
  EXPECT_EQ(info->width, c.width);
  EXPECT_EQ(info->height, c.height);
  EXPECT_NEAR(info->fps, c.fps, 0.01);
  EXPECT_NEAR(info->pixelAspect, c.pixelAspect, 0.01);
  EXPECT_NE(info->format, PixelFormat::kUnknown);
  (*player)->play();
  Nanos t{0};
  const test::Playthrough run = test::playFor(**player, t, info->frameDuration, c.frames * 2 + 50);
  ASSERT_FALSE(run.stalled) << "the player stalled: no frame for 10 s after frame "
                            << (run.frames.empty() ? -1 : run.frames.back());
  ASSERT_TRUE(run.reachedEnd) << "did not reach the end";
  ASSERT_FALSE(run.frames.empty());
  EXPECT_EQ(run.frames.front(), 0);
  EXPECT_EQ(run.frames.back(), c.frames - 1);
  EXPECT_EQ((*player)->frameCount(), c.frames);
  EXPECT_TRUE((*player)->info().frameCountExact);
  for (std::size_t i = 1; i < run.frames.size(); ++i) {
    if (c.gapsAllowed) {
      ASSERT_GT(run.frames[i], run.frames[i - 1]) << "frame " << i;
    } else {
      ASSERT_EQ(run.frames[i], run.frames[i - 1] + 1) << "frame " << i;
    }
  }
  if (!c.gapsAllowed) {
    EXPECT_EQ(static_cast<std::int64_t>(run.frames.size()), c.frames);
  }
}

// Sizes, rates and counts as MANIFEST.md describes the files (counts as decoded: the
// container's duration rounds; elementary streams have none).
INSTANTIATE_TEST_SUITE_P(
    Testdata, MovieFile,
    ::testing::Values(
        MovieCase{"mjpeg/stub_mjpeg.avi", 160, 120, 10, 3}, MovieCase{"mpeg1/pypy_test.mpg", 480, 360, 29.97, 181},
        MovieCase{"mpeg1/pypy_blackbg.mpg", 320, 240, 25, 113},
        MovieCase{"mpeg1/weird_aspect.small.mpg", 352, 288, 25, 37, 64.0 / 45.0, true},
        MovieCase{"mpeg1/test-sample-320x240-29.970fps-14.014s.m1v", 320, 240, 29.97, 420},
        MovieCase{"h264/stub_h264.mp4", 160, 120, 10, 5, 2.0},
        MovieCase{"h264/awesome_widescreen.mov", 320, 180, 10, 72},
        MovieCase{"h264/many_tracks.mp4", 640, 360, 10, 101},
        MovieCase{"h264/test-sample-636x360-25fps-53.76s.mp4", 636, 360, 25, 1344},
        MovieCase{"h264/annexb/SVA_BA2_D.264", 176, 144, 25, 17},
        MovieCase{"h264/annexb/BA_MW_D.264", 176, 144, 25, 100},
        MovieCase{"h264/annexb/MR1_BT_A.h264", 176, 144, 25, 62},
        MovieCase{"h264/annexb/SarVui.264", 176, 144, 25, 17, 80.0 / 33.0},
        MovieCase{"h264/annexb/Static.264", 152, 100, 25, 10},
        MovieCase{"h264/annexb/Cisco_Men_whisper_640x320_CABAC_Bframe_9.264", 640, 320, 25, 9},
        MovieCase{"h264/annexb/test_scalinglist_jm.264", 320, 192, 25, 5},
        MovieCase{"h264/annexb/QCIF_2P_I_allIPCM.264", 176, 144, 25, 2},
        // Error cases of the conformance suite: the decoder conceals, the show goes on.
        MovieCase{"h264/annexb/BA_MW_D_IDR_LOST.264", 176, 144, 25, 97},
        MovieCase{"h264/annexb/Error_I_P.264", 352, 288, 25, 6},
        MovieCase{"negative/broken.mp4", 0, 0, 0, 0, 1, false, "no 'moov' atom"},
        MovieCase{"negative/Mpeg4_smallest.mp4", 0, 0, 0, 0, 1, false, "no playable streams"},
        MovieCase{"negative/AudioVideoInterleave.avi", 0, 0, 0, 0, 1, false, "unsupported video codec: MPEG-4 Video"},
        MovieCase{"negative/stub_mp4v.mp4", 0, 0, 0, 0, 1, false, "unsupported video codec: MPEG-4 Video"}),
    [](const ::testing::TestParamInfo<MovieCase>& param) {
      std::string name = param.param.file;
      for (char& ch : name) {
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      }
      return name;
    });

TEST(MovieFileErrors, MissingFileFailsAtOnceNamingIt) {
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player);
  auto r = (*player)->load("/nonexistent/movie.mp4");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kNotFound);
  EXPECT_NE(r.error().describe().find("/nonexistent/movie.mp4"), std::string::npos);
  EXPECT_EQ((*player)->frameAt(Nanos{0}).get(), nullptr);
}

}  // namespace
}  // namespace basalt::media

// The colorimetry a decoder reports reaches the frames (and so the shader's conversion): an
// H.264 clip flagged BT.709 plays as BT.709 limited range, one flagged BT.601 as BT.601, and
// Motion-JPEG (full-range JPEG) as BT.601 full range. Clips made with GStreamer's own tools.
// Example failure: every stream converted as BT.601 limited, so HD video and JPEG cameras show
// shifted colours.
namespace basalt::media {
namespace {

std::string gstLaunchPath() {
  for (const char* dir : {"/usr/bin", "/bin", "/usr/local/bin"}) {
    const std::filesystem::path p = std::filesystem::path(dir) / "gst-launch-1.0";
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return {};
}

struct ColorimetryCase {
  const char* name;
  const char* caps;     // raw caps into the encoder
  const char* encoder;  // encoder and muxer, gst-launch syntax
  Colorimetry expected;
};

void PrintTo(const ColorimetryCase& c, std::ostream* os) { *os << c.name; }

class StreamColorimetry : public ::testing::TestWithParam<ColorimetryCase> {};

TEST_P(StreamColorimetry, ReachesTheFrames) {
  const ColorimetryCase& c = GetParam();
  const std::string launch = gstLaunchPath();
  if (launch.empty()) GTEST_SKIP() << "gst-launch-1.0 is not installed (gstreamer1.0-tools)";
  const auto file = test::scratchDir(std::string("stream-colorimetry-") + c.name) / "clip.mkv";
  std::vector<std::string> argv{launch, "-q", "videotestsrc", "num-buffers=10", "!", c.caps, "!"};
  std::istringstream encoder(c.encoder);
  for (std::string word; encoder >> word;) argv.push_back(word);
  argv.insert(argv.end(), {"!", "matroskamux", "!", "filesink", "location=" + file.string()});
  const auto made = test::run(argv, {}, std::chrono::seconds(60));
  ASSERT_EQ(made.exitCode, 0) << made.output;
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player) << player.error().describe();
  ASSERT_TRUE((*player)->load(file));
  auto info = (*player)->waitUntilLoaded(std::chrono::seconds(20));
  ASSERT_TRUE(info) << info.error().describe();
  (*player)->play();
  ASSERT_TRUE((*player)->waitForFrameDue(Nanos{0}, std::chrono::seconds(10)));
  FrameRef frame = (*player)->frameAt(Nanos{0});
  ASSERT_TRUE(frame);
  ASSERT_TRUE(isYuv(frame->format)) << "the decoder gave RGB; nothing to convert";
  EXPECT_EQ(frame->colorimetry.matrix, c.expected.matrix) << c.name;
  EXPECT_EQ(frame->colorimetry.range, c.expected.range) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Decoded, StreamColorimetry,
    ::testing::Values(ColorimetryCase{"h264_bt709",
                                      "video/x-raw,format=I420,width=320,height=240,colorimetry=bt709",
                                      "x264enc speed-preset=ultrafast",
                                      {Colorimetry::Matrix::kBt709, Colorimetry::Range::kLimited}},
                      ColorimetryCase{"h264_bt601",
                                      "video/x-raw,format=I420,width=320,height=240,colorimetry=bt601",
                                      "x264enc speed-preset=ultrafast",
                                      {Colorimetry::Matrix::kBt601, Colorimetry::Range::kLimited}},
                      ColorimetryCase{"mjpeg",
                                      "video/x-raw,format=I420,width=320,height=240",
                                      "jpegenc",
                                      {Colorimetry::Matrix::kBt601, Colorimetry::Range::kFull}}),
    [](const ::testing::TestParamInfo<ColorimetryCase>& i) { return std::string(i.param.name); });

}  // namespace
}  // namespace basalt::media
