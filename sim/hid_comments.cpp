// The comment lines Basalt writes into hid-recorder files: the descriptor's items and each
// report's fields. Names come from the HID Usage Tables for the pages dial boxes, knobs, mice,
// keyboards and tablets use; anything else is written by number. Bounded: a descriptor of
// thousands of items is listed item by item, but a report comment lists at most 256 values.

#include "sim/hid_comments.h"

#include <algorithm>
#include <fstream>

#include <fmt/format.h>

namespace basalt::sim {

namespace hid = devices::hid;

namespace {

constexpr std::size_t kMaxValuesPerComment = 256;

/// Little-endian value of an item's data bytes.
std::uint32_t itemValue(std::span<const std::uint8_t> data) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < data.size(); ++i) v |= std::uint32_t{data[i]} << (8 * i);
  return v;
}

std::int64_t signExtend(std::uint32_t v, std::size_t bytes) {
  if (bytes == 0) return 0;
  const unsigned bits = static_cast<unsigned>(bytes * 8);
  if (bits >= 32) return static_cast<std::int32_t>(v);
  const std::uint32_t sign = 1u << (bits - 1);
  return (v & sign) ? static_cast<std::int64_t>(v) - (std::int64_t{1} << bits) : static_cast<std::int64_t>(v);
}

std::string mainItemFlags(std::uint32_t v) {
  std::string s = (v & 0x01) ? "Cnst" : "Data";
  s += (v & 0x02) ? ",Var" : ",Arr";
  s += (v & 0x04) ? ",Rel" : ",Abs";
  if (v & 0x08) s += ",Wrap";
  if (v & 0x10) s += ",NonLin";
  if (v & 0x20) s += ",NoPref";
  if (v & 0x40) s += ",Null";
  if (v & 0x80) s += ",Vol";
  if (v & 0x100) s += ",Buff";
  return s;
}

std::string collectionName(std::uint32_t v) {
  switch (v) {
    case 0x00: return "Physical";
    case 0x01: return "Application";
    case 0x02: return "Logical";
    case 0x03: return "Report";
    case 0x04: return "Named Array";
    case 0x05: return "Usage Switch";
    case 0x06: return "Usage Modifier";
    default: return v >= 0x80 ? fmt::format("Vendor Defined 0x{:02x}", v) : fmt::format("Reserved 0x{:02x}", v);
  }
}

std::string genericDesktopUsage(std::uint16_t id) {
  switch (id) {
    case 0x01: return "Pointer";
    case 0x02: return "Mouse";
    case 0x04: return "Joystick";
    case 0x05: return "Game Pad";
    case 0x06: return "Keyboard";
    case 0x07: return "Keypad";
    case 0x08: return "Multi-axis Controller";
    case 0x0e: return "System Multi-Axis Controller";
    case 0x30: return "X";
    case 0x31: return "Y";
    case 0x32: return "Z";
    case 0x33: return "Rx";
    case 0x34: return "Ry";
    case 0x35: return "Rz";
    case 0x36: return "Slider";
    case 0x37: return "Dial";
    case 0x38: return "Wheel";
    case 0x39: return "Hat switch";
    case 0x3d: return "Start";
    case 0x3e: return "Select";
    case 0x48: return "Resolution Multiplier";
    case 0x80: return "System Control";
    default: return {};
  }
}

std::string consumerUsage(std::uint16_t id) {
  switch (id) {
    case 0x01: return "Consumer Control";
    case 0xb5: return "Scan Next Track";
    case 0xb6: return "Scan Previous Track";
    case 0xb7: return "Stop";
    case 0xcd: return "Play/Pause";
    case 0xe0: return "Volume";
    case 0xe2: return "Mute";
    case 0xe9: return "Volume Increment";
    case 0xea: return "Volume Decrement";
    case 0x238: return "AC Pan";
    default: return {};
  }
}

std::string digitizerUsage(std::uint16_t id) {
  switch (id) {
    case 0x01: return "Digitizer";
    case 0x02: return "Pen";
    case 0x20: return "Stylus";
    case 0x21: return "Puck";
    case 0x22: return "Finger";
    case 0x30: return "Tip Pressure";
    case 0x32: return "In Range";
    case 0x33: return "Touch";
    case 0x3c: return "Invert";
    case 0x3d: return "X Tilt";
    case 0x3e: return "Y Tilt";
    case 0x42: return "Tip Switch";
    case 0x44: return "Barrel Switch";
    case 0x45: return "Eraser";
    case 0x48: return "Width";
    case 0x49: return "Height";
    case 0x51: return "Contact Id";
    case 0x54: return "Contact Count";
    default: return {};
  }
}

std::string keyboardUsage(std::uint16_t id) {
  if (id >= 0x04 && id <= 0x1d) return std::string(1, static_cast<char>('a' + (id - 0x04)));
  if (id >= 0x1e && id <= 0x26) return std::string(1, static_cast<char>('1' + (id - 0x1e)));
  if (id == 0x27) return "0";
  static constexpr const char* kModifiers[] = {"LeftControl",  "LeftShift",  "LeftAlt",  "LeftGUI",
                                               "RightControl", "RightShift", "RightAlt", "RightGUI"};
  if (id >= 0xe0 && id <= 0xe7) return kModifiers[id - 0xe0];
  switch (id) {
    case 0x28: return "Enter";
    case 0x29: return "Escape";
    case 0x2a: return "Backspace";
    case 0x2b: return "Tab";
    case 0x2c: return "Space";
    default: return {};
  }
}

/// One line: the item's bytes, what it is (indented by collection), its offset.
std::string itemLine(std::span<const std::uint8_t> bytes, int depth, const std::string& what, std::size_t offset) {
  std::string hex;
  for (const std::uint8_t b : bytes.first(std::min<std::size_t>(bytes.size(), 8))) hex += fmt::format("0x{:02x}, ", b);
  if (bytes.size() > 8) hex += "... ";
  const std::string text = std::string(static_cast<std::size_t>(std::max(depth, 0)) * 2, ' ') + what;
  return fmt::format("# {:<32}// {:<48} {}\n", hex, text, offset);
}

}  // namespace

std::string usagePageName(std::uint16_t page) {
  switch (page) {
    case 0x01: return "Generic Desktop";
    case 0x02: return "Simulation Controls";
    case 0x03: return "VR Controls";
    case 0x04: return "Sport Controls";
    case 0x05: return "Game Controls";
    case 0x06: return "Generic Device Controls";
    case 0x07: return "Keyboard";
    case 0x08: return "LED";
    case 0x09: return "Button";
    case 0x0a: return "Ordinal";
    case 0x0b: return "Telephony";
    case 0x0c: return "Consumer";
    case 0x0d: return "Digitizers";
    case 0x0e: return "Haptics";
    case 0x0f: return "Physical Input Device";
    case 0x10: return "Unicode";
    case 0x14: return "Auxiliary Display";
    case 0x20: return "Sensors";
    case 0x59: return "Lighting And Illumination";
    default:
      return page >= 0xff00 ? fmt::format("Vendor Defined 0x{:04x}", page) : fmt::format("Usage Page 0x{:04x}", page);
  }
}

std::string shortUsageName(std::uint32_t usage) {
  const std::uint16_t page = hid::usagePage(usage);
  const std::uint16_t id = hid::usageId(usage);
  std::string name;
  switch (page) {
    case 0x01: name = genericDesktopUsage(id); break;
    case 0x07: name = keyboardUsage(id); break;
    case 0x09: return id == 0 ? std::string("No Buttons") : fmt::format("Button {}", id);
    case 0x0a: return fmt::format("Instance {}", id);
    case 0x0c: name = consumerUsage(id); break;
    case 0x0d: name = digitizerUsage(id); break;
    default: break;
  }
  if (!name.empty()) return name;
  if (page >= 0xff00) return fmt::format("Vendor Usage 0x{:02x}", id);
  return fmt::format("{} 0x{:02x}", usagePageName(page), id);
}

HidComments HidComments::create(std::span<const std::uint8_t> descriptor) {
  HidComments c;
  c.bytes_.assign(descriptor.begin(), descriptor.end());
  auto parsed = hid::parseReportDescriptor(descriptor);
  if (parsed) {
    c.parsed_ = std::move(*parsed);
    c.ok_ = true;
  } else {
    c.why_ = parsed.error().message();
  }
  return c;
}

std::string HidComments::descriptorLines() const {
  std::string out;
  std::uint16_t page = 0;
  int depth = 0;
  bool negativeLogical = false;
  bool negativePhysical = false;
  std::size_t i = 0;
  while (i < bytes_.size()) {
    const std::uint8_t prefix = bytes_[i];
    if (prefix == 0xfe) {  // a long item: its size and tag follow
      const std::size_t size = i + 1 < bytes_.size() ? bytes_[i + 1] : 0;
      const std::size_t end = std::min(bytes_.size(), i + 3 + size);
      out += itemLine(std::span(bytes_).subspan(i, end - i), depth, "Long Item", i);
      i = end;
      continue;
    }
    std::size_t size = prefix & 0x03u;
    if (size == 3) size = 4;
    if (i + 1 + size > bytes_.size()) {
      out += itemLine(std::span(bytes_).subspan(i), depth, "(the descriptor ends inside this item)", i);
      break;
    }
    const auto data = std::span(bytes_).subspan(i + 1, size);
    const std::uint32_t v = itemValue(data);
    const int type = (prefix >> 2) & 0x03;
    const int tag = prefix >> 4;
    std::string what;
    int lineDepth = depth;
    if (type == 0) {  // main
      switch (tag) {
        case 0x8: what = fmt::format("Input ({})", mainItemFlags(v)); break;
        case 0x9: what = fmt::format("Output ({})", mainItemFlags(v)); break;
        case 0xb: what = fmt::format("Feature ({})", mainItemFlags(v)); break;
        case 0xa:
          what = fmt::format("Collection ({})", collectionName(v));
          ++depth;
          break;
        case 0xc:
          what = "End Collection";
          depth = std::max(depth - 1, 0);
          lineDepth = depth;
          break;
        default: what = fmt::format("Main item 0x{:x} ({})", tag, v); break;
      }
    } else if (type == 1) {  // global
      switch (tag) {
        case 0x0:
          page = static_cast<std::uint16_t>(v);
          what = fmt::format("Usage Page ({})", usagePageName(page));
          break;
        case 0x1:
          negativeLogical = signExtend(v, size) < 0;
          what = fmt::format("Logical Minimum ({})", signExtend(v, size));
          break;
        case 0x2:
          what = fmt::format("Logical Maximum ({})", negativeLogical ? signExtend(v, size) : std::int64_t{v});
          break;
        case 0x3:
          negativePhysical = signExtend(v, size) < 0;
          what = fmt::format("Physical Minimum ({})", signExtend(v, size));
          break;
        case 0x4:
          what = fmt::format("Physical Maximum ({})", negativePhysical ? signExtend(v, size) : std::int64_t{v});
          break;
        case 0x5: what = fmt::format("Unit Exponent ({})", (v & 0x0f) > 7 ? int(v & 0x0f) - 16 : int(v & 0x0f)); break;
        case 0x6: what = fmt::format("Unit (0x{:x})", v); break;
        case 0x7: what = fmt::format("Report Size ({})", v); break;
        case 0x8: what = fmt::format("Report ID ({})", v); break;
        case 0x9: what = fmt::format("Report Count ({})", v); break;
        case 0xa: what = "Push"; break;
        case 0xb: what = "Pop"; break;
        default: what = fmt::format("Global item 0x{:x} ({})", tag, v); break;
      }
    } else if (type == 2) {  // local
      // A 4-byte usage carries its own page in the high half.
      const std::uint32_t full = size == 4 ? v : hid::usage(page, static_cast<std::uint16_t>(v));
      switch (tag) {
        case 0x0: what = fmt::format("Usage ({})", shortUsageName(full)); break;
        case 0x1: what = fmt::format("Usage Minimum ({})", shortUsageName(full)); break;
        case 0x2: what = fmt::format("Usage Maximum ({})", shortUsageName(full)); break;
        case 0x3: what = fmt::format("Designator Index ({})", v); break;
        case 0x4: what = fmt::format("Designator Minimum ({})", v); break;
        case 0x5: what = fmt::format("Designator Maximum ({})", v); break;
        case 0x7: what = fmt::format("String Index ({})", v); break;
        case 0x8: what = fmt::format("String Minimum ({})", v); break;
        case 0x9: what = fmt::format("String Maximum ({})", v); break;
        case 0xa: what = fmt::format("Delimiter ({})", v); break;
        default: what = fmt::format("Local item 0x{:x} ({})", tag, v); break;
      }
    } else {
      what = fmt::format("Reserved item 0x{:02x} ({})", prefix, v);
    }
    out += itemLine(std::span(bytes_).subspan(i, 1 + size), lineDepth, what, i);
    i += 1 + size;
  }
  if (!ok_) out += fmt::format("# Basalt cannot decode this descriptor ({}): its reports have no comments\n", why_);
  return out;
}

std::string HidComments::reportLine(std::span<const std::uint8_t> report) const {
  if (!ok_ || report.empty()) return {};
  std::string out = "#";
  std::uint8_t id = 0;
  std::span<const std::uint8_t> data = report;
  if (parsed_.usesReportIds) {
    id = report[0];
    data = report.subspan(1);
    out += fmt::format(" ReportID: {} /", id);
  }
  std::size_t values = 0;
  bool anyField = false;
  std::string group;  // the name shared by the values written last ("Dial", "Button")
  for (const hid::ReportField& f : parsed_.fields) {
    if (f.type != hid::ReportType::kInput || f.reportId != id || f.isConstant()) continue;
    anyField = true;
    if (values >= kMaxValuesPerComment) break;
    if (f.isVariable()) {
      for (std::uint32_t e = 0; e < f.count && values < kMaxValuesPerComment; ++e, ++values) {
        bool inside = true;
        const std::int64_t value = hid::extractElement(f, e, data, &inside);
        const std::uint32_t usage = e < f.usages.size() ? f.usages[e] : 0;
        // Buttons are one group ("Button: 0 1 0"); other usages group while they repeat ("Dial: 5, 0").
        const bool button = hid::usagePage(usage) == 0x09;
        const std::string name = button ? std::string("Button") : shortUsageName(usage);
        const std::string shown = inside ? fmt::format("{}", value) : std::string("?");
        if (name == group) {
          out += button ? " " + shown : ", " + shown;
        } else {
          out += fmt::format("{} {}: {}", group.empty() ? "" : " |", name, shown);
          group = name;
        }
      }
    } else {
      // An array: each element selects a usage (a pressed key, a consumer button), or none.
      std::string selected;
      for (std::uint32_t e = 0; e < f.count && values < kMaxValuesPerComment; ++e, ++values) {
        bool inside = true;
        const std::int64_t value = hid::extractElement(f, e, data, &inside);
        const std::uint32_t usage = inside ? f.arrayUsage(value) : 0;
        selected += fmt::format("{}'{}'", e ? ", " : "", usage && hid::usageId(usage) ? shortUsageName(usage) : "");
      }
      const std::uint32_t first = f.usages.empty() ? f.usageMin : f.usages.front();
      out += fmt::format("{} {} [{}]", group.empty() ? "" : " |", usagePageName(hid::usagePage(first)), selected);
      group = "[]";
    }
  }
  if (!anyField) out += " not an input report of the descriptor";
  if (values >= kMaxValuesPerComment) out += " | ...";
  return out + "\n";
}

std::string hidPhysicalPath(const devices::DeviceInfo& info, const std::filesystem::path& sysfs) {
  const std::filesystem::path node(info.path);
  if (info.path.starts_with("/dev/hidraw")) {
    std::ifstream uevent(sysfs / "class/hidraw" / node.filename() / "device/uevent");
    for (std::string line; std::getline(uevent, line);) {
      if (line.starts_with("HID_PHYS=") && line.size() > 9) return line.substr(9);
    }
  }
  return info.path.empty() ? std::string("basalt") : info.path;
}

}  // namespace basalt::sim
