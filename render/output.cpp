#include "render/output.h"

#include <algorithm>

#include <fmt/format.h>

#include "render/gl.h"

namespace basalt::render {

Result<void> Output::readBack(Image& out) { return readFramebuffer(size(), out); }

Result<void> readFramebuffer(Size size, Image& out) {
  if (out.width != size.width || out.height != size.height || out.channels != 4 || out.type != ChannelType::kU8) {
    out = Image::make(size.width, size.height, 4);
  }
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, static_cast<GLsizei>(size.width), static_cast<GLsizei>(size.height), GL_RGBA, GL_UNSIGNED_BYTE,
               out.pixels.data());
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kIo, fmt::format("reading the frame back failed: {}", gl::errorName(e)));
  }
  // GL's rows run bottom to top; images run top to bottom. Swap rows in place (no scratch row).
  const std::size_t rowBytes = out.rowBytes();
  std::uint8_t* data = out.pixels.data();
  for (std::uint32_t y = 0; y < size.height / 2; ++y) {
    std::uint8_t* top = data + rowBytes * y;
    std::uint8_t* bottom = data + rowBytes * (size.height - 1 - y);
    std::swap_ranges(top, top + rowBytes, bottom);
  }
  return {};
}

}  // namespace basalt::render
