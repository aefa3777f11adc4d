// Fuzzes Extended OBJ both ways: whatever reads, written back as Extended OBJ and read again,
// gives the same objects (names, parents, instances, placement, maps, meshes). Catches writer
// and reader disagreeing on any statement.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "formats_fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto options = fuzz::fuzzOptions();
  auto first = formats::parseObjText(text, "fuzz.obj", fuzz::kNoFolder, options);
  if (!first) return 0;
  fuzz::checkModel(*first);
  std::string mtl;
  const std::string written = formats::formatObj(*first, fuzz::kNoFolder, {}, "fuzz.mtl", mtl);
  auto second = formats::parseObjText(written, "fuzz.obj", fuzz::kNoFolder, options);
  fuzz::require(second.has_value());
  fuzz::require(second->objects.size() == first->objects.size());
  for (std::size_t i = 0; i < first->objects.size(); ++i) fuzz::require(first->objects[i] == second->objects[i]);
  return 0;
}
