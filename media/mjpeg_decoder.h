#pragma once

/// \file
/// \brief Motion-JPEG from cameras and capture cards decoded to I420 Frames on GStreamer's own
/// thread, for the renderer to upload (it cannot show JPEG). The kiosk wires a camera's MJPEG
/// frames in with push() and hands the decoder to a stream texture as its FrameSource.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "runtime/error.h"
#include "runtime/frame.h"
#include "runtime/frame_queue.h"

namespace basalt::media {

struct MjpegDecoderOptions {
  std::size_t queueFrames = 3;  ///< decoded frames kept; a live source drops the oldest
  std::string name = "camera";  ///< for messages: the device or stream
};

/// \brief MJPEG Frames in, I420 Frames out (pts, sequence and capture time kept).
///
/// Threading: push() from any one producer thread (a device's); frameAt() on the frame loop's
/// thread. Neither blocks. A corrupt JPEG is dropped and counted; the next good one shows.
class MjpegDecoder final : public FrameSource {
 public:
  [[nodiscard]] static Result<std::unique_ptr<MjpegDecoder>> create(MjpegDecoderOptions options = {});
  ~MjpegDecoder() override;
  MjpegDecoder(const MjpegDecoder&) = delete;
  MjpegDecoder& operator=(const MjpegDecoder&) = delete;

  /// \brief Queues one JPEG (a Frame of format kMjpeg with bytesUsed set) for decoding. The
  /// frame is held, not copied, until the decoder is done with it. False when the decoder is
  /// behind (the frame is dropped and counted), the frame is not MJPEG, or the JPEG was cut short
  /// (no end-of-image marker: counted as corrupt).
  bool push(const FrameRef& jpeg);
  /// \brief The newest decoded frame due at `showTime`.
  FrameRef frameAt(Nanos showTime) override;
  /// \brief For tests and offline tools: waits until `count` frames have been decoded in all.
  bool waitForDecoded(std::uint64_t count, std::chrono::milliseconds timeout);
  /// \brief For offline runs (a ManualClock show): waits until the decoder is done with `count`
  /// JPEGs in all, decoded or found corrupt, so that the frame due is the one pushed last.
  bool waitForFinished(std::uint64_t count, std::chrono::milliseconds timeout);

  [[nodiscard]] std::uint64_t decoded() const;
  [[nodiscard]] std::uint64_t dropped() const;
  /// \brief JPEGs the decoder could not read.
  [[nodiscard]] std::uint64_t corrupt() const;
  /// \brief The thread the last frame was decoded on (GStreamer's streaming thread, never the
  /// caller of push() or frameAt()); a default id before the first. For tests.
  [[nodiscard]] std::thread::id decodeThread() const;

 private:
  struct Impl;
  explicit MjpegDecoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace basalt::media
