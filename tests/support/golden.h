#pragma once

/// \file
/// \brief Golden-image comparison for render tests.
///
/// Each golden image `NAME.png` under tests/render/golden has a `NAME.txt` beside it stating
/// the renderer it was made with, the size and the tolerance. A failing comparison writes the
/// actual image and a diff image next to the test's scratch folder and says where.

#include <filesystem>
#include <string>

#include "runtime/image.h"

namespace basalt::test {

struct GoldenTolerance {
  int channel = 0;              ///< a channel may differ by this much without counting
  double maxPixelFraction = 0;  ///< fraction of pixels allowed beyond `channel`
};

/// \brief Reads `NAME.txt` beside the golden: lines `tolerance.channel = N` and
/// `tolerance.pixels = F` (a fraction). Missing values are 0.
GoldenTolerance readTolerance(const std::filesystem::path& golden);

/// \brief Compares `actual` with the golden PNG. Returns "" when it matches, otherwise a
/// message with the figures and the paths of the actual and diff images it wrote.
/// With BASALT_UPDATE_GOLDENS=1 the golden is rewritten instead and "" is returned.
std::string compareWithGolden(const Image& actual, const std::filesystem::path& golden);

}  // namespace basalt::test
