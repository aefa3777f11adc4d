// Reader and writer for hid-tools' hid-recorder text format, used by the replay backend, `basalt
// record`, manifests and the virtual lab's uhid replay. Tolerant of what real files contain
// (comments, blank lines, CRLF, decoded-report comment lines, extra spaces, uppercase hex, line
// types of newer recorders), strict
// about what would replay wrongly (a length that disagrees with the bytes, a bad hex byte, an
// event before any descriptor): those are errors naming the line.

#include "sim/hid_recording.h"

#include <charconv>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace basalt::sim {

namespace {

constexpr std::size_t kMaxBytes = 1 << 16;  // one report or descriptor

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// Splits on spaces and tabs.
std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

template <typename T>
bool parseNumber(std::string_view s, T& out, int base = 10) {
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out, base);
  return ec == std::errc{} && end == s.data() + s.size();
}

/// "len b0 b1 ..." -> bytes; false with `why` set on a problem.
bool parseBytes(const std::vector<std::string_view>& w, std::size_t first, std::vector<std::uint8_t>& out,
                std::string& why) {
  if (w.size() <= first) {
    why = "the byte count is missing";
    return false;
  }
  std::size_t len = 0;
  if (!parseNumber(w[first], len) || len > kMaxBytes) {
    why = fmt::format("'{}' is not a byte count (0..{})", w[first], kMaxBytes);
    return false;
  }
  if (w.size() - first - 1 != len) {
    why = fmt::format("the line says {} bytes but has {}", len, w.size() - first - 1);
    return false;
  }
  out.clear();
  out.reserve(len);
  for (std::size_t i = first + 1; i < w.size(); ++i) {
    unsigned v = 0;
    if (w[i].size() > 2 || !parseNumber(w[i], v, 16)) {
      why = fmt::format("'{}' is not a hexadecimal byte", w[i]);
      return false;
    }
    out.push_back(static_cast<std::uint8_t>(v));
  }
  return true;
}

/// "000064.859915" -> nanoseconds.
bool parseTime(std::string_view s, Nanos& out) {
  const auto dot = s.find('.');
  std::int64_t sec = 0, frac = 0;
  if (!parseNumber(s.substr(0, dot), sec) || sec < 0 || sec > 100'000'000) return false;
  if (dot != std::string_view::npos) {
    std::string_view f = s.substr(dot + 1);
    if (f.empty() || f.size() > 9 || !parseNumber(f, frac) || frac < 0) return false;
    for (std::size_t i = f.size(); i < 9; ++i) frac *= 10;
  }
  out = Nanos{sec * 1'000'000'000 + frac};
  return true;
}

}  // namespace

std::string busName(std::uint16_t bus) {
  switch (bus) {
    case 0x03: return "usb";
    case 0x05: return "bluetooth";
    case 0x06: return "virtual";
    case 0x18: return "i2c";
    default: return fmt::format("bus {}", bus);
  }
}

Result<HidRecording> parseHidRecording(std::string_view text, std::string_view name) {
  HidRecording rec;
  HidRecordedDevice* current = nullptr;
  int lineNo = 0;
  auto bad = [&](const std::string& what) {
    return fail(Errc::kParse, what + "; is this an hid-recorder file?", fmt::format("{}:{}", name, lineNo));
  };
  auto device = [&]() -> HidRecordedDevice& {
    if (!current) {
      rec.devices.emplace_back();
      current = &rec.devices.back();
    }
    return *current;
  };
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::string_view raw = text.substr(pos, nl == std::string_view::npos ? text.size() - pos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++lineNo;
    const std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') continue;
    if (line.size() < 2 || line[1] != ':') return bad(fmt::format("unknown line '{}'", line.substr(0, 40)));
    const char tag = line[0];
    const std::string_view rest = trim(line.substr(2));
    std::string why;
    switch (tag) {
      case 'D': {
        int index = 0;
        if (!parseNumber(rest, index) || index < 0 || index > 255) return bad("D: needs a device number 0..255");
        current = nullptr;
        for (auto& d : rec.devices) {
          if (d.index == index) current = &d;
        }
        if (!current) {
          // The first D: line names the device a file without D: lines so far started.
          if (rec.devices.size() == 1 && rec.devices[0].descriptor.empty() && rec.devices[0].reports.empty()) {
            current = &rec.devices[0];
          } else {
            rec.devices.emplace_back();
            current = &rec.devices.back();
          }
          current->index = index;
        }
        break;
      }
      case 'R': {
        HidRecordedDevice& d = device();
        if (!d.descriptor.empty()) {
          // A second R: without D: begins the next device (older multi-device files).
          rec.devices.emplace_back();
          current = &rec.devices.back();
          current->index = static_cast<int>(rec.devices.size() - 1);
        }
        if (!parseBytes(words(rest), 0, current->descriptor, why)) return bad("R: " + why);
        if (current->descriptor.empty()) return bad("R: the report descriptor is empty");
        break;
      }
      case 'N': device().name = std::string(rest); break;
      case 'P': device().phys = std::string(rest); break;
      case 'I': {
        const auto w = words(rest);
        HidRecordedDevice& d = device();
        if (w.size() != 3 || !parseNumber(w[0], d.bus, 16) || !parseNumber(w[1], d.vendor, 16) ||
            !parseNumber(w[2], d.product, 16)) {
          return bad("I: needs 'bus vendor product' in hexadecimal");
        }
        break;
      }
      case 'E': {
        const auto w = words(rest);
        if (!current || current->descriptor.empty()) return bad("E: an event before any R: report descriptor");
        HidReport r;
        if (w.empty() || !parseTime(w[0], r.time)) return bad("E: needs a time 'seconds.microseconds'");
        if (!parseBytes(w, 1, r.bytes, why)) return bad("E: " + why);
        if (r.bytes.empty()) return bad("E: an empty input report");
        current->reports.push_back(std::move(r));
        break;
      }
      default: break;  // a line type of a newer recorder: nothing Basalt replays
    }
  }
  std::erase_if(rec.devices, [](const HidRecordedDevice& d) { return d.descriptor.empty() && d.reports.empty(); });
  if (rec.devices.empty()) {
    return fail(Errc::kParse, "no R: report descriptor found; is this an hid-recorder file?", std::string(name));
  }
  for (const auto& d : rec.devices) {
    if (d.descriptor.empty()) {
      return fail(Errc::kParse, fmt::format("device D:{} has no R: report descriptor", d.index), std::string(name));
    }
  }
  return rec;
}

Result<HidRecording> readHidRecording(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return fail(Errc::kNotFound, "cannot read the recording: " + ec.message(), path.string());
  if (size > (std::uintmax_t{256} << 20))
    return fail(Errc::kResourceExhausted, "the recording is over 256 MiB", path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(Errc::kIo, "cannot open the recording", path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return parseHidRecording(text.str(), path.string());
}

std::string HidRecordingWriter::header(const HidRecordedDevice& device, bool withDeviceLine) {
  std::string out;
  if (withDeviceLine) out += fmt::format("D: {}\n", device.index);
  out += fmt::format("R: {}", device.descriptor.size());
  for (std::uint8_t b : device.descriptor) out += fmt::format(" {:02x}", b);
  out += "\n";
  out += fmt::format("N: {}\n", device.name);
  if (!device.phys.empty()) out += fmt::format("P: {}\n", device.phys);
  out += fmt::format("I: {:x} {:04x} {:04x}\n", device.bus, device.vendor, device.product);
  return out;
}

std::string HidRecordingWriter::reportLine(Nanos time, std::span<const std::uint8_t> bytes) {
  const std::int64_t us = std::max<std::int64_t>(0, (time.count() + 500) / 1000);
  std::string out = fmt::format("E: {:06}.{:06} {}", us / 1'000'000, us % 1'000'000, bytes.size());
  for (std::uint8_t b : bytes) out += fmt::format(" {:02x}", b);
  out += "\n";
  return out;
}

}  // namespace basalt::sim
