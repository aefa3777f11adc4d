#pragma once

/// \file
/// \brief The hid-tools `hid-recorder` text format: what `basalt record` writes for every dial
/// box and what the `replay` backend plays, so that recordings made with hid-recorder on any Linux
/// machine replay in Basalt and Basalt's replay with hid-replay.
///
/// Lines: `# comment`; `D: n` starts device n of a multi-device recording; `R: len bytes...` the
/// report descriptor; `N: name`; `P: phys`; `I: bus vendor product` (hex); `E: sec.usec len
/// bytes...` one input report at that time since the recording started.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::sim {

/// \brief One recorded input report.
struct HidReport {
  Nanos time{0};  ///< since the start of the recording (microsecond resolution in the file)
  std::vector<std::uint8_t> bytes;
};

/// \brief One recorded device.
struct HidRecordedDevice {
  int index = 0;  ///< the D: number (0 for single-device files)
  std::string name;
  std::string phys;
  std::uint16_t bus = 0;  ///< 3 USB, 5 Bluetooth, 6 virtual (Linux BUS_* numbers)
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::vector<std::uint8_t> descriptor;
  std::vector<HidReport> reports;  ///< in file order (hid-recorder writes them in time order)
};

struct HidRecording {
  std::vector<HidRecordedDevice> devices;
};

/// \brief Parses a recording. Errors name the file and line ("keydial.hid:12: ...").
[[nodiscard]] Result<HidRecording> parseHidRecording(std::string_view text, std::string_view name = "recording");
/// \brief Reads and parses a file (at most 256 MiB).
[[nodiscard]] Result<HidRecording> readHidRecording(const std::filesystem::path& path);

/// \brief "usb", "bluetooth", "virtual", "i2c", or the number.
std::string busName(std::uint16_t bus);

/// \brief Writes one device in the same format, incrementally: the header first, then one line
/// per report. Threading: one writer at a time (the recorder serialises).
class HidRecordingWriter {
 public:
  /// \brief The header lines (D:, R:, N:, P:, I:) for `device` (its reports are not written).
  static std::string header(const HidRecordedDevice& device, bool withDeviceLine);
  /// \brief One E: line.
  static std::string reportLine(Nanos time, std::span<const std::uint8_t> bytes);
};

}  // namespace basalt::sim
