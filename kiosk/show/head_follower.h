#pragma once

/// \file
/// \brief The viewer of a facet display following a tracker (thesis §4.4.3): the tracker's
/// samples due by a frame's time, placed in the display's space, smoothed, and put in the Show's
/// HeadPose, where the facet views and the frame lock read it.

#include <cstdint>
#include <memory>
#include <string>

#include "devices/device_manager.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/status/status_board.h"
#include "runtime/head_tracking.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

/// \brief Moves the Show's head from the manifest's `[viewer] tracker`.
///
/// Threading: the frame loop's thread; the tracker's samples arrive through its TrackerSamples.
class HeadFollower {
 public:
  explicit HeadFollower(const ViewerSpec& viewer);
  /// \brief Takes the samples due by `frameTime` and updates `show.head()`. A tracker that is
  /// not there (yet, or lost) leaves the head where it was last (at `[viewer] position` until
  /// the first sample). Never blocks; allocates nothing.
  void update(Nanos frameTime, devices::DeviceManager& devices, runtime::Show& show);
  [[nodiscard]] const TrackerFigures& figures() const { return figures_; }
  [[nodiscard]] const std::string& tracker() const { return tracker_; }

 private:
  std::string tracker_;
  runtime::HeadSmoother smoother_;
  runtime::TrackerPlacement placement_;
  Vec3 rest_;  ///< `[viewer] position`
  std::shared_ptr<devices::TrackerSamples> samples_;
  TrackerFigures figures_;
};

}  // namespace basalt::kiosk
