// Fuzzes the HID report descriptor parser and the dial mapping: any bytes must parse or give an
// error naming a byte, never crash, hang or read out of bounds; a descriptor that maps to dials
// must decode any report. Input: the descriptor, then optionally 0xff 0xfe and reports separated
// by 0xff 0xfd.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "devices/hid/dial_decoder.h"
#include "devices/hid/report_descriptor.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  std::size_t split = size;
  for (std::size_t i = 0; i + 1 < size; ++i) {
    if (input[i] == 0xff && input[i + 1] == 0xfe) {
      split = i;
      break;
    }
  }
  const auto descriptor = input.first(split);
  auto parsed = basalt::devices::hid::parseReportDescriptor(descriptor, "fuzz");
  if (!parsed && parsed.error().message().empty()) __builtin_trap();  // errors always say what
  if (parsed) {
    for (const auto& f : parsed->fields) {
      if (f.isVariable() && f.usages.size() != f.count) __builtin_trap();  // one usage per element
    }
  }
  auto decoder = basalt::devices::DialDecoder::create(0x1234, 0x5678, descriptor, "fuzz");
  if (!decoder) return 0;
  std::array<basalt::Event, basalt::devices::DialDecoder::kMaxEventsPerReport> events;
  std::size_t start = split + 2;
  for (std::size_t i = start; i <= size; ++i) {
    if (i == size || (i + 1 < size && input[i] == 0xff && input[i + 1] == 0xfd)) {
      if (i > start) {
        const std::size_t n = decoder->decode(input.subspan(start, i - start), events);
        for (std::size_t e = 0; e < n; ++e) {
          if (events[e].index >= basalt::devices::DialDecoder::kMaxButtons) __builtin_trap();
        }
      }
      start = i + 2;
      ++i;
    }
  }
  return 0;
}
