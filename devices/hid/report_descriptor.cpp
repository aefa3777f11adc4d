// HID report descriptor parser (HID 1.11 §6.2.2). Pure C++, no hidapi: the same parser serves
// the hidraw and libusb backends, trace replay, `basalt devices` and the fuzzer.
//
// Limits (generous for real devices, small enough that a hostile descriptor cannot exhaust
// memory): 1024 fields, 64 nested collections, 16 pushed global states, 1024-bit elements,
// 65536 bits per field, 4096 usages per main item.
//
// What Linux's parser (drivers/hid/hid-core.c) accepts is accepted: main items with a reserved
// tag (a trailing 0x00 pad byte is one), items of the reserved type and local items with a
// reserved tag are skipped, and a Usage Maximum below its Usage Minimum adds no usage. Long items
// (0xfe, defined by HID 1.11 but without any tag in use) are skipped by their length; Linux
// refuses them. Global items with a reserved tag are refused, as Linux refuses them. What was
// skipped is listed in `ignored`.

#include "devices/hid/report_descriptor.h"

#include <algorithm>
#include <array>
#include <map>
#include <utility>

#include <fmt/format.h>

namespace basalt::devices::hid {

namespace {

constexpr std::size_t kMaxFields = 1024;
constexpr std::size_t kMaxCollectionDepth = 64;
constexpr std::size_t kMaxPushDepth = 16;
constexpr std::uint32_t kMaxReportSize = 1024;
constexpr std::uint64_t kMaxFieldBits = 65536;
constexpr std::size_t kMaxUsages = 4096;
constexpr std::size_t kMaxIgnoredNotes = 16;  // further skipped items are counted, not described

struct Globals {
  std::uint16_t usagePage = 0;
  std::int32_t logicalMin = 0;
  std::uint32_t logicalMaxRaw = 0;
  int logicalMaxSize = 0;
  std::int32_t physicalMin = 0;
  std::uint32_t physicalMaxRaw = 0;
  int physicalMaxSize = 0;
  bool physicalSet = false;
  std::int8_t unitExponent = 0;
  std::uint32_t unit = 0;
  std::uint32_t reportSize = 0;
  std::uint8_t reportId = 0;
  std::uint32_t reportCount = 0;
};

struct UsageEntry {
  std::uint32_t min = 0;
  std::uint32_t max = 0;
};

struct Locals {
  std::vector<UsageEntry> usages;
  std::uint32_t pendingMin = 0;
  bool haveMin = false;
  std::size_t total = 0;
  void clear() {
    usages.clear();
    haveMin = false;
    total = 0;
  }
};

std::int32_t signExtend(std::uint32_t value, int size) {
  switch (size) {
    case 1: return static_cast<std::int8_t>(value);
    case 2: return static_cast<std::int16_t>(value);
    default: return static_cast<std::int32_t>(value);
  }
}

/// A maximum is signed when its minimum is negative (what Linux and Windows do with the
/// ambiguous encoding: `15 00 25 ff` means 0..255).
std::int32_t resolveMax(std::int32_t min, std::uint32_t raw, int size) {
  if (min < 0) return signExtend(raw, size);
  return static_cast<std::int32_t>(std::min<std::uint32_t>(raw, 0x7fffffff));
}

std::uint32_t fullUsage(std::uint32_t value, int size, std::uint16_t page) {
  return size == 4 ? value : usage(page, static_cast<std::uint16_t>(value & 0xffff));
}

}  // namespace

std::uint32_t ReportField::arrayUsage(std::int64_t value) const {
  if (value < logicalMin || value > logicalMax) return 0;
  const auto index = static_cast<std::uint64_t>(value - logicalMin);
  if (!usages.empty()) return index < usages.size() ? usages[index] : 0;
  if (usageMax >= usageMin && index <= usageMax - usageMin) return usageMin + static_cast<std::uint32_t>(index);
  return 0;
}

std::size_t ReportDescriptor::reportBytes(ReportType type, std::uint8_t id) const {
  std::uint64_t bits = 0;
  for (const ReportField& f : fields) {
    if (f.type == type && f.reportId == id) {
      bits = std::max<std::uint64_t>(bits, std::uint64_t{f.bitOffset} + std::uint64_t{f.bitSize} * f.count);
    }
  }
  return static_cast<std::size_t>((bits + 7) / 8);
}

bool ReportDescriptor::isInside(int index, int ancestor) const {
  for (int i = index, guard = 0; i >= 0 && guard < 256; i = collections[static_cast<std::size_t>(i)].parent, ++guard) {
    if (i == ancestor) return true;
  }
  return false;
}

Result<ReportDescriptor> parseReportDescriptor(std::span<const std::uint8_t> bytes, std::string_view where) {
  const std::string at = where.empty() ? std::string("HID report descriptor") : std::string(where);
  auto bad = [&](std::size_t offset, std::string what) {
    return fail(Errc::kParse,
                fmt::format("malformed HID report descriptor at byte {}: {}; the device or recording is damaged or "
                            "not a HID dial box",
                            offset, what),
                at);
  };
  if (bytes.empty()) return fail(Errc::kParse, "the HID report descriptor is empty", at);

  ReportDescriptor out;
  Globals g;
  std::vector<Globals> stack;
  Locals locals;
  std::vector<int> open;                            // indices of open collections
  std::map<std::uint32_t, std::uint32_t> bitsUsed;  // (type << 8 | id) -> bits so far
  std::size_t ignoredCount = 0;
  auto skip = [&](std::size_t offset, std::string what) {
    if (++ignoredCount <= kMaxIgnoredNotes) out.ignored.push_back(fmt::format("byte {}: {}", offset, what));
  };

  std::size_t pos = 0;
  while (pos < bytes.size()) {
    const std::size_t itemStart = pos;
    const std::uint8_t prefix = bytes[pos++];
    if (prefix == 0xfe) {  // long item: size, tag, data
      if (pos + 2 > bytes.size()) return bad(itemStart, "a long item is cut short");
      const std::size_t size = bytes[pos];
      const std::uint8_t longTag = bytes[pos + 1];
      pos += 2 + size;
      if (pos > bytes.size()) return bad(itemStart, "a long item is cut short");
      skip(itemStart, fmt::format("long item with tag 0x{:02x} and {} data byte(s)", longTag, size));
      continue;
    }
    static constexpr std::array<int, 4> kSizes = {0, 1, 2, 4};
    const int size = kSizes[prefix & 3];
    const int type = (prefix >> 2) & 3;
    const int tag = prefix >> 4;
    if (pos + static_cast<std::size_t>(size) > bytes.size()) {
      return bad(itemStart, fmt::format("item 0x{:02x} needs {} data byte(s) but the descriptor ends", prefix, size));
    }
    std::uint32_t value = 0;
    for (int i = 0; i < size; ++i) value |= std::uint32_t{bytes[pos + static_cast<std::size_t>(i)]} << (8 * i);
    pos += static_cast<std::size_t>(size);
    const std::int32_t svalue = signExtend(value, size);

    if (type == 0) {  // main
      if (tag == 0x8 || tag == 0x9 || tag == 0xb) {
        const ReportType rtype =
            tag == 0x8 ? ReportType::kInput : (tag == 0x9 ? ReportType::kOutput : ReportType::kFeature);
        if (g.reportSize > kMaxReportSize) {
          return bad(itemStart, fmt::format("Report Size {} bits is more than {}", g.reportSize, kMaxReportSize));
        }
        const std::uint64_t fieldBits = std::uint64_t{g.reportSize} * g.reportCount;
        if (fieldBits > kMaxFieldBits) {
          return bad(itemStart, fmt::format("a field of {} x {} bits is too large", g.reportCount, g.reportSize));
        }
        std::uint32_t& used = bitsUsed[static_cast<std::uint32_t>(rtype) << 8 | g.reportId];
        if (fieldBits > 0) {
          if (out.fields.size() >= kMaxFields) return bad(itemStart, "more than 1024 fields");
          ReportField f;
          f.type = rtype;
          f.reportId = g.reportId;
          f.bitOffset = used;
          f.bitSize = g.reportSize;
          f.count = g.reportCount;
          f.flags = value;
          f.logicalMin = g.logicalMin;
          f.logicalMax = resolveMax(g.logicalMin, g.logicalMaxRaw, g.logicalMaxSize);
          if (g.physicalSet && !(g.physicalMin == 0 && g.physicalMaxRaw == 0)) {
            f.physicalMin = g.physicalMin;
            f.physicalMax = resolveMax(g.physicalMin, g.physicalMaxRaw, g.physicalMaxSize);
          } else {
            f.physicalMin = f.logicalMin;
            f.physicalMax = f.logicalMax;
          }
          f.unit = g.unit;
          f.unitExponent = g.unitExponent;
          f.collection = open.empty() ? -1 : open.back();
          for (int c = f.collection, guard = 0; c >= 0 && guard < 256;
               c = out.collections[static_cast<std::size_t>(c)].parent, ++guard) {
            if (out.collections[static_cast<std::size_t>(c)].type == 1) {
              f.application = out.collections[static_cast<std::size_t>(c)].usage;
              break;
            }
          }
          if (f.isVariable()) {
            for (const UsageEntry& e : locals.usages) {
              for (std::uint64_t u = e.min; u <= e.max && f.usages.size() < f.count; ++u) {
                f.usages.push_back(static_cast<std::uint32_t>(u));
              }
              if (f.usages.size() >= f.count) break;
            }
            if (!f.usages.empty()) {
              while (f.usages.size() < f.count) f.usages.push_back(f.usages.back());
            } else {
              f.usages.assign(f.count, 0);
            }
          } else if (locals.usages.size() == 1 && locals.usages[0].max > locals.usages[0].min) {
            f.usageMin = locals.usages[0].min;
            f.usageMax = locals.usages[0].max;
          } else {
            for (const UsageEntry& e : locals.usages) {
              for (std::uint64_t u = e.min; u <= e.max && f.usages.size() < kMaxUsages; ++u) {
                f.usages.push_back(static_cast<std::uint32_t>(u));
              }
            }
          }
          out.fields.push_back(std::move(f));
        }
        used += static_cast<std::uint32_t>(fieldBits);
      } else if (tag == 0xa) {  // Collection
        if (open.size() >= kMaxCollectionDepth) return bad(itemStart, "collections nested more than 64 deep");
        Collection c;
        c.usage = locals.usages.empty() ? 0 : locals.usages.front().min;
        c.type = static_cast<std::uint8_t>(value & 0xff);
        c.parent = open.empty() ? -1 : open.back();
        out.collections.push_back(c);
        open.push_back(static_cast<int>(out.collections.size() - 1));
      } else if (tag == 0xc) {  // End Collection
        if (open.empty()) return bad(itemStart, "End Collection without an open collection");
        open.pop_back();
      } else {
        // Reserved main tags, 0x00 padding among them; Linux skips them and so do we. Like any
        // main item they end the local state.
        skip(itemStart, fmt::format("main item 0x{:02x} with a reserved tag", prefix));
      }
      locals.clear();
    } else if (type == 1) {  // global
      switch (tag) {
        case 0x0: g.usagePage = static_cast<std::uint16_t>(value & 0xffff); break;
        case 0x1: g.logicalMin = svalue; break;
        case 0x2:
          g.logicalMaxRaw = value;
          g.logicalMaxSize = size;
          break;
        case 0x3:
          g.physicalMin = svalue;
          g.physicalSet = true;
          break;
        case 0x4:
          g.physicalMaxRaw = value;
          g.physicalMaxSize = size;
          g.physicalSet = true;
          break;
        case 0x5:
          // HID 1.11 stores the exponent as a 4-bit two's complement nibble; some devices use a
          // whole signed byte.
          g.unitExponent = value <= 0xf ? static_cast<std::int8_t>(value >= 8 ? static_cast<int>(value) - 16
                                                                              : static_cast<int>(value))
                                        : static_cast<std::int8_t>(svalue);
          break;
        case 0x6: g.unit = value; break;
        case 0x7: g.reportSize = value; break;
        case 0x8:
          if (value == 0 || value > 255) return bad(itemStart, fmt::format("Report ID {} is not 1..255", value));
          g.reportId = static_cast<std::uint8_t>(value);
          out.usesReportIds = true;
          break;
        case 0x9: g.reportCount = value; break;
        case 0xa:
          if (stack.size() >= kMaxPushDepth) return bad(itemStart, "Push nested more than 16 deep");
          stack.push_back(g);
          break;
        case 0xb:
          if (stack.empty()) return bad(itemStart, "Pop without Push");
          g = stack.back();
          stack.pop_back();
          break;
        default: return bad(itemStart, fmt::format("unknown global item 0x{:02x}", prefix));
      }
    } else if (type == 2) {  // local
      switch (tag) {
        case 0x0:
          if (locals.total >= kMaxUsages) return bad(itemStart, "more than 4096 usages before one main item");
          locals.usages.push_back({fullUsage(value, size, g.usagePage), fullUsage(value, size, g.usagePage)});
          ++locals.total;
          break;
        case 0x1:
          locals.pendingMin = fullUsage(value, size, g.usagePage);
          locals.haveMin = true;
          break;
        case 0x2: {
          // Linux counts from usage 0 without a minimum, which with any usage page runs past its
          // usage limit and refuses the descriptor; refused here too. A maximum below its
          // minimum adds no usage (Linux).
          if (!locals.haveMin) return bad(itemStart, "Usage Maximum without Usage Minimum");
          const std::uint32_t min = locals.pendingMin;
          const std::uint32_t max = fullUsage(value, size, g.usagePage);
          if (max < min) {
            skip(itemStart, "Usage Maximum below its Usage Minimum; no usages");
            locals.haveMin = false;
            break;
          }
          if (locals.total >= kMaxUsages) return bad(itemStart, "more than 4096 usages before one main item");
          locals.usages.push_back({min, max});
          locals.total += 1;
          locals.haveMin = false;
          break;
        }
        case 0x3:
        case 0x4:
        case 0x5:
        case 0x7:
        case 0x8:
        case 0x9:
        case 0xa: break;  // designators, strings and delimiters do not change the layout
        default: skip(itemStart, fmt::format("local item 0x{:02x} with a reserved tag", prefix)); break;
      }
    } else {
      // A short item of the reserved type (0xfe, the long item, is handled above): skipped.
      skip(itemStart, fmt::format("item 0x{:02x} of the reserved type", prefix));
    }
  }
  if (!open.empty()) {
    return bad(bytes.size(), fmt::format("the descriptor ends inside {} open collection(s)", open.size()));
  }
  if (ignoredCount > kMaxIgnoredNotes) {
    out.ignored.push_back(fmt::format("{} more skipped item(s)", ignoredCount - kMaxIgnoredNotes));
  }
  return out;
}

std::int64_t extractElement(const ReportField& field, std::uint32_t index, std::span<const std::uint8_t> data,
                            bool* ok) {
  const std::uint64_t start = std::uint64_t{field.bitOffset} + std::uint64_t{index} * field.bitSize;
  const std::uint64_t end = start + field.bitSize;
  if (ok) *ok = index < field.count && end <= std::uint64_t{data.size()} * 8;
  if (field.bitSize == 0 || field.bitSize > 32 || index >= field.count || end > std::uint64_t{data.size()} * 8) {
    return 0;
  }
  std::uint64_t raw = 0;
  for (std::uint32_t b = 0; b < field.bitSize; ++b) {
    const std::uint64_t bit = start + b;
    if ((static_cast<unsigned>(data[static_cast<std::size_t>(bit / 8)]) >> (bit % 8)) & 1u)
      raw |= std::uint64_t{1} << b;
  }
  if (field.isSigned() && field.bitSize < 64 && (raw >> (field.bitSize - 1)) & 1u) {
    return static_cast<std::int64_t>(raw) - (std::int64_t{1} << field.bitSize);
  }
  return static_cast<std::int64_t>(raw);
}

std::string usageName(std::uint32_t full) {
  const std::uint16_t page = usagePage(full), id = usageId(full);
  if (page == usages::kButton) return fmt::format("Button {}", id);
  if (page == usages::kGenericDesktop) {
    switch (id) {
      case 0x30: return "Generic Desktop X";
      case 0x31: return "Generic Desktop Y";
      case 0x32: return "Generic Desktop Z";
      case 0x33: return "Generic Desktop Rx";
      case 0x34: return "Generic Desktop Ry";
      case 0x35: return "Generic Desktop Rz";
      case 0x37: return "Generic Desktop Dial";
      case 0x38: return "Generic Desktop Wheel";
      case 0x48: return "Generic Desktop Resolution Multiplier";
      default: break;
    }
  }
  return fmt::format("0x{:04x}:0x{:04x}", page, id);
}

}  // namespace basalt::devices::hid
