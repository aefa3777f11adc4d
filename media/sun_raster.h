#pragma once

/// \file
/// \brief Sun rasterfiles (`.ras`, and LAVA's `.im8`, `.im24`, `.im32`): LAVA's texture and
/// "Save Raster" format, read and written by Basalt's own codec (no maintained library in
/// Debian 12 that Basalt already uses handles them; see runtime/formats/README.md).
///
/// Reads depths 1, 8 (grey or colour-mapped), 24 and 32, standard, RGB-ordered and
/// byte-run-length-encoded files. Writes 8-bit grey (with a grey colour map), 24-bit and 32-bit
/// (alpha in the pad byte) standard files.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::media {

/// \brief The first four bytes of every Sun rasterfile.
inline constexpr std::uint32_t kSunRasterMagic = 0x59a66a95;

/// \brief Decodes a Sun rasterfile held in memory into 1 (grey), 3 (RGB) or 4 (RGBA) 8-bit
/// channels, top row first. A 32-bit file whose pad bytes are all zero has no alpha and gives 3
/// channels; otherwise the pad byte is alpha (as ImageMagick writes it).
[[nodiscard]] Result<Image> decodeSunRaster(std::span<const std::uint8_t> bytes);

/// \brief Encodes an image (1 to 4 channels, 8 or 16 bits; 16 bits are reduced to 8) as a
/// standard Sun rasterfile of `depth` 8 (grey, colour images become their luminance), 24 or 32.
[[nodiscard]] Result<std::vector<std::uint8_t>> encodeSunRaster(const Image& image, int depth);

/// \brief The depth LAVA's extensions mean: .im8 8, .im24 24, .im32 32; .ras by the image's
/// channels (1: 8, 3: 24, 2 or 4: 32). 0 for other extensions. `extension` is lower case with
/// its dot.
int sunRasterDepthFor(std::string_view extension, std::uint32_t channels);

}  // namespace basalt::media
