// Movies on the GPU end to end, headless: a MoviePlayer's frames through a StreamTexture read
// back with the right number on every show frame (a loop seam included); four streams at once,
// at four frame rates, each showing on every show frame the newest frame due and never one from
// the future; the Zoom picture drawn over the scene where it is put, and moved.
// Example failures: a stream texture that lags a frame behind its player; two streams sharing
// one texture or one plane; a 25 fps clip shown a frame early on a 60 fps show; the Zoom picture
// upside down or not moving.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "kiosk/show/video_streams.h"
#include "media/movie_player.h"
#include "render/output.h"
#include "render/renderer.h"
#include "render/stream_texture.h"
#include "runtime/bindings.h"
#include "runtime/show/show.h"
#include "support/numbered_clip.h"
#include "support/test_paths.h"

namespace basalt::render {
namespace {

std::filesystem::path clip(const std::string& name, int frames, double fps, media::VideoCodec codec, int first) {
  const auto folder = test::binaryDir() / "test-scratch" / "numbered-clips";
  std::filesystem::create_directories(folder);
  auto c = test::makeNumberedClip(folder / name, frames, fps, codec, 160, 120, first);
  EXPECT_TRUE(c) << c.error().describe();
  return c ? *c : std::filesystem::path{};
}

class VideoTextures : public ::testing::Test {
 protected:
  void SetUp() override {
    auto output = createHeadlessOutput({320, 240});
    if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
    output_ = std::move(*output);
  }
  std::unique_ptr<media::MoviePlayer> startPlayer(const std::filesystem::path& file) {
    auto p = media::MoviePlayer::create({});
    EXPECT_TRUE(p);
    if (!p) return nullptr;
    EXPECT_TRUE((*p)->load(file));
    EXPECT_TRUE((*p)->waitUntilLoaded(std::chrono::seconds(20)));
    (*p)->setRepeat(true);
    (*p)->play();
    return std::move(*p);
  }
  std::unique_ptr<Output> output_;
};

TEST_F(VideoTextures, EveryShowFrameShowsTheDueMovieFrame) {
  auto player = startPlayer(clip("tex-h264.mkv", 30, 30, media::VideoCodec::kH264, 0));
  ASSERT_TRUE(player);
  auto stream = StreamTexture::create("movie");
  ASSERT_TRUE(stream);
  Image pixels;
  const Nanos step = fromSeconds(1.0 / 30);
  for (int i = 0; i < 45; ++i) {  // one and a half passes: the loop seam is checked too
    const Nanos t = step * i;
    player->waitForFrameDue(t, std::chrono::seconds(10));
    ASSERT_TRUE((*stream)->update(player->frameAt(t)));
    ASSERT_TRUE((*stream)->readPixels(pixels));
    ASSERT_EQ(test::readImageNumber(pixels, 0, 0, pixels.width, pixels.height), i % 30) << "show frame " << i;
  }
  EXPECT_EQ((*stream)->conversions(), 45u);
}

TEST_F(VideoTextures, FourStreamsAtFourRatesNeverEarly) {
  struct Spec {
    const char* file;
    double fps;
    media::VideoCodec codec;
    int first;
  };
  const std::vector<Spec> specs = {{"four-a.mkv", 30, media::VideoCodec::kH264, 0},
                                   {"four-b.avi", 25, media::VideoCodec::kMjpeg, 100},
                                   {"four-c.webm", 15, media::VideoCodec::kVp8, 200},
                                   {"four-d.webm", 10, media::VideoCodec::kVp9, 300}};
  std::vector<std::unique_ptr<media::MoviePlayer>> players;
  std::vector<std::unique_ptr<StreamTexture>> streams;
  TextureRegistry registry;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    players.push_back(startPlayer(clip(specs[i].file, 40, specs[i].fps, specs[i].codec, specs[i].first)));
    ASSERT_TRUE(players.back());
    auto s = StreamTexture::create(fmt::format("stream{}", i));
    ASSERT_TRUE(s);
    streams.push_back(std::move(*s));
  }
  const double showFps = 60;
  Image pixels;
  for (int n = 0; n < 120; ++n) {  // two seconds of a 60 fps show
    const Nanos t = frameTime(n, showFps);
    for (std::size_t i = 0; i < specs.size(); ++i) {
      players[i]->waitForFrameDue(t, std::chrono::seconds(10));
      ASSERT_TRUE(streams[i]->update(players[i]->frameAt(t)));
      streams[i]->publish(registry);
    }
    for (std::size_t i = 0; i < specs.size(); ++i) {
      ASSERT_TRUE(streams[i]->readPixels(pixels));
      // The newest frame due: floor(t * fps), never the next one.
      const auto due = static_cast<int>(std::floor(toSeconds(t) * specs[i].fps + 1e-6)) % 40;
      ASSERT_EQ(test::readImageNumber(pixels, 0, 0, pixels.width, pixels.height), specs[i].first + due)
          << "stream " << i << " at show frame " << n;
    }
  }
  EXPECT_EQ(registry.size(), 4u);
  for (std::size_t i = 0; i < specs.size(); ++i) {
    EXPECT_NE(registry.find(fmt::format("stream{}", i))->id, registry.find(fmt::format("stream{}", (i + 1) % 4))->id);
  }
}

TEST_F(VideoTextures, ZoomPictureSitsWhereItIsPutAndMoves) {
  auto player = startPlayer(clip("zoom.mkv", 30, 30, media::VideoCodec::kH264, 0));
  ASSERT_TRUE(player);
  auto stream = StreamTexture::create("movie");
  ASSERT_TRUE(stream);
  auto overlay = PictureOverlay::create();
  ASSERT_TRUE(overlay);
  auto renderer = Renderer::create();
  ASSERT_TRUE(renderer);
  player->seekFrame(21);
  player->waitForFrameDue(Nanos{0}, std::chrono::seconds(10));
  ASSERT_TRUE((*stream)->update(player->frameAt(Nanos{0})));
  runtime::Show show = runtime::Show::makeDefault();
  auto drawAt = [&](PictureRect rect) {
    Image out;
    EXPECT_TRUE(output_->beginFrame());
    (*renderer)->draw(show, runtime::computeView(show, 320.0f / 240.0f), output_->size());
    (*overlay)->draw((*stream)->view(), rect, output_->size());
    EXPECT_TRUE(output_->readBack(out));
    return out;
  };
  // LAVA's "1/2x": half the movie's size, top-left at (10, 20).
  const Image a = drawAt({10, 20, 80, 60});
  EXPECT_EQ(test::readImageNumber(a, 10, 20, 80, 60), 21);
  EXPECT_EQ(a.at(5, 5, 0) + a.at(5, 5, 1) + a.at(5, 5, 2), 0) << "outside the picture: the background";
  // Moved (LAVA: Shift + drag) to the bottom-right corner, at full size.
  const Image b = drawAt({150, 110, 160, 120});
  EXPECT_EQ(test::readImageNumber(b, 150, 110, 160, 120), 21);
  EXPECT_NE(test::readImageNumber(b, 10, 20, 80, 60), 21) << "the picture left its old place";
}

TEST_F(VideoTextures, ZoomDialsMoveTheZoomPictureOfAShow) {
  // The Zoom picture moved by dials, the way `basalt run --zoom PART --zoom-dials 6,7 --replay`
  // wires it: the dials' turns go through the show's Bindings (move_zoom_x/y) to VideoStreams,
  // which draws the picture at its new place on the next frame.
  // Failure caught: moveZoom with nothing calling it; dials that turn the object instead.
  const auto file = clip("zoom-dials-40.mkv", 30, 30, media::VideoCodec::kH264, 40);
  auto renderer = Renderer::create();
  ASSERT_TRUE(renderer);
  runtime::Show show = runtime::Show::makeDefault();
  kiosk::MovieStreamSpec spec;
  spec.name = "movie";
  spec.files = {file};
  spec.zoom = kiosk::ZoomSpec{0.5, 10, 20};
  auto streams = kiosk::VideoStreams::create({spec}, show, **renderer, true);
  ASSERT_TRUE(streams) << streams.error().describe();
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  bindings.setDial(6, {runtime::Action::kMoveZoomX, 320});
  bindings.setDial(7, {runtime::Action::kMoveZoomY, 240});
  (*streams)->followZoomDials(&bindings);
  std::int64_t frame = 0;
  auto drawFrame = [&] {
    kiosk::FrameContext context;
    context.frame = frame;
    context.time = Nanos{0};  // the movie's first frame, on every frame of this test
    ++frame;
    Image out;
    EXPECT_TRUE((*streams)->beforeDraw(context));
    EXPECT_TRUE(output_->beginFrame());
    (*renderer)->draw(show, runtime::computeView(show, 320.0f / 240.0f), output_->size());
    EXPECT_TRUE((*streams)->afterDraw(context, *output_));
    EXPECT_TRUE(output_->readBack(out));
    return out;
  };
  const Image a = drawFrame();
  EXPECT_EQ(test::readImageNumber(a, 10, 20, 80, 60), 40) << "half size at (10, 20)";
  const Mat4 object = show.position().global;
  // Half a turn on each dial: half the output across and down.
  EXPECT_TRUE(bindings.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 6, 0.5}, show));
  EXPECT_TRUE(bindings.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 7, 0.25}, show));
  EXPECT_TRUE(bindings.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 7, 0.25}, show));
  const Image b = drawFrame();
  const auto rect = (*streams)->zoomRect("movie");
  ASSERT_TRUE(rect.has_value());
  EXPECT_FLOAT_EQ(rect->x, 170.0f);
  EXPECT_FLOAT_EQ(rect->y, 140.0f);
  EXPECT_EQ(test::readImageNumber(b, 170, 140, 80, 60), 40) << "the picture is at its new place";
  EXPECT_NE(test::readImageNumber(b, 10, 20, 80, 60), 40) << "and left the old one";
  EXPECT_EQ(show.position().global.m, object.m) << "the zoom dials did not turn the object";
  // No more turns: it stays.
  const Image c = drawFrame();
  EXPECT_EQ(test::readImageNumber(c, 170, 140, 80, 60), 40);
}

}  // namespace
}  // namespace basalt::render
