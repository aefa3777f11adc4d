#include "kiosk/frame_metrics.h"

namespace basalt::kiosk {

Result<void> FrameMetrics::beforeDraw(const FrameContext& /*frame*/) {
  frameStart_ = wall_.now();
  return {};
}

void FrameMetrics::afterPresent(const FrameContext& frame) {
  const Nanos now = wall_.now();
  const double work = toSeconds(now - frameStart_);
  const double interval = lastPresent_ == Nanos{0} ? work : toSeconds(now - lastPresent_);
  lastPresent_ = now;
  board_.recordFrame(frame.frame, work, interval);
  if (events_) board_.setInputDropped(events_->dropped());
}

}  // namespace basalt::kiosk
