// media::pickFrame, the one place that decides which movie frame a frame of the show shows (movie
// textures, movie items and a script's VCR all call it), tried on a real MoviePlayer with a clip
// whose frames show their own number: frame n is stamped n / fps and shows n, so the frame
// expected at a show time follows from how the clip was made. Makes sure an offline run (manual
// clock) gets the frame due, a follower gets the leader's frame by its number with the outcome
// it reports, a movie sought onto a group's timeline shows the frame due now rather than the
// seek's, and nothing waits on the system clock without a frame-locked patience. Example
// failures: an offline run shows an older frame because the decoder was slow; a follower's frame
// counted as agreeing when its own timeline would have shown another; a show on the system clock
// stalls its frame loop on a hung decoder.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <thread>

#include "media/frame_picker.h"
#include "media/movie_player.h"
#include "support/numbered_clip.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

constexpr int kFrames = 30;
constexpr double kFps = 30;
const Nanos kStep = fromSeconds(1.0 / kFps);
/// Frames decoded before the decoder of openAndStall() hangs: 1 to this one at least.
constexpr int kDecodedBeforeStall = 5;
/// A frame well beyond the player's queue (8 frames) and what its decoder has on the way.
constexpr int kFarFrame = 15;

std::filesystem::path numberedClip() {
  const auto folder = test::binaryDir() / "test-scratch" / "numbered-clips";
  std::filesystem::create_directories(folder);
  auto clip = test::makeNumberedClip(folder / "frame-picker.mkv", kFrames, kFps, VideoCodec::kH264, 160, 120);
  EXPECT_TRUE(clip) << clip.error().describe();
  return clip ? *clip : std::filesystem::path{};
}

class MovieFramePicker : public ::testing::Test {
 protected:
  void SetUp() override { open({}); }

  void open(MoviePlayerOptions options) {
    auto p = MoviePlayer::create(std::move(options));
    ASSERT_TRUE(p) << p.error().describe();
    player_ = std::move(*p);
    ASSERT_TRUE(player_->load(numberedClip()));
    auto info = player_->waitUntilLoaded(std::chrono::seconds(20));
    ASSERT_TRUE(info) << info.error().describe();
    ASSERT_EQ(info->frameCount, kFrames);
    player_->setRepeat(true);
    player_->play();
  }

  /// A player that shows frame 0, has decoded frames up to kDecodedBeforeStall at least, then
  /// hangs; its decoder is built again a second later.
  void openAndStall() {
    MoviePlayerOptions options;
    options.stallTimeout = std::chrono::milliseconds(1000);
    player_.reset();
    open(options);
    FrameOutcome outcome{};
    ASSERT_EQ(pick({.showTime = Nanos{0}, .manualClock = true}, outcome), 0);
    ASSERT_TRUE(player_->waitForFrameDue(kStep * kDecodedBeforeStall, kFrameTimeout));
    player_->injectStall();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }

  /// Picks a frame for `request` and returns the number on the picture on screen then (the one
  /// shown before when the pick hands over no frame).
  int pick(const FrameRequest& request, FrameOutcome& outcome) {
    PickedFrame picked = pickFrame(*player_, request);
    outcome = picked.outcome;
    if (picked.frame) {
      shown_ = test::readFrameNumber(*picked.frame);
      EXPECT_EQ(shown_, static_cast<int>(picked.frame->sequence)) << "the frame's number and its sequence disagree";
    }
    return shown_;
  }

  std::unique_ptr<MoviePlayer> player_;
  int shown_ = -1;
};

// Makes sure an offline run shows, at each show time, the frame stamped for it. Example failure:
// a frame shown before the decoder delivered the one due, or a frame skipped.
TEST_F(MovieFramePicker, AManualClockGetsTheFrameDue) {
  FrameOutcome outcome{};
  for (int n = 0; n < kFrames; ++n) {
    ASSERT_EQ(pick({.showTime = kStep * n, .manualClock = true}, outcome), n) << "show frame " << n;
    EXPECT_EQ(outcome, FrameOutcome::kNone) << "no leader's frame was asked for";
  }
}

// Makes sure a leader's frame is shown by its number, reported as agreeing while the player's
// own timeline shows the same frame and as corrected when it would not. Example failure: a
// follower ahead of or behind its leader shows its own frame, or counts none as corrected.
TEST_F(MovieFramePicker, TheLeadersFrameComesByNumberWithItsOutcome) {
  FrameOutcome outcome{};
  for (int n = 0; n < 5; ++n) {
    EXPECT_EQ(pick({.showTime = kStep * n, .leaderFrame = n, .manualClock = true}, outcome), n);
    EXPECT_EQ(outcome, FrameOutcome::kAgreed) << "frame " << n;
  }
  // Frame 9 at the show time of frame 5: ahead of the own timeline.
  EXPECT_EQ(pick({.showTime = kStep * 5, .leaderFrame = 9, .manualClock = true}, outcome), 9);
  EXPECT_EQ(outcome, FrameOutcome::kCorrected);
  // Frame 3 at the show time of frame 6: behind the player, sought back to.
  EXPECT_EQ(pick({.showTime = kStep * 6, .leaderFrame = 3, .manualClock = true}, outcome), 3);
  EXPECT_EQ(outcome, FrameOutcome::kCorrected);
  EXPECT_EQ(player_->currentFrame(), 3);
}

// Makes sure a movie sought onto a group's timeline (its frame 3 due at the show time of frame 3)
// shows, when the seek's frame comes at the show time of frame 10, frame 10 as the group does;
// and that a movie not on a group's timeline shows the seek's own frame. Example failure: a node
// that joined late shows the seek's frame, seven frames behind the others, for one frame.
TEST_F(MovieFramePicker, OnAGroupTimelineTheFrameDueNowFollowsTheSeek) {
  constexpr int kSought = 3;
  constexpr int kNow = 10;
  FrameOutcome outcome{};
  player_->seekFrameDueAt(kSought, kStep * kSought, kStep * kSought);
  EXPECT_EQ(pick({.showTime = kStep * kNow, .manualClock = true}, outcome), kSought);
  player_->seekFrameDueAt(kSought, kStep * kSought, kStep * kSought);
  EXPECT_EQ(pick({.showTime = kStep * kNow, .manualClock = true, .onGroupTimeline = true}, outcome), kNow);
  EXPECT_EQ(outcome, FrameOutcome::kNone);
}

// Makes sure a show on the system clock takes what is decoded and never waits for the frame due:
// without a patience, and with one when the movie is not on a group's timeline (the patience is a
// frame-locked node's); an offline run waits until the decoder, built again after its stall,
// delivers it. Example failure: a kiosk's frame loop blocks on a hung decoder.
TEST_F(MovieFramePicker, WithoutPatienceOnTheSystemClockNothingWaits) {
  openAndStall();
  FrameOutcome outcome{};
  const int shown = pick({.showTime = kStep * kFarFrame}, outcome);
  EXPECT_GE(shown, kDecodedBeforeStall) << "the frames decoded before the stall are due: the newest shows";
  EXPECT_LT(shown, kFarFrame) << "the frame due was not decoded before the stall";
  EXPECT_EQ(outcome, FrameOutcome::kNone);
  (void)pick({.showTime = kStep * kFarFrame, .patience = std::chrono::milliseconds(5000)}, outcome);
  EXPECT_EQ(player_->currentFrame(), shown) << "a patience off a group's timeline waits for nothing";
  EXPECT_EQ(pick({.showTime = kStep * kFarFrame, .manualClock = true}, outcome), kFarFrame);
}

// Makes sure a leader's frame not decoded yet is late at once without a patience (the frame on
// screen stays), and comes within one. Example failure: a follower waits on the system clock
// with no patience given, or shows an older frame as the leader's.
TEST_F(MovieFramePicker, ALeadersFrameIsLateWithoutPatienceAndComesWithIt) {
  openAndStall();
  FrameOutcome outcome{};
  EXPECT_EQ(pick({.showTime = kStep * kFarFrame, .leaderFrame = kFarFrame}, outcome), 0);
  EXPECT_EQ(outcome, FrameOutcome::kLate);
  EXPECT_EQ(player_->currentFrame(), 0);
  EXPECT_EQ(
      pick({.showTime = kStep * kFarFrame, .leaderFrame = kFarFrame, .patience = std::chrono::seconds(5)}, outcome),
      kFarFrame);
  EXPECT_NE(outcome, FrameOutcome::kLate);
}

}  // namespace
}  // namespace basalt::media
