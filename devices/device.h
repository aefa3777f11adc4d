#pragma once

/// \file
/// \brief What every device has: an identity, a kind, and the hotplug state machine's states.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "runtime/clock.h"
#include "runtime/event.h"

namespace basalt::devices {

/// \brief The hotplug state machine (DESIGN.md §3): absent -> opening -> live -> lost ->
/// reopening -> live ... A device that is not live never stops the show.
enum class DeviceState : std::uint8_t { kAbsent, kOpening, kLive, kLost, kReopening };

std::string_view deviceStateName(DeviceState state);

/// \brief The kinds of device a show uses.
enum class DeviceKind : std::uint8_t {
  kDialBox,      ///< dials and buttons: knobs, jog wheels, the SGI box
  kVideoSource,  ///< a camera or a capture card
  kTracker,      ///< the position and orientation of a head or an object
};

std::string_view deviceKindName(DeviceKind kind);

/// \brief Who a device is: enough to match it against a manifest and to tell an operator.
struct DeviceInfo {
  std::string name;     ///< product name as the device reports it
  std::string backend;  ///< "hid", "v4l2", "libcamera", "serial", "replay", "synthetic"
  std::string bus;      ///< "usb", "bluetooth", "virtual", ...
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::string path;  ///< /dev node, USB path, tty, trace file or "synthetic:NAME"
  std::string serial;
};

/// \brief "Griffin PowerMate (hid 077d:0410 at /dev/hidraw3)".
std::string describeDevice(const DeviceInfo& info);

/// \brief Receives the raw input reports of a dial box, as they arrive, for trace recording.
/// Called on the device's reader thread (or the manager's for simulated devices): must not
/// block for long and must be thread-safe.
class ReportTap {
 public:
  virtual ~ReportTap() = default;
  /// \brief One input report (with its report id byte when the descriptor uses ids), stamped on
  /// the show's Clock.
  virtual void onReport(DeviceId device, Nanos time, std::span<const std::uint8_t> report) = 0;
};

}  // namespace basalt::devices
