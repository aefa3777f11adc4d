// Fuzzes the trace readers: hid-recorder files and trace.toml. Any text must parse or give an
// error naming the line; a recording that parses must decode every report of every device that
// maps to dials. Input: a first byte 0x01 selects trace.toml (the rest of the input); anything
// else is an hid-recorder file as it stands (so ../shared/testdata/hid seeds it directly).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "devices/hid/dial_decoder.h"
#include "sim/hid_recording.h"
#include "sim/trace.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if (data[0] == 0x01) {
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    auto trace = basalt::sim::parseTraceToml(text, "fuzz.toml");
    if (trace) {
      for (const auto& d : trace->devices) {
        if (d.file.find('/') != std::string::npos) __builtin_trap();  // names stay inside the folder
      }
      (void)basalt::sim::formatTraceToml(*trace);
    } else if (trace.error().where().empty()) {
      __builtin_trap();  // errors name the file
    }
    return 0;
  }
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto rec = basalt::sim::parseHidRecording(text, "fuzz.hid");
  if (!rec) {
    if (rec.error().where().empty()) __builtin_trap();
    return 0;
  }
  std::array<basalt::Event, basalt::devices::DialDecoder::kMaxEventsPerReport> events;
  for (const auto& d : rec->devices) {
    auto decoder = basalt::devices::DialDecoder::create(d.vendor, d.product, d.descriptor, "fuzz");
    if (!decoder) continue;
    for (const auto& r : d.reports) (void)decoder->decode(r.bytes, events);
  }
  return 0;
}
