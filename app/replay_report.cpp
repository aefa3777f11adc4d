#include "app/replay_report.h"

#include <fmt/format.h>
#include <fmt/std.h>

#include "sim/trace.h"

namespace basalt::kiosk {

ReplayReport::ReplayReport(std::filesystem::path path, const Clock& clock)
    : path_(std::move(path)), clock_(clock), start_(clock.now()) {}

void ReplayReport::onReport(DeviceId, Nanos, std::span<const std::uint8_t>) {
  std::lock_guard lock(mutex_);
  ++reports_;
}

void ReplayReport::onFrame(DeviceId, const FrameRef&) {
  std::lock_guard lock(mutex_);
  ++frames_;
}

std::string ReplayReport::summary(const std::vector<devices::DeviceStatus>& devices) const {
  std::string what;
  std::error_code ec;
  if (std::filesystem::is_directory(path_, ec)) {
    what = fmt::format("trace {}", path_.string());
    if (auto info = sim::readTrace(path_)) {
      what += fmt::format(" ({:.1f} s recorded{}{})", info->seconds, info->host.empty() ? "" : " on ", info->host);
    }
  } else {
    what = fmt::format("hid-recorder file {}", path_.string());
  }
  const double span = toSeconds(clock_.now() - start_);
  std::lock_guard lock(mutex_);
  std::string text =
      fmt::format("replayed {}: {} device{}, {} input report{} and {} video frame{} over {:.1f} s of show time", what,
                  devices.size(), devices.size() == 1 ? "" : "s", reports_, reports_ == 1 ? "" : "s", frames_,
                  frames_ == 1 ? "" : "s", span);
  for (const devices::DeviceStatus& d : devices) {
    if (d.state == devices::DeviceState::kLive && d.lastError.empty()) continue;
    text += fmt::format("\nbasalt: replayed {} '{}' did not play: {}", devices::deviceKindName(d.kind), d.name,
                        d.lastError.empty() ? std::string(devices::deviceStateName(d.state)) : d.lastError);
  }
  return text;
}

}  // namespace basalt::kiosk
