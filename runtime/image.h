#pragma once

/// \file
/// \brief A CPU image: what snapshots, read-back and texture files are in memory.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace basalt {

/// \brief The type of one channel of an Image.
enum class ChannelType : std::uint8_t { kU8, kU16, kF32 };

std::size_t channelBytes(ChannelType type);

/// \brief A tightly packed image, rows top to bottom, channels interleaved.
struct Image {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint32_t channels = 0;  ///< 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA
  ChannelType type = ChannelType::kU8;
  std::vector<std::uint8_t> pixels;

  /// \brief An image of the given shape, zero-filled.
  static Image make(std::uint32_t width, std::uint32_t height, std::uint32_t channels,
                    ChannelType type = ChannelType::kU8);

  [[nodiscard]] std::size_t rowBytes() const { return std::size_t{width} * channels * channelBytes(type); }
  [[nodiscard]] std::size_t byteSize() const { return rowBytes() * height; }
  [[nodiscard]] bool empty() const { return width == 0 || height == 0; }
  [[nodiscard]] std::uint8_t* row(std::uint32_t y) { return pixels.data() + rowBytes() * y; }
  [[nodiscard]] const std::uint8_t* row(std::uint32_t y) const { return pixels.data() + rowBytes() * y; }
  /// \brief Channel `c` of pixel (x, y) of an 8-bit image.
  [[nodiscard]] std::uint8_t at(std::uint32_t x, std::uint32_t y, std::uint32_t c) const {
    return pixels[(std::size_t{y} * width + x) * channels + c];
  }
};

/// \brief How two 8-bit images differ, for golden-image tests and determinism checks.
struct ImageDifference {
  bool sameShape = false;
  int maxChannelDelta = 0;              ///< largest absolute difference of any channel
  double meanAbsoluteDelta = 0;         ///< over all channels of all pixels
  std::size_t pixelsOverTolerance = 0;  ///< pixels with any channel differing by more than tol
};

/// \brief Compares two 8-bit images channel by channel. `tolerance` sets which pixels count
/// in `pixelsOverTolerance`. When `diffOut` is given it receives an RGBA image that shows
/// differing pixels in red over a dimmed copy of `a`.
ImageDifference compareImages(const Image& a, const Image& b, int tolerance, Image* diffOut = nullptr);

}  // namespace basalt
