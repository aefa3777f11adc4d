#pragma once

/// \file
/// \brief Movies whose frames carry their own number, for frame-exact tests of the player:
/// frame n shows n in binary as ten vertical bars (white = 1, most significant bit left), big
/// enough to survive H.264, VP8/VP9 and JPEG compression and chroma subsampling.

#include <cstdint>
#include <filesystem>

#include "media/recorder.h"
#include "runtime/error.h"
#include "runtime/frame.h"
#include "runtime/image.h"

namespace basalt::test {

constexpr int kNumberBits = 10;

/// \brief An RGBA image showing `number` as bars (and a colour that changes with it).
Image numberedImage(std::uint32_t width, std::uint32_t height, int number);

/// \brief Writes a clip of `frames` frames numbered from `firstNumber` at `fps` with `codec` to `path` (the
/// container from the extension), unless it exists already from an earlier test.
Result<std::filesystem::path> makeNumberedClip(const std::filesystem::path& path, int frames, double fps,
                                               media::VideoCodec codec, std::uint32_t width = 160,
                                               std::uint32_t height = 120, int firstNumber = 0);

/// \brief `video` (an AVI, as makeNumberedClip writes it) with a Vorbis sine tone of `frequency`
/// Hz beside it, `toneBuffers` of audiotestsrc's buffers long, muxed into Matroska at `path`
/// with GStreamer's own tools. An error of kUnavailable when gst-launch-1.0 is not installed.
Result<std::filesystem::path> addTone(const std::filesystem::path& video, const std::filesystem::path& path,
                                      int toneBuffers, double frequency = 440, double volume = 0.8);

/// \brief The number a decoded frame shows (I420, YV12, NV12, NV21, YUYV, UYVY, RGBA, BGRA,
/// GRAY8), or -1 when the format is not readable here.
int readFrameNumber(const Frame& frame);
/// \brief The number an RGBA image (a read-back) shows inside the rectangle x, y, w, h.
int readImageNumber(const Image& image, std::uint32_t x, std::uint32_t y, std::uint32_t w, std::uint32_t h);

}  // namespace basalt::test
