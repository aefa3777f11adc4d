#include "media/frame_picker.h"

#include "media/movie_player.h"

namespace basalt::media {

namespace {

FrameOutcome outcomeOf(NumberedOutcome outcome) {
  switch (outcome) {
    case NumberedOutcome::kAgreed: return FrameOutcome::kAgreed;
    case NumberedOutcome::kCorrected: return FrameOutcome::kCorrected;
    case NumberedOutcome::kLate: return FrameOutcome::kLate;
  }
  return FrameOutcome::kLate;
}

}  // namespace

PickedFrame pickFrame(MoviePlayer& player, const FrameRequest& request) {
  const Nanos t = request.showTime;
  if (request.leaderFrame >= 0) {
    // A follower shows the leader's frame by its number, not by its own decoder's timestamps:
    // two decoders' timestamps (and loops) need not add up alike.
    NumberedFrame pick =
        player.frameNumbered(request.leaderFrame, t, framePatience(request.manualClock, request.patience));
    return {std::move(pick.frame), outcomeOf(pick.outcome)};
  }
  // The own timeline: a frame-locked node's patience is for the group's timeline only; a movie
  // that keeps to a timeline of its own has nothing to wait for on the system clock.
  const std::chrono::milliseconds wait =
      framePatience(request.manualClock, request.onGroupTimeline ? request.patience : std::chrono::milliseconds(0));
  if (wait.count() > 0) player.waitForFrameDue(t, wait);
  PickedFrame out{player.frameAt(t), FrameOutcome::kNone};
  if (request.onGroupTimeline && out.frame && wait.count() > 0) {
    // The frame a seek onto the group's timeline brought is due when the seek was asked for; a
    // node that waited for it takes the frame due now as well.
    player.waitForFrameDue(t, wait);
    if (FrameRef newer = player.frameAt(t)) out.frame = std::move(newer);
  }
  return out;
}

}  // namespace basalt::media
