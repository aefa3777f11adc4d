#pragma once

/// \file
/// \brief The capture buffers of one V4L2 format negotiation, shared by the camera and the
/// frames lent out of them. Private to devices/v4l2 (and its tests); includes no kernel header.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "runtime/frame.h"
#include "runtime/unique_fd.h"

namespace basalt::devices {

/// \brief One mmap'd capture buffer and its dmabuf export (if any). Move-only; unmaps the
/// buffer when destroyed.
class V4l2MappedBuffer {
 public:
  V4l2MappedBuffer() = default;
  /// \brief Takes the mapping of `length` bytes at `data` (from mmap, not MAP_FAILED).
  V4l2MappedBuffer(void* data, std::size_t length) : data_(data), length_(length) {}
  V4l2MappedBuffer(V4l2MappedBuffer&& other) noexcept;
  V4l2MappedBuffer& operator=(V4l2MappedBuffer&& other) noexcept;
  V4l2MappedBuffer(const V4l2MappedBuffer&) = delete;
  V4l2MappedBuffer& operator=(const V4l2MappedBuffer&) = delete;
  ~V4l2MappedBuffer() { reset(); }

  [[nodiscard]] void* data() const { return data_; }
  [[nodiscard]] std::size_t length() const { return length_; }
  /// \brief The buffer exported as a dmabuf (VIDIOC_EXPBUF), or empty.
  UniqueFd dmabuf;

 private:
  void reset();
  void* data_ = nullptr;
  std::size_t length_ = 0;
};

/// \brief The buffers of one negotiation. The camera holds one share while it streams from them;
/// every frame lent to the show holds another until its last reference goes, so the last owner
/// (the camera at stopStreaming(), or the show's last frame after a close or a renegotiation)
/// unmaps the buffers and closes their descriptors. A frame coming back queues its buffer again
/// while the set streams.
///
/// Threading: lend() on the capture thread; frames come back on any thread. `leases_` is guarded
/// by `leaseMutex_`; `streaming_` and QBUF by `qbufMutex_`.
class V4l2BufferSet : public std::enable_shared_from_this<V4l2BufferSet> {
 public:
  /// \brief Takes `buffers`, mapped from the capture node, and `fd`: a duplicate of the camera's
  /// descriptor, so that a frame coming back can still queue its buffer after the camera closed
  /// its own.
  static std::shared_ptr<V4l2BufferSet> create(UniqueFd fd, std::vector<V4l2MappedBuffer> buffers);
  V4l2BufferSet(const V4l2BufferSet&) = delete;
  V4l2BufferSet& operator=(const V4l2BufferSet&) = delete;

  /// \brief Queues buffer `index` (VIDIOC_QBUF) while streaming; true when not streaming.
  [[nodiscard]] bool queue(std::uint32_t index);
  void setStreaming(bool on);
  /// \brief Lends buffer `index` to `frame` (its release hook and producer cookie): the frame
  /// keeps the set alive until its last reference goes, and then gives the buffer back.
  void lend(Frame& frame, std::uint32_t index);
  /// \brief Buffers lent to the show and not given back yet.
  [[nodiscard]] int outstanding() const;
  /// \brief Waits (capture thread) until the show has given every buffer back, or `timeout`.
  [[nodiscard]] bool waitForFrames(std::chrono::milliseconds timeout);

  [[nodiscard]] const std::vector<V4l2MappedBuffer>& buffers() const { return buffers_; }

 private:
  struct Token {};

 public:
  V4l2BufferSet(Token, UniqueFd fd, std::vector<V4l2MappedBuffer> buffers);  // use create()

 private:
  static void giveBack(void* context, Frame& frame);
  [[nodiscard]] int outstandingLocked() const;

  UniqueFd fd_;
  std::vector<V4l2MappedBuffer> buffers_;
  mutable std::mutex leaseMutex_;
  std::condition_variable returned_;
  // One per buffer: the share of the set a lent buffer's frame holds; empty while the buffer is
  // with the driver or the camera. Guarded by leaseMutex_.
  std::vector<std::shared_ptr<V4l2BufferSet>> leases_;
  std::mutex qbufMutex_;
  bool streaming_ = false;  // guarded by qbufMutex_
};

}  // namespace basalt::devices
