// Fuzzes the crash-recovery state file the kiosk reads back from disk: any bytes give a resume
// point or an error, never a crash or a negative position.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "kiosk/policy/state_store.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto point = basalt::kiosk::decodeState(text, "/show.toml");
  if (point && point->position.count() < 0) __builtin_trap();
  return 0;
}
