#pragma once

/// \file
/// \brief HID trackers: reports of a device with absolute Generic Desktop X/Y/Z (and optionally
/// Rx/Ry/Rz) decoded into tracker samples, and Basalt's virtual tracker descriptor, into which
/// trackers without HID reports (synthetic, fed) are encoded for recording. Pure C++: used by
/// the hidraw backend and by trace replay alike.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "devices/hid/report_descriptor.h"
#include "runtime/error.h"
#include "runtime/head_tracking.h"

namespace basalt::devices {

/// \brief Maps one report of a tracker's descriptor to a sample.
///
/// Positions: a field whose unit is a length (SI linear centimetres, English linear inches) is
/// given in metres; a field without a unit in its logical counts (the manifest's placement
/// scales them). Rotations: SI radians and English degrees are given in degrees; without a unit,
/// in logical counts taken as degrees. Physical ranges and unit exponents apply (HID 1.11
/// §6.2.2.7). X, Y and Z must be absolute variables of one report; Rx/Ry/Rz are optional (0).
class TrackerDecoder {
 public:
  /// \brief Finds the axes; an error names what the descriptor lacks ("no absolute X, Y and Z:
  /// a relative 6-axis puck is a dial box").
  [[nodiscard]] static Result<TrackerDecoder> create(const hid::ReportDescriptor& descriptor,
                                                     std::string_view where = {});
  /// \brief One input report as read from hidraw (with its id byte when the descriptor uses
  /// ids). Nothing for a report of another id or too short.
  [[nodiscard]] std::optional<runtime::TrackerSample> decode(std::span<const std::uint8_t> report, Nanos time) const;
  [[nodiscard]] std::uint8_t reportId() const { return reportId_; }
  [[nodiscard]] bool hasRotation() const { return hasRotation_; }

 private:
  TrackerDecoder() = default;

  std::vector<hid::ReportField> fields_;                 // copies of the fields the axes read
  std::array<std::optional<std::size_t>, 6> fieldOf_{};  // X Y Z Rx Ry Rz -> fields_ index
  std::array<std::uint32_t, 6> elementOf_{};
  std::array<double, 6> scaleOf_{};  // metres or degrees per physical unit, with the exponent
  std::uint8_t reportId_ = 0;
  bool usesIds_ = false;
  bool hasRotation_ = false;
};

/// \brief Basalt's virtual tracker: one 24-byte report, X/Y/Z as signed 32-bit micrometres and
/// Rx/Ry/Rz as signed 32-bit ten-thousandths of a degree, absolute, in a Multi-axis Controller
/// application collection; no report id.
const std::vector<std::uint8_t>& virtualTrackerDescriptor();

/// \brief A sample as a report of the virtual tracker descriptor (positions taken as metres;
/// values beyond the 32-bit range are clamped). Decoding it gives the sample rounded to a
/// micrometre and a ten-thousandth of a degree, the same every time.
std::array<std::uint8_t, 24> encodeVirtualTrackerReport(const runtime::TrackerSample& sample);

}  // namespace basalt::devices
