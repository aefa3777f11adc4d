#include "devices/device.h"

#include <fmt/format.h>

namespace basalt::devices {

std::string_view deviceStateName(DeviceState state) {
  switch (state) {
    case DeviceState::kAbsent: return "absent";
    case DeviceState::kOpening: return "opening";
    case DeviceState::kLive: return "live";
    case DeviceState::kLost: return "lost";
    case DeviceState::kReopening: return "reopening";
  }
  return "unknown";
}

std::string_view deviceKindName(DeviceKind kind) {
  switch (kind) {
    case DeviceKind::kDialBox: return "dial box";
    case DeviceKind::kVideoSource: return "video source";
    case DeviceKind::kTracker: return "tracker";
  }
  return "device";
}

std::string describeDevice(const DeviceInfo& info) {
  std::string text = info.name.empty() ? std::string("unnamed device") : info.name;
  text += fmt::format(" ({}", info.backend);
  if (info.vendor != 0 || info.product != 0) text += fmt::format(" {:04x}:{:04x}", info.vendor, info.product);
  if (!info.path.empty()) text += fmt::format(" at {}", info.path);
  text += ")";
  return text;
}

}  // namespace basalt::devices
