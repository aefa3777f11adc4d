#include "devices/device.h"

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

}  // namespace basalt::devices
