// LAVA's VCR remote (manual §7.1) on clips whose frames show their own number: play, pause,
// stop, step forward and back, rewind, fast-forward 10, shuttle both ways, seek to a frame and
// to a time, repeat with no gap, playlists, unload and reload; and every codec Basalt records
// plays back frame-exactly (H.264, Motion-JPEG, VP8, VP9 in Matroska, MP4, AVI and WebM).
// Each check reads the number off the decoded pixels, so a frame that is merely labelled right
// cannot pass. Example failures: a step that lands one frame off (an inaccurate seek keyframe);
// a loop that shows a frame twice or a black frame at the seam; a seek that shows a stale frame
// from before it; the shuttle running the wrong way.

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

#include "media/movie_player.h"
#include "support/movie_playback.h"
#include "support/numbered_clip.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

constexpr int kFrames = 60;
constexpr double kFps = 30;
const Nanos kStep = fromSeconds(1.0 / kFps);

std::filesystem::path clipFolder() {
  static const std::filesystem::path folder = [] {
    auto p = test::binaryDir() / "test-scratch" / "numbered-clips";
    std::filesystem::create_directories(p);
    return p;
  }();
  return folder;
}

std::filesystem::path numberedClip(const std::string& name, VideoCodec codec, int frames = kFrames, int first = 0) {
  auto clip = test::makeNumberedClip(clipFolder() / name, frames, kFps, codec, 160, 120, first);
  EXPECT_TRUE(clip) << clip.error().describe();
  return clip ? *clip : std::filesystem::path{};
}

class Vcr : public ::testing::Test {
 protected:
  void SetUp() override {
    auto p = MoviePlayer::create({});
    ASSERT_TRUE(p) << p.error().describe();
    player_ = std::move(*p);
    ASSERT_TRUE(player_->load(numberedClip("vcr.mkv", VideoCodec::kH264)));
    auto info = player_->waitUntilLoaded(std::chrono::seconds(20));
    ASSERT_TRUE(info) << info.error().describe();
    ASSERT_EQ(info->frameCount, kFrames);
    EXPECT_EQ(show(), 0) << "a loaded movie shows its first frame";
  }

  /// Advances the show one frame and returns the number on the picture shown then (the last
  /// frame when no new one came).
  int show() {
    player_->waitForFrameDue(t_, std::chrono::seconds(10));
    FrameRef f = player_->frameAt(t_);
    t_ += kStep;
    if (f) {
      last_ = test::readFrameNumber(*f);
      EXPECT_EQ(last_, static_cast<int>(f->sequence)) << "the frame's number and its sequence disagree";
    }
    return last_;
  }
  /// Waits for the frame a control asked for and returns its number as read off the picture.
  int settle() {
    if (player_->waitForFrameDue(t_, std::chrono::seconds(10))) {
      FrameRef f = player_->frameAt(t_);
      if (f) {
        last_ = test::readFrameNumber(*f);
        EXPECT_EQ(last_, static_cast<int>(f->sequence)) << "the frame's number and its sequence disagree";
      }
    }
    t_ += kStep;
    return last_;
  }

  std::unique_ptr<MoviePlayer> player_;
  Nanos t_{0};
  int last_ = -1;
};

TEST_F(Vcr, PlayShowsEveryFrameOnceInOrder) {
  player_->play();
  EXPECT_EQ(player_->transport(), Transport::kPlaying);
  for (int n = 1; n < kFrames; ++n) ASSERT_EQ(show(), n);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(show(), kFrames - 1) << "the last frame stays at the end";
  EXPECT_TRUE(player_->atEnd());
  EXPECT_EQ(player_->currentFrame(), kFrames - 1);
}

TEST_F(Vcr, PauseHoldsTheFrameAndPlayGoesOn) {
  player_->play();
  for (int n = 1; n <= 10; ++n) ASSERT_EQ(show(), n);
  player_->pause();
  for (int i = 0; i < 8; ++i) EXPECT_EQ(show(), 10);
  player_->play();
  for (int n = 11; n <= 20; ++n) ASSERT_EQ(show(), n);
}

TEST_F(Vcr, StepForwardAndBackOneFrameExactly) {
  player_->seekFrame(20);
  ASSERT_EQ(settle(), 20);
  for (int n = 21; n <= 24; ++n) {
    player_->stepForward();
    ASSERT_EQ(settle(), n);
  }
  for (int n = 23; n >= 15; --n) {
    player_->stepBack();
    ASSERT_EQ(settle(), n);
  }
  EXPECT_EQ(player_->transport(), Transport::kPaused);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(show(), 15) << "stepping pauses";
  player_->seekFrame(0);
  ASSERT_EQ(settle(), 0);
  player_->stepBack();
  EXPECT_EQ(settle(), 0) << "step back at the first frame stays there without repeat";
}

TEST_F(Vcr, StepBackWhilePlayingPausesOneFrameBack) {
  player_->play();
  for (int n = 1; n <= 30; ++n) ASSERT_EQ(show(), n);
  player_->stepBack();
  EXPECT_EQ(settle(), 29);
  EXPECT_EQ(show(), 29);
}

TEST_F(Vcr, RewindFastForwardAndStop) {
  player_->play();
  for (int n = 1; n <= 12; ++n) ASSERT_EQ(show(), n);
  player_->fastForward();
  EXPECT_EQ(settle(), 22) << "FFwd moves 10 frames";
  EXPECT_EQ(show(), 23) << "and keeps playing";
  player_->rewind();
  EXPECT_EQ(settle(), 0);
  EXPECT_EQ(show(), 1) << "rewind keeps playing";
  player_->seekFrame(55);
  ASSERT_EQ(settle(), 55);
  player_->fastForward();
  EXPECT_EQ(settle(), kFrames - 1) << "FFwd stops at the last frame";
  player_->stop();
  EXPECT_EQ(player_->transport(), Transport::kStopped);
  EXPECT_EQ(settle(), 0) << "stop shows the first frame";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(show(), 0);
}

TEST_F(Vcr, SeekToFrameAndTime) {
  for (int target : {37, 3, 59, 0, 44}) {
    player_->seekFrame(target);
    ASSERT_EQ(settle(), target);
    EXPECT_EQ(player_->currentFrame(), target);
  }
  player_->seekTime(fromSeconds(1.0));
  EXPECT_EQ(settle(), 30);
  player_->seekTime(fromSeconds(0.51));
  EXPECT_EQ(settle(), 15);
  player_->seekFrame(1000);
  EXPECT_EQ(settle(), kFrames - 1) << "a seek past the end clamps to the last frame";
}

TEST_F(Vcr, ShuttleForwardSkipsFrames) {
  player_->shuttle(2.0);
  for (int i = 1; i <= 10; ++i) ASSERT_EQ(show(), 2 * i);
  player_->shuttle(0.5);
  const int at = show();
  for (int i = 1; i <= 6; ++i) ASSERT_EQ(show(), at + (i + 1) / 2) << "half speed shows each frame twice";
}

TEST_F(Vcr, ShuttleBackwardRunsTheMovieBackwards) {
  player_->seekFrame(40);
  ASSERT_EQ(settle(), 40);
  player_->shuttle(-1.0);
  int previous = 40;
  for (int i = 0; i < 20; ++i) {
    const int n = settle();
    ASSERT_LE(n, previous) << "backwards";
    previous = n;
  }
  EXPECT_LE(previous, 30) << "20 show frames at -1x go back about 20 frames";
  player_->shuttle(-4.0);
  for (int i = 0; i < 20; ++i) settle();
  EXPECT_EQ(player_->currentFrame(), 0) << "reverse stops at the first frame";
}

TEST_F(Vcr, RepeatLoopsWithNoGapNoRepeatNoBlack) {
  player_->setRepeat(true);
  player_->play();
  // Three and a half passes, every show frame checked: 0..59, 0..59, ...
  for (int i = 1; i < kFrames * 7 / 2; ++i) {
    const int n = show();
    ASSERT_EQ(n, i % kFrames) << "show frame " << i;
  }
  EXPECT_GE(player_->stats().loops, 3u);
  EXPECT_FALSE(player_->atEnd());
}

TEST_F(Vcr, RepeatSwitchedOnAtTheEndStartsOver) {
  player_->play();
  for (int n = 1; n < kFrames; ++n) ASSERT_EQ(show(), n);
  EXPECT_EQ(show(), kFrames - 1);
  player_->setRepeat(true);
  player_->play();
  int n = show();
  for (int i = 0; i < 5 && n == kFrames - 1; ++i) n = show();
  EXPECT_EQ(n, 0);
  EXPECT_EQ(show(), 1);
}

TEST_F(Vcr, UnloadShowsNothingAndReloadWorks) {
  player_->unload();
  EXPECT_EQ(player_->state(), MovieState::kEmpty);
  EXPECT_EQ(player_->frameAt(t_).get(), nullptr);
  ASSERT_TRUE(player_->load(numberedClip("vcr.mkv", VideoCodec::kH264)));
  ASSERT_TRUE(player_->waitUntilLoaded(std::chrono::seconds(20)));
  EXPECT_EQ(settle(), 0);
  player_->play();
  EXPECT_EQ(show(), 1);
}

TEST(Playlist, MovesToTheNextClipWithNoGapAndLoops) {
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player);
  const auto a = numberedClip("list-a.mkv", VideoCodec::kH264, 20, 0);
  const auto b = numberedClip("list-b.avi", VideoCodec::kMjpeg, 15, 100);
  const auto c = numberedClip("list-c.mp4", VideoCodec::kH264, 10, 200);
  ASSERT_TRUE((*player)->loadPlaylist({a, b, c}));
  ASSERT_TRUE((*player)->waitUntilLoaded(std::chrono::seconds(20)));
  (*player)->setRepeat(true);
  (*player)->play();
  std::vector<int> expected;
  for (int pass = 0; pass < 2; ++pass) {
    for (int n = 0; n < 20; ++n) expected.push_back(n);
    for (int n = 0; n < 15; ++n) expected.push_back(100 + n);
    for (int n = 0; n < 10; ++n) expected.push_back(200 + n);
  }
  Nanos t{0};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    (*player)->waitForFrameDue(t, std::chrono::seconds(10));
    FrameRef f = (*player)->frameAt(t);
    ASSERT_TRUE(f) << "no new frame at show frame " << i << ": a gap";
    ASSERT_EQ(test::readFrameNumber(*f), expected[i]) << "show frame " << i;
    t += kStep;
  }
  EXPECT_GE((*player)->stats().loops, 5u);
}

TEST(Playlist, EndsAfterTheLastClipWithoutRepeat) {
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player);
  const auto a = numberedClip("list-a.mkv", VideoCodec::kH264, 20, 0);
  const auto b = numberedClip("list-b.avi", VideoCodec::kMjpeg, 15, 100);
  ASSERT_TRUE((*player)->loadPlaylist({a, b}));
  ASSERT_TRUE((*player)->waitUntilLoaded(std::chrono::seconds(20)));
  (*player)->play();
  Nanos t{0};
  const test::Playthrough run = test::playFor(**player, t, kStep, 100);
  EXPECT_TRUE(run.reachedEnd);
  EXPECT_EQ(run.frames.size(), 35u);
  EXPECT_EQ((*player)->currentClip(), 1u);
}

struct CodecCase {
  const char* file;
  VideoCodec codec;
};

class RecordedCodec : public ::testing::TestWithParam<CodecCase> {};

TEST_P(RecordedCodec, PlaysBackFrameExactly) {
  const auto clip = numberedClip(GetParam().file, GetParam().codec, 24);
  ASSERT_FALSE(clip.empty());
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player);
  ASSERT_TRUE((*player)->load(clip));
  auto info = (*player)->waitUntilLoaded(std::chrono::seconds(20));
  ASSERT_TRUE(info) << info.error().describe();
  EXPECT_EQ(info->width, 160u);
  EXPECT_EQ(info->height, 120u);
  EXPECT_NEAR(info->fps, kFps, 0.01);
  (*player)->play();
  Nanos t{0};
  int expected = 0;
  for (int i = 0; i < 24; ++i) {
    (*player)->waitForFrameDue(t, std::chrono::seconds(10));
    FrameRef f = (*player)->frameAt(t);
    ASSERT_TRUE(f) << "frame " << i;
    ASSERT_EQ(test::readFrameNumber(*f), expected++);
    t += kStep;
  }
  (*player)->seekFrame(13);
  EXPECT_EQ(test::settle(**player, t), 13);
}

INSTANTIATE_TEST_SUITE_P(
    Codecs, RecordedCodec,
    ::testing::Values(CodecCase{"h264.mkv", VideoCodec::kH264}, CodecCase{"h264.mp4", VideoCodec::kH264},
                      CodecCase{"mjpeg.avi", VideoCodec::kMjpeg}, CodecCase{"mjpeg.mkv", VideoCodec::kMjpeg},
                      CodecCase{"vp8.webm", VideoCodec::kVp8}, CodecCase{"vp9.webm", VideoCodec::kVp9}),
    [](const ::testing::TestParamInfo<CodecCase>& p) {
      std::string name = p.param.file;
      for (char& ch : name) {
        if (ch == '.') ch = '_';
      }
      return name;
    });

}  // namespace
}  // namespace basalt::media
