// Fuzzes what the kiosk reads from disk besides the manifest: the crash-recovery state file,
// POSIX TZ rules and TZif time zone files. Any bytes give a value or an error, never a crash.
// The first byte picks the reader.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "kiosk/manifest/time_zone.h"
#include "kiosk/policy/state_store.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 3) {
    case 0: {
      auto point = basalt::kiosk::decodeState(text, "/show.toml");
      if (point && point->position.count() < 0) __builtin_trap();
      break;
    }
    case 1: {
      auto zone = basalt::kiosk::TimeZone::fromPosix(text);
      if (zone) {
        for (std::int64_t t = -4000000000; t < 8000000000; t += 997'000'013) (void)zone->offsetAt(t);
      }
      break;
    }
    default: {
      auto zone = basalt::kiosk::TimeZone::fromTzif(std::span(data + 1, size - 1), "fuzz");
      if (zone) {
        for (std::int64_t t = -4000000000; t < 8000000000; t += 997'000'013)
          (void)zone->toLocal(basalt::WallTime{std::chrono::seconds(t)});
      }
      break;
    }
  }
  return 0;
}
