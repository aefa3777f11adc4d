#include "tools/vlab/uvc/usb_device.h"

namespace basalt::sim::vlab {

std::array<std::uint8_t, 8> UsbSetup::bytes() const {
  return {requestType,
          request,
          static_cast<std::uint8_t>(value),
          static_cast<std::uint8_t>(value >> 8U),
          static_cast<std::uint8_t>(index),
          static_cast<std::uint8_t>(index >> 8U),
          static_cast<std::uint8_t>(length),
          static_cast<std::uint8_t>(length >> 8U)};
}

UsbSetup UsbSetup::fromBytes(std::span<const std::uint8_t, 8> b) {
  UsbSetup s;
  s.requestType = b[0];
  s.request = b[1];
  s.value = static_cast<std::uint16_t>(b[2] | (b[3] << 8U));
  s.index = static_cast<std::uint16_t>(b[4] | (b[5] << 8U));
  s.length = static_cast<std::uint16_t>(b[6] | (b[7] << 8U));
  return s;
}

ControlReply controlReply(std::vector<std::uint8_t> data, std::uint16_t wLength) {
  if (data.size() > wLength) data.resize(wLength);
  return {UsbStatus::kOk, std::move(data)};
}

std::vector<std::uint8_t> stringDescriptor(const std::string& text) {
  std::vector<std::uint8_t> d{static_cast<std::uint8_t>(2 + 2 * text.size()), usb::kDescString};
  for (const char c : text) {
    d.push_back(static_cast<std::uint8_t>(c));
    d.push_back(0);
  }
  return d;
}

}  // namespace basalt::sim::vlab
