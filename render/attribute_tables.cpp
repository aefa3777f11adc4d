#include "render/attribute_tables.h"

namespace basalt::render {

using runtime::LinePattern;
using runtime::RasterOp;

namespace {

/// A mask from dash lengths: on, off, on, off, ...
constexpr LinePatternMask dashes(std::initializer_list<int> lengths) {
  LinePatternMask m;
  int bit = 0;
  bool on = true;
  for (int length : lengths) {
    for (int i = 0; i < length; ++i, ++bit) {
      if (on) m.mask |= 1U << bit;
    }
    on = !on;
  }
  m.period = bit;
  return m;
}

}  // namespace

LinePatternMask linePatternMask(LinePattern pattern) {
  switch (pattern) {
    case LinePattern::kDotted: return dashes({1, 3});
    case LinePattern::kDashed: return dashes({6, 4});
    case LinePattern::kDashedDotted: return dashes({6, 3, 1, 3});
    case LinePattern::kCgmDotted: return dashes({2, 2});
    case LinePattern::kCgmDashed: return dashes({9, 3});
    case LinePattern::kDashDot: return dashes({9, 3, 2, 3});
    case LinePattern::kDashDotDotted: return dashes({9, 3, 2, 3, 2, 3});
    case LinePattern::kLongDashed: return dashes({16, 6});
  }
  return dashes({1, 3});
}

std::string_view rasterOpName(RasterOp op) {
  switch (op) {
    case RasterOp::kClear: return "clear";
    case RasterOp::kSet: return "set";
    case RasterOp::kCopy: return "copy";
    case RasterOp::kCopyInverted: return "copy_inv";
    case RasterOp::kInvert: return "invert";
    case RasterOp::kAnd: return "and";
    case RasterOp::kAndReverse: return "and_reverse";
    case RasterOp::kAndInverted: return "and_inv";
    case RasterOp::kNand: return "nand";
    case RasterOp::kOr: return "or";
    case RasterOp::kOrReverse: return "or_reverse";
    case RasterOp::kOrInverted: return "or_inv";
    case RasterOp::kNor: return "nor";
    case RasterOp::kXor: return "xor";
    case RasterOp::kEquiv: return "equiv";
    case RasterOp::kNoop: return "noop";
  }
  return "?";
}

bool rasterOpIsDirect(RasterOp op) {
  switch (op) {
    case RasterOp::kClear:
    case RasterOp::kSet:
    case RasterOp::kCopy:
    case RasterOp::kCopyInverted:
    case RasterOp::kInvert:
    case RasterOp::kNoop: return true;
    default: return false;
  }
}

std::uint8_t applyRasterOp(RasterOp op, std::uint8_t src, std::uint8_t dst) {
  const unsigned s = src, d = dst;
  unsigned r = 0;
  switch (op) {
    case RasterOp::kClear: r = 0; break;
    case RasterOp::kSet: r = 255; break;
    case RasterOp::kCopy: r = s; break;
    case RasterOp::kCopyInverted: r = ~s; break;
    case RasterOp::kInvert: r = ~d; break;
    case RasterOp::kAnd: r = s & d; break;
    case RasterOp::kAndReverse: r = s & ~d; break;
    case RasterOp::kAndInverted: r = ~s & d; break;
    case RasterOp::kNand: r = ~(s & d); break;
    case RasterOp::kOr: r = s | d; break;
    case RasterOp::kOrReverse: r = s | ~d; break;
    case RasterOp::kOrInverted: r = ~s | d; break;
    case RasterOp::kNor: r = ~(s | d); break;
    case RasterOp::kXor: r = s ^ d; break;
    case RasterOp::kEquiv: r = ~(s ^ d); break;
    case RasterOp::kNoop: r = d; break;
  }
  return static_cast<std::uint8_t>(r & 0xFFU);
}

}  // namespace basalt::render
