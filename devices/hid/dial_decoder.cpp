// Dial box report decoding: the PowerMate and Shuttle profiles by vendor:product, and a generic
// mapping for any HID descriptor that declares dials. Counts per turn come, in this order, from a
// Resolution Multiplier feature beside the dial (the Surface Dial and Huion puck pattern), from a
// rotation unit (degrees or radians), or from the defaults in dial_decoder.h.

#include "devices/hid/dial_decoder.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::devices {

namespace {

BASALT_LOG_CATEGORY(Hid, "devices");

using hid::ReportField;
namespace u = hid::usages;

constexpr std::array<std::uint16_t, 6> kConsumerButtons = {0xcd, 0xb5, 0xb6, 0xe2, 0xe9, 0xea};

/// Dials first, then wheels, then rotations, then translations: a knob's turn becomes dial 0.
int dialRank(std::uint32_t usage) {
  if (usage == u::kDial) return 0;
  if (usage == u::kWheel) return 1;
  if (usage == u::kRx || usage == u::kRy || usage == u::kRz) return 2;
  if (usage == u::kX || usage == u::kY || usage == u::kZ) return 3;
  return -1;
}

/// Counts per turn from a rotation unit (English Rotation = degrees, SI Rotation = radians), or 0.
double countsFromUnit(const ReportField& f) {
  const std::uint32_t system = f.unit & 0xf;
  const std::uint32_t length = (f.unit >> 4) & 0xf;
  if ((system != 2 && system != 4) || length != 1 || (f.unit >> 8) != 0) return 0;
  const double logicalSpan = static_cast<double>(f.logicalMax) - f.logicalMin;
  const double physicalSpan = static_cast<double>(f.physicalMax) - f.physicalMin;
  const double scale = std::pow(10.0, f.unitExponent);
  double countsPerUnit = 1.0 / scale;
  if (physicalSpan > 0 && logicalSpan > 0) countsPerUnit = logicalSpan / (physicalSpan * scale);
  return countsPerUnit * (system == 4 ? 360.0 : 2 * std::numbers::pi);
}

}  // namespace

std::string_view dialProfileName(DialProfile profile) {
  switch (profile) {
    case DialProfile::kPowerMate: return "Griffin PowerMate";
    case DialProfile::kShuttle: return "Contour Shuttle";
    case DialProfile::kGenericHid: return "generic HID dial";
  }
  return "unknown";
}

DialProfile profileFor(std::uint16_t vendor, std::uint16_t product) {
  if (vendor == kGriffinVendor && product == kPowerMateProduct) return DialProfile::kPowerMate;
  if (vendor == kContourVendor &&
      (product == kShuttleProV1Product || product == kShuttleXpressProduct || product == kShuttleProV2Product)) {
    return DialProfile::kShuttle;
  }
  return DialProfile::kGenericHid;
}

std::span<const std::uint16_t> consumerButtonUsages() { return kConsumerButtons; }

Result<DialDecoder> DialDecoder::create(std::uint16_t vendor, std::uint16_t product,
                                        std::span<const std::uint8_t> descriptor, std::string_view where) {
  DialDecoder d;
  d.profile_ = profileFor(vendor, product);
  if (d.profile_ == DialProfile::kPowerMate) {
    d.dialCount_ = 1;
    d.buttonCount_ = 1;
    d.channelInfo_.push_back({u::kDial, EventKind::kDialDelta, kPowerMateCountsPerTurn});
    return d;
  }
  if (d.profile_ == DialProfile::kShuttle) {
    d.dialCount_ = 1;
    d.buttonCount_ = 16;
    d.channelInfo_.push_back({u::kDial, EventKind::kDialDelta, kShuttleJogCountsPerTurn});
    d.channelInfo_.push_back({u::kWheel, EventKind::kShuttle, 7});
    return d;
  }
  auto parsed = hid::parseReportDescriptor(descriptor, where);
  if (!parsed) return std::unexpected(parsed.error());
  for (const std::string& note : parsed->ignored) {
    log::debug(kLogHid, "{}: report descriptor {} (skipped)", where, note);
  }
  d.descriptor_ = std::move(*parsed);
  const auto& fields = d.descriptor_.fields;

  struct Candidate {
    int rank;
    std::size_t order;
    Channel channel;
    std::uint32_t usage;
  };
  std::vector<Candidate> candidates;
  bool consumerArray = false;
  for (std::size_t fi = 0; fi < fields.size(); ++fi) {
    const ReportField& f = fields[fi];
    if (f.type != hid::ReportType::kInput || f.isConstant() || f.bitSize == 0 || f.bitSize > 32) continue;
    if (f.isVariable()) {
      for (std::uint32_t e = 0; e < f.count; ++e) {
        const std::uint32_t usage = f.usages[e];
        if (hid::usagePage(usage) == u::kButton && d.variableButtons_ < kMaxButtons) {
          d.buttons_.push_back({fi, e, false, static_cast<std::uint16_t>(d.variableButtons_++)});
          continue;
        }
        const int rank = dialRank(usage);
        if (rank < 0 || f.logicalMin >= f.logicalMax) continue;
        Channel c;
        c.field = fi;
        c.element = e;
        if (f.isRelative()) {
          c.kind = EventKind::kDialDelta;
        } else if (f.wraps()) {
          c.kind = EventKind::kDialDelta;
          c.wrapAbsolute = true;
        } else {
          c.kind = EventKind::kDialAbsolute;
        }
        double counts = 0;
        for (const ReportField& m : fields) {
          if (m.type != hid::ReportType::kFeature || m.usages.empty() || m.usages.front() != u::kResolutionMultiplier)
            continue;
          if (m.collection >= 0 && d.descriptor_.isInside(f.collection, m.collection) && m.physicalMax > 0) {
            counts = m.physicalMax;
            break;
          }
        }
        if (counts <= 0) counts = countsFromUnit(f);
        if (counts <= 0) {
          if (c.wrapAbsolute) {
            counts = static_cast<double>(f.logicalMax) - f.logicalMin + 1;
          } else if (usage == u::kDial) {
            counts = kDialCountsPerTurn;
          } else if (usage == u::kWheel) {
            counts = kWheelCountsPerTurn;
          } else {
            counts = kAxisCountsPerTurn;
          }
        }
        c.countsPerTurn = counts;
        candidates.push_back({rank, candidates.size(), c, usage});
      }
    } else {
      const bool consumer =
          (f.usages.empty() ? hid::usagePage(f.usageMin) : hid::usagePage(f.usages.front())) == u::kConsumer;
      if (consumer) {
        d.buttons_.push_back({fi, 0, true, 0});
        consumerArray = true;
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.rank != b.rank ? a.rank < b.rank : a.order < b.order;  // stable: descriptor order within a rank
  });
  for (const Candidate& c : candidates) {
    if (d.dials_.size() >= kMaxDials) break;
    Channel ch = c.channel;
    ch.index = static_cast<std::uint16_t>(d.dials_.size());
    d.dials_.push_back(ch);
    d.channelInfo_.push_back({c.usage, ch.kind, ch.countsPerTurn});
  }
  if (d.dials_.empty()) {
    return fail(Errc::kUnsupported,
                "the HID report descriptor declares no dial, wheel or axis (Generic Desktop Dial, Wheel, X/Y/Z, "
                "Rx/Ry/Rz); choose a dial device, or another backend",
                std::string(where));
  }
  d.dialCount_ = d.dials_.size();
  d.buttonCount_ = std::min(kMaxButtons, d.variableButtons_ + (consumerArray ? kConsumerButtons.size() : 0));
  return d;
}

void DialDecoder::reset() {
  for (Channel& c : dials_) c.haveLast = false;
  pressed_.fill(false);
  haveShuttleJog_ = false;
  shuttleRing_ = 0;
}

std::size_t DialDecoder::decode(std::span<const std::uint8_t> report, std::span<Event> out) {
  switch (profile_) {
    case DialProfile::kPowerMate: return decodePowerMate(report, out);
    case DialProfile::kShuttle: return decodeShuttle(report, out);
    case DialProfile::kGenericHid: return decodeGeneric(report, out);
  }
  return 0;
}

std::size_t DialDecoder::decodePowerMate(std::span<const std::uint8_t> report, std::span<Event> out) {
  // Byte 0 bit 0: the knob is pressed. Byte 1: signed rotation since the last report.
  if (report.size() < 2) return 0;
  std::size_t n = 0;
  const bool down = (report[0] & 1u) != 0;
  if (down != pressed_[0] && n < out.size()) {
    pressed_[0] = down;
    out[n++] = Event{Nanos{0}, 0, EventKind::kButton, 0, down ? 1.0 : 0.0};
  }
  const auto delta = static_cast<std::int8_t>(report[1]);
  if (delta != 0 && n < out.size())
    out[n++] = Event{Nanos{0}, 0, EventKind::kDialDelta, 0, delta / kPowerMateCountsPerTurn};
  return n;
}

std::size_t DialDecoder::decodeShuttle(std::span<const std::uint8_t> report, std::span<Event> out) {
  // Byte 0: shuttle ring -7..+7. Byte 1: jog wheel, an absolute count that wraps at 256.
  // Bytes 3-4: buttons, little-endian.
  if (report.size() < 5) return 0;
  std::size_t n = 0;
  const auto ring = static_cast<std::int8_t>(report[0]);
  if (ring != shuttleRing_ && n < out.size()) {
    shuttleRing_ = ring;
    out[n++] = Event{Nanos{0}, 0, EventKind::kShuttle, 0, std::clamp(ring / 7.0, -1.0, 1.0)};
  }
  if (haveShuttleJog_) {
    const auto delta = static_cast<std::int8_t>(static_cast<std::uint8_t>(report[1] - shuttleJog_));
    if (delta != 0 && n < out.size()) {
      out[n++] = Event{Nanos{0}, 0, EventKind::kDialDelta, 0, delta / kShuttleJogCountsPerTurn};
    }
  }
  shuttleJog_ = report[1];
  haveShuttleJog_ = true;
  const unsigned buttons = report[3] | (unsigned{report[4]} << 8);
  for (std::uint16_t b = 0; b < 16 && n < out.size(); ++b) {
    const bool down = ((buttons >> b) & 1u) != 0;
    if (down != pressed_[b]) {
      pressed_[b] = down;
      out[n++] = Event{Nanos{0}, 0, EventKind::kButton, b, down ? 1.0 : 0.0};
    }
  }
  return n;
}

std::size_t DialDecoder::decodeGeneric(std::span<const std::uint8_t> report, std::span<Event> out) {
  if (report.empty()) return 0;
  std::uint8_t id = 0;
  std::span<const std::uint8_t> data = report;
  if (descriptor_.usesReportIds) {
    id = report[0];
    data = report.subspan(1);
  }
  std::size_t n = 0;
  for (Channel& c : dials_) {
    const ReportField& f = descriptor_.fields[c.field];
    if (f.reportId != id) continue;
    bool ok = false;
    const std::int64_t v = extractElement(f, c.element, data, &ok);
    if (!ok) continue;
    if ((v < f.logicalMin || v > f.logicalMax)) continue;  // null state or out of range: no reading
    if (n >= out.size()) break;
    if (c.kind == EventKind::kDialDelta && !c.wrapAbsolute) {
      if (v != 0)
        out[n++] = Event{Nanos{0}, 0, EventKind::kDialDelta, c.index, static_cast<double>(v) / c.countsPerTurn};
    } else if (c.wrapAbsolute) {
      if (c.haveLast) {
        const std::int64_t range = std::int64_t{f.logicalMax} - f.logicalMin + 1;
        std::int64_t d = v - c.last;
        if (d > range / 2) d -= range;
        if (d < -range / 2) d += range;
        if (d != 0)
          out[n++] = Event{Nanos{0}, 0, EventKind::kDialDelta, c.index, static_cast<double>(d) / c.countsPerTurn};
      }
    } else if (!c.haveLast || v != c.last) {
      const double span = static_cast<double>(f.logicalMax) - f.logicalMin;
      out[n++] = Event{Nanos{0}, 0, EventKind::kDialAbsolute, c.index, (static_cast<double>(v) - f.logicalMin) / span};
    }
    c.last = v;
    c.haveLast = true;
  }
  bool anyArray = false;
  for (const ButtonChannel& b : buttons_) {
    const ReportField& f = descriptor_.fields[b.field];
    if (f.reportId != id) continue;
    if (!b.array) {
      bool ok = false;
      const std::int64_t v = extractElement(f, b.element, data, &ok);
      if (!ok) continue;
      const bool down = v != 0;
      if (down != pressed_[b.index] && n < out.size()) {
        pressed_[b.index] = down;
        out[n++] = Event{Nanos{0}, 0, EventKind::kButton, b.index, down ? 1.0 : 0.0};
      }
      continue;
    }
    if (!anyArray) {
      seen_.fill(false);
      anyArray = true;
    }
    for (std::uint32_t e = 0; e < f.count; ++e) {
      bool ok = false;
      const std::int64_t v = extractElement(f, e, data, &ok);
      if (!ok) continue;
      const std::uint32_t usage = f.arrayUsage(v);
      if (hid::usagePage(usage) != u::kConsumer) continue;
      const auto it = std::find(kConsumerButtons.begin(), kConsumerButtons.end(), hid::usageId(usage));
      if (it == kConsumerButtons.end()) continue;
      const std::size_t index = variableButtons_ + static_cast<std::size_t>(it - kConsumerButtons.begin());
      if (index < kMaxButtons) seen_[index] = true;
    }
  }
  if (anyArray) {
    for (std::size_t i = variableButtons_; i < buttonCount_ && n < out.size(); ++i) {
      if (seen_[i] != pressed_[i]) {
        pressed_[i] = seen_[i];
        out[n++] = Event{Nanos{0}, 0, EventKind::kButton, static_cast<std::uint16_t>(i), seen_[i] ? 1.0 : 0.0};
      }
    }
  }
  return n;
}

const std::vector<std::uint8_t>& virtualDialBoxDescriptor() {
  static const std::vector<std::uint8_t> kDescriptor = {
      0x05, 0x01,                                      // Usage Page (Generic Desktop)
      0x09, 0x08,                                      // Usage (Multi-axis Controller)
      0xa1, 0x01,                                      // Collection (Application)
      0x85, 0x01,                                      //   Report ID (1)
      0x09, 0x37, 0x09, 0x37, 0x09, 0x37, 0x09, 0x37,  // Usage (Dial) x 8
      0x09, 0x37, 0x09, 0x37, 0x09, 0x37, 0x09, 0x37,  //
      0x16, 0x01, 0x80,                                //   Logical Minimum (-32767)
      0x26, 0xff, 0x7f,                                //   Logical Maximum (32767)
      0x55, 0x0f,                                      //   Unit Exponent (-1)
      0x65, 0x14,                                      //   Unit (English Rotation: degrees)
      0x75, 0x10,                                      //   Report Size (16)
      0x95, 0x08,                                      //   Report Count (8)
      0x81, 0x06,                                      //   Input (Data, Variable, Relative)
      0x55, 0x00,                                      //   Unit Exponent (0)
      0x65, 0x00,                                      //   Unit (none)
      0x05, 0x09,                                      //   Usage Page (Button)
      0x19, 0x01,                                      //   Usage Minimum (1)
      0x29, 0x20,                                      //   Usage Maximum (32)
      0x15, 0x00,                                      //   Logical Minimum (0)
      0x25, 0x01,                                      //   Logical Maximum (1)
      0x75, 0x01,                                      //   Report Size (1)
      0x95, 0x20,                                      //   Report Count (32)
      0x81, 0x02,                                      //   Input (Data, Variable, Absolute)
      0xc0,                                            // End Collection
  };
  return kDescriptor;
}

void VirtualReportEncoder::encode(const Event& event, const Sink& sink) {
  std::array<std::uint8_t, 21> report{};
  report[0] = 1;
  auto putButtons = [&] {
    for (int i = 0; i < 4; ++i)
      report[17 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(buttons_ >> (8 * i));
  };
  if (event.kind == EventKind::kButton && event.index < 32) {
    const std::uint32_t bit = 1u << event.index;
    buttons_ = event.value != 0 ? (buttons_ | bit) : (buttons_ & ~bit);
    putButtons();
    sink(report);
    return;
  }
  if (event.kind != EventKind::kDialDelta || event.index >= 8) return;
  const double exact = event.value * kDialCountsPerTurn + residue_[event.index];
  auto counts = static_cast<std::int64_t>(std::llround(exact));
  residue_[event.index] = exact - static_cast<double>(counts);
  while (counts != 0) {
    const std::int64_t chunk = std::clamp<std::int64_t>(counts, -32767, 32767);
    const auto raw = static_cast<std::uint16_t>(static_cast<std::int16_t>(chunk));
    report.fill(0);
    report[0] = 1;
    report[1 + 2 * std::size_t{event.index}] = static_cast<std::uint8_t>(raw & 0xff);
    report[2 + 2 * std::size_t{event.index}] = static_cast<std::uint8_t>(raw >> 8);
    putButtons();
    sink(report);
    counts -= chunk;
  }
}

}  // namespace basalt::devices
