// The OpenImageIO module: every image format OIIO reads and writes, loaded on demand by
// media/image_io.cpp (see oiio_module.h for why it is a module).
//
// Serves: snapshots in formats other than PNG, image textures of any format.
// Limits: 1 to 4 channels; 8-bit, 16-bit or float samples.

#include "media/oiio_module.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <string>

namespace {

void setError(char* error, std::size_t size, const std::string& text) {
  if (size == 0) return;
  // OIIO's messages may span lines; Basalt's messages are one line.
  std::string line;
  for (char c : text) {
    if (c == '\n') {
      if (!line.empty() && line.back() != ' ') line += "; ";
    } else {
      line += c;
    }
  }
  while (!line.empty() && (line.back() == ' ' || line.back() == ';')) line.pop_back();
  std::snprintf(error, size, "%s", line.c_str());
}

OIIO::TypeDesc typeFor(std::uint32_t bytesPerChannel) {
  switch (bytesPerChannel) {
    case 2: return OIIO::TypeDesc::UINT16;
    case 4: return OIIO::TypeDesc::FLOAT;
    default: return OIIO::TypeDesc::UINT8;
  }
}

int writeImage(const char* path, const void* pixels, std::uint32_t width, std::uint32_t height, std::uint32_t channels,
               std::uint32_t bytesPerChannel, char* error, std::size_t errorSize) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) {
    setError(error, errorSize, "no image writer for this file's extension (" + OIIO::geterror() + ")");
    return 1;
  }
  const OIIO::TypeDesc type = typeFor(bytesPerChannel);
  OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), static_cast<int>(channels), type);
  if (!out->open(path, spec)) {
    setError(error, errorSize, out->geterror());
    return 1;
  }
  const bool written = out->write_image(type, pixels);
  std::string message = written ? std::string() : out->geterror();
  const bool closed = out->close();
  if (!written || !closed) {
    setError(error, errorSize, message.empty() ? out->geterror() : message);
    return 1;
  }
  return 0;
}

int readImage(const char* path, BasaltOiioImage* out, char* error, std::size_t errorSize) {
  // Alpha as stored (unassociated): OIIO would otherwise premultiply PNG and TGA colours.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::ImageBuf source(path, 0, 0, nullptr, &config);
  if (!source.init_spec(path, 0, 0)) {
    setError(error, errorSize, source.geterror());
    return 1;
  }
  const OIIO::ImageSpec& spec = source.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.nchannels > 4) {
    setError(error, errorSize,
             "an image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " with " +
                 std::to_string(spec.nchannels) + " channels is not supported (1 to 4 channels)");
    return 1;
  }
  if (static_cast<long long>(spec.width) * spec.height > 16384LL * 16384LL) {
    setError(error, errorSize, "the image is larger than 16384x16384 pixels");
    return 1;
  }
  // Decode first, so that a broken file reports the decoder's reason (reorient would only say
  // that it failed).
  if (!source.read(0, 0, true, OIIO::TypeDesc::UNKNOWN) || source.has_error()) {
    std::string why = source.geterror();
    if (why.empty()) why = "the decoder gave up without saying why";
    (void)OIIO::geterror();  // taken, so that OIIO does not print it again at exit
    setError(error, errorSize, why);
    return 1;
  }
  // EXIF orientation: turn the pixels so that row 0 is the top as the camera meant it.
  OIIO::ImageBuf oriented = OIIO::ImageBufAlgo::reorient(source);
  if (oriented.has_error()) {
    setError(error, errorSize, oriented.geterror());
    return 1;
  }
  const OIIO::ImageSpec& o = oriented.spec();
  const std::uint32_t bytes = spec.format.size() > 1 ? 2 : 1;
  std::uint8_t* pixels =
      out->allocate(out->context, static_cast<std::uint32_t>(o.width), static_cast<std::uint32_t>(o.height),
                    static_cast<std::uint32_t>(o.nchannels), bytes);
  if (!pixels) {
    setError(error, errorSize, "out of memory for the image");
    return 1;
  }
  if (!oriented.get_pixels(OIIO::ROI::All(), typeFor(bytes), pixels)) {
    setError(error, errorSize, oriented.geterror());
    return 1;
  }
  out->width = static_cast<std::uint32_t>(o.width);
  out->height = static_cast<std::uint32_t>(o.height);
  out->channels = static_cast<std::uint32_t>(o.nchannels);
  out->bytesPerChannel = bytes;
  return 0;
}

constexpr BasaltOiioApi kApi{kBasaltOiioApiVersion, writeImage, readImage};

}  // namespace

extern "C" __attribute__((visibility("default"))) const BasaltOiioApi* basalt_oiio_api() { return &kApi; }
