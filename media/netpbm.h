#pragma once

/// \file
/// \brief Netpbm images (PBM, PGM, PPM in plain and raw form, and PAM) read and written by
/// Basalt's own codec: Debian 12's OpenImageIO reads no PAM and misreads plain PBM written
/// without blanks between the bits, both of which the thesis' and other tools' files use.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::media {

/// \brief True when `bytes` start like a Netpbm file ("P1" to "P7" and a blank).
bool looksLikeNetpbm(std::span<const std::uint8_t> bytes);

/// \brief Decodes the first image of a Netpbm file: P1/P4 bitmaps and PAM BLACKANDWHITE become
/// 8-bit grey (black 0, white 255), P2/P5 grey, P3/P6 RGB, P7 1 to 4 channels. A maxval up to
/// 255 gives 8-bit samples scaled to 0..255; a larger one 16-bit samples scaled to 0..65535.
[[nodiscard]] Result<Image> decodeNetpbm(std::span<const std::uint8_t> bytes);

/// \brief Encodes an 8- or 16-bit image: 1 channel as P5, 3 as P6, 2 and 4 as PAM (P7); `pam`
/// writes PAM whatever the channels.
[[nodiscard]] Result<std::vector<std::uint8_t>> encodeNetpbm(const Image& image, bool pam);

}  // namespace basalt::media
