#pragma once

/// \file
/// \brief What every device has: an identity and the hotplug state machine's states.

#include <cstdint>
#include <string>
#include <string_view>

namespace basalt::devices {

/// \brief The hotplug state machine (DESIGN.md §3): absent -> opening -> live -> lost ->
/// reopening -> live ... A device that is not live never stops the show.
enum class DeviceState : std::uint8_t { kAbsent, kOpening, kLive, kLost, kReopening };

std::string_view deviceStateName(DeviceState state);

/// \brief Who a device is: enough to match it against a manifest and to tell an operator.
struct DeviceInfo {
  std::string name;     ///< product name as the device reports it
  std::string backend;  ///< "hid", "v4l2", "libcamera", "replay", "synthetic", ...
  std::string bus;      ///< "usb", "bluetooth", "virtual", ...
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::string path;  ///< /dev node, USB path or trace file
  std::string serial;
};

}  // namespace basalt::devices
