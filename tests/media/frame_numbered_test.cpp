// MoviePlayer::frameNumbered, the call a frame-locked follower shows the leader's movie frame
// with: on a clip whose frames show their own number, the frame asked for is the frame shown
// (read off the pixels), whatever the player's own timeline says; frames before it are passed
// over, the next loop's frame 0 follows the last, a frame not decoded yet is waited for (or
// reported late), a frame already behind the player is sought back to, and the outcome says
// whether the player's own timeline would have picked the same frame. Example failures: a
// follower a fraction of a millisecond behind the leader shows the frame before the leader's;
// frame 0 after the last frame taken from the loop before; a late frame reported as shown.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <thread>

#include "media/movie_player.h"
#include "support/numbered_clip.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

constexpr int kFrames = 30;
constexpr double kFps = 30;
const Nanos kStep = fromSeconds(1.0 / kFps);
constexpr std::chrono::milliseconds kPatience{5000};

std::filesystem::path numberedClip() {
  const auto folder = test::binaryDir() / "test-scratch" / "numbered-clips";
  std::filesystem::create_directories(folder);
  auto clip = test::makeNumberedClip(folder / "frame-numbered.mkv", kFrames, kFps, VideoCodec::kH264, 160, 120);
  EXPECT_TRUE(clip) << clip.error().describe();
  return clip ? *clip : std::filesystem::path{};
}

class MoviePlayerByNumber : public ::testing::Test {
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

  /// Asks for frame `index` at show time `t` and returns the number on the picture shown then
  /// (the one on screen when the call hands over no frame).
  int ask(std::int64_t index, Nanos t, NumberedOutcome& outcome, std::chrono::milliseconds patience = kPatience) {
    NumberedFrame pick = player_->frameNumbered(index, t, patience);
    outcome = pick.outcome;
    if (pick.frame) {
      shown_ = test::readFrameNumber(*pick.frame);
      EXPECT_EQ(shown_, static_cast<int>(pick.frame->sequence)) << "the frame's number and its sequence disagree";
    }
    return shown_;
  }

  std::unique_ptr<MoviePlayer> player_;
  int shown_ = -1;
};

// Makes sure the frame asked for is shown when the player's own timeline says the same, and is
// reported as agreeing. Example failure: every frame of a follower in step counted as corrected.
TEST_F(MoviePlayerByNumber, AFrameTheTimelineAlsoPicksAgrees) {
  NumberedOutcome outcome{};
  for (int n = 0; n < 8; ++n) {
    EXPECT_EQ(ask(n, kStep * n, outcome), n);
    EXPECT_EQ(outcome, NumberedOutcome::kAgreed) << "frame " << n;
  }
  // The same frame again a hair later: it stays, and the timeline agrees.
  EXPECT_EQ(ask(7, kStep * 7 + std::chrono::milliseconds(10), outcome), 7);
  EXPECT_EQ(outcome, NumberedOutcome::kAgreed);
  EXPECT_EQ(player_->currentFrame(), 7);
}

// Makes sure the number wins over the timeline both ways: a frame not due yet on this player's
// timeline, a frame held that the timeline would move past, and frames skipped over. Example
// failure: a follower whose loop came out longer shows the frame before the leader's.
TEST_F(MoviePlayerByNumber, TheNumberWinsOverTheTimeline) {
  NumberedOutcome outcome{};
  EXPECT_EQ(ask(0, Nanos{0}, outcome), 0);
  // Frame 1 at show time 0: the timeline still shows frame 0 there.
  EXPECT_EQ(ask(1, Nanos{0}, outcome), 1);
  EXPECT_EQ(outcome, NumberedOutcome::kCorrected);
  // Frame 1 held at a show time where the timeline shows frame 4.
  EXPECT_EQ(ask(1, kStep * 4, outcome), 1);
  EXPECT_EQ(outcome, NumberedOutcome::kCorrected);
  // Frame 9 from frame 1: the frames between are passed over, not shown.
  const std::uint64_t shownBefore = player_->stats().shown;
  EXPECT_EQ(ask(9, kStep * 4, outcome), 9);
  EXPECT_EQ(outcome, NumberedOutcome::kCorrected);
  EXPECT_EQ(player_->stats().shown, shownBefore + 1);
  EXPECT_EQ(player_->currentFrame(), 9);
}

// Makes sure the next loop's frames follow the last frame of the loop before, by number.
// Example failure: frame 0 taken as a frame behind the player (a seek) or skipped for frame 0
// of the loop after.
TEST_F(MoviePlayerByNumber, FrameZeroAfterTheLastIsTheNextLoops) {
  NumberedOutcome outcome{};
  for (int n = 0; n < 2 * kFrames + 5; ++n) {
    const int want = n % kFrames;
    ASSERT_EQ(ask(want, kStep * n, outcome), want) << "show frame " << n;
    EXPECT_NE(outcome, NumberedOutcome::kLate) << "show frame " << n;
  }
  EXPECT_GE(player_->stats().loops, 2U);
  // The player's own timeline went on across both seams: it still agrees.
  EXPECT_EQ(ask(5, kStep * (2 * kFrames + 5), outcome), 5);
  EXPECT_EQ(outcome, NumberedOutcome::kAgreed);
}

// Makes sure a frame not decoded yet is waited for within the patience, and reported late (the
// shown frame stays) when it does not come in time. Example failure: a follower shows an older
// frame as if it were the leader's, or waits for ever.
TEST_F(MoviePlayerByNumber, AFrameNotDecodedYetIsWaitedForOrLate) {
  // A decoder that hangs after the frames queued now, and is built again 300 ms later.
  MoviePlayerOptions options;
  options.stallTimeout = std::chrono::milliseconds(300);
  player_.reset();
  open(options);
  NumberedOutcome outcome{};
  EXPECT_EQ(ask(0, Nanos{0}, outcome), 0);
  player_->injectStall();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  // Frame 15 is half a loop ahead, beyond the queue (8 frames) and what the decoder had on its
  // way: without patience it is late, and frame 0 stays.
  EXPECT_EQ(ask(15, kStep * 15, outcome, std::chrono::milliseconds(0)), 0);
  EXPECT_EQ(outcome, NumberedOutcome::kLate);
  EXPECT_EQ(player_->currentFrame(), 0);
  // With patience it comes once the decoder is going again.
  EXPECT_EQ(ask(15, kStep * 15, outcome), 15);
  EXPECT_NE(outcome, NumberedOutcome::kLate);
  // A number the clip does not have (its length is exact once it has been played through) is
  // late at once; so is a negative one.
  for (int n = 16; n < kFrames + 3; ++n) (void)ask(n % kFrames, kStep * n, outcome);
  ASSERT_TRUE(player_->info().frameCountExact);
  EXPECT_EQ(ask(kFrames + 4, kStep * 40, outcome), 2);
  EXPECT_EQ(outcome, NumberedOutcome::kLate);
  EXPECT_EQ(ask(-1, kStep * 40, outcome), 2);
  EXPECT_EQ(outcome, NumberedOutcome::kLate);
}

// Makes sure a frame behind the player (already taken from the queue) is sought back to rather
// than a later frame held, and that the player goes on from it. Example failure: a follower
// ahead of its leader keeps showing its own frame.
TEST_F(MoviePlayerByNumber, AFrameBehindThePlayerIsSoughtBackTo) {
  NumberedOutcome outcome{};
  for (int n = 0; n <= 6; ++n) (void)ask(n, kStep * n, outcome);
  EXPECT_EQ(shown_, 6);
  EXPECT_EQ(ask(4, kStep * 7, outcome), 4);
  EXPECT_EQ(outcome, NumberedOutcome::kCorrected);
  EXPECT_EQ(ask(5, kStep * 8, outcome), 5);
  EXPECT_NE(outcome, NumberedOutcome::kLate);
  // More than half a loop ahead is nearer behind: sought back to as well, not decoded through.
  EXPECT_EQ(ask(25, kStep * 9, outcome), 25);
  EXPECT_EQ(outcome, NumberedOutcome::kCorrected);
  EXPECT_EQ(ask(26, kStep * 10, outcome), 26);
  // And a pending seek's frame that is not the one asked for: passed over by number.
  player_->seekFrame(10);
  EXPECT_EQ(ask(12, kStep * 11, outcome), 12);
  EXPECT_EQ(outcome, NumberedOutcome::kCorrected);
}

}  // namespace
}  // namespace basalt::media
