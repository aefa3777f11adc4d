// Dial boxes on hidraw, through hidapi's hidraw backend.
//
// Hardware: any HID device the kernel gives a hidraw node whose report descriptor maps to dials
// (devices/hid/dial_decoder.h): the Contour ShuttleXpress and ShuttlePRO (by vendor:product), the
// Microsoft Surface Dial, Huion dial pads, knobs that report Dial or Wheel, joystick axes. The
// descriptor is read from sysfs, since hidapi 0.13 cannot return it. Limits: input reports only
// (no feature reports: a Surface Dial's resolution multiplier stays at the device's default), up
// to 32 dials and 64 buttons; reads poll every 100 ms for close().
//
// Trackers on hidraw: any HID device with absolute Generic Desktop X, Y and Z (and optionally
// Rx, Ry, Rz) in one input report (devices/hid/tracker_decoder.h), such as a head tracker that
// presents itself as a generic 6-axis HID device. Such a device is offered both as a tracker and,
// where its axes make dials, as a dial box; the manifest's kind picks. Each report is stamped on
// the show's Clock when read.

#include <hidapi/hidapi.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "devices/hid/decoding_dial_box.h"
#include "devices/hid/dial_decoder.h"
#include "devices/hid/hid_backend.h"
#include "devices/hid/tracker_decoder.h"

namespace basalt::devices {

namespace {

struct HidDeviceCloser {
  void operator()(hid_device* d) const { hid_close(d); }
};
using HidDevicePtr = std::unique_ptr<hid_device, HidDeviceCloser>;
struct HidEnumerationFree {
  void operator()(hid_device_info* d) const { hid_free_enumeration(d); }
};
using HidEnumerationPtr = std::unique_ptr<hid_device_info, HidEnumerationFree>;

/// hidapi keeps global state; hid_init once per process.
bool hidInit() {
  static const bool ok = hid_init() == 0;
  return ok;
}

std::string narrow(const wchar_t* w) {
  std::string out;
  if (!w) return out;
  for (; *w; ++w) out += *w < 0x80 ? static_cast<char>(*w) : '?';
  return out;
}

std::string hidError(hid_device* d) { return narrow(hid_error(d)); }

std::string busOf(hid_bus_type bus) {
  switch (bus) {
    case HID_API_BUS_USB: return "usb";
    case HID_API_BUS_BLUETOOTH: return "bluetooth";
    case HID_API_BUS_I2C: return "i2c";
    case HID_API_BUS_SPI: return "spi";
    default: return "unknown";
  }
}

/// Opens the hidraw node of a dial box or tracker, saying why it cannot (permissions: the udev rule).
Result<HidDevicePtr> openHidraw(const DeviceInfo& info) {
  if (!hidInit()) return fail(Errc::kUnavailable, "hidapi could not start", info.path);
  HidDevicePtr dev(hid_open_path(info.path.c_str()));
  if (!dev) {
    const int e = errno;
    if (e == EACCES || e == EPERM) {
      return fail(Errc::kPermissionDenied, fmt::format("permission denied; {}", kUdevRuleHint), info.path);
    }
    return fail(Errc::kUnavailable, fmt::format("cannot open: {}", hidError(nullptr)), info.path);
  }
  return dev;
}

class HidrawDialBox final : public DecodingDialBox {
 public:
  HidrawDialBox(DeviceInfo info, std::vector<std::uint8_t> descriptor, DialDecoder decoder, const Clock& clock)
      : DecodingDialBox(std::move(info), std::move(decoder), clock) {
    setReportDescriptor(std::move(descriptor));
  }
  ~HidrawDialBox() override { close(); }

 private:
  Result<void> doOpen() override {
    auto dev = openHidraw(info());
    if (!dev) return std::unexpected(dev.error());
    device_ = std::move(*dev);
    startReader();
    return {};
  }

  void doClose() override {
    stopReader();
    device_.reset();
  }

  void readLoop() override {
    std::array<std::uint8_t, 4096> buf{};
    while (!stopping()) {
      const int n = hid_read_timeout(device_.get(), buf.data(), buf.size(), 100);
      if (n < 0) {
        reportLost(Error(Errc::kDeviceLost, fmt::format("read failed: {}", hidError(device_.get())), info().path));
        return;
      }
      if (n > 0) handleReport(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    }
  }

  HidDevicePtr device_;
};

/// A tracker on a hidraw node: a reader thread decodes each report into a sample.
class HidrawTracker final : public Tracker {
 public:
  HidrawTracker(DeviceInfo info, std::vector<std::uint8_t> descriptor, TrackerDecoder decoder, const Clock& clock)
      : Tracker(std::move(info), true), decoder_(std::move(decoder)), clock_(clock) {
    setReportDescriptor(std::move(descriptor));
  }
  ~HidrawTracker() override { close(); }

 private:
  Result<void> doOpen() override {
    auto dev = openHidraw(info());
    if (!dev) return std::unexpected(dev.error());
    device_ = std::move(*dev);
    stop_.store(false);
    reader_ = std::thread([this] { readLoop(); });
    return {};
  }

  void doClose() override {
    stop_.store(true);
    if (reader_.joinable()) reader_.join();
    device_.reset();
  }

  void readLoop() {
    std::array<std::uint8_t, 4096> buf{};
    while (!stop_.load()) {
      const int n = hid_read_timeout(device_.get(), buf.data(), buf.size(), 100);
      if (n < 0) {
        reportLost(Error(Errc::kDeviceLost, fmt::format("read failed: {}", hidError(device_.get())), info().path));
        return;
      }
      if (n == 0) continue;
      const std::span<const std::uint8_t> report(buf.data(), static_cast<std::size_t>(n));
      const Nanos now = clock_.now();
      tapReport(now, report);
      if (auto sample = decoder_.decode(report, now)) emit(*sample);
    }
  }

  TrackerDecoder decoder_;  // read by the reader thread only (immutable after construction)
  const Clock& clock_;
  std::atomic<bool> stop_{false};  // set by doClose(), read by the reader thread
  std::thread reader_;
  HidDevicePtr device_;  // opened before the reader starts, closed after it is joined
};

/// The tracker decoder for a descriptor, or why it is not a tracker.
Result<TrackerDecoder> trackerDecoder(const std::vector<std::uint8_t>& descriptor, const std::string& where) {
  auto parsed = hid::parseReportDescriptor(descriptor, where);
  if (!parsed) return std::unexpected(parsed.error());
  return TrackerDecoder::create(*parsed, where);
}

}  // namespace

Result<std::vector<std::uint8_t>> readHidrawDescriptor(const std::string& devnode) {
  const std::filesystem::path node(devnode);
  const std::filesystem::path sys =
      std::filesystem::path("/sys/class/hidraw") / node.filename() / "device" / "report_descriptor";
  std::ifstream in(sys, std::ios::binary);
  if (!in) return fail(Errc::kNotFound, fmt::format("cannot read {}", sys.string()), devnode);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) return fail(Errc::kParse, "the report descriptor is empty", devnode);
  return bytes;
}

Result<std::unique_ptr<DialBox>> openHidrawDialBox(const std::string& devnode, const Clock& clock) {
  if (!hidInit()) return fail(Errc::kUnavailable, "hidapi could not start", devnode);
  DeviceInfo info{"", "hid", "unknown", 0, 0, devnode, ""};
  HidEnumerationPtr list(hid_enumerate(0, 0));
  for (hid_device_info* d = list.get(); d; d = d->next) {
    if (devnode != d->path) continue;
    info.name = narrow(d->product_string);
    info.vendor = d->vendor_id;
    info.product = d->product_id;
    info.serial = narrow(d->serial_number);
    info.bus = busOf(d->bus_type);
  }
  auto descriptor = readHidrawDescriptor(devnode);
  if (!descriptor) return std::unexpected(descriptor.error());
  auto decoder = DialDecoder::create(info.vendor, info.product, *descriptor, devnode);
  if (!decoder) return std::unexpected(decoder.error());
  if (info.name.empty()) info.name = std::string(dialProfileName(decoder->profile()));
  return std::unique_ptr<DialBox>(
      std::make_unique<HidrawDialBox>(std::move(info), std::move(*descriptor), std::move(*decoder), clock));
}

std::string hidrawAccessProblem(const std::string& devnode) {
  if (::access(devnode.c_str(), R_OK | W_OK) == 0) return {};
  const int e = errno;
  if (e == EACCES || e == EPERM) return fmt::format("{}; {}", systemErrorText("cannot open", e), kUdevRuleHint);
  return systemErrorText("cannot open", e);
}

Result<std::unique_ptr<Tracker>> openHidrawTracker(const std::string& devnode, const Clock& clock) {
  if (!hidInit()) return fail(Errc::kUnavailable, "hidapi could not start", devnode);
  DeviceInfo info{"", "hid", "unknown", 0, 0, devnode, ""};
  HidEnumerationPtr list(hid_enumerate(0, 0));
  for (hid_device_info* d = list.get(); d; d = d->next) {
    if (devnode != d->path) continue;
    info.name = narrow(d->product_string);
    info.vendor = d->vendor_id;
    info.product = d->product_id;
    info.serial = narrow(d->serial_number);
    info.bus = busOf(d->bus_type);
  }
  auto descriptor = readHidrawDescriptor(devnode);
  if (!descriptor) return std::unexpected(descriptor.error());
  auto decoder = trackerDecoder(*descriptor, devnode);
  if (!decoder) return std::unexpected(decoder.error());
  if (info.name.empty()) info.name = "HID tracker";
  return std::unique_ptr<Tracker>(
      std::make_unique<HidrawTracker>(std::move(info), std::move(*descriptor), std::move(*decoder), clock));
}

HidProvider::HidProvider() = default;
HidProvider::~HidProvider() = default;

std::vector<DeviceCandidate> listPowerMates();  // powermate.cpp

std::vector<DeviceCandidate> HidProvider::enumerate() {
  std::vector<DeviceCandidate> out;
  if (hidInit()) {
    HidEnumerationPtr list(hid_enumerate(0, 0));
    for (hid_device_info* d = list.get(); d; d = d->next) {
      DeviceCandidate c;
      c.kind = DeviceKind::kDialBox;
      c.info = DeviceInfo{
          narrow(d->product_string), "hid", busOf(d->bus_type), d->vendor_id, d->product_id, d->path ? d->path : "",
          narrow(d->serial_number)};
      auto descriptor = readHidrawDescriptor(c.info.path);
      if (!descriptor) {
        c.problem = descriptor.error().describe();
      } else if (auto decoder = DialDecoder::create(c.info.vendor, c.info.product, *descriptor, c.info.path);
                 !decoder) {
        c.problem = fmt::format("not a dial box: {}", decoder.error().message());
      } else {
        c.usage = fmt::format("{}: {} dial(s), {} button(s)", dialProfileName(decoder->profile()), decoder->dialCount(),
                              decoder->buttonCount());
        c.problem = hidrawAccessProblem(c.info.path);
      }
      if (descriptor) {
        if (auto tracker = trackerDecoder(*descriptor, c.info.path)) {
          DeviceCandidate t = c;
          t.kind = DeviceKind::kTracker;
          t.usage = fmt::format("tracker: X/Y/Z{}", tracker->hasRotation() ? ", Rx/Ry/Rz" : "");
          t.problem = hidrawAccessProblem(c.info.path);
          out.push_back(std::move(t));
        }
      }
      out.push_back(std::move(c));
    }
  }
  for (DeviceCandidate& c : listPowerMates()) out.push_back(std::move(c));
  return out;
}

Result<std::unique_ptr<Tracker>> HidProvider::openTracker(const DeviceCandidate& candidate, const DeviceRequest&,
                                                          const Clock& clock) {
  return openHidrawTracker(candidate.info.path, clock);
}

Result<std::unique_ptr<DialBox>> HidProvider::openDialBox(const DeviceCandidate& candidate, const DeviceRequest&,
                                                          const Clock& clock) {
  return candidate.info.path.starts_with("usb:") ? openPowerMate(candidate.info.path, clock)
                                                 : openHidrawDialBox(candidate.info.path, clock);
}

}  // namespace basalt::devices
