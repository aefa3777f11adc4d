#pragma once

/// \file
/// \brief LAVA's "Rec": the rendered output encoded to a movie file (H.264, Motion-JPEG, VP8 or
/// VP9 in Matroska, MP4, AVI or WebM), a set number of frames or until stopped.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::media {

enum class VideoCodec : std::uint8_t { kAuto, kH264, kMjpeg, kVp8, kVp9 };

/// \brief "h264", "mjpeg", "vp8", "vp9" (and "auto").
std::string_view videoCodecName(VideoCodec codec);
/// \brief Parses a codec name; the error lists the names.
[[nodiscard]] Result<VideoCodec> parseVideoCodec(std::string_view name);

struct RecorderOptions {
  std::filesystem::path path;  ///< .mkv, .mp4, .mov, .avi or .webm: the container
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double fps = 30;
  /// kAuto: H.264 for .mkv, .mp4 and .mov; Motion-JPEG for .avi; VP9 for .webm.
  VideoCodec codec = VideoCodec::kAuto;
  int quality = 85;             ///< 1..100: JPEG quality; H.264/VP8/VP9 map it to a rate
  std::int64_t maxFrames = -1;  ///< stop after this many frames (LAVA: 330 by default, up to 1000)
  std::size_t queueFrames = 4;  ///< frames waiting for the encoder
  /// True for offline runs (manual clock): push() waits for the encoder so that no frame is
  /// lost. False for live shows: a frame the encoder has no room for is dropped and counted.
  bool waitForEncoder = true;
};

/// \brief Encodes RGBA frames to a movie file on GStreamer's threads.
///
/// Threading: push() and finish() on one thread (the frame loop's). Nothing blocks unless
/// `waitForEncoder` is set. A write error (a full disk, a removed drive) makes push() and
/// finish() return it; the show goes on without recording.
class Recorder {
 public:
  [[nodiscard]] static Result<std::unique_ptr<Recorder>> create(const RecorderOptions& options);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// \brief Adds one frame: 8-bit RGBA, top row first, of the recorder's size.
  [[nodiscard]] Result<void> push(const Image& rgba);
  /// \brief Ends the file (the container's index is written here) and waits for it to be on
  /// disk. Called once; later calls return the first result.
  [[nodiscard]] Result<void> finish(std::chrono::milliseconds timeout = std::chrono::seconds(30));

  [[nodiscard]] std::int64_t framesWritten() const { return frames_; }
  [[nodiscard]] std::int64_t framesDropped() const { return dropped_; }
  /// \brief True once maxFrames frames were pushed.
  [[nodiscard]] bool full() const { return options_.maxFrames >= 0 && frames_ >= options_.maxFrames; }
  [[nodiscard]] const RecorderOptions& options() const { return options_; }
  /// \brief "H.264 in Matroska", for messages.
  [[nodiscard]] std::string describe() const;

 private:
  struct Impl;
  Recorder(const RecorderOptions& options, std::unique_ptr<Impl> impl);
  Result<void> checkBus();

  RecorderOptions options_;
  std::unique_ptr<Impl> impl_;
  std::int64_t frames_ = 0;
  std::int64_t dropped_ = 0;
  bool finished_ = false;
  std::optional<Error> failure_;
};

}  // namespace basalt::media
