#pragma once

/// \file
/// \brief HID report descriptors (Device Class Definition for HID 1.11, §6.2.2): parsed into the
/// fields of each input, output and feature report, with their usages, ranges, units and bit
/// positions. Pure C++: used by the hidraw and libusb backends, by trace replay and by
/// `basalt devices`. Malformed descriptors give an error naming the byte, never a crash.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/error.h"

namespace basalt::devices::hid {

enum class ReportType : std::uint8_t { kInput, kOutput, kFeature };

/// \brief A full 32-bit usage: page in the high half, id in the low half.
constexpr std::uint32_t usage(std::uint16_t page, std::uint16_t id) { return std::uint32_t{page} << 16 | id; }
constexpr std::uint16_t usagePage(std::uint32_t full) { return static_cast<std::uint16_t>(full >> 16); }
constexpr std::uint16_t usageId(std::uint32_t full) { return static_cast<std::uint16_t>(full & 0xffff); }

namespace usages {
inline constexpr std::uint16_t kGenericDesktop = 0x01;
inline constexpr std::uint16_t kKeyboard = 0x07;
inline constexpr std::uint16_t kButton = 0x09;
inline constexpr std::uint16_t kConsumer = 0x0c;
inline constexpr std::uint16_t kDigitizer = 0x0d;
inline constexpr std::uint32_t kX = usage(kGenericDesktop, 0x30);
inline constexpr std::uint32_t kY = usage(kGenericDesktop, 0x31);
inline constexpr std::uint32_t kZ = usage(kGenericDesktop, 0x32);
inline constexpr std::uint32_t kRx = usage(kGenericDesktop, 0x33);
inline constexpr std::uint32_t kRy = usage(kGenericDesktop, 0x34);
inline constexpr std::uint32_t kRz = usage(kGenericDesktop, 0x35);
inline constexpr std::uint32_t kDial = usage(kGenericDesktop, 0x37);
inline constexpr std::uint32_t kWheel = usage(kGenericDesktop, 0x38);
inline constexpr std::uint32_t kResolutionMultiplier = usage(kGenericDesktop, 0x48);
inline constexpr std::uint32_t kMultiAxisController = usage(kGenericDesktop, 0x08);
inline constexpr std::uint32_t kSystemMultiAxisController = usage(kGenericDesktop, 0x0e);
inline constexpr std::uint32_t kPuck = usage(kDigitizer, 0x21);
}  // namespace usages

/// \brief Bits of a main item's data (Input, Output, Feature).
namespace field_flags {
inline constexpr std::uint32_t kConstant = 1u << 0;
inline constexpr std::uint32_t kVariable = 1u << 1;
inline constexpr std::uint32_t kRelative = 1u << 2;
inline constexpr std::uint32_t kWrap = 1u << 3;
inline constexpr std::uint32_t kNullState = 1u << 6;
}  // namespace field_flags

/// \brief A collection, with the index of its parent (-1 for top level).
struct Collection {
  std::uint32_t usage = 0;
  std::uint8_t type = 0;  ///< 0 physical, 1 application, 2 logical, ...
  int parent = -1;
};

/// \brief One main item: `count` elements of `bitSize` bits each, at `bitOffset` in its report
/// (counted after the report id byte).
struct ReportField {
  ReportType type = ReportType::kInput;
  std::uint8_t reportId = 0;  ///< 0 when the descriptor declares no report ids
  std::uint32_t bitOffset = 0;
  std::uint32_t bitSize = 0;
  std::uint32_t count = 0;
  std::uint32_t flags = 0;
  std::int32_t logicalMin = 0;
  std::int32_t logicalMax = 0;
  std::int32_t physicalMin = 0;
  std::int32_t physicalMax = 0;
  std::uint32_t unit = 0;
  std::int8_t unitExponent = 0;
  /// Variable fields: the usage of each element (`count` entries). Array fields: the usages an
  /// element's value selects, from index logicalMin on (may be empty when a range is given).
  std::vector<std::uint32_t> usages;
  std::uint32_t usageMin = 0;  ///< array fields declared with a usage range
  std::uint32_t usageMax = 0;
  int collection = -1;            ///< innermost enclosing collection
  std::uint32_t application = 0;  ///< usage of the enclosing application collection

  [[nodiscard]] bool isConstant() const { return (flags & field_flags::kConstant) != 0; }
  [[nodiscard]] bool isVariable() const { return (flags & field_flags::kVariable) != 0; }
  [[nodiscard]] bool isRelative() const { return (flags & field_flags::kRelative) != 0; }
  [[nodiscard]] bool wraps() const { return (flags & field_flags::kWrap) != 0; }
  [[nodiscard]] bool isSigned() const { return logicalMin < 0; }
  /// \brief The usage an array element's value selects, or 0.
  [[nodiscard]] std::uint32_t arrayUsage(std::int64_t value) const;
};

/// \brief A parsed report descriptor.
struct ReportDescriptor {
  std::vector<ReportField> fields;
  std::vector<Collection> collections;
  bool usesReportIds = false;
  /// Items skipped (reserved tags and types, 0x00 padding and long items, see the parser), one
  /// line each ("byte 41: main item 0x00 with a reserved tag"); at most 17 lines.
  std::vector<std::string> ignored;

  /// \brief Bytes of report `id` of `type`, without the id byte.
  [[nodiscard]] std::size_t reportBytes(ReportType type, std::uint8_t id) const;
  /// \brief Whether collection `index` is `ancestor` or inside it.
  [[nodiscard]] bool isInside(int index, int ancestor) const;
};

/// \brief Parses `bytes`. Errors say which byte and what is wrong; `where` names the device or
/// file for the message.
[[nodiscard]] Result<ReportDescriptor> parseReportDescriptor(std::span<const std::uint8_t> bytes,
                                                             std::string_view where = {});

/// \brief Element `index` of `field` in `data` (the report without its id byte), sign-extended
/// when the logical minimum is negative. Fields wider than 32 bits and bits past the end of
/// `data` read as 0; `ok` (when given) says whether the element was inside `data`.
[[nodiscard]] std::int64_t extractElement(const ReportField& field, std::uint32_t index,
                                          std::span<const std::uint8_t> data, bool* ok = nullptr);

/// \brief "Generic Desktop Dial", "Button 3", "0xff00:0x01": a usage for messages.
std::string usageName(std::uint32_t full);

}  // namespace basalt::devices::hid
