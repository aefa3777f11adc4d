#include "kiosk/show/head_follower.h"

#include <algorithm>

namespace basalt::kiosk {

HeadFollower::HeadFollower(const ViewerSpec& viewer)
    : tracker_(viewer.tracker),
      smoother_(viewer.smoothing),
      placement_{{viewer.trackerOffset[0], viewer.trackerOffset[1], viewer.trackerOffset[2]}, viewer.trackerScale},
      rest_{viewer.position[0], viewer.position[1], viewer.position[2]} {
  figures_.tracker = tracker_;
}

void HeadFollower::update(Nanos frameTime, devices::DeviceManager& devices, runtime::Show& show) {
  runtime::HeadPose& head = show.head();
  if (!head.tracked) {
    // Until the first sample the viewer stands where the manifest puts it.
    head.position = rest_;
    head.right = {1, 0, 0};
  }
  if (!samples_) samples_ = devices.trackerSamples(tracker_);
  if (!samples_) return;
  Nanos newest{-1};
  const std::size_t n = samples_->takeDue(frameTime, [&](const runtime::TrackerSample& s) {
    smoother_.add(s.time, placement_.toDisplay(s.position), runtime::headRight(s.rotation));
    newest = s.time;
  });
  figures_.dropped = samples_->dropped();
  if (n == 0) return;
  head = smoother_.pose();
  figures_.samples += n;
  figures_.lastLatency = frameTime - newest;
  figures_.maxLatency = std::max(figures_.maxLatency, figures_.lastLatency);
  figures_.latencySum += std::chrono::duration<double>(figures_.lastLatency).count();
  ++figures_.frames;
}

}  // namespace basalt::kiosk
