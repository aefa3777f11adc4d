#pragma once

/// \file
/// \brief The picture the virtual lab's UVC camera sends: colour bars, a white bar that moves
/// one step per frame, and the frame counter, drawn both in digits (for people looking at a
/// capture) and as 32 black-or-white cells with a row of their complement below (for tests,
/// which read it back from YUYV frames or from decoded JPEGs).
///
/// The cells are 8-pixel aligned squares of at least 8 pixels, so each 8x8 luma block of a JPEG
/// is one flat colour and survives compression; the complement row lets a reader tell a
/// counter from noise.

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <span>
#include <vector>

#include "runtime/error.h"
#include "runtime/image.h"
#include "sim/jpeg_encoder.h"

namespace basalt::sim::vlab {

/// \brief Where the counter cells are in a picture of a given size.
struct CounterLayout {
  std::uint32_t cell = 0;     ///< cell side in pixels (a multiple of 8)
  std::uint32_t x0 = 0;       ///< left edge of bit 31 (the most significant)
  std::uint32_t bitsRow = 0;  ///< top of the row of bits; the complement row is one cell below

  static CounterLayout forSize(std::uint32_t width, std::uint32_t height);
};

/// \brief Draws the lab camera's frames of one size. Immutable after create(): render calls
/// only read the precomputed background, so one picture may serve several threads.
class TestPicture {
 public:
  /// \brief Brightness the picture is drawn at unchanged (the UVC control's default).
  static constexpr int kNeutralBrightness = 128;
  /// \brief Fails with kInvalidArgument unless width is a multiple of 16 from 288 to 4096 and
  /// height a multiple of 8 from 96 to 4096 (the counter needs 32 cells of 8 pixels).
  [[nodiscard]] static Result<TestPicture> create(std::uint32_t width, std::uint32_t height);

  [[nodiscard]] std::uint32_t width() const { return width_; }
  [[nodiscard]] std::uint32_t height() const { return height_; }

  /// \brief Draws frame `counter` into `out`, at `brightness` (0-255; luma moves by
  /// (brightness - 128) / 2). `out` is resized on first use only.
  void renderPlanar(std::uint32_t counter, int brightness, Yuv422Planes& out) const;
  /// \brief Draws frame `counter` as packed YUYV (Y0 Cb Y1 Cr) into `out`, which must hold
  /// width * height * 2 bytes.
  void renderYuyv(std::uint32_t counter, int brightness, Yuv422Planes& scratch, std::span<std::uint8_t> out) const;

 private:
  TestPicture(std::uint32_t width, std::uint32_t height) : width_(width), height_(height) {}

  std::uint32_t width_;
  std::uint32_t height_;
  CounterLayout layout_;
  std::uint32_t barsEnd_ = 0;  // rows [0, barsEnd_) hold the colour bars and the moving bar
  Yuv422Planes background_;
};

/// \brief Reads the counter from a picture's luma, `luma(x, y)` giving 0-255. Returns nothing
/// when the cells are not there or do not check.
template <typename LumaAt>
std::optional<std::uint32_t> readFrameCounter(std::uint32_t width, std::uint32_t height, const LumaAt& luma);

/// \brief The counter of a packed YUYV frame of this size.
std::optional<std::uint32_t> readFrameCounterYuyv(std::span<const std::uint8_t> frame, std::uint32_t width,
                                                  std::uint32_t height);
/// \brief The counter of an 8-bit RGB or RGBA image (a decoded JPEG frame).
std::optional<std::uint32_t> readFrameCounterRgb(const Image& image);

// ---- implementation of the template ----

template <typename LumaAt>
std::optional<std::uint32_t> readFrameCounter(std::uint32_t width, std::uint32_t height, const LumaAt& luma) {
  const CounterLayout l = CounterLayout::forSize(width, height);
  if (l.cell == 0) return std::nullopt;
  // The mean of the middle half of a cell, so that ringing at its edges does not count.
  auto cellLevel = [&](std::uint32_t bit, std::uint32_t top) {
    const std::uint32_t left = l.x0 + bit * l.cell;
    const std::uint32_t q = l.cell / 4;
    int sum = 0;
    int n = 0;
    for (std::uint32_t y = top + q; y < top + l.cell - q; ++y) {
      for (std::uint32_t x = left + q; x < left + l.cell - q; ++x) {
        sum += luma(x, y);
        ++n;
      }
    }
    return sum / n;
  };
  std::uint32_t value = 0;
  for (std::uint32_t bit = 0; bit < 32; ++bit) {
    const int on = cellLevel(bit, l.bitsRow);
    const int complement = cellLevel(bit, l.bitsRow + l.cell);
    const bool set = on >= 128;
    if (set == (complement >= 128) || std::abs(on - complement) < 48) return std::nullopt;
    value = (value << 1U) | (set ? 1U : 0U);
  }
  return value;
}

}  // namespace basalt::sim::vlab
