#pragma once

/// \file
/// \brief The C interface between media/ and its OpenImageIO module.
///
/// OpenImageIO in Debian 12 links about 260 libraries (OpenCV, FFmpeg, OpenVDB, ...); loading
/// them costs about 250 ms and 130 MB in every process. So OIIO lives in a module that media/
/// loads the first time an image format other than PNG is read or written, and shows that use
/// no image files never pay for it. This header is the only contract between the two.

#include <cstddef>
#include <cstdint>

extern "C" {

/// \brief Version of this table; bump when a member changes.
inline constexpr std::uint32_t kBasaltOiioApiVersion = 1;

/// \brief An image the module fills: it asks `allocate` for storage once it knows the shape.
struct BasaltOiioImage {
  std::uint32_t width;
  std::uint32_t height;
  std::uint32_t channels;
  std::uint32_t bytesPerChannel;  ///< 1, 2 or 4 (float)
  void* context;
  std::uint8_t* (*allocate)(void* context, std::uint32_t width, std::uint32_t height, std::uint32_t channels,
                            std::uint32_t bytesPerChannel);
};

struct BasaltOiioApi {
  std::uint32_t version;
  /// Writes interleaved pixels to `path` in the format of its extension; 0 on success,
  /// otherwise a message in `error`.
  int (*write)(const char* path, const void* pixels, std::uint32_t width, std::uint32_t height, std::uint32_t channels,
               std::uint32_t bytesPerChannel, char* error, std::size_t errorSize);
  /// Reads `path` into `out` (8-bit, or 16-bit for deeper files), top row first, EXIF
  /// orientation applied; 0 on success, otherwise a message in `error`.
  int (*read)(const char* path, BasaltOiioImage* out, char* error, std::size_t errorSize);
};

/// \brief The module's one exported symbol.
const BasaltOiioApi* basalt_oiio_api();
using BasaltOiioApiFn = const BasaltOiioApi* (*)();
}
