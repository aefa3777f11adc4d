#pragma once

/// \file
/// \brief Measures every frame on the wall clock (the loop's own work, and present to present)
/// and in the frame loop thread's CPU time (its work without the time other threads took the
/// CPU from it), and publishes the figures to the status board. Added first to the frame loop, so that its
/// beforeDraw() starts the frame's clock.

#include <string>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/status/status_board.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "runtime/event.h"

namespace basalt::kiosk {

/// \brief Frame timing for the status server and the summary line.
///
/// Threading: the frame loop's thread. Allocates nothing per frame.
class FrameMetrics final : public FrameParticipant {
 public:
  /// \brief `output` names where frames go, for the line logged when the first one is presented.
  FrameMetrics(StatusBoard& board, const BoundedQueue<Event>* events, std::string output = {})
      : board_(board), events_(events), output_(std::move(output)) {}

  Result<void> beforeDraw(const FrameContext& frame) override;
  void afterPresent(const FrameContext& frame) override;

 private:
  StatusBoard& board_;
  const BoundedQueue<Event>* events_;
  std::string output_;
  SystemClock wall_;
  Nanos frameStart_{0};
  Nanos cpuStart_{0};
  Nanos lastPresent_{0};
};

}  // namespace basalt::kiosk
