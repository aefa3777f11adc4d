// Fuzzes the OSC input's packet reader (liblo's deserialiser behind Basalt's bundle walk): any
// datagram gives messages and a malformed count, never a crash, and never more messages than a
// packet may hold.

#include <cstddef>
#include <cstdint>
#include <span>

#include "kiosk/osc/osc_message.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto packet =
      basalt::kiosk::parseOscPacket(std::span<const std::byte>(reinterpret_cast<const std::byte*>(data), size));
  if (packet.messages.size() > basalt::kiosk::kOscMaxMessagesPerPacket) __builtin_trap();
  return 0;
}
