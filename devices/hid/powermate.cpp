// The Griffin PowerMate (077d:0410) through libusb.
//
// Hardware: an aluminium knob with a push button and a blue LED under it. The Linux HID core
// ignores it (it is on the HID ignore list; the kernel's own powermate input driver may bind it),
// so there is no hidraw node: Basalt claims interface 0 with libusb, detaching a kernel driver
// while it holds the device, and reads its 6-byte interrupt reports (byte 0 bit 0 the button,
// byte 1 the signed rotation). The LED is set with the vendor control request 0x01 (request type
// 0x41): wValue 1 sets the static brightness (wIndex 0..255), wValue 3 turns pulsing while awake on
// or off. The report descriptor is read with GET_DESCRIPTOR, since hidapi 0.13 has no such call.
// Limits: one interface, interrupt endpoint found from the configuration (0x81 by default).

#include <libusb-1.0/libusb.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "devices/hid/decoding_dial_box.h"
#include "devices/hid/dial_decoder.h"
#include "devices/hid/hid_backend.h"

namespace basalt::devices {

namespace {

struct DeviceListFree {
  void operator()(libusb_device** list) const { libusb_free_device_list(list, 1); }
};
using DeviceListPtr = std::unique_ptr<libusb_device*, DeviceListFree>;
struct HandleClose {
  void operator()(libusb_device_handle* h) const { libusb_close(h); }
};
using HandlePtr = std::unique_ptr<libusb_device_handle, HandleClose>;
struct ConfigFree {
  void operator()(libusb_config_descriptor* c) const { libusb_free_config_descriptor(c); }
};
using ConfigPtr = std::unique_ptr<libusb_config_descriptor, ConfigFree>;

libusb_context* usbContext() {
  static libusb_context* ctx = [] {
    libusb_context* c = nullptr;
    return libusb_init(&c) == 0 ? c : nullptr;
  }();
  return ctx;
}

std::string usbPath(libusb_device* dev) {
  std::uint8_t ports[8];
  const int n = libusb_get_port_numbers(dev, ports, 8);
  std::string path = fmt::format("usb:{}-", libusb_get_bus_number(dev));
  for (int i = 0; i < n; ++i) {
    if (i) path += ".";
    path += std::to_string(ports[i]);
  }
  return path;
}

std::string usbNode(libusb_device* dev) {
  return fmt::format("/dev/bus/usb/{:03}/{:03}", libusb_get_bus_number(dev), libusb_get_device_address(dev));
}

// A descriptor for the PowerMate's 6-byte vendor report, for recordings when GET_DESCRIPTOR fails.
const std::vector<std::uint8_t> kFallbackDescriptor = {0x06, 0x00, 0xff, 0x09, 0x01, 0xa1, 0x01, 0x15, 0x00, 0x26, 0xff,
                                                       0x00, 0x75, 0x08, 0x95, 0x06, 0x09, 0x01, 0x81, 0x02, 0xc0};

class PowerMateDialBox final : public DecodingDialBox {
 public:
  PowerMateDialBox(DeviceInfo info, const Clock& clock)
      : DecodingDialBox(std::move(info), *DialDecoder::create(kGriffinVendor, kPowerMateProduct, {}), clock) {}
  ~PowerMateDialBox() override { close(); }

 private:
  Result<void> doOpen() override {
    libusb_context* ctx = usbContext();
    if (!ctx) return fail(Errc::kUnavailable, "libusb could not start", info().path);
    libusb_device** raw = nullptr;
    const ssize_t count = libusb_get_device_list(ctx, &raw);
    DeviceListPtr list(raw);
    libusb_device* found = nullptr;
    for (ssize_t i = 0; i < count; ++i) {
      libusb_device_descriptor d{};
      if (libusb_get_device_descriptor(raw[i], &d) != 0) continue;
      if (d.idVendor == kGriffinVendor && d.idProduct == kPowerMateProduct && usbPath(raw[i]) == info().path) {
        found = raw[i];
      }
    }
    if (!found) return fail(Errc::kNotFound, "the PowerMate is not on USB any more", info().path);
    libusb_device_handle* h = nullptr;
    if (const int rc = libusb_open(found, &h); rc != 0) {
      if (rc == LIBUSB_ERROR_ACCESS) {
        return fail(Errc::kPermissionDenied, fmt::format("permission denied on {}; {}", usbNode(found), kUdevRuleHint),
                    info().path);
      }
      return fail(Errc::kUnavailable, fmt::format("cannot open: {}", libusb_strerror(rc)), info().path);
    }
    HandlePtr handle(h);
    libusb_set_auto_detach_kernel_driver(h, 1);
    if (const int rc = libusb_claim_interface(h, 0); rc != 0) {
      return fail(
          rc == LIBUSB_ERROR_BUSY ? Errc::kUnavailable : Errc::kIo,
          fmt::format("cannot claim the interface: {} (is another program using the PowerMate?)", libusb_strerror(rc)),
          info().path);
    }
    endpoint_ = 0x81;
    libusb_config_descriptor* cfg = nullptr;
    if (libusb_get_active_config_descriptor(found, &cfg) == 0) {
      ConfigPtr config(cfg);
      if (cfg->bNumInterfaces > 0 && cfg->interface[0].num_altsetting > 0) {
        const libusb_interface_descriptor& alt = cfg->interface[0].altsetting[0];
        for (int e = 0; e < alt.bNumEndpoints; ++e) {
          const auto& ep = alt.endpoint[e];
          if ((ep.bEndpointAddress & LIBUSB_ENDPOINT_IN) &&
              (ep.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) == LIBUSB_TRANSFER_TYPE_INTERRUPT) {
            endpoint_ = ep.bEndpointAddress;
            break;
          }
        }
      }
    }
    std::vector<std::uint8_t> descriptor(1024);
    const int got = libusb_control_transfer(h, static_cast<std::uint8_t>(0x81),  // in, standard, interface
                                            LIBUSB_REQUEST_GET_DESCRIPTOR, LIBUSB_DT_REPORT << 8, 0, descriptor.data(),
                                            static_cast<std::uint16_t>(descriptor.size()), 1000);
    if (got > 0) {
      descriptor.resize(static_cast<std::size_t>(got));
    } else {
      descriptor = kFallbackDescriptor;
    }
    setReportDescriptor(std::move(descriptor));
    handle_ = std::move(handle);
    startReader();
    return {};
  }

  void doClose() override {
    stopReader();
    if (handle_) libusb_release_interface(handle_.get(), 0);
    handle_.reset();
  }

  Result<void> doSetLight(int index, double level, bool pulse) override {
    if (index != 0) return fail(Errc::kInvalidArgument, "the PowerMate has one light, 0", info().path);
    std::lock_guard lock(controlMutex_);
    const auto brightness = static_cast<std::uint16_t>(std::lround(std::clamp(level, 0.0, 1.0) * 255));
    int rc = libusb_control_transfer(handle_.get(), 0x41, 0x01, 0x0001, brightness, nullptr, 0, 1000);
    if (rc >= 0) rc = libusb_control_transfer(handle_.get(), 0x41, 0x01, 0x0003, pulse ? 1 : 0, nullptr, 0, 1000);
    if (rc < 0) return fail(Errc::kIo, fmt::format("cannot set the LED: {}", libusb_strerror(rc)), info().path);
    return {};
  }

  void readLoop() override {
    std::array<std::uint8_t, 64> buf{};
    while (!stopping()) {
      int transferred = 0;
      const int rc = libusb_interrupt_transfer(handle_.get(), endpoint_, buf.data(), static_cast<int>(buf.size()),
                                               &transferred, 100);
      if (rc == LIBUSB_ERROR_TIMEOUT || rc == LIBUSB_ERROR_INTERRUPTED) continue;
      if (rc != 0) {
        reportLost(Error(Errc::kDeviceLost, fmt::format("read failed: {}", libusb_strerror(rc)), info().path));
        return;
      }
      handleReport(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(transferred)));
    }
  }

  HandlePtr handle_;
  std::uint8_t endpoint_ = 0x81;
  std::mutex controlMutex_;  // serialises LED control transfers
};

}  // namespace

std::vector<DeviceCandidate> listPowerMates() {
  std::vector<DeviceCandidate> out;
  libusb_context* ctx = usbContext();
  if (!ctx) return out;
  libusb_device** raw = nullptr;
  const ssize_t count = libusb_get_device_list(ctx, &raw);
  DeviceListPtr list(raw);
  for (ssize_t i = 0; i < count; ++i) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(raw[i], &d) != 0) continue;
    if (d.idVendor != kGriffinVendor || d.idProduct != kPowerMateProduct) continue;
    DeviceCandidate c;
    c.kind = DeviceKind::kDialBox;
    c.info = DeviceInfo{"Griffin PowerMate", "hid", "usb", d.idVendor, d.idProduct, usbPath(raw[i]), ""};
    c.usage = "Griffin PowerMate through libusb: 1 dial, 1 button, LED";
    const std::string node = usbNode(raw[i]);
    if (::access(node.c_str(), R_OK | W_OK) != 0) {
      c.problem = fmt::format("{} on {}; {}", systemErrorText("cannot open", errno), node, kUdevRuleHint);
    }
    out.push_back(std::move(c));
  }
  return out;
}

Result<std::unique_ptr<DialBox>> openPowerMate(const std::string& path, const Clock& clock) {
  std::string chosen = path;
  if (chosen.empty()) {
    auto all = listPowerMates();
    if (all.empty()) return fail(Errc::kNotFound, "no Griffin PowerMate (077d:0410) on USB", "usb");
    chosen = all.front().info.path;
  }
  return std::unique_ptr<DialBox>(std::make_unique<PowerMateDialBox>(
      DeviceInfo{"Griffin PowerMate", "hid", "usb", kGriffinVendor, kPowerMateProduct, chosen, ""}, clock));
}

}  // namespace basalt::devices
