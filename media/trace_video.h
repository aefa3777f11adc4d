#pragma once

/// \file
/// \brief The video part of a device trace (DESIGN.md §5): one Matroska file per video source,
/// holding the frames as the device gave them (raw YUV or MJPEG, never re-encoded) with their
/// original timestamps, so that a replay shows the same frames at the same times.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>

#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/frame.h"

namespace basalt::media {

/// \brief Writes a video source's frames to a Matroska file.
///
/// Stores frame.pts - origin as each frame's timestamp (origin: the trace's start on the show
/// clock, or the first frame's pts); the reader numbers frames in order. Formats: MJPEG, YUYV,
/// UYVY, I420, YV12, GRAY8 and RGB as they are; NV12 and NV21 are rearranged to I420
/// (lossless); RGBA and BGRA lose their alpha (RGB).
/// Threading: one thread (the recording tap's). write() copies the frame, so the device gets
/// its buffer back at once.
class TraceVideoWriter {
 public:
  /// \brief Creates the file for frames of `format` at `width`x`height`.
  [[nodiscard]] static Result<std::unique_ptr<TraceVideoWriter>> create(const std::filesystem::path& path,
                                                                        PixelFormat format, std::uint32_t width,
                                                                        std::uint32_t height,
                                                                        std::optional<Nanos> origin = std::nullopt);
  ~TraceVideoWriter();
  TraceVideoWriter(const TraceVideoWriter&) = delete;
  TraceVideoWriter& operator=(const TraceVideoWriter&) = delete;

  [[nodiscard]] Result<void> write(const Frame& frame);
  /// \brief Finishes the file (its index and durations). Called by the destructor otherwise.
  [[nodiscard]] Result<void> finish(std::chrono::milliseconds timeout = std::chrono::seconds(20));
  [[nodiscard]] std::uint64_t framesWritten() const { return frames_; }

 private:
  struct Impl;
  TraceVideoWriter(std::unique_ptr<Impl> impl, std::filesystem::path path);
  std::unique_ptr<Impl> impl_;
  std::filesystem::path path_;
  std::uint64_t frames_ = 0;
  bool finished_ = false;
};

/// \brief Reads a trace's video file back: the frames in order with their original timestamps
/// (plus `origin`, to place them on the replaying show's clock).
class TraceVideoReader {
 public:
  [[nodiscard]] static Result<std::unique_ptr<TraceVideoReader>> open(const std::filesystem::path& path,
                                                                      Nanos origin = Nanos{0});
  ~TraceVideoReader();
  TraceVideoReader(const TraceVideoReader&) = delete;
  TraceVideoReader& operator=(const TraceVideoReader&) = delete;

  /// \brief The next frame (pts = stored timestamp + origin), an empty ref at the end, or the
  /// error of a damaged file. Blocks while the file is read (a replay thread's job).
  [[nodiscard]] Result<FrameRef> next(std::chrono::milliseconds timeout = std::chrono::seconds(10));
  [[nodiscard]] PixelFormat format() const { return format_; }
  [[nodiscard]] std::uint32_t width() const { return width_; }
  [[nodiscard]] std::uint32_t height() const { return height_; }

 private:
  struct Impl;
  TraceVideoReader(std::unique_ptr<Impl> impl, std::filesystem::path path);
  std::unique_ptr<Impl> impl_;
  std::filesystem::path path_;
  PixelFormat format_ = PixelFormat::kUnknown;
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
};

}  // namespace basalt::media
