#pragma once

/// \file
/// \brief An OSC message as plain data (its address, its arguments by type) and taking packets
/// apart with liblo: a message, or a bundle of messages and bundles.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "runtime/log.h"

namespace basalt::kiosk {

/// \brief The log category of the OSC room (`BASALT_LOG=osc:debug`).
BASALT_LOG_CATEGORY(Osc, "osc");

/// \brief One argument: its OSC type tag, and its value where Basalt reads one.
struct OscArgument {
  char type = 'N';    ///< the OSC type tag: i h f d (numbers), s S (strings), T F N I, b, m, c, t, ...
  double number = 0;  ///< i, h, f, d
  std::string text;   ///< s, S
  [[nodiscard]] bool isNumber() const { return type == 'i' || type == 'h' || type == 'f' || type == 'd'; }
  [[nodiscard]] bool isString() const { return type == 's' || type == 'S'; }
};

/// \brief One message and who sent it.
struct OscMessage {
  std::string address;  ///< may be a pattern (OSC 1.0: ? * [] {})
  std::vector<OscArgument> arguments;
  std::string sender;  ///< the sender's numeric address ("127.0.0.1"), without its port
  /// \brief ",fs": the type tags as OSC writes them.
  [[nodiscard]] std::string typeTags() const;
};

/// \brief Bundles nest at most this deep; a packet holds at most this many messages.
inline constexpr int kOscMaxBundleDepth = 8;
inline constexpr std::size_t kOscMaxMessagesPerPacket = 64;

/// \brief What a packet held: its messages (sender left empty), and how many parts of it were
/// malformed (a message liblo could not take apart, a bundle cut short, too deep or too many).
struct OscPacket {
  std::vector<OscMessage> messages;
  std::size_t malformed = 0;
};

/// \brief Takes `bytes` apart: one message, or a bundle ("#bundle", a time tag, elements each
/// with its size). liblo reads each message; Basalt walks the bundles (elements act at once,
/// whatever their time tag: a show controller sends "now"). Never reads past `bytes`.
[[nodiscard]] OscPacket parseOscPacket(std::span<const std::byte> bytes);

}  // namespace basalt::kiosk
