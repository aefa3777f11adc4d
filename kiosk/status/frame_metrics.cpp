#include "kiosk/status/frame_metrics.h"

#include <time.h>

#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Metrics, "kiosk");

namespace {

/// CPU time of the calling thread: a measurement of the loop's own work, not show time.
Nanos threadCpuTime() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return Nanos{static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec};
}

}  // namespace

Result<void> FrameMetrics::beforeDraw(const FrameContext& /*frame*/) {
  frameStart_ = wall_.now();
  cpuStart_ = threadCpuTime();
  return {};
}

void FrameMetrics::afterPresent(const FrameContext& frame) {
  const Nanos now = wall_.now();
  const double work = toSeconds(now - frameStart_);
  const double cpu = toSeconds(threadCpuTime() - cpuStart_);
  const double interval = lastPresent_ == Nanos{0} ? work : toSeconds(now - lastPresent_);
  lastPresent_ = now;
  board_.recordFrame(frame.frame, work, interval, cpu, events_ ? events_->dropped() : 0);
  if (frame.frame == 0 && !output_.empty()) log::info(kLogMetrics, "first frame on {}", output_);
}

}  // namespace basalt::kiosk
