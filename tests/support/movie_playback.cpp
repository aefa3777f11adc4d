#include "support/movie_playback.h"

namespace basalt::test {

Playthrough playFor(media::MoviePlayer& player, Nanos& showTime, Nanos step, std::int64_t maxSteps) {
  Playthrough result;
  for (std::int64_t i = 0; i < maxSteps; ++i) {
    if (!player.waitForFrameDue(showTime, std::chrono::seconds(10)) && player.state() != media::MovieState::kFailed &&
        player.state() != media::MovieState::kEmpty) {
      result.stalled = true;
      break;
    }
    FrameRef f = player.frameAt(showTime);
    if (f) result.frames.push_back(static_cast<std::int64_t>(f->sequence));
    ++result.showSteps;
    if (player.atEnd()) {
      result.reachedEnd = true;
      break;
    }
    if (player.state() == media::MovieState::kFailed) break;
    showTime += step;
  }
  return result;
}

std::int64_t settle(media::MoviePlayer& player, Nanos showTime, std::chrono::milliseconds limit) {
  if (!player.waitForFrameDue(showTime, limit)) return -1;
  FrameRef f = player.frameAt(showTime);
  return f ? static_cast<std::int64_t>(f->sequence) : player.currentFrame();
}

}  // namespace basalt::test
