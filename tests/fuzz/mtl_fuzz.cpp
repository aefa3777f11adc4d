// Fuzzes the MTL reader: any bytes give materials (never a crash), and the materials written
// back as MTL read again the same.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "formats_fuzz_check.h"
#include "runtime/formats/mtl.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  formats::Diagnostics first("fuzz.mtl", 50, false);
  const auto materials = formats::parseMtl(text, fuzz::kNoFolder, {}, first);
  const std::string written = formats::formatMtl(materials, fuzz::kNoFolder);
  formats::Diagnostics second("fuzz.mtl", 50, false);
  const auto again = formats::parseMtl(written, fuzz::kNoFolder, {}, second);
  fuzz::require(again == materials);
  return 0;
}
