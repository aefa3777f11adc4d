// `basalt run`'s movie options: --movie PART=FILE, --zoom PART[=SCALE][@X,Y], --record and its
// codec, parsed into what the kiosk wires; bad values are usage errors that name the option.
// Example failures: a part name with spaces cut at the space; "nan" accepted as a Zoom scale; a
// --zoom for a movie that was never given accepted silently.

#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "app/run_command.h"
#include "kiosk/show/video_streams.h"

namespace basalt::kiosk {
namespace {

TEST(VideoOptions, MovieNamesAPartAndAFile) {
  auto m = parseMovieOption("face 1=/media/clips/intro.mp4");
  ASSERT_TRUE(m) << m.error().describe();
  EXPECT_EQ(m->first, "face 1");
  EXPECT_EQ(m->second, "/media/clips/intro.mp4");
  for (std::string_view bad : {"nofile", "=x.mp4", "part="}) {
    auto r = parseMovieOption(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message().find("--movie needs PART=FILE"), std::string::npos);
  }
}

TEST(VideoOptions, ZoomTakesScaleAndPosition) {
  auto z = parseZoomOption("face 1=0.5@12,34.5");
  ASSERT_TRUE(z) << z.error().describe();
  EXPECT_EQ(z->first, "face 1");
  EXPECT_DOUBLE_EQ(z->second.scale, 0.5);
  EXPECT_FLOAT_EQ(z->second.x, 12);
  EXPECT_FLOAT_EQ(z->second.y, 34.5f);
  auto plain = parseZoomOption("movie");
  ASSERT_TRUE(plain);
  EXPECT_DOUBLE_EQ(plain->second.scale, 0.5) << "LAVA's 1/2x by default";
  for (std::string_view bad : {"m=nan", "m=0", "m=-1", "m=100", "m=1@5", "m=1@x,y", "m=1@inf,3", "=1", "m=1@1,2,3"}) {
    EXPECT_FALSE(parseZoomOption(bad)) << bad;
  }
}

TEST(VideoOptions, RunOptionsCollectMoviesZoomsAndRecording) {
  const std::vector<std::string_view> args = {
      "--movie",  "a=1.mp4",   "--movie",        "a=2.mkv", "--movie",         "b=3.webm", "--zoom",       "b=2@0,0",
      "--record", "out/r.mp4", "--record-codec", "mjpeg",   "--record-frames", "330",      "--movie-once", "--audio"};
  auto o = parseRunOptions(args);
  ASSERT_TRUE(o) << o.error().describe();
  ASSERT_EQ(o->movies.size(), 3u);
  EXPECT_EQ(o->movies[1].second, "2.mkv");
  ASSERT_EQ(o->zooms.size(), 1u);
  EXPECT_EQ(o->zooms[0].first, "b");
  EXPECT_EQ(*o->record, "out/r.mp4");
  EXPECT_EQ(o->recordCodec, "mjpeg");
  EXPECT_EQ(*o->recordFrames, 330);
  EXPECT_TRUE(o->movieOnce);
  EXPECT_TRUE(o->audio);
}

TEST(VideoOptions, ZoomWithoutItsMovieAndUnknownCodecsAreErrors) {
  const std::vector<std::string_view> zoom = {"--movie", "a=1.mp4", "--zoom", "b"};
  auto r = parseRunOptions(zoom);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("--zoom b: no movie of that name"), std::string::npos) << r.error().message();
  const std::vector<std::string_view> codec = {"--record-codec", "divx"};
  auto c = parseRunOptions(codec);
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message().find("h264, mjpeg, vp8, vp9"), std::string::npos);
}

// --zoom-dials X,Y: the two dials that move the Zoom picture. Failure caught: one dial for both
// directions, a dial number past the bindings' table, dials given with no Zoom picture to move.
TEST(VideoOptions, ZoomDialsNameTwoDialsAndNeedAZoom) {
  const std::vector<std::string_view> ok = {"--movie", "a=1.mp4", "--zoom", "a", "--zoom-dials", "6,7"};
  auto o = parseRunOptions(ok);
  ASSERT_TRUE(o) << o.error().describe();
  ASSERT_TRUE(o->zoomDials.has_value());
  EXPECT_EQ(o->zoomDials->first, 6);
  EXPECT_EQ(o->zoomDials->second, 7);
  for (std::string_view bad : {"6", "6,6", "6,x", "-1,2", "6,32", "6,7,8"}) {
    const std::vector<std::string_view> args = {"--movie", "a=1.mp4", "--zoom", "a", "--zoom-dials", bad};
    auto r = parseRunOptions(args);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message().find("--zoom-dials needs two different dial numbers"), std::string::npos)
        << r.error().message();
  }
  const std::vector<std::string_view> noZoom = {"--movie", "a=1.mp4", "--zoom-dials", "6,7"};
  auto n = parseRunOptions(noZoom);
  ASSERT_FALSE(n);
  EXPECT_NE(n.error().message().find("give --zoom PART too"), std::string::npos) << n.error().message();
}

}  // namespace
}  // namespace basalt::kiosk
