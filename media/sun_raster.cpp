// Sun rasterfile codec: LAVA's .ras/.im8/.im24/.im32 images, read and written without a library.
//
// Format: eight big-endian 32-bit header words (magic, width, height, depth, length, type,
// colour-map type, colour-map length), the colour map (for RMT_EQUAL_RGB three planes: all reds,
// all greens, all blues), then rows padded to 16 bits. Type 1 stores 24/32-bit pixels as
// [X]BGR, type 3 as [X]RGB; type 2 is type 1 run-length encoded with the escape byte 0x80
// (0x80 0x00 = one 0x80; 0x80 n v = n + 1 copies of v).
// Limits: 16384 x 16384 pixels; the data must be present before anything is allocated for it
// (a run-length file may expand at most 86 times, the most its encoding allows).

#include "media/sun_raster.h"

#include <algorithm>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

namespace basalt::media {

namespace {

constexpr std::uint32_t kMaxSide = 16384;
enum : std::uint32_t { kTypeOld = 0, kTypeStandard = 1, kTypeByteEncoded = 2, kTypeRgb = 3 };
enum : std::uint32_t { kMapNone = 0, kMapEqualRgb = 1, kMapRaw = 2 };

std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}

void putBe32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 24));
  out.push_back(static_cast<std::uint8_t>(v >> 16));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

std::size_t rowBytesFor(std::uint32_t width, std::uint32_t depth) {
  return ((std::size_t{width} * depth + 15) / 16) * 2;
}

/// Expands byte-encoded data until `out` is full; false when the input ends first.
bool decodeRuns(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out) {
  std::size_t i = 0, o = 0;
  while (o < out.size()) {
    if (i >= in.size()) return false;
    const std::uint8_t b = in[i++];
    if (b != 0x80) {
      out[o++] = b;
      continue;
    }
    if (i >= in.size()) return false;
    const std::uint8_t count = in[i++];
    if (count == 0) {
      out[o++] = 0x80;
      continue;
    }
    if (i >= in.size()) return false;
    const std::uint8_t value = in[i++];
    const std::size_t n = std::min<std::size_t>(std::size_t{count} + 1, out.size() - o);
    std::fill_n(out.begin() + static_cast<long>(o), n, value);
    o += n;
  }
  return true;
}

}  // namespace

Result<Image> decodeSunRaster(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 32) return fail(Errc::kParse, "the file is too short for a Sun rasterfile header (32 bytes)");
  if (be32(bytes.data()) != kSunRasterMagic) return fail(Errc::kParse, "this is not a Sun rasterfile (no 0x59a66a95)");
  const std::uint32_t width = be32(bytes.data() + 4), height = be32(bytes.data() + 8), depth = be32(bytes.data() + 12);
  const std::uint32_t type = be32(bytes.data() + 20), mapType = be32(bytes.data() + 24);
  const std::uint32_t mapLength = be32(bytes.data() + 28);
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide) {
    return fail(Errc::kParse,
                fmt::format("the image is {} x {} pixels; Basalt reads 1 to {} a side", width, height, kMaxSide));
  }
  if (depth != 1 && depth != 8 && depth != 24 && depth != 32) {
    return fail(Errc::kParse, fmt::format("depth {} is not a Sun rasterfile depth (1, 8, 24 or 32)", depth));
  }
  if (type != kTypeOld && type != kTypeStandard && type != kTypeByteEncoded && type != kTypeRgb) {
    return fail(Errc::kUnsupported,
                fmt::format("rasterfile type {} is not supported (TIFF, IFF and experimental types are not); convert "
                            "it to a standard rasterfile or PNG",
                            type));
  }
  if (mapType > kMapRaw) return fail(Errc::kParse, fmt::format("colour-map type {} is not valid", mapType));
  const std::span<const std::uint8_t> rest = bytes.subspan(32);
  if (mapLength > rest.size()) return fail(Errc::kParse, "the file ends inside its colour map");
  const std::span<const std::uint8_t> map = rest.first(mapLength);
  const std::span<const std::uint8_t> data = rest.subspan(mapLength);

  // The colour map: only RMT_EQUAL_RGB maps say what the pixel values mean.
  std::uint32_t mapEntries = 0;
  bool greyMap = true;
  if (mapType == kMapEqualRgb && mapLength > 0) {
    if (mapLength % 3 != 0 || mapLength > 3 * 256) {
      return fail(Errc::kParse,
                  fmt::format("a colour map of {} bytes is not 3 planes of up to 256 entries", mapLength));
    }
    mapEntries = mapLength / 3;
    for (std::uint32_t i = 0; i < mapEntries; ++i) {
      greyMap = greyMap && map[i] == map[mapEntries + i] && map[i] == map[2 * mapEntries + i];
    }
  }
  const bool mapped = mapEntries > 0 && depth <= 8;

  const std::size_t rowBytes = rowBytesFor(width, depth);
  const std::size_t dataBytes = rowBytes * height;
  std::vector<std::uint8_t> raw;
  if (type == kTypeByteEncoded) {
    if (dataBytes / 86 > data.size()) {
      return fail(Errc::kParse, "the run-length data is far too short for the image's size; the file is truncated");
    }
    raw.resize(dataBytes);
    if (!decodeRuns(data, raw)) return fail(Errc::kParse, "the run-length data ends before the image does");
  } else {
    if (data.size() < dataBytes) {
      return fail(Errc::kParse, fmt::format("the file ends after {} of the image's {} bytes", data.size(), dataBytes));
    }
  }
  const std::uint8_t* pixels = type == kTypeByteEncoded ? raw.data() : data.data();

  std::uint32_t channels = 3;
  bool alpha = false;
  if (depth <= 8) {
    channels = (!mapped || greyMap) ? 1 : 3;
  } else if (depth == 32) {
    for (std::uint32_t y = 0; y < height && !alpha; ++y) {
      const std::uint8_t* row = pixels + rowBytes * y;
      for (std::uint32_t x = 0; x < width; ++x) {
        if (row[4 * std::size_t{x}] != 0) {
          alpha = true;
          break;
        }
      }
    }
    channels = alpha ? 4 : 3;
  }
  Image image = Image::make(width, height, channels);
  const auto lookup = [&](std::uint32_t index, std::uint32_t plane) -> std::uint8_t {
    return index < mapEntries ? map[plane * mapEntries + index] : 0;
  };
  for (std::uint32_t y = 0; y < height; ++y) {
    const std::uint8_t* row = pixels + rowBytes * y;
    std::uint8_t* out = image.row(y);
    for (std::uint32_t x = 0; x < width; ++x) {
      switch (depth) {
        case 1: {
          const bool bit = (row[x / 8] >> (7 - x % 8)) & 1;
          if (mapped) {
            for (std::uint32_t c = 0; c < channels; ++c) out[x * channels + c] = lookup(bit ? 1 : 0, c);
          } else {
            out[x] = bit ? 0 : 255;  // 1 is black
          }
          break;
        }
        case 8:
          if (mapped) {
            for (std::uint32_t c = 0; c < channels; ++c) out[x * channels + c] = lookup(row[x], c);
          } else {
            out[x] = row[x];
          }
          break;
        case 24: {
          const std::uint8_t* p = row + 3 * std::size_t{x};
          const bool rgb = type == kTypeRgb;
          out[3 * x + 0] = rgb ? p[0] : p[2];
          out[3 * x + 1] = p[1];
          out[3 * x + 2] = rgb ? p[2] : p[0];
          break;
        }
        default: {
          const std::uint8_t* p = row + 4 * std::size_t{x};
          const bool rgb = type == kTypeRgb;
          out[channels * x + 0] = rgb ? p[1] : p[3];
          out[channels * x + 1] = p[2];
          out[channels * x + 2] = rgb ? p[3] : p[1];
          if (alpha) out[channels * x + 3] = p[0];
          break;
        }
      }
    }
  }
  return image;
}

Result<std::vector<std::uint8_t>> encodeSunRaster(const Image& image, int depth) {
  if (image.empty() || image.channels < 1 || image.channels > 4 || image.type == ChannelType::kF32 ||
      image.pixels.size() < image.byteSize()) {
    return fail(Errc::kInvalidArgument, "a Sun rasterfile holds 8-bit images of 1 to 4 channels");
  }
  if (depth != 8 && depth != 24 && depth != 32) {
    return fail(Errc::kInvalidArgument,
                fmt::format("Basalt writes Sun rasterfiles of depth 8, 24 or 32, not {}", depth));
  }
  const std::uint32_t w = image.width, h = image.height, c = image.channels;
  const auto sample = [&](std::uint32_t x, std::uint32_t y, std::uint32_t ch) -> std::uint8_t {
    const std::size_t i = (std::size_t{y} * w + x) * c + ch;
    if (image.type == ChannelType::kU16) {
      std::uint16_t v = 0;
      std::memcpy(&v, image.pixels.data() + i * 2, 2);
      return static_cast<std::uint8_t>(v >> 8);
    }
    return image.pixels[i];
  };
  const auto rgba = [&](std::uint32_t x, std::uint32_t y, std::uint8_t out[4]) {
    if (c <= 2) {
      out[0] = out[1] = out[2] = sample(x, y, 0);
      out[3] = c == 2 ? sample(x, y, 1) : 255;
    } else {
      out[0] = sample(x, y, 0);
      out[1] = sample(x, y, 1);
      out[2] = sample(x, y, 2);
      out[3] = c == 4 ? sample(x, y, 3) : 255;
    }
  };
  const auto d = static_cast<std::uint32_t>(depth);
  const std::size_t rowBytes = rowBytesFor(w, d);
  std::vector<std::uint8_t> out;
  out.reserve(32 + (d == 8 ? 768 : 0) + rowBytes * h);
  putBe32(out, kSunRasterMagic);
  putBe32(out, w);
  putBe32(out, h);
  putBe32(out, d);
  putBe32(out, static_cast<std::uint32_t>(rowBytes * h));
  putBe32(out, kTypeStandard);
  putBe32(out, d == 8 ? kMapEqualRgb : kMapNone);
  putBe32(out, d == 8 ? 768 : 0);
  if (d == 8) {
    for (int plane = 0; plane < 3; ++plane) {
      for (int i = 0; i < 256; ++i) out.push_back(static_cast<std::uint8_t>(i));
    }
  }
  std::uint8_t px[4];
  for (std::uint32_t y = 0; y < h; ++y) {
    const std::size_t start = out.size();
    for (std::uint32_t x = 0; x < w; ++x) {
      rgba(x, y, px);
      if (d == 8) {
        out.push_back(c <= 2 ? px[0]
                             : static_cast<std::uint8_t>((299 * px[0] + 587 * px[1] + 114 * px[2] + 500) / 1000));
      } else if (d == 24) {
        out.insert(out.end(), {px[2], px[1], px[0]});
      } else {
        out.insert(out.end(), {px[3], px[2], px[1], px[0]});
      }
    }
    out.resize(start + rowBytes, 0);
  }
  return out;
}

int sunRasterDepthFor(std::string_view extension, std::uint32_t channels) {
  if (extension == ".im8") return 8;
  if (extension == ".im24") return 24;
  if (extension == ".im32") return 32;
  if (extension == ".ras" || extension == ".sun" || extension == ".rs") {
    return channels == 1 ? 8 : channels == 3 ? 24 : 32;
  }
  return 0;
}

}  // namespace basalt::media
