#include "runtime/test_pattern.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace basalt {

namespace {

struct Yuv {
  std::uint8_t y = 16, u = 128, v = 128;
};

// BT.601 limited range, integer arithmetic (the usual 8-bit approximation).
Yuv toYuv(Rgb8 c) {
  const int r = c.r, g = c.g, b = c.b;
  const int y = ((66 * r + 129 * g + 25 * b + 128) >> 8) + 16;
  const int u = ((-38 * r - 74 * g + 112 * b + 128) >> 8) + 128;
  const int v = ((112 * r - 94 * g - 18 * b + 128) >> 8) + 128;
  return {static_cast<std::uint8_t>(std::clamp(y, 0, 255)), static_cast<std::uint8_t>(std::clamp(u, 0, 255)),
          static_cast<std::uint8_t>(std::clamp(v, 0, 255))};
}

constexpr std::array<Rgb8, 8> kBars = {
    {{191, 191, 191}, {191, 191, 0}, {0, 191, 191}, {0, 191, 0}, {191, 0, 191}, {191, 0, 0}, {0, 0, 191}, {0, 0, 0}}};

/// The pattern's colour at (x, y), before the moving box.
Rgb8 patternColour(TestPattern pattern, std::uint32_t x, std::uint32_t y, std::uint32_t w, std::uint32_t h,
                   Rgb8 solid) {
  switch (pattern) {
    case TestPattern::kColourBars: return kBars[std::min<std::size_t>(7, std::size_t{x} * 8 / std::max(w, 1u))];
    case TestPattern::kGradient: {
      const auto l = static_cast<std::uint8_t>(std::size_t{x} * 255 / std::max(w - 1, 1u));
      const auto c = static_cast<std::uint8_t>(std::size_t{y} * 255 / std::max(h - 1, 1u));
      return {l, l, c};
    }
    case TestPattern::kChecker: {
      const bool white = ((x / 32) + (y / 32)) % 2 == 0;
      const std::uint8_t v = white ? 235 : 16;
      return {v, v, v};
    }
    case TestPattern::kSolid: return solid;
  }
  return {};
}

struct Box {
  std::uint32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  [[nodiscard]] bool contains(std::uint32_t x, std::uint32_t y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

Box movingBox(std::uint32_t w, std::uint32_t h, std::uint64_t frameNumber) {
  const std::uint32_t side = std::max(h / 8, 2u);
  const std::uint64_t travel = w > side ? w - side : 1;
  const std::uint64_t pos = (frameNumber * side / 16) % travel;
  Box b;
  b.x0 = static_cast<std::uint32_t>(pos);
  b.x1 = b.x0 + side;
  b.y0 = (h - std::min(h, side)) / 2;
  b.y1 = b.y0 + side;
  return b;
}

}  // namespace

bool drawTestPattern(Frame& frame, TestPattern pattern, std::uint64_t frameNumber, bool moving, Rgb8 solid) {
  return drawTestPatternRegion(frame, pattern, frameNumber, moving, solid, 0, 0, frame.width, frame.height);
}

bool drawMovingBoxOver(Frame& frame, const Frame& background, TestPattern pattern, std::uint64_t frameNumber,
                       Rgb8 solid) {
  if (background.format != frame.format || background.width != frame.width || background.height != frame.height ||
      background.planeCount != frame.planeCount) {
    return false;
  }
  for (int i = 0; i < frame.planeCount; ++i) {
    const auto& src = background.planes[static_cast<std::size_t>(i)];
    auto& dst = frame.planes[static_cast<std::size_t>(i)];
    if (!src.data || !dst.data) return false;
    const std::size_t rows = src.stride ? src.size / src.stride : 0;
    const std::size_t bytes = std::min(src.stride, dst.stride);
    for (std::size_t y = 0; y < rows; ++y) std::memcpy(dst.data + y * dst.stride, src.data + y * src.stride, bytes);
  }
  const Box b = movingBox(frame.width, frame.height, frameNumber);
  // Redraw the box and a 2-pixel margin (shared chroma samples) exactly as a full draw would.
  const std::uint32_t x0 = b.x0 >= 2 ? (b.x0 - 2) & ~1u : 0, y0 = b.y0 >= 2 ? (b.y0 - 2) & ~1u : 0;
  const std::uint32_t x1 = std::min(frame.width, b.x1 + 2), y1 = std::min(frame.height, b.y1 + 2);
  return drawTestPatternRegion(frame, pattern, frameNumber, true, solid, x0, y0, x1, y1);
}

bool drawTestPatternRegion(Frame& frame, TestPattern pattern, std::uint64_t frameNumber, bool moving, Rgb8 solid,
                           std::uint32_t rx0, std::uint32_t ry0, std::uint32_t rx1, std::uint32_t ry1) {
  const std::uint32_t w = frame.width, h = frame.height;
  rx0 &= ~1u;
  ry0 &= ~1u;
  rx1 = std::min(rx1, w);
  ry1 = std::min(ry1, h);
  for (int i = 0; i < frame.planeCount; ++i) {
    if (!frame.planes[static_cast<std::size_t>(i)].data) return false;
  }
  if (frame.planeCount == 0 || w == 0 || h == 0) return false;
  Box box;
  if (moving) box = movingBox(w, h, frameNumber);
  const Rgb8 white{235, 235, 235};
  auto colourAt = [&](std::uint32_t x, std::uint32_t y) {
    return moving && box.contains(x, y) ? white : patternColour(pattern, x, y, w, h, solid);
  };
  auto& p0 = frame.planes[0];
  switch (frame.format) {
    case PixelFormat::kRgba8:
    case PixelFormat::kBgra8:
    case PixelFormat::kRgb8: {
      const std::uint32_t bpp = frame.format == PixelFormat::kRgb8 ? 3 : 4;
      const bool bgr = frame.format == PixelFormat::kBgra8;
      for (std::uint32_t y = ry0; y < ry1; ++y) {
        std::uint8_t* row = p0.data + std::size_t{y} * p0.stride;
        for (std::uint32_t x = rx0; x < rx1; ++x) {
          const Rgb8 c = colourAt(x, y);
          std::uint8_t* px = row + std::size_t{x} * bpp;
          px[0] = bgr ? c.b : c.r;
          px[1] = c.g;
          px[2] = bgr ? c.r : c.b;
          if (bpp == 4) px[3] = 255;
        }
      }
      return true;
    }
    case PixelFormat::kGray8:
      for (std::uint32_t y = ry0; y < ry1; ++y) {
        std::uint8_t* row = p0.data + std::size_t{y} * p0.stride;
        for (std::uint32_t x = rx0; x < rx1; ++x) row[x] = toYuv(colourAt(x, y)).y;
      }
      return true;
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy: {
      const bool yuyv = frame.format == PixelFormat::kYuyv;
      for (std::uint32_t y = ry0; y < ry1; ++y) {
        std::uint8_t* row = p0.data + std::size_t{y} * p0.stride;
        for (std::uint32_t x = rx0; x < rx1; x += 2) {
          const Yuv a = toYuv(colourAt(x, y));
          const Yuv b = x + 1 < w ? toYuv(colourAt(x + 1, y)) : a;
          std::uint8_t* px = row + std::size_t{x} * 2;
          const auto u = static_cast<std::uint8_t>((a.u + b.u + 1) / 2);
          const auto v = static_cast<std::uint8_t>((a.v + b.v + 1) / 2);
          if (yuyv) {
            px[0] = a.y, px[1] = u, px[2] = b.y, px[3] = v;
          } else {
            px[0] = u, px[1] = a.y, px[2] = v, px[3] = b.y;
          }
        }
      }
      return true;
    }
    case PixelFormat::kNv12:
    case PixelFormat::kNv21:
    case PixelFormat::kI420:
    case PixelFormat::kYv12: {
      for (std::uint32_t y = ry0; y < ry1; ++y) {
        std::uint8_t* row = p0.data + std::size_t{y} * p0.stride;
        for (std::uint32_t x = rx0; x < rx1; ++x) row[x] = toYuv(colourAt(x, y)).y;
      }
      const bool semi = frame.format == PixelFormat::kNv12 || frame.format == PixelFormat::kNv21;
      const bool vFirst = frame.format == PixelFormat::kNv21 || frame.format == PixelFormat::kYv12;
      for (std::uint32_t cy = ry0 / 2; cy < (ry1 + 1) / 2; ++cy) {
        for (std::uint32_t cx = rx0 / 2; cx < (rx1 + 1) / 2; ++cx) {
          const Yuv c = toYuv(colourAt(std::min(cx * 2, w - 1), std::min(cy * 2, h - 1)));
          if (semi) {
            auto& p1 = frame.planes[1];
            std::uint8_t* px = p1.data + std::size_t{cy} * p1.stride + std::size_t{cx} * 2;
            px[0] = vFirst ? c.v : c.u;
            px[1] = vFirst ? c.u : c.v;
          } else {
            auto& pu = frame.planes[vFirst ? 2 : 1];
            auto& pv = frame.planes[vFirst ? 1 : 2];
            pu.data[std::size_t{cy} * pu.stride + cx] = c.u;
            pv.data[std::size_t{cy} * pv.stride + cx] = c.v;
          }
        }
      }
      return true;
    }
    case PixelFormat::kMjpeg:
    case PixelFormat::kUnknown: return false;
  }
  return false;
}

Rgb8 samplePixel(const Frame& frame, std::uint32_t x, std::uint32_t y) {
  if (x >= frame.width || y >= frame.height || frame.planeCount == 0 || !frame.planes[0].data) return {};
  const auto& p0 = frame.planes[0];
  const std::uint8_t* row = p0.data + std::size_t{y} * p0.stride;
  switch (frame.format) {
    case PixelFormat::kRgba8: return {row[std::size_t{x} * 4], row[std::size_t{x} * 4 + 1], row[std::size_t{x} * 4 + 2]};
    case PixelFormat::kBgra8: return {row[std::size_t{x} * 4 + 2], row[std::size_t{x} * 4 + 1], row[std::size_t{x} * 4]};
    case PixelFormat::kRgb8: return {row[std::size_t{x} * 3], row[std::size_t{x} * 3 + 1], row[std::size_t{x} * 3 + 2]};
    case PixelFormat::kYuyv: {
      const std::uint8_t l = row[std::size_t{x} * 2];
      return {l, l, l};
    }
    case PixelFormat::kUyvy: {
      const std::uint8_t l = row[std::size_t{x} * 2 + 1];
      return {l, l, l};
    }
    default: return {row[x], row[x], row[x]};
  }
}

}  // namespace basalt
