#include "devices/hid/tracker_decoder.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace basalt::devices {
namespace {

constexpr std::array<std::uint32_t, 6> kAxes{hid::usages::kX,  hid::usages::kY,  hid::usages::kZ,
                                             hid::usages::kRx, hid::usages::kRy, hid::usages::kRz};

// HID 1.11 §6.2.2.7: the low nibble is the system, the next the length exponent.
constexpr std::uint32_t kSystemSiLinear = 1, kSystemSiRotation = 2, kSystemEnglishLinear = 3,
                        kSystemEnglishRotation = 4;

// Metres (positions) or degrees (rotations) per physical unit, or nothing for a unit that is
// neither a length nor an angle.
std::optional<double> unitScale(std::uint32_t unit, bool rotation) {
  if (unit == 0) return 1.0;
  const std::uint32_t system = unit & 0xf;
  const std::uint32_t length = (unit >> 4) & 0xf;
  if (length != 1 || (unit >> 8) != 0) return std::nullopt;
  if (!rotation && system == kSystemSiLinear) return 0.01;
  if (!rotation && system == kSystemEnglishLinear) return 0.0254;
  if (rotation && system == kSystemSiRotation) return 180.0 / 3.14159265358979323846;
  if (rotation && system == kSystemEnglishRotation) return 1.0;
  return std::nullopt;
}

}  // namespace

Result<TrackerDecoder> TrackerDecoder::create(const hid::ReportDescriptor& descriptor, std::string_view where) {
  TrackerDecoder d;
  d.usesIds_ = descriptor.usesReportIds;
  std::optional<std::uint8_t> report;
  for (std::size_t axis = 0; axis < kAxes.size(); ++axis) {
    for (const hid::ReportField& f : descriptor.fields) {
      if (f.type != hid::ReportType::kInput || !f.isVariable() || f.isConstant() || f.isRelative()) continue;
      if (report && f.reportId != *report) continue;
      const auto at = std::ranges::find(f.usages, kAxes[axis]);
      if (at == f.usages.end()) continue;
      const auto scale = unitScale(f.unit, axis >= 3);
      if (!scale) {
        return fail(Errc::kUnsupported,
                    fmt::format("the tracker's {} has unit 0x{:x}, which is neither a length nor an angle",
                                hid::usageName(kAxes[axis]), f.unit),
                    std::string(where));
      }
      report = f.reportId;
      d.fields_.push_back(f);
      d.fieldOf_[axis] = d.fields_.size() - 1;
      d.elementOf_[axis] = static_cast<std::uint32_t>(at - f.usages.begin());
      d.scaleOf_[axis] = *scale * std::pow(10.0, f.unitExponent);
      break;
    }
    if (axis < 3 && !d.fieldOf_[axis]) {
      return fail(Errc::kUnsupported,
                  fmt::format("not a tracker: the descriptor has no absolute {} beside the other axes (a device "
                              "with relative axes, a 6-axis puck, is a dial box)",
                              hid::usageName(kAxes[axis])),
                  std::string(where));
    }
  }
  d.reportId_ = report.value_or(0);
  d.hasRotation_ = d.fieldOf_[3] || d.fieldOf_[4] || d.fieldOf_[5];
  return d;
}

std::optional<runtime::TrackerSample> TrackerDecoder::decode(std::span<const std::uint8_t> report, Nanos time) const {
  std::span<const std::uint8_t> data = report;
  if (usesIds_) {
    if (report.empty() || report[0] != reportId_) return std::nullopt;
    data = report.subspan(1);
  }
  std::array<float, 6> v{};
  for (std::size_t axis = 0; axis < v.size(); ++axis) {
    if (!fieldOf_[axis]) continue;
    const hid::ReportField& f = fields_[*fieldOf_[axis]];
    bool ok = false;
    const std::int64_t raw = hid::extractElement(f, elementOf_[axis], data, &ok);
    if (!ok) return std::nullopt;
    // HID 1.11 §6.2.2.7: the logical range maps linearly onto the physical range.
    const double span = static_cast<double>(f.logicalMax) - static_cast<double>(f.logicalMin);
    double physical = static_cast<double>(raw);
    if (span != 0 && (f.physicalMin != f.logicalMin || f.physicalMax != f.logicalMax)) {
      physical = f.physicalMin + (static_cast<double>(raw) - f.logicalMin) *
                                     (static_cast<double>(f.physicalMax) - static_cast<double>(f.physicalMin)) / span;
    }
    v[axis] = static_cast<float>(physical * scaleOf_[axis]);
  }
  runtime::TrackerSample s;
  s.time = time;
  s.position = {v[0], v[1], v[2]};
  s.rotation = {v[3], v[4], v[5]};
  return s;
}

const std::vector<std::uint8_t>& virtualTrackerDescriptor() {
  static const std::vector<std::uint8_t> descriptor{
      0x05, 0x01,                          // Usage Page (Generic Desktop)
      0x09, 0x08,                          // Usage (Multi-axis Controller)
      0xa1, 0x01,                          // Collection (Application)
      0x09, 0x30, 0x09, 0x31, 0x09, 0x32,  //   Usage (X), Usage (Y), Usage (Z)
      0x17, 0x01, 0x00, 0x00, 0x80,        //   Logical Minimum (-2147483647)
      0x27, 0xff, 0xff, 0xff, 0x7f,        //   Logical Maximum (2147483647)
      0x65, 0x11,                          //   Unit (SI Linear: centimetre)
      0x55, 0x0c,                          //   Unit Exponent (-4): micrometres
      0x75, 0x20,                          //   Report Size (32)
      0x95, 0x03,                          //   Report Count (3)
      0x81, 0x02,                          //   Input (Data, Variable, Absolute)
      0x09, 0x33, 0x09, 0x34, 0x09, 0x35,  //   Usage (Rx), Usage (Ry), Usage (Rz)
      0x65, 0x14,                          //   Unit (English Rotation: degree)
      0x55, 0x0c,                          //   Unit Exponent (-4)
      0x81, 0x02,                          //   Input (Data, Variable, Absolute)
      0xc0,                                // End Collection
  };
  return descriptor;
}

std::array<std::uint8_t, 24> encodeVirtualTrackerReport(const runtime::TrackerSample& sample) {
  const auto d = [](float v) { return static_cast<double>(v); };
  const std::array<double, 6> values{d(sample.position.x) * 1e6, d(sample.position.y) * 1e6,
                                     d(sample.position.z) * 1e6, d(sample.rotation.x) * 1e4,
                                     d(sample.rotation.y) * 1e4, d(sample.rotation.z) * 1e4};
  std::array<std::uint8_t, 24> report{};
  for (std::size_t i = 0; i < values.size(); ++i) {
    constexpr double kMax = std::numeric_limits<std::int32_t>::max();
    const double v = std::isfinite(values[i]) ? std::clamp(std::round(values[i]), -kMax, kMax) : 0.0;
    const auto bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(v));
    for (std::size_t b = 0; b < 4; ++b) report[i * 4 + b] = static_cast<std::uint8_t>(bits >> (8 * b));
  }
  return report;
}

}  // namespace basalt::devices
