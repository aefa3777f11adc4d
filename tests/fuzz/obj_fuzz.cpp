// Fuzzes the OBJ reader: any bytes give a model or an error, never a crash, a hang or a mesh
// that breaks its invariants (formats_fuzz_check.h).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "formats_fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto model = basalt::formats::parseObjText(text, "fuzz.obj", basalt::fuzz::kNoFolder, basalt::fuzz::fuzzOptions());
  if (model) basalt::fuzz::checkModel(*model);
  return 0;
}
