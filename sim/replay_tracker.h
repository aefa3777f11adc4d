#pragma once

/// \file
/// \brief A recorded tracker played back: its hid-recorder reports (a HID tracker's own, or the
/// virtual tracker's that synthetic and fed trackers are recorded as) through the same
/// TrackerDecoder as the real device, at open time + recorded time on the show's Clock.

#include <memory>
#include <vector>

#include "devices/hid/tracker_decoder.h"
#include "devices/tracker.h"
#include "sim/hid_recording.h"

namespace basalt::sim {

/// \brief Its raw reports go to the report tap unchanged, so recording a replay gives the same
/// file; under a ManualClock it gives the same samples, bit for bit, every time.
class ReplayTracker final : public devices::Tracker {
 public:
  /// \brief Fails when the recording's descriptor is not a tracker's (no absolute X, Y, Z).
  [[nodiscard]] static Result<std::unique_ptr<ReplayTracker>> create(devices::DeviceInfo info,
                                                                     const HidRecordedDevice& recording,
                                                                     const Clock& clock, bool loop);
  [[nodiscard]] bool finished() const { return finished_; }

 private:
  ReplayTracker(devices::DeviceInfo info, const HidRecordedDevice& recording, devices::TrackerDecoder decoder,
                const Clock& clock, bool loop);
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;

  std::vector<HidReport> reports_;
  devices::TrackerDecoder decoder_;
  const Clock& clock_;
  bool loop_;
  std::size_t next_ = 0;
  Nanos origin_{0};
  bool finished_ = false;
};

}  // namespace basalt::sim
