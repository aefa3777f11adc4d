#pragma once

/// \file
/// \brief Reads HID recordings in hid-tools' `hid-recorder` text format, for the virtual lab's
/// uhid replay (sim/vlab/hid_replay_main.cpp).
///
/// The format, one record per line: `# comment`; `D: N` selects device N (a new one when N is
/// the next index); `R: LEN BYTES...` its report descriptor; `N: name`; `I: BUS VENDOR PRODUCT`
/// (hex); `P: phys`; `E: SECONDS.MICROS LEN BYTES...` an input report at that time. Other
/// line types are ignored, so newer recorders stay readable.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::sim::vlab {

/// \brief One input report as recorded, with its time since the recording started.
struct HidRecordedReport {
  Nanos time{0};
  std::vector<std::uint8_t> bytes;
};

/// \brief One recorded HID device: who it is, its report descriptor and its reports.
struct HidRecordedDevice {
  std::string name;
  std::string phys;
  std::uint16_t bus = 0;  ///< BUS_USB (3), BUS_BLUETOOTH (5), ...
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::vector<std::uint8_t> descriptor;
  std::vector<HidRecordedReport> reports;
};

/// \brief Parses a recording. `file` names it in errors ("file:line: what is wrong").
/// A device without a report descriptor, a length that disagrees with the bytes, or a value
/// that is not hex is an error; a recording with no device is one too.
[[nodiscard]] Result<std::vector<HidRecordedDevice>> parseHidRecording(std::string_view text, std::string_view file);

/// \brief Reads and parses a recording file (at most 64 MiB).
[[nodiscard]] Result<std::vector<HidRecordedDevice>> readHidRecording(const std::filesystem::path& path);

}  // namespace basalt::sim::vlab
