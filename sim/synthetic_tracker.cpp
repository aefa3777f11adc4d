// The synthetic tracker: no hardware. It serves tests, demos and benchmarks of head-tracked
// facet displays: a path (circle, line, figure-eight) at a fixed sample rate on the show's
// Clock, and an unplug through its PresenceFlag. Configuration: TrackerPath (in shows, the
// [devices.NAME] entry's motion, radius, period and rate).

#include "sim/synthetic_tracker.h"

#include <cmath>
#include <numbers>

namespace basalt::sim {

runtime::TrackerSample pathSample(const TrackerPath& path, Nanos t) {
  const double period = std::chrono::duration<double>(path.period).count();
  const double phase =
      period > 0 ? 2.0 * std::numbers::pi * std::fmod(std::chrono::duration<double>(t).count(), period) / period : 0.0;
  const auto r = static_cast<double>(path.radius);
  Vec3 offset;
  switch (path.shape) {
    case TrackerPath::Shape::kCircle:
      offset = {static_cast<float>(r * std::cos(phase)), 0, static_cast<float>(r * std::sin(phase))};
      break;
    case TrackerPath::Shape::kLine: offset = {static_cast<float>(r * std::sin(phase)), 0, 0}; break;
    case TrackerPath::Shape::kFigureEight:
      offset = {static_cast<float>(r * std::sin(phase)), 0, static_cast<float>(r * std::sin(phase) * std::cos(phase))};
      break;
  }
  runtime::TrackerSample s;
  s.time = t;
  s.position = path.centre + offset;
  s.rotation = {0, static_cast<float>(static_cast<double>(path.yaw) * std::sin(phase)), 0};
  return s;
}

SyntheticTracker::SyntheticTracker(devices::DeviceInfo info, TrackerPath path, const Clock& clock, PresenceFlag present)
    : Tracker(std::move(info)), path_(path), clock_(clock), present_(std::move(present)) {}

devices::DeviceInfo SyntheticTracker::defaultInfo() {
  return {"Synthetic tracker", "synthetic", "virtual", 0, 0, "synthetic:tracker", ""};
}

Result<void> SyntheticTracker::doOpen() {
  if (present_ && !present_->load(std::memory_order_acquire)) {
    return fail(Errc::kUnavailable, "the synthetic tracker is unplugged", describeDevice(info()));
  }
  origin_ = clock_.now();
  next_ = 0;
  return {};
}

void SyntheticTracker::doClose() {}

void SyntheticTracker::doService(Nanos now) {
  if (present_ && !present_->load(std::memory_order_acquire)) {
    reportLost(Error(Errc::kUnavailable, "the synthetic tracker was unplugged"));
    return;
  }
  const std::int64_t step = path_.rate > 0 ? 1'000'000'000LL / path_.rate : 1'000'000'000LL;
  // Never more than a second's samples at once: a clock that jumps ahead does not flood.
  for (std::uint32_t n = 0; n < path_.rate + 1; ++n) {
    const Nanos t{static_cast<std::int64_t>(next_) * step};
    if (origin_ + t > now) break;
    runtime::TrackerSample s = pathSample(path_, t);
    s.time = origin_ + t;
    emit(s);
    ++next_;
  }
}

}  // namespace basalt::sim
