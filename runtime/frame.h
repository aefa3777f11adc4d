#pragma once

/// \file
/// \brief Frames: one image of a video stream, as devices and media produce it and the renderer
/// consumes it. Frames are pooled and reference-counted; the last reference returns a frame to
/// its pool (or hands it back to its producer), so steady-state streaming never allocates.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string_view>
#include <vector>

#include "runtime/clock.h"

namespace basalt {

/// \brief Pixel layouts Basalt moves around. YUV formats are uploaded plane by plane and
/// converted in the shader; MJPEG is compressed and must be decoded by media/ first.
enum class PixelFormat : std::uint8_t {
  kUnknown,
  kRgba8,  ///< 4 bytes per pixel, R G B A in memory order
  kBgra8,  ///< 4 bytes per pixel, B G R A in memory order
  kRgb8,   ///< 3 bytes per pixel
  kGray8,  ///< 1 byte per pixel
  kI420,   ///< planar Y, U, V; chroma halved both ways
  kYv12,   ///< planar Y, V, U; chroma halved both ways
  kNv12,   ///< Y plane, then interleaved UV; chroma halved both ways
  kNv21,   ///< Y plane, then interleaved VU
  kYuyv,   ///< packed 4:2:2, Y0 U Y1 V
  kUyvy,   ///< packed 4:2:2, U Y0 V Y1
  kMjpeg,  ///< one JPEG image per frame (bytesUsed says how long)
};

std::string_view pixelFormatName(PixelFormat format);
/// \brief Number of planes in memory for `format` (1 for packed and compressed formats).
int planeCount(PixelFormat format);
bool isYuv(PixelFormat format);

/// \brief The YUV-to-RGB matrix and range of a stream (ignored for RGB formats).
struct Colorimetry {
  enum class Matrix : std::uint8_t { kBt601, kBt709, kBt2020 };
  enum class Range : std::uint8_t { kLimited, kFull };
  Matrix matrix = Matrix::kBt601;
  Range range = Range::kLimited;
  friend bool operator==(const Colorimetry&, const Colorimetry&) = default;
};

/// \brief Where one plane's bytes are: CPU memory, a dmabuf, or both (a mapped dmabuf).
struct Plane {
  std::uint8_t* data = nullptr;  ///< CPU address, or null for a dmabuf that is not mapped
  std::uint32_t stride = 0;      ///< bytes per row
  std::uint32_t offset = 0;      ///< offset of the plane inside the dmabuf
  std::size_t size = 0;          ///< bytes in the plane
  int dmabufFd = -1;             ///< borrowed from the producer; valid while the frame is held
};

/// \brief Byte layout of a format at a size, with rows padded to `alignment` bytes.
struct FrameLayout {
  std::array<Plane, 4> planes{};  ///< offsets relative to the start of one buffer; data null
  int planeCount = 0;
  std::size_t totalSize = 0;
};
FrameLayout computeLayout(PixelFormat format, std::uint32_t width, std::uint32_t height, std::uint32_t alignment = 1);

class FramePool;
class FrameRef;

/// \brief One image with its format, size, planes, timestamp and sequence number.
///
/// Frames are never created directly: a FramePool hands them out as FrameRef. Metadata may be
/// written by the producer before it publishes the frame; after that the frame is read-only.
class Frame {
 public:
  /// \brief Called when the last reference goes, before the frame returns to its pool, so that
  /// the producer can take its buffer back (re-queue a V4L2 buffer, unref a GstBuffer).
  /// May run on any thread: implementations must be thread-safe and must not block.
  using ReleaseFn = void (*)(void* context, Frame& frame);

  PixelFormat format = PixelFormat::kUnknown;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::array<Plane, 4> planes{};
  int planeCount = 0;
  std::size_t bytesUsed = 0;   ///< payload length for compressed formats
  Nanos pts{0};                ///< presentation time on the show's Clock
  Nanos captureTime{0};        ///< when the device captured it (driver timestamp), if known
  std::uint64_t sequence = 0;  ///< producer's frame counter; gaps mean dropped frames
  Colorimetry colorimetry{};
  std::uint64_t producerCookie = 0;  ///< free for the producer (buffer index, GstBuffer*)

  /// \brief Sets the release hook for this use of the frame (cleared when it returns).
  void setRelease(ReleaseFn fn, void* context) {
    releaseFn_ = fn;
    releaseContext_ = context;
  }
  /// \brief Storage owned by the pool (empty for shells wrapping a producer's buffers).
  [[nodiscard]] std::uint8_t* storage() { return storage_.empty() ? nullptr : storage_.data(); }
  [[nodiscard]] std::size_t storageSize() const { return storage_.size(); }

 private:
  friend class FramePool;
  friend class FrameRef;
  std::atomic<std::uint32_t> refs_{0};
  ReleaseFn releaseFn_ = nullptr;
  void* releaseContext_ = nullptr;
  std::vector<std::uint8_t> storage_;  // allocated once by the pool
  std::shared_ptr<FramePool> owner_;   // set while handed out; keeps the pool alive
};

/// \brief A counted reference to a pooled Frame. Copying is cheap and never allocates.
class FrameRef {
 public:
  FrameRef() = default;
  FrameRef(const FrameRef& other);
  FrameRef(FrameRef&& other) noexcept;
  FrameRef& operator=(const FrameRef& other);
  FrameRef& operator=(FrameRef&& other) noexcept;
  ~FrameRef();

  [[nodiscard]] Frame* get() const { return frame_; }
  Frame* operator->() const { return frame_; }
  Frame& operator*() const { return *frame_; }
  explicit operator bool() const { return frame_ != nullptr; }
  void reset();

 private:
  friend class FramePool;
  explicit FrameRef(Frame* frame) : frame_(frame) {}
  Frame* frame_ = nullptr;
};

/// \brief A fixed set of frames, allocated once.
///
/// Threading: `acquire()` and the return of frames (from any thread dropping the last FrameRef)
/// are guarded by `mutex_`. The pool stays alive while any of its frames is held.
class FramePool : public std::enable_shared_from_this<FramePool> {
 public:
  struct Config {
    PixelFormat format = PixelFormat::kRgba8;
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::size_t count = 4;
    std::uint32_t rowAlignment = 1;
    /// When false the frames are shells without storage, for wrapping a producer's buffers.
    bool allocateStorage = true;
  };

  static std::shared_ptr<FramePool> create(const Config& config);
  FramePool(const FramePool&) = delete;
  FramePool& operator=(const FramePool&) = delete;

  /// \brief A free frame with its planes laid out, or an empty ref when all are in use.
  /// Never blocks and never allocates.
  [[nodiscard]] FrameRef acquire();
  [[nodiscard]] std::size_t available() const;
  [[nodiscard]] const Config& config() const { return config_; }

 private:
  struct Token {};

 public:
  FramePool(Token, const Config& config);  // use create()

 private:
  friend class FrameRef;
  void giveBack(Frame* frame);

  Config config_;
  FrameLayout layout_;
  std::vector<std::unique_ptr<Frame>> frames_;  // fixed after construction
  mutable std::mutex mutex_;
  std::vector<Frame*> free_;  // guarded by mutex_; capacity reserved for every frame
};

}  // namespace basalt
