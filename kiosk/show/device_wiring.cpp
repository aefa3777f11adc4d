#include "kiosk/show/device_wiring.h"

#include <fmt/format.h>

#include "devices/hid/hid_backend.h"
#include "devices/libcamera/libcamera_camera.h"
#include "devices/midi/midi_backend.h"
#include "devices/serial/sgi_dial_box.h"
#include "devices/v4l2/v4l2_camera.h"
#include "runtime/log.h"
#include "sim/providers.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Wiring, "kiosk");

Result<devices::DeviceRequest> parseDeviceSpec(std::string_view text, devices::DeviceKind kind, std::string name) {
  devices::DeviceRequest r;
  r.name = std::move(name);
  r.kind = kind;
  const auto colon = text.find(':');
  r.match.backend = std::string(text.substr(0, colon));
  static constexpr std::string_view kBackends[] = {"hid", "serial", "midi", "v4l2", "libcamera", "synthetic", "replay"};
  if (std::find(std::begin(kBackends), std::end(kBackends), r.match.backend) == std::end(kBackends)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' does not start with a backend: hid, serial, midi, v4l2, libcamera, synthetic or "
                            "replay (e.g. hid:077d:0410, midi:X-TOUCH MINI, v4l2:/dev/video0)",
                            text));
  }
  if (colon == std::string_view::npos) return r;
  const std::string_view rest = text.substr(colon + 1);
  if (rest.size() == 9 && rest[4] == ':' && parseVendorProduct(rest, r.match)) return r;
  if (rest.starts_with("/") || rest.starts_with("usb:") || rest.starts_with("seq:") || r.match.backend == "libcamera" ||
      r.match.backend == "synthetic") {
    r.match.path = std::string(rest);
  } else {
    r.match.name = std::string(rest);
  }
  return r;
}

std::vector<std::unique_ptr<devices::DeviceProvider>> allProviders(const std::vector<std::string>& serialPorts) {
  std::vector<std::unique_ptr<devices::DeviceProvider>> out;
  out.push_back(std::make_unique<devices::HidProvider>());
  out.push_back(std::make_unique<devices::SerialProvider>(serialPorts));
  out.push_back(std::make_unique<devices::MidiProvider>());
  out.push_back(std::make_unique<devices::V4l2Provider>());
  out.push_back(std::make_unique<devices::LibcameraProvider>());
  out.push_back(std::make_unique<sim::SyntheticProvider>());
  return out;
}

namespace {

devices::DeviceManager::Config numberedFrom(DeviceId firstId) {
  devices::DeviceManager::Config config;
  config.firstId = firstId;
  return config;
}

}  // namespace

DeviceWiring::DeviceWiring(const Clock& clock, BoundedQueue<Event>& events, DeviceId firstId)
    : clock_(clock), events_(events), manager_(clock, events_, numberedFrom(firstId)) {}

DeviceWiring::~DeviceWiring() { stop(); }

Result<std::vector<DeviceId>> DeviceWiring::addReplay(const std::filesystem::path& path, bool loop,
                                                      sim::TraceVideoReaderFactory videoReader) {
  auto provider = std::make_unique<sim::ReplayProvider>(std::move(videoReader));
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    if (auto r = provider->addTrace(path); !r) return std::unexpected(r.error());
  } else if (auto r = provider->addHidRecording(path); !r) {
    return std::unexpected(r.error());
  }
  auto requests = provider->requests();
  manager_.addProvider(std::move(provider));
  std::vector<DeviceId> ids;
  for (auto& r : requests) {
    if (r.kind == devices::DeviceKind::kTracker) {
      // A replayed head moves a show's viewer only where the manifest says which tracker it follows.
      log::warn(kLogWiring,
                "{}: '{}' is a tracker, which --replay does not play; to move the facet views' viewer with it, "
                "add it to the show's [devices] (kind = \"tracker\", backend = \"replay\") and name it in "
                "[viewer] tracker",
                path.string(), r.name);
      continue;
    }
    r.options["loop"] = loop ? "true" : "false";
    auto id = manager_.request(r);
    if (!id) return std::unexpected(id.error());
    ids.push_back(*id);
  }
  return ids;
}

void DeviceWiring::start(bool manualClock) {
  manual_ = manualClock;
  started_ = true;
  if (manual_) {
    manager_.step(clock_.now());  // open what is there before the first frame
    return;
  }
  if (auto monitor = devices::UdevMonitor::create()) {
    udev_ = std::move(*monitor);
    udev_->start([this](devices::HotplugEvent e) { manager_.notifyHotplug(std::move(e)); });
  } else {
    log::debug(kLogWiring, "{}", monitor.error().describe());
  }
  manager_.start();
}

void DeviceWiring::stop() {
  if (!started_) return;
  started_ = false;
  if (udev_) udev_->stop();
  manager_.stop();
}

Result<void> DeviceWiring::Stepper::beforeDraw(const FrameContext& frame) {
  if (wiring_.manual_) wiring_.manager_.step(frame.time);
  return {};
}

}  // namespace basalt::kiosk
