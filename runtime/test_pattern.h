#pragma once

/// \file
/// \brief Test pictures drawn straight into a Frame in its own pixel format: the synthetic
/// camera's content and a lost camera's fallback texture. No colour conversion library; the
/// YUV values are BT.601 limited range, computed once per colour.

#include <cstdint>

#include "runtime/frame.h"

namespace basalt {

enum class TestPattern : std::uint8_t {
  kColourBars,  ///< eight vertical 75% bars (white, yellow, cyan, green, magenta, red, blue, black)
  kGradient,    ///< horizontal luma ramp, vertical chroma ramp
  kChecker,     ///< 32-pixel black and white squares
  kSolid,       ///< one colour everywhere
};

/// \brief 8-bit RGB colour.
struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb8&, const Rgb8&) = default;
};

/// \brief Fills `frame` (RGBA, BGRA, RGB, GRAY, YUYV, UYVY, NV12, NV21, I420 or YV12, CPU planes)
/// with `pattern`. When `movingBox` is true, a white box 1/8 of the height moves across the
/// picture with `frameNumber` (one box width every 16 frames), so that stalls and repeated
/// frames can be seen and tested. Returns false for formats it cannot draw (MJPEG, dmabuf-only).
bool drawTestPattern(Frame& frame, TestPattern pattern, std::uint64_t frameNumber, bool movingBox, Rgb8 solid = {});

/// \brief The same picture as drawTestPattern(..., moving = true), drawn the fast way: copies
/// `background` (drawn once with moving = false, same format and size) and redraws only the box.
bool drawMovingBoxOver(Frame& frame, const Frame& background, TestPattern pattern, std::uint64_t frameNumber,
                       Rgb8 solid = {});

/// \brief drawTestPattern restricted to the pixels [x0, x1) x [y0, y1) (x0 and y0 rounded down to
/// even, so that shared chroma samples are written whole).
bool drawTestPatternRegion(Frame& frame, TestPattern pattern, std::uint64_t frameNumber, bool movingBox, Rgb8 solid,
                           std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1);

/// \brief The colour at pixel (x, y) of an RGB-family frame or the luma of a YUV one, for tests.
[[nodiscard]] Rgb8 samplePixel(const Frame& frame, std::uint32_t x, std::uint32_t y);

}  // namespace basalt
