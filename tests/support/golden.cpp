#include "support/golden.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "media/image_io.h"
#include "support/test_paths.h"

namespace basalt::test {

GoldenTolerance readTolerance(const std::filesystem::path& golden) {
  GoldenTolerance t;
  std::ifstream in(std::filesystem::path(golden).replace_extension(".txt"));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string key, eq;
    double value = 0;
    if (!(fields >> key >> eq >> value) || eq != "=") continue;
    if (key == "tolerance.channel") t.channel = static_cast<int>(value);
    if (key == "tolerance.pixels") t.maxPixelFraction = value;
  }
  return t;
}

std::string compareWithGolden(const Image& actual, const std::filesystem::path& golden) {
  if (const char* update = std::getenv("BASALT_UPDATE_GOLDENS"); update && std::string(update) == "1") {
    if (auto r = media::writeImage(golden, actual); !r) return "cannot update golden: " + r.error().describe();
    return {};
  }
  auto expected = media::readImage(golden);
  if (!expected) return "cannot read golden image: " + expected.error().describe();
  const GoldenTolerance tol = readTolerance(golden);
  Image diff;
  const ImageDifference d = compareImages(actual, *expected, tol.channel, &diff);
  const double pixels = static_cast<double>(actual.width) * actual.height;
  const double fraction = pixels > 0 ? static_cast<double>(d.pixelsOverTolerance) / pixels : 1.0;
  if (d.sameShape && fraction <= tol.maxPixelFraction) return {};

  const std::filesystem::path out = binaryDir() / "test-failures";
  const std::string stem = golden.stem().string();
  const auto actualPath = out / (stem + ".actual.png");
  const auto diffPath = out / (stem + ".diff.png");
  if (auto r = media::writeImage(actualPath, actual); !r)
    return "cannot write the actual image: " + r.error().describe();
  if (d.sameShape) {
    if (auto r = media::writeImage(diffPath, diff); !r) return "cannot write the diff image: " + r.error().describe();
  }
  if (!d.sameShape) {
    return fmt::format("image shape {}x{}x{} differs from golden {}x{}x{}; actual written to {}", actual.width,
                       actual.height, actual.channels, expected->width, expected->height, expected->channels,
                       actualPath.string());
  }
  return fmt::format(
      "{:.4f}% of pixels differ by more than {} (allowed {:.4f}%), max delta {}, mean {:.3f}; "
      "actual: {}, diff: {}",
      fraction * 100, tol.channel, tol.maxPixelFraction * 100, d.maxChannelDelta, d.meanAbsoluteDelta,
      actualPath.string(), diffPath.string());
}

}  // namespace basalt::test
