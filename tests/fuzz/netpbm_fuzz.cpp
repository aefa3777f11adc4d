// Fuzzes Basalt's Netpbm codec (PBM, PGM, PPM, PAM): any bytes give an image or an error, never a
// crash or an allocation for samples the file does not hold; a decoded image encoded and
// decoded again is the same image.

#include <cstddef>
#include <cstdint>
#include <span>

#include "media/netpbm.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt;
  auto image = media::decodeNetpbm(std::span<const std::uint8_t>(data, size));
  if (!image) return 0;
  if (image->pixels.size() != image->byteSize()) __builtin_trap();
  auto bytes = media::encodeNetpbm(*image, false);
  if (!bytes) __builtin_trap();
  auto again = media::decodeNetpbm(*bytes);
  if (!again || again->type != image->type || again->pixels != image->pixels) __builtin_trap();
  return 0;
}
