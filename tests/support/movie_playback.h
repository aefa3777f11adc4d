#pragma once

/// \file
/// \brief Drives a MoviePlayer the way an offline frame loop does (a manual show clock stepped
/// one frame at a time, waiting for the decoder), for media and render tests.

#include <chrono>
#include <cstdint>
#include <vector>

#include "media/movie_player.h"

namespace basalt::test {

/// \brief What one played-through movie showed.
struct Playthrough {
  std::vector<std::int64_t> frames;  ///< frame numbers shown, in order (one per new frame)
  std::int64_t showSteps = 0;        ///< show-clock steps taken
  bool reachedEnd = false;
  /// The decoder delivered nothing due for the limit of a step (10 s) while playing: the
  /// playthrough stopped there instead of waiting out every remaining step.
  bool stalled = false;
};

/// \brief Plays from the current position with a show clock stepped `step` at a time from
/// `start`, until the clip ends or `maxSteps` steps have passed. `start` is advanced.
Playthrough playFor(media::MoviePlayer& player, Nanos& showTime, Nanos step, std::int64_t maxSteps);

/// \brief Takes the frame a seek or step asked for (waiting for the decoder), at `showTime`.
/// Returns its number, or -1 when none came within the time limit.
std::int64_t settle(media::MoviePlayer& player, Nanos showTime,
                    std::chrono::milliseconds limit = std::chrono::seconds(10));

}  // namespace basalt::test
