// Taking OSC packets apart: liblo's deserialiser reads each message (its address, type tags and
// arguments, with every size and padding checked); bundles are walked here because liblo hands
// bundles only to a server of its own, and Basalt owns its sockets (see osc_input.cpp).

#include "kiosk/osc/osc_message.h"

#include <lo/lo.h>

#include <cstdint>
#include <cstring>
#include <memory>

namespace basalt::kiosk {

namespace {

struct MessageFree {
  void operator()(lo_message m) const { lo_message_free(m); }
};
using MessagePtr = std::unique_ptr<std::remove_pointer_t<lo_message>, MessageFree>;

constexpr std::string_view kBundleTag{"#bundle\0", 8};

std::uint32_t bigEndian32(const std::byte* p) {
  return (std::to_integer<std::uint32_t>(p[0]) << 24) | (std::to_integer<std::uint32_t>(p[1]) << 16) |
         (std::to_integer<std::uint32_t>(p[2]) << 8) | std::to_integer<std::uint32_t>(p[3]);
}

void parseMessage(std::span<const std::byte> bytes, OscPacket& out) {
  if (out.messages.size() >= kOscMaxMessagesPerPacket) {
    ++out.malformed;
    return;
  }
  // liblo reads from a buffer it may keep pointers into while it builds the message: a copy of
  // its own, aligned for the 4-byte fields.
  std::vector<std::uint32_t> aligned((bytes.size() + 3) / 4);
  std::memcpy(aligned.data(), bytes.data(), bytes.size());
  int result = 0;
  MessagePtr message(lo_message_deserialise(aligned.data(), bytes.size(), &result));
  const char* path = message ? lo_get_path(aligned.data(), static_cast<ssize_t>(bytes.size())) : nullptr;
  if (!message || !path) {
    ++out.malformed;
    return;
  }
  OscMessage m;
  m.address = path;
  const char* types = lo_message_get_types(message.get());
  lo_arg** argv = lo_message_get_argv(message.get());
  const int argc = lo_message_get_argc(message.get());
  m.arguments.reserve(static_cast<std::size_t>(argc));
  for (int i = 0; i < argc && types[i] != '\0'; ++i) {
    OscArgument a;
    a.type = types[i];
    // liblo's argument pointers point into the message's data, which OSC aligns to 4 bytes only:
    // a 64-bit value may sit at an address an lo_arg (8-byte aligned) cannot. Each value is
    // copied out by its own size instead of read through the union.
    const auto* raw = reinterpret_cast<const char*>(argv[i]);
    switch (a.type) {
      case LO_INT32: {
        std::int32_t v = 0;
        std::memcpy(&v, raw, sizeof v);
        a.number = v;
        break;
      }
      case LO_INT64: {
        std::int64_t v = 0;
        std::memcpy(&v, raw, sizeof v);
        a.number = static_cast<double>(v);
        break;
      }
      case LO_FLOAT: {
        float v = 0;
        std::memcpy(&v, raw, sizeof v);
        a.number = static_cast<double>(v);
        break;
      }
      case LO_DOUBLE: {
        double v = 0;
        std::memcpy(&v, raw, sizeof v);
        a.number = v;
        break;
      }
      case LO_STRING:
      case LO_SYMBOL: a.text = raw; break;
      default: break;  // kept as its type: no binding takes it
    }
    m.arguments.push_back(std::move(a));
  }
  out.messages.push_back(std::move(m));
}

void parseElement(std::span<const std::byte> bytes, int depth, OscPacket& out) {
  const bool bundle =
      bytes.size() >= kBundleTag.size() && std::memcmp(bytes.data(), kBundleTag.data(), kBundleTag.size()) == 0;
  if (!bundle) {
    parseMessage(bytes, out);
    return;
  }
  if (depth >= kOscMaxBundleDepth || bytes.size() < 16) {
    ++out.malformed;
    return;
  }
  std::size_t at = 16;  // "#bundle\0" and the 8-byte time tag
  while (at < bytes.size()) {
    if (bytes.size() - at < 4) {
      ++out.malformed;
      return;
    }
    const std::uint32_t size = bigEndian32(bytes.data() + at);
    at += 4;
    if (size == 0 || size % 4 != 0 || size > bytes.size() - at) {
      ++out.malformed;
      return;
    }
    parseElement(bytes.subspan(at, size), depth + 1, out);
    at += size;
  }
}

}  // namespace

std::string OscMessage::typeTags() const {
  std::string tags(",");
  for (const OscArgument& a : arguments) tags += a.type;
  return tags;
}

OscPacket parseOscPacket(std::span<const std::byte> bytes) {
  OscPacket out;
  if (bytes.empty() || bytes.size() % 4 != 0) {
    ++out.malformed;
    return out;
  }
  parseElement(bytes, 0, out);
  return out;
}

}  // namespace basalt::kiosk
