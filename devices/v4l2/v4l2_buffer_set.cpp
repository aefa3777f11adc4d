// The capture buffers of a V4L2 camera, shared between the camera and the show's frames.
//
// Hardware: any V4L2 capture node with mmap streaming (see v4l2_camera.cpp). A frame the show
// still holds when the camera stops streaming (a close, a renegotiation after an HDMI source
// change) keeps its buffers mapped; the last frame given back unmaps them.
// Limits: single-planar buffers only. Configuration: none.

#include "devices/v4l2/v4l2_buffer_set.h"

#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/mman.h>

#include <cerrno>
#include <utility>

namespace basalt::devices {

V4l2MappedBuffer::V4l2MappedBuffer(V4l2MappedBuffer&& other) noexcept
    : dmabuf(std::move(other.dmabuf)),
      data_(std::exchange(other.data_, nullptr)),
      length_(std::exchange(other.length_, 0)) {}

V4l2MappedBuffer& V4l2MappedBuffer::operator=(V4l2MappedBuffer&& other) noexcept {
  if (this != &other) {
    reset();
    dmabuf = std::move(other.dmabuf);
    data_ = std::exchange(other.data_, nullptr);
    length_ = std::exchange(other.length_, 0);
  }
  return *this;
}

void V4l2MappedBuffer::reset() {
  if (data_) ::munmap(data_, length_);
  data_ = nullptr;
  length_ = 0;
  dmabuf.reset();
}

std::shared_ptr<V4l2BufferSet> V4l2BufferSet::create(UniqueFd fd, std::vector<V4l2MappedBuffer> buffers) {
  return std::make_shared<V4l2BufferSet>(Token{}, std::move(fd), std::move(buffers));
}

V4l2BufferSet::V4l2BufferSet(Token, UniqueFd fd, std::vector<V4l2MappedBuffer> buffers)
    : fd_(std::move(fd)), buffers_(std::move(buffers)), leases_(buffers_.size()) {}

bool V4l2BufferSet::queue(std::uint32_t index) {
  std::lock_guard lock(qbufMutex_);
  if (!streaming_) return true;
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  b.index = index;
  int r = 0;
  do {
    r = ::ioctl(fd_.get(), VIDIOC_QBUF, &b);
  } while (r == -1 && errno == EINTR);
  return r == 0;
}

void V4l2BufferSet::setStreaming(bool on) {
  std::lock_guard lock(qbufMutex_);
  streaming_ = on;
}

void V4l2BufferSet::lend(Frame& frame, std::uint32_t index) {
  {
    std::lock_guard lock(leaseMutex_);
    leases_[index] = shared_from_this();  // a copy of a share: allocates nothing
  }
  frame.producerCookie = index;
  frame.setRelease(&V4l2BufferSet::giveBack, this);
}

void V4l2BufferSet::giveBack(void* context, Frame& frame) {
  auto* set = static_cast<V4l2BufferSet*>(context);
  const auto index = static_cast<std::uint32_t>(frame.producerCookie);
  // The frame's share leaves its slot before the buffer goes back to the driver (which may hand
  // it out, and the slot with it, again at once), and is dropped last: it may be the set's last
  // owner, and everything below uses the set.
  std::shared_ptr<V4l2BufferSet> share;
  {
    std::lock_guard lock(set->leaseMutex_);
    share = std::move(set->leases_[index]);
  }
  (void)set->queue(index);
  {
    std::lock_guard lock(set->leaseMutex_);
    set->returned_.notify_all();
  }
}

int V4l2BufferSet::outstandingLocked() const {
  int n = 0;
  for (const auto& lease : leases_) n += lease ? 1 : 0;
  return n;
}

int V4l2BufferSet::outstanding() const {
  std::lock_guard lock(leaseMutex_);
  return outstandingLocked();
}

bool V4l2BufferSet::waitForFrames(std::chrono::milliseconds timeout) {
  std::unique_lock lock(leaseMutex_);
  return returned_.wait_for(lock, timeout, [this] { return outstandingLocked() == 0; });
}

}  // namespace basalt::devices
