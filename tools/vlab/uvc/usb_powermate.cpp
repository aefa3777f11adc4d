// The lab's PowerMate: descriptors as a full-speed HID knob presents them, the standard requests
// a host sends while enumerating and configuring it, HID's SET_IDLE, the LED's vendor request,
// and input reports handed out one per interrupt IN transfer.

#include "tools/vlab/uvc/usb_powermate.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace basalt::sim::vlab {
namespace {

using namespace usb;  // USB 2.0 chapter 9
constexpr std::uint8_t kDescHid = 0x21;
constexpr std::uint8_t kDescReport = 0x22;
constexpr std::uint8_t kHidSetIdle = 0x0a;
constexpr std::uint8_t kEndpoint = 0x81;
constexpr std::uint16_t kVendor = 0x077d;
constexpr std::uint16_t kProduct = 0x0410;
// The LED's vendor request: wValue selects the setting.
constexpr std::uint8_t kLedRequest = 0x01;
constexpr std::uint16_t kLedStaticBrightness = 0x0001;
constexpr std::uint16_t kLedPulseDuringSleep = 0x0002;
constexpr std::uint16_t kLedPulseAlways = 0x0003;
constexpr std::uint16_t kLedPulseSpeed = 0x0004;

ControlReply reply(const std::vector<std::uint8_t>& data, std::uint16_t wLength) { return controlReply(data, wLength); }

ControlReply ok() { return {UsbStatus::kOk, {}}; }

std::uint8_t lo(unsigned v) { return static_cast<std::uint8_t>(v & 0xffU); }
std::uint8_t hi(unsigned v) { return static_cast<std::uint8_t>((v >> 8U) & 0xffU); }

}  // namespace

const std::vector<std::uint8_t>& UsbPowerMate::reportDescriptor() {
  // Usage page vendor 0xff00, one application collection, six 8-bit input fields.
  static const std::vector<std::uint8_t> d = {0x06, 0x00, 0xff, 0x09, 0x01, 0xa1, 0x01, 0x15, 0x00, 0x26, 0xff,
                                              0x00, 0x75, 0x08, 0x95, 0x06, 0x09, 0x01, 0x81, 0x02, 0xc0};
  return d;
}

UsbPowerMate::UsbPowerMate() {
  identity_.speed = UsbSpeed::kFull;
  identity_.vendor = kVendor;
  identity_.product = kProduct;
  identity_.bcdDevice = 0x0311;
  identity_.interfaces = {{0, 0x03, 0x00, 0x00}};
  identity_.endpoints = {{kEndpoint, UsbEndpointType::kInterrupt, 6, 10, 0}};

  deviceDescriptor_ = {18,          kDescDevice,  0x00,         0x02,       0x00,       0x00, 0x00, 8, lo(kVendor),
                       hi(kVendor), lo(kProduct), hi(kProduct), lo(0x0311), hi(0x0311), 1,    2,    0, 1};
  strings_ = {
      {4, kDescString, 0x09, 0x04}, stringDescriptor("Griffin Technologies"), stringDescriptor("Griffin PowerMate")};
  const auto reportLength = static_cast<unsigned>(reportDescriptor().size());
  configDescriptor_ = {9,
                       kDescConfiguration,
                       34,
                       0,
                       1,
                       1,
                       0,
                       0xa0,
                       50,  // bus powered, remote wake-up, 100 mA
                       9,
                       kDescInterface,
                       0,
                       0,
                       1,
                       0x03,
                       0x00,
                       0x00,
                       0,  // HID, no boot protocol
                       9,
                       kDescHid,
                       0x11,
                       0x01,
                       0,
                       1,
                       kDescReport,
                       lo(reportLength),
                       hi(reportLength),  // HID 1.11
                       7,
                       kDescEndpoint,
                       kEndpoint,
                       0x03,
                       6,
                       0,
                       10};  // interrupt IN, 6 bytes, 10 ms
}

void UsbPowerMate::pushReport(std::uint8_t button, std::int8_t rotation) {
  std::lock_guard lock(mutex_);
  reports_.push_back({button, static_cast<std::uint8_t>(rotation), 0, 0, 0, 0});
}

UsbPowerMate::Led UsbPowerMate::led() const {
  std::lock_guard lock(mutex_);
  return led_;
}

void UsbPowerMate::reset() { configuration_ = 0; }

ControlReply UsbPowerMate::control(const UsbSetup& setup, std::span<const std::uint8_t> /*data*/, Nanos /*now*/) {
  switch (setup.type()) {
    case 0: return standardRequest(setup);
    case 1:
      // HID class requests: SET_IDLE is accepted (reports go out only when something changed
      // anyway); GET_REPORT and the rest are not offered, as on the real knob.
      if (setup.recipient() == 1 && setup.request == kHidSetIdle) return ok();
      return ControlReply::stall();
    case 2: {
      if (setup.isIn() || setup.request != kLedRequest) return ControlReply::stall();
      std::lock_guard lock(mutex_);
      ++led_.requests;
      switch (setup.value) {
        case kLedStaticBrightness: led_.brightness = setup.index & 0xff; return ok();
        case kLedPulseAlways: led_.pulse = setup.index != 0 ? 1 : 0; return ok();
        case kLedPulseDuringSleep:
        case kLedPulseSpeed: return ok();
        default: return ControlReply::stall();
      }
    }
    default: return ControlReply::stall();
  }
}

ControlReply UsbPowerMate::standardRequest(const UsbSetup& s) {
  const unsigned recipient = s.recipient();
  switch (s.request) {
    case kGetDescriptor: {
      if (!s.isIn()) return ControlReply::stall();
      const unsigned type = s.value >> 8U;
      const unsigned index = s.value & 0xffU;
      if (recipient == 1) {  // the interface's HID class descriptors
        if (type == kDescReport && (s.index & 0xffU) == 0) return reply(reportDescriptor(), s.length);
        if (type == kDescHid) return reply({configDescriptor_.begin() + 18, configDescriptor_.begin() + 27}, s.length);
        return ControlReply::stall();
      }
      if (recipient != 0) return ControlReply::stall();
      if (type == kDescDevice) return reply(deviceDescriptor_, s.length);
      if (type == kDescConfiguration && index == 0) return reply(configDescriptor_, s.length);
      if (type == kDescString && index < strings_.size()) return reply(strings_[index], s.length);
      return ControlReply::stall();
    }
    case kSetAddress: return ok();
    case kSetConfiguration:
      if ((s.value & 0xffU) > 1) return ControlReply::stall();
      configuration_ = static_cast<std::uint8_t>(s.value & 0xffU);
      return ok();
    case kGetConfiguration: return reply({configuration_}, s.length);
    case kGetStatus: return reply({0, 0}, s.length);
    case kClearFeature:
    case kSetFeature: return ok();  // endpoint halt and remote wake-up: nothing to do
    case kSetInterface: return s.value == 0 && (s.index & 0xffU) == 0 ? ok() : ControlReply::stall();
    case kGetInterface: return reply({0}, s.length);
    default: return ControlReply::stall();
  }
}

std::optional<InCompletion> UsbPowerMate::transferIn(std::uint8_t endpoint, std::span<std::uint8_t> buffer,
                                                     Nanos /*now*/) {
  if (endpoint != kEndpoint || configuration_ == 0) return InCompletion{UsbStatus::kStall, 0};
  std::lock_guard lock(mutex_);
  if (reports_.empty()) return std::nullopt;
  const std::array<std::uint8_t, 6> r = reports_.front();
  reports_.pop_front();
  const std::size_t n = std::min(buffer.size(), r.size());
  std::memcpy(buffer.data(), r.data(), n);
  return InCompletion{UsbStatus::kOk, n};
}

Nanos UsbPowerMate::readyAt() const {
  std::lock_guard lock(mutex_);
  return reports_.empty() ? Nanos::max() : Nanos{0};
}

}  // namespace basalt::sim::vlab
