#pragma once

/// \file
/// \brief The `hid` backend: dial boxes on hidraw (through hidapi's hidraw backend: the Contour
/// Shuttles, the Surface Dial, Huion dials, any HID device with dials) and the Griffin PowerMate
/// through libusb (the HID core ignores it, so it has no hidraw node). Includes no hidapi or
/// libusb header: those stay in devices/hid/*.cpp.

#include <memory>
#include <string>
#include <vector>

#include "devices/device_manager.h"

namespace basalt::devices {

/// \brief The udev rule `basalt devices` points to when a device cannot be opened.
inline constexpr std::string_view kUdevRuleHint =
    "install configs/udev/70-basalt.rules (sudo cp configs/udev/70-basalt.rules /etc/udev/rules.d/ && sudo udevadm "
    "control --reload && sudo udevadm trigger), then replug the device";

/// \brief The `hid` backend. Enumerates hidraw devices whose descriptors map to dials (others are
/// listed with the reason they are not used) and PowerMates on USB (path `usb:BUS-PORTS`).
class HidProvider final : public DeviceProvider {
 public:
  HidProvider();
  ~HidProvider() override;
  [[nodiscard]] std::string_view backend() const override { return "hid"; }
  std::vector<DeviceCandidate> enumerate() override;
  Result<std::unique_ptr<DialBox>> openDialBox(const DeviceCandidate& candidate, const DeviceRequest& request,
                                               const Clock& clock) override;
  /// \brief A hidraw node with absolute X, Y and Z (devices/hid/tracker_decoder.h).
  Result<std::unique_ptr<Tracker>> openTracker(const DeviceCandidate& candidate, const DeviceRequest& request,
                                               const Clock& clock) override;
};

/// \brief Reads a hidraw node's report descriptor from sysfs (/sys/class/hidraw/NAME/device/
/// report_descriptor): hidapi 0.13 has no call for it.
[[nodiscard]] Result<std::vector<std::uint8_t>> readHidrawDescriptor(const std::string& devnode);

/// \brief Why this process may not open a hidraw node for reading and writing, pointing at the
/// udev rule when permissions are the reason; empty when it may.
[[nodiscard]] std::string hidrawAccessProblem(const std::string& devnode);

/// \brief Opens a hidraw node as a dial box directly (tests, `basalt record --hid PATH`).
[[nodiscard]] Result<std::unique_ptr<DialBox>> openHidrawDialBox(const std::string& devnode, const Clock& clock);

/// \brief Opens a hidraw node as a tracker directly (tests).
[[nodiscard]] Result<std::unique_ptr<Tracker>> openHidrawTracker(const std::string& devnode, const Clock& clock);

/// \brief Opens the first PowerMate on USB whose `usb:BUS-PORTS` path is `path` (any when empty).
[[nodiscard]] Result<std::unique_ptr<DialBox>> openPowerMate(const std::string& path, const Clock& clock);

}  // namespace basalt::devices
