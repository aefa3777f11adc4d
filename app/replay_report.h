#pragma once

/// \file
/// \brief What `basalt run --replay` replayed, said once at the end: the trace, its devices, how
/// many input reports and video frames they played, over how much show time.

#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "devices/device_manager.h"
#include "devices/video_source.h"
#include "runtime/clock.h"

namespace basalt::kiosk {

/// \brief Counts what the replayed devices play, as the DeviceManager's report and frame tap.
///
/// Threading: onReport() and onFrame() come from the devices' threads; summary() from any.
class ReplayReport final : public devices::ReportTap, public devices::FrameTap {
 public:
  /// \brief `path` as given to --replay: a trace folder or an hid-recorder file. The replay
  /// starts now on `clock` (the show's), which must outlive this.
  ReplayReport(std::filesystem::path path, const Clock& clock);

  void onReport(DeviceId device, Nanos time, std::span<const std::uint8_t> report) override;
  void onFrame(DeviceId device, const FrameRef& frame) override;

  /// \brief "replayed trace demo.trace (2.0 s recorded on kiosk-3): 2 devices, 40 input reports
  /// and 60 video frames over 3.0 s of show time" (from construction to now on the clock), then a
  /// line for each device that did not play, with why.
  [[nodiscard]] std::string summary(const std::vector<devices::DeviceStatus>& devices) const;

 private:
  std::filesystem::path path_;
  const Clock& clock_;
  Nanos start_;
  mutable std::mutex mutex_;  // guards the counts below
  std::uint64_t reports_ = 0;
  std::uint64_t frames_ = 0;
};

}  // namespace basalt::kiosk
