// Fuzzes the show manifest reader: any bytes must give a manifest or diagnostics, never a crash,
// a hang or an exception. Paths resolve against a folder that does not exist, so every file
// check runs its "does not exist" path.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "kiosk/manifest/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  basalt::kiosk::Diagnostics diagnostics;
  const auto manifest = basalt::kiosk::readManifestText(text, "/nonexistent/basalt-fuzz/show.toml", diagnostics);
  // The reader's contract: a manifest exactly when there is no error.
  if (manifest.has_value() == diagnostics.hasErrors()) __builtin_trap();
  for (const auto& d : diagnostics.items()) (void)d.format();
  return 0;
}
