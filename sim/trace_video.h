#pragma once

/// \file
/// \brief The seams between traces and video files. A trace's video is written and read through
/// these interfaces: media/ implements them for Matroska (GStreamer, original timestamps), and
/// sim/ has a plain uncompressed format (`.bvraw`, raw_video.h) that needs no codec. The kiosk
/// injects the Matroska implementation; sim/ never includes GStreamer.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "devices/video_source.h"
#include "runtime/error.h"
#include "runtime/frame.h"

namespace basalt::sim {

/// \brief Writes one video source's frames with their original timestamps.
/// Threading: one thread at a time (the recorder's writer thread).
class TraceVideoWriter {
 public:
  virtual ~TraceVideoWriter() = default;
  /// \brief Appends a frame; `pts` is its time since the recording started.
  [[nodiscard]] virtual Result<void> write(const Frame& frame, Nanos pts) = 0;
  /// \brief Flushes and closes the file (also done by the destructor, without the error).
  [[nodiscard]] virtual Result<void> finish() = 0;
};

/// \brief Reads a recorded video back, frame by frame, in file order.
/// Threading: one thread at a time (the replay camera's owner).
class TraceVideoReader {
 public:
  virtual ~TraceVideoReader() = default;
  [[nodiscard]] virtual devices::VideoMode mode() const = 0;
  /// \brief The next frame with `pts` = its time since the recording started, or an empty ref
  /// at the end of the file.
  [[nodiscard]] virtual Result<FrameRef> next() = 0;
  /// \brief Goes back to the first frame (for looping).
  [[nodiscard]] virtual Result<void> rewind() = 0;
};

/// \brief Makes a writer for `file` (the factory may change the extension: it returns the name
/// it wrote, relative to the trace folder, through `fileName`).
using TraceVideoWriterFactory = std::function<Result<std::unique_ptr<TraceVideoWriter>>(
    const std::filesystem::path& folder, const std::string& stem, const devices::VideoMode& mode,
    std::string& fileName)>;
/// \brief Opens a reader for a recorded file.
using TraceVideoReaderFactory =
    std::function<Result<std::unique_ptr<TraceVideoReader>>(const std::filesystem::path& file)>;

}  // namespace basalt::sim
