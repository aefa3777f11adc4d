#pragma once

/// \file
/// \brief Which movie frame a frame of the show shows, for every place that shows a movie (a
/// movie texture, a movie item, a script's VCR): the frame due at the show time on the player's
/// own timeline, or a frame-locked leader's frame by its number; and how long the frame loop may
/// wait for it. Offline runs (a ManualClock) wait for every frame, so that each one is exact; a
/// show on the system clock never waits, except a frame-locked node, bounded by its patience.

#include <chrono>
#include <cstdint>

#include "runtime/clock.h"
#include "runtime/frame.h"

namespace basalt::media {

class MoviePlayer;

/// \brief How long a frame of an offline run (a ManualClock) waits for the decoder: far longer
/// than any decoder takes for one frame, so that a run on a busy machine stays exact, yet short
/// enough that a decoder that hangs ends the run instead of holding it for ever.
inline constexpr std::chrono::milliseconds kFrameTimeout{10000};

/// \brief What a frame of the show asks of a movie.
struct FrameRequest {
  Nanos showTime{0};              ///< the frame's presentation time on the show clock
  std::int64_t leaderFrame = -1;  ///< frame-locked follower: the leader's frame number; -1: the own timeline
  bool manualClock = false;       ///< offline: wait up to kFrameTimeout for the frame, whatever `patience` says
  /// On the system clock: how long a frame-locked node waits for the leader's frame, and (with
  /// `onGroupTimeline`) for the frame due on the group's timeline. 0: the frame loop never waits.
  std::chrono::milliseconds patience{0};
  /// The movie was sought onto a frame-locked group's timeline (MoviePlayer::seekFrameDueAt()):
  /// the frame that seek brings was due when the seek was asked for, so a node that waited for it
  /// waits again for the frame due now, and shows what the others show in this very frame.
  bool onGroupTimeline = false;
};

/// \brief How the frame was come by.
enum class FrameOutcome : std::uint8_t {
  kNone,       ///< no leader's frame was asked for: the player's own timeline picked it
  kAgreed,     ///< the leader's frame, which the player's own timeline picked too
  kCorrected,  ///< the leader's frame, which the player's own timeline would not have picked
  kLate,       ///< the leader's frame did not come in time: the frame on screen stays
};

/// \brief A frame of a movie for a frame of the show.
struct PickedFrame {
  FrameRef frame;  ///< empty when the frame on screen stays
  FrameOutcome outcome = FrameOutcome::kNone;
};

/// \brief How long a frame waits for the decoder: kFrameTimeout on a manual clock, else
/// `patience` (0 for a show on the system clock that is not frame-locked).
[[nodiscard]] constexpr std::chrono::milliseconds framePatience(bool manualClock, std::chrono::milliseconds patience) {
  return manualClock ? kFrameTimeout : patience;
}

/// \brief The frame `player` shows for `request`: the leader's frame by its number when one is
/// given (MoviePlayer::frameNumbered), else the newest frame due (MoviePlayer::frameAt), waited
/// for as the request allows. Called on the frame loop's thread. Callers count the outcomes they
/// report (a follower's corrected and late frames).
[[nodiscard]] PickedFrame pickFrame(MoviePlayer& player, const FrameRequest& request);

}  // namespace basalt::media
