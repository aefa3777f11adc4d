#include "runtime/image.h"

#include <algorithm>
#include <cstdlib>

namespace basalt {

std::size_t channelBytes(ChannelType type) {
  switch (type) {
    case ChannelType::kU8: return 1;
    case ChannelType::kU16: return 2;
    case ChannelType::kF32: return 4;
  }
  return 1;
}

Image Image::make(std::uint32_t width, std::uint32_t height, std::uint32_t channels, ChannelType type) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.type = type;
  image.pixels.assign(image.byteSize(), 0);
  return image;
}

ImageDifference compareImages(const Image& a, const Image& b, int tolerance, Image* diffOut) {
  ImageDifference d;
  d.sameShape = a.width == b.width && a.height == b.height && a.channels == b.channels && a.type == ChannelType::kU8 &&
                b.type == ChannelType::kU8;
  if (!d.sameShape) return d;
  if (diffOut) *diffOut = Image::make(a.width, a.height, 4);
  double sum = 0;
  const std::size_t pixels = std::size_t{a.width} * a.height;
  for (std::size_t p = 0; p < pixels; ++p) {
    int worst = 0;
    for (std::uint32_t c = 0; c < a.channels; ++c) {
      const std::size_t i = p * a.channels + c;
      const int delta = std::abs(int{a.pixels[i]} - int{b.pixels[i]});
      worst = std::max(worst, delta);
      sum += delta;
    }
    d.maxChannelDelta = std::max(d.maxChannelDelta, worst);
    if (worst > tolerance) ++d.pixelsOverTolerance;
    if (diffOut) {
      std::uint8_t* out = diffOut->pixels.data() + p * 4;
      const std::uint8_t grey =
          a.channels >= 3
              ? static_cast<std::uint8_t>(
                    (a.pixels[p * a.channels] + a.pixels[p * a.channels + 1] + a.pixels[p * a.channels + 2]) / 12)
              : static_cast<std::uint8_t>(a.pixels[p * a.channels] / 4);
      if (worst > tolerance) {
        out[0] = 255;
        out[1] = out[2] = 0;
      } else {
        out[0] = out[1] = out[2] = grey;
      }
      out[3] = 255;
    }
  }
  d.meanAbsoluteDelta = pixels ? sum / static_cast<double>(pixels * a.channels) : 0;
  return d;
}

}  // namespace basalt
