// OSC packets taken apart: messages and bundles written byte by byte here (from the OSC 1.0
// specification, not by liblo), and broken ones.
// Example failures: a bundle's second message lost; a size that points past the packet read
// anyway; a bundle nested a thousand deep exhausting the stack.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "kiosk/osc/osc_message.h"

namespace basalt::kiosk {
namespace {

using Bytes = std::vector<std::byte>;

void padded(Bytes& out, std::string_view s) {
  for (const char c : s) out.push_back(static_cast<std::byte>(c));
  out.push_back(std::byte{0});
  while (out.size() % 4 != 0) out.push_back(std::byte{0});
}

void big32(Bytes& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::byte>((v >> shift) & 0xff));
}

Bytes floatMessage(std::string_view address, float value) {
  Bytes out;
  padded(out, address);
  padded(out, ",f");
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  big32(out, bits);
  return out;
}

Bytes bundle(const std::vector<Bytes>& elements) {
  Bytes out;
  padded(out, "#bundle");
  big32(out, 0);
  big32(out, 1);  // time tag "immediately"
  for (const Bytes& e : elements) {
    big32(out, static_cast<std::uint32_t>(e.size()));
    out.insert(out.end(), e.begin(), e.end());
  }
  return out;
}

TEST(OscPacket, AMessageWithEachArgumentType) {
  Bytes m;
  padded(m, "/basalt/cmd");
  padded(m, ",isfd");
  big32(m, static_cast<std::uint32_t>(-7));
  padded(m, "wireframe");
  const float f = 0.25f;
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, 4);
  big32(m, bits);
  const double d = -1.5;
  std::uint64_t bits64 = 0;
  std::memcpy(&bits64, &d, 8);
  big32(m, static_cast<std::uint32_t>(bits64 >> 32));
  big32(m, static_cast<std::uint32_t>(bits64));
  const OscPacket p = parseOscPacket(m);
  EXPECT_EQ(p.malformed, 0u);
  ASSERT_EQ(p.messages.size(), 1u);
  const OscMessage& msg = p.messages[0];
  EXPECT_EQ(msg.address, "/basalt/cmd");
  EXPECT_EQ(msg.typeTags(), ",isfd");
  EXPECT_EQ(msg.arguments[0].number, -7);
  EXPECT_EQ(msg.arguments[1].text, "wireframe");
  EXPECT_EQ(msg.arguments[2].number, 0.25);
  EXPECT_EQ(msg.arguments[3].number, -1.5);
}

TEST(OscPacket, BundlesNestedAndFlat) {
  const Bytes b = bundle({floatMessage("/a", 1), bundle({floatMessage("/b", 2), floatMessage("/c", 3)})});
  const OscPacket p = parseOscPacket(b);
  EXPECT_EQ(p.malformed, 0u);
  ASSERT_EQ(p.messages.size(), 3u);
  EXPECT_EQ(p.messages[0].address, "/a");
  EXPECT_EQ(p.messages[1].address, "/b");
  EXPECT_EQ(p.messages[2].address, "/c");
  EXPECT_EQ(p.messages[2].arguments.at(0).number, 3);
}

TEST(OscPacket, BrokenPacketsAreCountedNeverRead) {
  EXPECT_EQ(parseOscPacket({}).malformed, 1u);
  Bytes odd = floatMessage("/a", 1);
  odd.pop_back();
  EXPECT_EQ(parseOscPacket(odd).malformed, 1u) << "not a multiple of 4";
  Bytes cut = floatMessage("/a", 1);
  cut.resize(cut.size() - 4);
  EXPECT_EQ(parseOscPacket(cut).malformed, 1u) << "the float is missing";
  Bytes noTags;
  padded(noTags, "/a");
  padded(noTags, "xyz");
  EXPECT_EQ(parseOscPacket(noTags).messages.size(), 0u);
  // A bundle element whose size points past the packet.
  Bytes past = bundle({floatMessage("/a", 1)});
  past[19] = std::byte{200};
  const OscPacket p = parseOscPacket(past);
  EXPECT_EQ(p.messages.size(), 0u);
  EXPECT_EQ(p.malformed, 1u);
  // Too deep: refused at the limit, not by running out of stack.
  Bytes deep = floatMessage("/deep", 1);
  for (int i = 0; i < 100; ++i) deep = bundle({deep});
  EXPECT_EQ(parseOscPacket(deep).messages.size(), 0u);
  EXPECT_EQ(parseOscPacket(deep).malformed, 1u);
  // Too many messages in one packet: the first kOscMaxMessagesPerPacket are read.
  std::vector<Bytes> many(100, floatMessage("/m", 1));
  const OscPacket lots = parseOscPacket(bundle(many));
  EXPECT_EQ(lots.messages.size(), kOscMaxMessagesPerPacket);
  EXPECT_EQ(lots.malformed, 100 - kOscMaxMessagesPerPacket);
  // Random bytes never crash it.
  Bytes noise(4096);
  std::uint32_t x = 12345;
  for (int round = 0; round < 200; ++round) {
    for (std::byte& b : noise) {
      x = x * 1664525 + 1013904223;
      b = static_cast<std::byte>(x >> 24);
    }
    if (round % 2 == 0) std::memcpy(noise.data(), "#bundle", 8);
    (void)parseOscPacket(noise);
  }
}

}  // namespace
}  // namespace basalt::kiosk
