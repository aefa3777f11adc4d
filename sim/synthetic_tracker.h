#pragma once

/// \file
/// \brief A tracker that moves by itself along a path: a circle, a line or a figure-eight. The
/// simulated twin of the tracker kind, for demos, tests and benchmarks.

#include <cstdint>

#include "devices/tracker.h"
#include "sim/synthetic_dial.h"

namespace basalt::sim {

/// \brief Where a synthetic tracker goes, in metres about `centre`, in the tracker's XZ plane
/// (the floor): a head walking in front of a display. Its rotation turns the head to face along
/// -Z with `yaw` degrees of side-to-side swing, in step with the path.
struct TrackerPath {
  enum class Shape : std::uint8_t {
    kCircle,       ///< x = r cos(wt), z = r sin(wt)
    kLine,         ///< x = r sin(wt): back and forth along X
    kFigureEight,  ///< x = r sin(wt), z = r sin(wt) cos(wt) (Gerono's lemniscate)
  };
  Shape shape = Shape::kCircle;
  Vec3 centre{0, 0, 0};
  float radius = 0.3f;
  Nanos period = std::chrono::seconds(4);  ///< one lap
  float yaw = 0;                           ///< degrees of swing about Y
  std::uint32_t rate = 90;                 ///< samples per second
};

/// \brief The pose on `path` at `t` after the start (position and rotation).
runtime::TrackerSample pathSample(const TrackerPath& path, Nanos t);

/// \brief Plays a TrackerPath on the show's Clock: the sample due at open + k / rate is emitted
/// by the service() that reaches it, so under a ManualClock the samples are exact.
class SyntheticTracker final : public devices::Tracker {
 public:
  SyntheticTracker(devices::DeviceInfo info, TrackerPath path, const Clock& clock, PresenceFlag present = nullptr);
  static devices::DeviceInfo defaultInfo();

 private:
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;

  TrackerPath path_;
  const Clock& clock_;
  PresenceFlag present_;
  Nanos origin_{0};
  std::uint64_t next_ = 0;  ///< the next sample's number since open
};

}  // namespace basalt::sim
