// Fuzzes cave files and cave geometry: any bytes give settings or an error (never a crash), the
// settings written back read again the same, and the same bytes as a cave geometry give
// validated facets or an error, which turn round and back to themselves.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "formats_fuzz_check.h"
#include "runtime/formats/cave.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto parsed = formats::parseCaveText(text, "fuzz.cave", {}, false);
  if (parsed) {
    auto again = formats::parseCaveText(formats::formatCave(parsed->settings), "fuzz.cave", {}, false);
    fuzz::require(again.has_value() && again->settings == parsed->settings);
  }
  std::vector<formats::Diagnostic> warnings;
  auto geometry = formats::parseCaveGeometry(text, "fuzz.obj", fuzz::fuzzOptions(), warnings);
  if (geometry) {
    for (const auto& f : geometry->facets) {
      fuzz::require(f.corners.size() >= 3);
      fuzz::require(std::isfinite(f.normal.x) && std::isfinite(f.area) && f.area > 0);
      fuzz::require(f.longestSide < f.corners.size());
    }
    // Turning every facet round twice gives the facets back; the facing is said or not, never a crash.
    const formats::CaveGeometry twice = formats::windFacets(
        formats::windFacets(*geometry, formats::FacetWinding::kOutward), formats::FacetWinding::kOutward);
    for (std::size_t i = 0; i < twice.facets.size(); ++i) {
      fuzz::require(twice.facets[i].corners == geometry->facets[i].corners);
    }
    (void)formats::caveFacingProblem(*geometry, formats::FacetWinding::kAuto);
  }
  return 0;
}
