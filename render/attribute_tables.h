#pragma once

/// \file
/// \brief How LAVA's attribute values become drawing parameters: line patterns as pixel masks,
/// raster operations and the path that can draw each exactly on OpenGL ES, and a CPU reference of
/// the raster operations for tests.

#include <cstdint>
#include <string_view>

#include "runtime/show/attributes.h"

namespace basalt::render {

/// \brief One of LAVA's eight line patterns as a repeating pixel mask: bit i (counted along the
/// line's major screen axis) is drawn when set. Patterns scale with the line width.
struct LinePatternMask {
  std::uint32_t mask = 0;
  int period = 1;  ///< pixels, 1..32
};
LinePatternMask linePatternMask(runtime::LinePattern pattern);

/// \brief The script's name of a raster operation ("xor", "and_reverse", ...).
std::string_view rasterOpName(runtime::RasterOp op);

/// \brief True when OpenGL ES draws `op` exactly with shader output and fixed-function state
/// alone (copy, clear, set, copy inverted, invert, no-op); the rest need the destination's value
/// in the shader (framebuffer fetch, or a copy of the frame).
bool rasterOpIsDirect(runtime::RasterOp op);

/// \brief The operation on one 8-bit channel, as XGL and X11 define it (src, dst).
std::uint8_t applyRasterOp(runtime::RasterOp op, std::uint8_t src, std::uint8_t dst);

}  // namespace basalt::render
