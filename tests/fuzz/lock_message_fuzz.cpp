// Fuzzes the frame-lock wire format (kiosk/lock/lock_protocol.h): what a follower reads from the
// network and the leader from its followers. Any bytes decode to a message or an error, never a
// crash or a read past the end; what decodes encodes back to the same bytes.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "kiosk/lock/lock_protocol.h"

namespace {

template <typename Message>
void roundTrip(const Message& m, std::span<const std::byte> in) {
  basalt::kiosk::LockBuffer out{};
  const std::size_t n = basalt::kiosk::encode(m, out);
  // A frame's floats may hold -0 or NaN payload bits that read back equal; compare sizes only then.
  if (n != in.size()) __builtin_trap();
}

/// Messages without floats encode back to exactly the bytes they were read from.
template <typename Message>
void sameBytes(const Message& m, std::span<const std::byte> in) {
  basalt::kiosk::LockBuffer out{};
  const std::size_t n = basalt::kiosk::encode(m, out);
  if (n != in.size() || std::memcmp(out.data(), in.data(), n) != 0) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> in(reinterpret_cast<const std::byte*>(data), size);
  using basalt::kiosk::LockMessageKind;
  auto kind = basalt::kiosk::peekKind(in);
  if (!kind) return 0;
  switch (*kind) {
    case LockMessageKind::kFrame:
      if (auto m = basalt::kiosk::decodeFrame(in)) roundTrip(*m, in);
      break;
    case LockMessageKind::kPresent:
      if (auto m = basalt::kiosk::decodePresent(in)) roundTrip(*m, in);
      break;
    case LockMessageKind::kReady:
      if (auto m = basalt::kiosk::decodeReady(in)) {
        basalt::kiosk::LockBuffer out{};
        const std::size_t n = basalt::kiosk::encode(*m, out);
        if (n != size || std::memcmp(out.data(), data, n) != 0) __builtin_trap();
      }
      break;
    case LockMessageKind::kBye:
      if (auto m = basalt::kiosk::decodeBye(in)) {
        basalt::kiosk::LockBuffer out{};
        const std::size_t n = basalt::kiosk::encode(*m, out);
        if (n != size || std::memcmp(out.data(), data, n) != 0) __builtin_trap();
      }
      break;
    case LockMessageKind::kResend:
      if (auto m = basalt::kiosk::decodeResend(in)) sameBytes(*m, in);
      break;
    case LockMessageKind::kCommand:
      if (auto m = basalt::kiosk::decodeCommand(in)) sameBytes(*m, in);
      break;
  }
  return 0;
}
