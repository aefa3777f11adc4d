// Standard MIDI Files (the MIDI Manufacturers Association's SMF 1.0): Basalt's writer and reader.
// No Debian library fits: libportsmf reads into Allegro sequences with times as doubles in
// beats (not exact), and pulls in a library for a format of a few hundred lines
// (docs/decisions/0064-midi-through-alsa.md).

#include "sim/midi_file.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "devices/midi/midi_decoder.h"

namespace basalt::sim {

namespace {

constexpr std::uint16_t kDivision = 1000;  // ticks per quarter
constexpr std::uint32_t kTempo = 1000;     // µs per quarter: one tick per µs

void put16(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}
void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put16(out, v >> 16);
  put16(out, v & 0xffff);
}
void putVarLen(std::vector<std::uint8_t>& out, std::uint64_t v) {
  std::uint8_t buf[10];
  int n = 0;
  buf[n++] = static_cast<std::uint8_t>(v & 0x7f);
  while ((v >>= 7) != 0) buf[n++] = static_cast<std::uint8_t>(0x80 | (v & 0x7f));
  while (n > 0) out.push_back(buf[--n]);
}
void putMeta(std::vector<std::uint8_t>& out, std::uint8_t type, std::span<const std::uint8_t> data) {
  out.push_back(0);  // delta
  out.push_back(0xff);
  out.push_back(type);
  putVarLen(out, data.size());
  out.insert(out.end(), data.begin(), data.end());
}

/// a * b / c, rounded down, without overflow for the sizes SMF times have (r * b < 2^64).
std::uint64_t mulDiv(std::uint64_t a, std::uint64_t b, std::uint64_t c) { return a / c * b + a % c * b / c; }

struct TimedMessage {
  std::uint64_t tick = 0;
  std::size_t order = 0;  // file order, for a stable merge of tracks
  std::vector<std::uint8_t> bytes;
};

class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, std::string_view name) : b_(bytes), name_(name) {}
  [[nodiscard]] bool has(std::size_t n) const { return pos_ + n <= end_; }
  std::uint32_t u(int n) {
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | b_[pos_++];
    return v;
  }
  Result<std::uint64_t> varLen() {
    std::uint64_t v = 0;
    for (int i = 0; i < 4; ++i) {
      if (!has(1)) return error("a variable-length number runs past the chunk");
      const std::uint8_t c = b_[pos_++];
      v = (v << 7) | (c & 0x7f);
      if ((c & 0x80) == 0) return v;
    }
    return error("a variable-length number is longer than 4 bytes");
  }
  std::unexpected<Error> error(std::string_view what) const {
    return fail(Errc::kParse, fmt::format("not a Standard MIDI File: {} (byte {})", what, pos_), std::string(name_));
  }
  std::span<const std::uint8_t> b_;
  std::string_view name_;
  std::size_t pos_ = 0;
  std::size_t end_ = 0;
};

}  // namespace

bool isMidiFilePath(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".mid" || ext == ".midi" || ext == ".smf";
}

std::vector<std::uint8_t> formatMidiFile(const HidRecordedDevice& device) {
  std::vector<std::uint8_t> track;
  const std::uint8_t tempo[3] = {static_cast<std::uint8_t>(kTempo >> 16), static_cast<std::uint8_t>(kTempo >> 8),
                                 static_cast<std::uint8_t>(kTempo)};
  putMeta(track, 0x51, tempo);
  putMeta(track, 0x03, std::span(reinterpret_cast<const std::uint8_t*>(device.name.data()), device.name.size()));
  if (devices::isMidiDescriptor(device.descriptor)) putMeta(track, 0x01, device.descriptor);
  std::uint64_t last = 0;
  for (const HidReport& r : device.reports) {
    if (r.bytes.empty() || r.bytes[0] < 0x80 || r.bytes[0] >= 0xf0) continue;  // channel messages only
    const auto us = static_cast<std::uint64_t>(std::max<std::int64_t>(r.time.count() / 1000, 0));
    putVarLen(track, us >= last ? us - last : 0);
    last = std::max(last, us);
    track.insert(track.end(), r.bytes.begin(), r.bytes.end());
  }
  track.insert(track.end(), {0x00, 0xff, 0x2f, 0x00});
  std::vector<std::uint8_t> out = {'M', 'T', 'h', 'd'};
  put32(out, 6);
  put16(out, 0);  // format 0: one track
  put16(out, 1);
  put16(out, kDivision);
  out.insert(out.end(), {'M', 'T', 'r', 'k'});
  put32(out, static_cast<std::uint32_t>(track.size()));
  out.insert(out.end(), track.begin(), track.end());
  return out;
}

Result<HidRecordedDevice> parseMidiFile(std::span<const std::uint8_t> bytes, std::string_view name) {
  Reader r(bytes, name);
  r.end_ = bytes.size();
  if (!r.has(14) || !std::equal(bytes.begin(), bytes.begin() + 4, "MThd")) return r.error("no MThd header");
  r.pos_ = 4;
  const std::uint32_t headerLength = r.u(4);
  if (headerLength < 6 || !r.has(headerLength)) return r.error("the header chunk is too short");
  const std::uint32_t format = r.u(2);
  const std::uint32_t tracks = r.u(2);
  const std::uint32_t division = r.u(2);
  r.pos_ = 8 + headerLength;
  if (format > 1)
    return r.error(fmt::format("format {} (sequences of patterns) is not read; formats 0 and 1 are", format));
  if (division == 0) return r.error("division 0");
  std::vector<TimedMessage> messages;
  std::map<std::uint64_t, std::uint32_t> tempos;  // tick -> µs per quarter
  HidRecordedDevice device;
  std::string trackName;
  std::size_t order = 0;
  for (std::uint32_t t = 0; t < tracks; ++t) {
    r.end_ = bytes.size();
    if (!r.has(8)) return r.error(fmt::format("track {} is missing", t + 1));
    const bool mtrk = std::equal(bytes.begin() + static_cast<std::ptrdiff_t>(r.pos_),
                                 bytes.begin() + static_cast<std::ptrdiff_t>(r.pos_ + 4), "MTrk");
    r.pos_ += 4;
    const std::uint32_t length = r.u(4);
    if (!r.has(length)) return r.error("a chunk runs past the end of the file");
    r.end_ = r.pos_ + length;
    if (!mtrk) {  // an unknown chunk: skipped, as the standard says
      r.pos_ = r.end_;
      --t;
      continue;
    }
    std::uint64_t tick = 0;
    std::uint8_t running = 0;
    while (r.pos_ < r.end_) {
      auto delta = r.varLen();
      if (!delta) return std::unexpected(delta.error());
      tick += *delta;
      if (!r.has(1)) return r.error("an event is cut off");
      std::uint8_t status = bytes[r.pos_];
      if (status == 0xff) {
        ++r.pos_;
        if (!r.has(1)) return r.error("a meta event is cut off");
        const std::uint8_t type = bytes[r.pos_++];
        auto len = r.varLen();
        if (!len) return std::unexpected(len.error());
        if (!r.has(*len)) return r.error("a meta event runs past its track");
        const auto data = bytes.subspan(r.pos_, *len);
        if (type == 0x51 && *len == 3)
          tempos[tick] = (std::uint32_t{data[0]} << 16) | (std::uint32_t{data[1]} << 8) | std::uint32_t{data[2]};
        if (type == 0x03 && trackName.empty()) trackName.assign(data.begin(), data.end());
        if (type == 0x01 && devices::isMidiDescriptor(data)) device.descriptor.assign(data.begin(), data.end());
        r.pos_ += *len;
        running = 0;
        continue;
      }
      if (status == 0xf0 || status == 0xf7) {
        ++r.pos_;
        auto len = r.varLen();
        if (!len) return std::unexpected(len.error());
        if (!r.has(*len)) return r.error("a system exclusive event runs past its track");
        r.pos_ += *len;
        running = 0;
        continue;
      }
      if (status < 0x80) {
        if (running == 0) return r.error("running status without a status byte before it");
        status = running;
      } else {
        ++r.pos_;
        running = status < 0xf0 ? status : 0;
      }
      const int size = devices::midiMessageLength(status);
      if (size == 0 || status >= 0xf0) return r.error(fmt::format("status byte {:#04x} in a track", status));
      if (!r.has(static_cast<std::size_t>(size - 1))) return r.error("a channel message is cut off");
      TimedMessage m;
      m.tick = tick;
      m.order = order++;
      m.bytes.push_back(status);
      for (int i = 1; i < size; ++i) m.bytes.push_back(bytes[r.pos_++] & 0x7f);
      messages.push_back(std::move(m));
    }
    r.pos_ = r.end_;
  }
  // std::sort on (tick, file order) rather than std::stable_sort, whose temporary buffer
  // (std::get_temporary_buffer) is deprecated in C++17 and flagged by clang-tidy.
  std::sort(messages.begin(), messages.end(), [](const TimedMessage& a, const TimedMessage& b) {
    return a.tick != b.tick ? a.tick < b.tick : a.order < b.order;
  });
  // Ticks to nanoseconds, exactly: each tempo segment from its own start (no accumulated rounding).
  const auto toNanos = [&](std::uint64_t tick) -> std::int64_t {
    if ((division & 0x8000) != 0) {
      const int fps = -static_cast<std::int8_t>(division >> 8);
      const unsigned perFrame = division & 0xff;
      // 29 is 30 drop-frame: 29.97 frames a second.
      const std::uint64_t num = fps == 29 ? std::uint64_t{1001} * 1000000000 : std::uint64_t{1000000000};
      const std::uint64_t den =
          fps == 29 ? std::uint64_t{30000} * perFrame : static_cast<std::uint64_t>(fps) * perFrame;
      return static_cast<std::int64_t>(mulDiv(tick, num, den == 0 ? 1 : den));
    }
    std::uint64_t ns = 0;
    std::uint64_t at = 0;
    std::uint32_t tempo = 500000;  // 120 beats a minute until the file says otherwise
    for (const auto& [start, value] : tempos) {
      if (start >= tick) break;
      ns += mulDiv(start - at, std::uint64_t{tempo} * 1000, division);
      at = start;
      tempo = value;
    }
    ns += mulDiv(tick - at, std::uint64_t{tempo} * 1000, division);
    return static_cast<std::int64_t>(ns);
  };
  device.name = trackName.empty() ? std::string(name) : trackName;
  if (device.descriptor.empty()) device.descriptor = devices::midiDescriptor(devices::midiProfileForPort(device.name));
  device.bus = 6;
  for (TimedMessage& m : messages) device.reports.push_back({Nanos{toNanos(m.tick)}, std::move(m.bytes)});
  return device;
}

Result<HidRecordedDevice> readMidiFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(Errc::kNotFound, "cannot open the MIDI file", path.string());
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parseMidiFile(bytes, path.string());
}

}  // namespace basalt::sim
