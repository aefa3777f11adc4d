#pragma once

/// \file
/// \brief The virtual-lab contract for real-backend tests: the BASALT_VLAB_* variables the lab
/// sets (tools/vlab/README.md), and helpers to drive its gadgets.

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "devices/hid/report_descriptor.h"

namespace basalt::test {

/// \brief The variable's value, or nullopt when unset or empty.
inline std::optional<std::string> vlabEnv(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return std::nullopt;
  return std::string(v);
}

/// \brief The reason a real-backend test gives when the lab is not there.
inline std::string needsVlab(const std::string& what) { return "needs the virtual lab (make vlab): " + what; }

/// \brief A report for `descriptor` in which dial `dialIndex` (in the order of the first
/// relative Dial/Wheel/axis fields) moves by `counts` and everything else is zero. Empty when the
/// descriptor has no such field.
inline std::vector<std::uint8_t> makeDialReport(std::span<const std::uint8_t> descriptor, int counts) {
  auto parsed = devices::hid::parseReportDescriptor(descriptor);
  if (!parsed) return {};
  for (const auto& f : parsed->fields) {
    if (f.type != devices::hid::ReportType::kInput || !f.isVariable() || f.isConstant() || f.bitSize > 32) continue;
    const std::uint32_t u = f.usages.empty() ? 0 : f.usages[0];
    namespace us = devices::hid::usages;
    if (u != us::kDial && u != us::kWheel && u != us::kRx && u != us::kX) continue;
    const std::size_t bytes = parsed->reportBytes(devices::hid::ReportType::kInput, f.reportId);
    std::vector<std::uint8_t> report(bytes + (parsed->usesReportIds ? 1 : 0), 0);
    std::uint8_t* data = report.data();
    if (parsed->usesReportIds) {
      report[0] = f.reportId;
      ++data;
    }
    const auto raw = static_cast<std::uint32_t>(counts);
    for (std::uint32_t b = 0; b < f.bitSize; ++b) {
      const std::uint32_t bit = f.bitOffset + b;
      if ((raw >> b) & 1u) data[bit / 8] = static_cast<std::uint8_t>(data[bit / 8] | (1u << (bit % 8)));
    }
    return report;
  }
  return {};
}

}  // namespace basalt::test
