// Fuzzes the scene reader: any bytes give a scene description (bad statements are warnings),
// never a crash; and the description written back reads again the same.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "formats_fuzz_check.h"
#include "runtime/formats/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<formats::Diagnostic> warnings;
  auto first = formats::parseSceneText(text, "fuzz.sce", fuzz::fuzzOptions(), warnings);
  if (!first) return 0;
  const std::string written = formats::formatScene(*first);
  auto second = formats::parseSceneText(written, "fuzz.sce", fuzz::fuzzOptions(), warnings);
  fuzz::require(second.has_value() && *second == *first);
  return 0;
}
