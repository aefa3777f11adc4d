#pragma once

/// \file
/// \brief `.bvraw`: Basalt's uncompressed trace video. Frames exactly as the device delivered
/// them (any raw format, MJPEG as its JPEG bytes), each with its original timestamp. It needs no
/// codec, so that traces record and replay bit for bit in every build; the Matroska files of
/// media/ are smaller and play in any video player.
///
/// Layout (little-endian): "BSLTRAW1", u32 pixel format, u32 width, u32 height, f64 fps; then per
/// frame: i64 pts (ns since the recording started), i64 capture time (ns), u64 sequence, u32
/// payload bytes, the payload (planes tightly packed, rows without padding).

#include <cstdio>
#include <filesystem>
#include <memory>

#include "sim/trace_video.h"

namespace basalt::sim {

class RawVideoWriter final : public TraceVideoWriter {
 public:
  [[nodiscard]] static Result<std::unique_ptr<RawVideoWriter>> create(const std::filesystem::path& path,
                                                                      const devices::VideoMode& mode);
  ~RawVideoWriter() override;
  Result<void> write(const Frame& frame, Nanos pts) override;
  Result<void> finish() override;

 private:
  RawVideoWriter(std::FILE* file, std::filesystem::path path, const devices::VideoMode& mode)
      : file_(file), path_(std::move(path)), mode_(mode) {}
  std::FILE* file_;
  std::filesystem::path path_;
  devices::VideoMode mode_;
  std::vector<std::uint8_t> scratch_;
};

class RawVideoReader final : public TraceVideoReader {
 public:
  [[nodiscard]] static Result<std::unique_ptr<RawVideoReader>> open(const std::filesystem::path& path);
  ~RawVideoReader() override;
  [[nodiscard]] devices::VideoMode mode() const override { return mode_; }
  Result<FrameRef> next() override;
  Result<void> rewind() override;

 private:
  RawVideoReader(std::FILE* file, std::filesystem::path path, const devices::VideoMode& mode)
      : file_(file), path_(std::move(path)), mode_(mode) {}
  std::FILE* file_;
  std::filesystem::path path_;
  devices::VideoMode mode_;
  std::shared_ptr<FramePool> pool_;
  std::size_t frameBytes_ = 0;
};

/// \brief The writer factory for `.bvraw` files (the default when no other is injected).
TraceVideoWriterFactory rawVideoWriterFactory();
/// \brief Opens `.bvraw` files, and hands other extensions to `other` (media's Matroska reader),
/// or explains that this build cannot read them.
TraceVideoReaderFactory videoReaderFactory(TraceVideoReaderFactory other = {});

}  // namespace basalt::sim
