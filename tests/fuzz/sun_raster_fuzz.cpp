// Fuzzes Basalt's Sun rasterfile codec: any bytes give an image or an error, never a crash or an
// allocation larger than the file can fill; a decoded image encoded and decoded again is the
// same image.

#include <cstddef>
#include <cstdint>
#include <span>

#include "media/sun_raster.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt;
  auto image = media::decodeSunRaster(std::span<const std::uint8_t>(data, size));
  if (!image) return 0;
  if (image->pixels.size() != image->byteSize()) __builtin_trap();
  const int depth = image->channels == 1 ? 8 : image->channels == 3 ? 24 : 32;
  auto bytes = media::encodeSunRaster(*image, depth);
  if (!bytes) __builtin_trap();
  auto again = media::decodeSunRaster(*bytes);
  if (!again || again->channels != image->channels || again->pixels != image->pixels) __builtin_trap();
  return 0;
}
