// Fuzzes the virtual lab's HID recording reader (sim/vlab/hid_recording.h): any text must give
// devices or a parse error with a location, never a crash, and every device it returns must have
// a descriptor (what uhid needs).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "sim/vlab/hid_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto devices = basalt::sim::vlab::parseHidRecording(text, "fuzz.hid");
  if (devices) {
    if (devices->empty()) __builtin_trap();
    for (const auto& d : *devices) {
      if (d.descriptor.empty()) __builtin_trap();
    }
  } else if (devices.error().where().empty()) {
    __builtin_trap();
  }
  return 0;
}
