#include "sim/vlab/hid_recording.h"

#include <charconv>
#include <fstream>

namespace basalt::sim::vlab {
namespace {

constexpr std::size_t kMaxFileBytes = 64U << 20;
constexpr std::size_t kMaxDevices = 64;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

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
bool parseNumber(std::string_view s, T& out, int base) {
  const char* first = s.data();  // NOLINT(bugprone-suspicious-stringview-data-usage): the end goes with it
  const char* last = first + s.size();
  auto [ptr, ec] = std::from_chars(first, last, out, base);
  return ec == std::errc{} && ptr == last;
}

/// "LEN b0 b1 ..." with LEN decimal and bytes hex; the count must match.
Result<std::vector<std::uint8_t>> parseBytes(const std::vector<std::string_view>& w, std::size_t first,
                                             const std::string& where) {
  std::size_t len = 0;
  if (w.size() <= first || !parseNumber(w[first], len, 10)) {
    return fail(Errc::kParse, "expected a byte count", where);
  }
  if (w.size() - first - 1 != len) {
    return fail(Errc::kParse, fmt::format("the line says {} bytes but has {}", len, w.size() - first - 1), where);
  }
  std::vector<std::uint8_t> bytes;
  bytes.reserve(len);
  for (std::size_t i = first + 1; i < w.size(); ++i) {
    unsigned value = 0;
    if (w[i].size() > 2 || !parseNumber(w[i], value, 16)) {
      return fail(Errc::kParse, fmt::format("'{}' is not a hex byte", w[i]), where);
    }
    bytes.push_back(static_cast<std::uint8_t>(value));
  }
  return bytes;
}

/// "SECONDS.MICROS" -> time
bool parseTime(std::string_view s, Nanos& out) {
  const auto dot = s.find('.');
  if (dot == std::string_view::npos || dot == 0 || s.size() - dot - 1 != 6) return false;
  std::int64_t seconds = 0;
  std::int64_t micros = 0;
  if (!parseNumber(s.substr(0, dot), seconds, 10) || !parseNumber(s.substr(dot + 1), micros, 10)) return false;
  if (seconds < 0 || seconds > 100'000'000) return false;
  out = std::chrono::seconds(seconds) + std::chrono::microseconds(micros);
  return true;
}

}  // namespace

Result<std::vector<HidRecordedDevice>> parseHidRecording(std::string_view text, std::string_view file) {
  std::vector<HidRecordedDevice> devices;
  std::size_t current = 0;
  std::size_t lineNo = 0;
  auto device = [&]() -> HidRecordedDevice& {
    if (devices.empty()) devices.emplace_back();
    return devices[current];
  };
  while (!text.empty()) {
    const auto nl = text.find('\n');
    const std::string_view raw = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    ++lineNo;
    const std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') continue;
    if (line.size() < 2 || line[1] != ':') continue;
    const char kind = line.front();
    const std::string_view rest = trim(line.substr(2));
    const std::string where = fmt::format("{}:{}", file, lineNo);
    const auto w = words(rest);
    switch (kind) {
      case 'D': {
        std::size_t index = 0;
        if (w.size() != 1 || !parseNumber(w[0], index, 10)) {
          return fail(Errc::kParse, "D: needs a device index", where);
        }
        if (index > devices.size() || index >= kMaxDevices) {
          return fail(Errc::kParse, fmt::format("device {} comes before device {}", index, devices.size()), where);
        }
        if (index == devices.size()) devices.emplace_back();
        current = index;
        break;
      }
      case 'R': {
        auto bytes = parseBytes(w, 0, where);
        if (!bytes) return std::unexpected(bytes.error());
        if (bytes->empty()) return fail(Errc::kParse, "an empty report descriptor", where);
        device().descriptor = std::move(*bytes);
        break;
      }
      case 'N': device().name = std::string(rest); break;
      case 'P': device().phys = std::string(rest); break;
      case 'I': {
        unsigned bus = 0;
        unsigned vendor = 0;
        unsigned product = 0;
        if (w.size() != 3 || !parseNumber(w[0], bus, 16) || !parseNumber(w[1], vendor, 16) ||
            !parseNumber(w[2], product, 16) || bus > 0xffff || vendor > 0xffff || product > 0xffff) {
          return fail(Errc::kParse, "I: needs BUS VENDOR PRODUCT in hex", where);
        }
        device().bus = static_cast<std::uint16_t>(bus);
        device().vendor = static_cast<std::uint16_t>(vendor);
        device().product = static_cast<std::uint16_t>(product);
        break;
      }
      case 'E': {
        HidRecordedReport report;
        if (w.empty() || !parseTime(w[0], report.time)) {
          return fail(Errc::kParse, "E: needs a time as SECONDS.MICROSECONDS", where);
        }
        auto bytes = parseBytes(w, 1, where);
        if (!bytes) return std::unexpected(bytes.error());
        if (bytes->empty()) return fail(Errc::kParse, "an empty input report", where);
        report.bytes = std::move(*bytes);
        device().reports.push_back(std::move(report));
        break;
      }
      default: break;
    }
  }
  if (devices.empty()) return fail(Errc::kParse, "no device in the recording (no R: line)", std::string(file));
  for (std::size_t i = 0; i < devices.size(); ++i) {
    if (devices[i].descriptor.empty()) {
      return fail(Errc::kParse, fmt::format("device {} has no report descriptor (R: line)", i), std::string(file));
    }
  }
  return devices;
}

Result<std::vector<HidRecordedDevice>> readHidRecording(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return fail(Errc::kNotFound, "cannot open the HID recording: " + ec.message(), path.string());
  if (size > kMaxFileBytes) {
    return fail(Errc::kResourceExhausted, "the HID recording is larger than 64 MiB", path.string());
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(Errc::kNotFound, "cannot open the HID recording", path.string());
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return parseHidRecording(text, path.string());
}

}  // namespace basalt::sim::vlab
