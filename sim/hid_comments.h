#pragma once

/// \file
/// \brief The `# ` comment lines of an hid-recorder file, which make a recording readable
/// without tools: the report descriptor item by item before the `R:` line, and before each `E:`
/// line what the report says, field by field, by the descriptor's usages ("ReportID: 1 / Dial:
/// 5, 0, 0 | Button: 0 1 0"). Readers skip them (hid-recorder's own files carry the same kind of
/// comments), so they are for people only; what replays is the bytes.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "devices/device.h"
#include "devices/hid/report_descriptor.h"

namespace basalt::sim {

/// \brief Comment lines for one device's descriptor and reports.
///
/// Threading: const after create(); one instance may describe reports from any thread.
class HidComments {
 public:
  /// \brief Never fails: a descriptor that does not parse still gets its items listed, and its
  /// reports get no comment (the header says why).
  static HidComments create(std::span<const std::uint8_t> descriptor);

  /// \brief "# 0x05, 0x01,  // Usage Page (Generic Desktop)  0" lines, one per descriptor item
  /// (indented by collection, with the item's byte offset), each ending in '\n'.
  [[nodiscard]] std::string descriptorLines() const;
  /// \brief "# ReportID: 1 / Dial: 5, 0 | Button: 0 1\n" for an input report (with its id byte
  /// when the descriptor uses ids); "" when the descriptor could not be parsed.
  [[nodiscard]] std::string reportLine(std::span<const std::uint8_t> report) const;

 private:
  std::vector<std::uint8_t> bytes_;
  devices::hid::ReportDescriptor parsed_;
  bool ok_ = false;
  std::string why_;  // why the descriptor did not parse
};

/// \brief "Generic Desktop", "Button", "Consumer", "Vendor Defined 0xff00": a usage page's name.
std::string usagePageName(std::uint16_t page);
/// \brief "Dial", "X", "Button 3", "Play/Pause", "Vendor Usage 0x01": a usage's short name.
std::string shortUsageName(std::uint32_t usage);

/// \brief The `P:` line's physical path of a recorded device: the kernel's (HID_PHYS in
/// `SYSFS/class/hidraw/hidrawN/device/uevent`, as hid-recorder's HIDIOCGRAWPHYS gives it) for a
/// hidraw node, otherwise the device's path ("usb:1-2" for a PowerMate on libusb,
/// "synthetic:dials"), or "basalt" when it has none. `sysfs` is "/sys" but for tests.
std::string hidPhysicalPath(const devices::DeviceInfo& info, const std::filesystem::path& sysfs = "/sys");

}  // namespace basalt::sim
