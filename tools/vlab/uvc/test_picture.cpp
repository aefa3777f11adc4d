#include "tools/vlab/uvc/test_picture.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace basalt::sim::vlab {
namespace {

constexpr std::uint8_t kBlack = 16;
constexpr std::uint8_t kWhite = 235;
constexpr std::uint8_t kNeutralChroma = 128;

// 5x7 digits, one byte per row, bit 4 the leftmost pixel.
constexpr std::array<std::array<std::uint8_t, 7>, 10> kDigits = {{
    {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e},
    {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e},
    {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f},
    {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e},
    {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02},
    {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e},
    {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e},
    {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e},
    {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c},
}};
constexpr std::uint32_t kDigitCount = 10;  // a 32-bit counter has at most 10 decimal digits

struct Ycc {
  std::uint8_t y;
  std::uint8_t cb;
  std::uint8_t cr;
};

std::uint8_t clampByte(double v) { return static_cast<std::uint8_t>(std::clamp(v + 0.5, 0.0, 255.0)); }

// BT.601, limited range, from R'G'B' in 0..1.
Ycc fromRgb(double r, double g, double b) {
  const double luma = 0.299 * r + 0.587 * g + 0.114 * b;
  return {clampByte(16 + 219 * luma), clampByte(128 + 224 * (b - luma) / 1.772),
          clampByte(128 + 224 * (r - luma) / 1.402)};
}

// 75% colour bars, as on a test card: white, yellow, cyan, green, magenta, red, blue.
const std::array<Ycc, 7>& bars() {
  static const std::array<Ycc, 7> kBars = {fromRgb(.75, .75, .75), fromRgb(.75, .75, 0), fromRgb(0, .75, .75),
                                           fromRgb(0, .75, 0),     fromRgb(.75, 0, .75), fromRgb(.75, 0, 0),
                                           fromRgb(0, 0, .75)};
  return kBars;
}

std::uint32_t glyphScale(const CounterLayout& l) { return std::max<std::uint32_t>(2, l.cell / 4); }
std::uint32_t digitsTop(const CounterLayout& l) { return l.bitsRow - l.cell / 2 - 7 * glyphScale(l); }

void fillRect(Yuv422Planes& p, std::uint32_t x, std::uint32_t y, std::uint32_t w, std::uint32_t h, Ycc c) {
  const std::uint32_t x1 = std::min(p.width, x + w);
  const std::uint32_t y1 = std::min(p.height, y + h);
  for (std::uint32_t row = y; row < y1; ++row) {
    std::uint8_t* luma = p.y.data() + std::size_t{row} * p.width;
    std::fill(luma + x, luma + x1, c.y);
    const std::size_t chromaRow = std::size_t{row} * (p.width / 2);
    std::fill(p.cb.data() + chromaRow + x / 2, p.cb.data() + chromaRow + (x1 + 1) / 2, c.cb);
    std::fill(p.cr.data() + chromaRow + x / 2, p.cr.data() + chromaRow + (x1 + 1) / 2, c.cr);
  }
}

}  // namespace

CounterLayout CounterLayout::forSize(std::uint32_t width, std::uint32_t height) {
  CounterLayout l;
  const std::uint32_t cell = std::max<std::uint32_t>(8, (width / 40) / 8 * 8);
  if (width < 32 * cell + 32 || height < 12 * cell) return l;
  l.cell = cell;
  l.x0 = (width - 32 * cell) / 2 / 8 * 8;
  l.bitsRow = (height - 3 * cell) / 8 * 8;
  return l;
}

Result<TestPicture> TestPicture::create(std::uint32_t width, std::uint32_t height) {
  if (width % 16 != 0 || width < 288 || width > 4096 || height % 8 != 0 || height < 96 || height > 4096) {
    return failf(Errc::kInvalidArgument,
                 "a lab camera picture of {}x{} cannot be drawn: the width must be a multiple of 16 from 288 to "
                 "4096 and the height a multiple of 8 from 96 to 4096",
                 width, height);
  }
  TestPicture p(width, height);
  p.layout_ = CounterLayout::forSize(width, height);
  p.barsEnd_ = (digitsTop(p.layout_) - p.layout_.cell) / 8 * 8;
  p.background_.resize(width, height);
  fillRect(p.background_, 0, 0, width, height, {kBlack, kNeutralChroma, kNeutralChroma});
  const auto& colours = bars();
  for (std::uint32_t i = 0; i < colours.size(); ++i) {
    const std::uint32_t left = i * width / 7 / 2 * 2;
    const std::uint32_t right = (i + 1) * width / 7 / 2 * 2;
    fillRect(p.background_, left, 0, (i + 1 == colours.size() ? width : right) - left, p.barsEnd_, colours[i]);
  }
  return p;
}

void TestPicture::renderPlanar(std::uint32_t counter, int brightness, Yuv422Planes& out) const {
  if (out.width != width_ || out.height != height_) out.resize(width_, height_);
  std::memcpy(out.y.data(), background_.y.data(), out.y.size());
  std::memcpy(out.cb.data(), background_.cb.data(), out.cb.size());
  std::memcpy(out.cr.data(), background_.cr.data(), out.cr.size());

  const CounterLayout& l = layout_;
  const Ycc white{kWhite, kNeutralChroma, kNeutralChroma};
  const Ycc black{kBlack, kNeutralChroma, kNeutralChroma};
  // The moving bar: one cell to the right per frame, wrapping around.
  const std::uint32_t barX = static_cast<std::uint32_t>((std::uint64_t{counter} * l.cell) % width_);
  fillRect(out, barX, 0, l.cell, barsEnd_, white);

  // The counter in digits, most significant first, without leading zeros.
  std::array<std::uint8_t, kDigitCount> digits{};
  std::uint32_t n = 0;
  for (std::uint32_t v = counter; n == 0 || v != 0; v /= 10) digits[n++] = static_cast<std::uint8_t>(v % 10);
  const std::uint32_t s = glyphScale(l);
  const std::uint32_t top = digitsTop(l);
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto& glyph = kDigits[digits[n - 1 - i]];
    const std::uint32_t left = l.x0 + i * 6 * s;
    for (std::uint32_t row = 0; row < 7; ++row) {
      for (std::uint32_t col = 0; col < 5; ++col) {
        if ((static_cast<std::uint32_t>(glyph[row]) >> (4U - col)) & 1U)
          fillRect(out, left + col * s, top + row * s, s, s, white);
      }
    }
  }

  // The counter in cells: bit 31 first; the row below holds the complement.
  for (std::uint32_t bit = 0; bit < 32; ++bit) {
    const bool set = ((counter >> (31 - bit)) & 1U) != 0;
    const std::uint32_t left = l.x0 + bit * l.cell;
    fillRect(out, left, l.bitsRow, l.cell, l.cell, set ? white : black);
    fillRect(out, left, l.bitsRow + l.cell, l.cell, l.cell, set ? black : white);
  }

  const int offset = (std::clamp(brightness, 0, 255) - kNeutralBrightness) / 2;
  if (offset != 0) {
    for (auto& v : out.y) v = static_cast<std::uint8_t>(std::clamp(v + offset, int{kBlack}, int{kWhite}));
  }
}

void TestPicture::renderYuyv(std::uint32_t counter, int brightness, Yuv422Planes& scratch,
                             std::span<std::uint8_t> out) const {
  renderPlanar(counter, brightness, scratch);
  const std::size_t pairs = std::size_t{width_} / 2 * height_;
  if (out.size() < pairs * 4) return;
  const std::uint8_t* y = scratch.y.data();
  const std::uint8_t* cb = scratch.cb.data();
  const std::uint8_t* cr = scratch.cr.data();
  std::uint8_t* o = out.data();
  for (std::size_t i = 0; i < pairs; ++i) {
    o[4 * i] = y[2 * i];
    o[4 * i + 1] = cb[i];
    o[4 * i + 2] = y[2 * i + 1];
    o[4 * i + 3] = cr[i];
  }
}

std::optional<std::uint32_t> readFrameCounterYuyv(std::span<const std::uint8_t> frame, std::uint32_t width,
                                                  std::uint32_t height) {
  if (frame.size() < std::size_t{width} * height * 2) return std::nullopt;
  return readFrameCounter(
      width, height, [&](std::uint32_t x, std::uint32_t y) { return int{frame[(std::size_t{y} * width + x) * 2]}; });
}

std::optional<std::uint32_t> readFrameCounterRgb(const Image& image) {
  if (image.type != ChannelType::kU8 || image.channels < 3 || image.pixels.size() < image.byteSize()) {
    return std::nullopt;
  }
  return readFrameCounter(image.width, image.height, [&](std::uint32_t x, std::uint32_t y) {
    // Full-range luma of the decoded RGB; the limited-range levels 16 and 235 land near 0 and 255.
    const int r = image.at(x, y, 0);
    const int g = image.at(x, y, 1);
    const int b = image.at(x, y, 2);
    return (299 * r + 587 * g + 114 * b) / 1000;
  });
}

}  // namespace basalt::sim::vlab
