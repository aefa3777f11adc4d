#include "support/numbered_clip.h"

#include <unistd.h>

#include <string>
#include <system_error>

#include "support/process.h"

namespace basalt::test {

Image numberedImage(std::uint32_t width, std::uint32_t height, int number) {
  Image image = Image::make(width, height, 4);
  for (std::uint32_t y = 0; y < height; ++y) {
    for (std::uint32_t x = 0; x < width; ++x) {
      const int bar = static_cast<int>(x * kNumberBits / width);
      const bool on = ((number >> (kNumberBits - 1 - bar)) & 1) != 0;
      std::uint8_t* p = image.row(y) + std::size_t{x} * 4;
      p[0] = on ? 235 : 20;
      p[1] = on ? 235 : 20;
      p[2] = on ? 235 : 20;
      p[3] = 255;
    }
  }
  return image;
}

Result<std::filesystem::path> makeNumberedClip(const std::filesystem::path& path, int frames, double fps,
                                               media::VideoCodec codec, std::uint32_t width, std::uint32_t height,
                                               int firstNumber) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) return path;
  // Test cases run as parallel processes: each writes its own partial file, then renames it.
  const std::filesystem::path partial =
      path.parent_path() / ("partial-" + std::to_string(::getpid()) + "-" + path.filename().string());
  media::RecorderOptions o;
  o.path = partial;
  o.width = width;
  o.height = height;
  o.fps = fps;
  o.codec = codec;
  o.quality = 90;
  auto recorder = media::Recorder::create(o);
  if (!recorder) return std::unexpected(recorder.error());
  for (int n = 0; n < frames; ++n) {
    if (auto r = (*recorder)->push(numberedImage(width, height, firstNumber + n)); !r)
      return std::unexpected(r.error());
  }
  if (auto r = (*recorder)->finish(); !r) return std::unexpected(r.error());
  std::filesystem::rename(partial, path, ec);
  if (ec) return fail(Errc::kIo, ec.message(), path.string());
  return path;
}

Result<std::filesystem::path> addTone(const std::filesystem::path& video, const std::filesystem::path& path,
                                      int toneBuffers, double frequency, double volume) {
  const std::string gstLaunch = onPath("gst-launch-1.0");
  if (gstLaunch.empty()) return fail(Errc::kUnavailable, "gst-launch-1.0 is not installed (gstreamer1.0-tools)");
  const auto made = run({gstLaunch,
                         "-q",
                         "filesrc",
                         "location=" + video.string(),
                         "!",
                         "avidemux",
                         "!",
                         "queue",
                         "!",
                         "mux.",
                         "audiotestsrc",
                         "freq=" + std::to_string(frequency),
                         "volume=" + std::to_string(volume),
                         "num-buffers=" + std::to_string(toneBuffers),
                         "!",
                         "audioconvert",
                         "!",
                         "vorbisenc",
                         "!",
                         "queue",
                         "!",
                         "mux.",
                         "matroskamux",
                         "name=mux",
                         "!",
                         "filesink",
                         "location=" + path.string()});
  if (made.exitCode != 0) return fail(Errc::kIo, "gst-launch-1.0 could not make a clip with sound: " + made.output);
  return path;
}

namespace {

int decodeBars(std::uint32_t width, const auto& lumaAt) {
  int number = 0;
  for (int bar = 0; bar < kNumberBits; ++bar) {
    const auto x = static_cast<std::uint32_t>((2 * bar + 1) * static_cast<int>(width) / (2 * kNumberBits));
    number = (number << 1) | (lumaAt(x) > 128 ? 1 : 0);
  }
  return number;
}

}  // namespace

int readFrameNumber(const Frame& frame) {
  const std::uint32_t y = frame.height / 2;
  const Plane& p = frame.planes[0];
  if (!p.data) return -1;
  const std::uint8_t* row = p.data + std::size_t{p.stride} * y;
  switch (frame.format) {
    case PixelFormat::kI420:
    case PixelFormat::kYv12:
    case PixelFormat::kNv12:
    case PixelFormat::kNv21:
    case PixelFormat::kGray8: return decodeBars(frame.width, [&](std::uint32_t x) { return row[x]; });
    case PixelFormat::kYuyv: return decodeBars(frame.width, [&](std::uint32_t x) { return row[std::size_t{2} * x]; });
    case PixelFormat::kUyvy:
      return decodeBars(frame.width, [&](std::uint32_t x) { return row[std::size_t{2} * x + 1]; });
    case PixelFormat::kRgba8:
    case PixelFormat::kBgra8:
      return decodeBars(frame.width, [&](std::uint32_t x) { return row[std::size_t{4} * x + 1]; });
    default: return -1;
  }
}

int readImageNumber(const Image& image, std::uint32_t x0, std::uint32_t y0, std::uint32_t w, std::uint32_t h) {
  const std::uint32_t y = y0 + h / 2;
  return decodeBars(w, [&](std::uint32_t x) { return image.at(x0 + x, y, 1); });
}

}  // namespace basalt::test
