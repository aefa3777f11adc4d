// Fuzzes the HID recording reader (sim/hid_recording.h), which the replay backend and the
// virtual lab's uhid replay share: any text must give devices or a parse error with a location,
// never a crash, and every device it returns must have a descriptor (what uhid needs) and no
// empty report.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "sim/hid_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto recording = basalt::sim::parseHidRecording(text, "fuzz.hid");
  if (recording) {
    if (recording->devices.empty()) __builtin_trap();
    for (const auto& d : recording->devices) {
      if (d.descriptor.empty()) __builtin_trap();
      for (const auto& r : d.reports) {
        if (r.bytes.empty()) __builtin_trap();
      }
    }
  } else if (recording.error().where().empty()) {
    __builtin_trap();
  }
  return 0;
}
