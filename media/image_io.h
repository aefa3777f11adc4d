#pragma once

/// \file
/// \brief Image files through OpenImageIO: snapshots out, textures in.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::media {

/// \brief Writes `image` to `path`, in the format its extension names: .png, Netpbm (.ppm, .pgm
/// and .pnm without alpha, .pam with it) and Sun rasters by Basalt's own codecs; .jpg, .tif,
/// .exr, ... whatever this OpenImageIO writes. The file is written to a temporary name in the
/// same folder and renamed, so a reader never sees half a file.
[[nodiscard]] Result<void> writeImage(const std::filesystem::path& path, const Image& image);

/// \brief Encodes an 8-bit image (1 to 4 channels) as PNG in memory: snapshots served over
/// HTTP by the status server.
[[nodiscard]] Result<std::vector<std::uint8_t>> encodePng(const Image& image);

/// \brief Reads an image file into 8-bit (or 16-bit, for 16-bit files) interleaved channels,
/// top row first.
[[nodiscard]] Result<Image> readImage(const std::filesystem::path& path);

}  // namespace basalt::media
