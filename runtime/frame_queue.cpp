#include "runtime/frame_queue.h"

#include <utility>

namespace basalt {

FrameQueue::FrameQueue(std::size_t capacity) : slots_(capacity > 0 ? capacity : 1) {}

FrameRef FrameQueue::popFrontLocked() {
  FrameRef f = std::move(slots_[head_]);
  head_ = (head_ + 1) % slots_.size();
  --size_;
  return f;
}

bool FrameQueue::tryPush(FrameRef frame) {
  std::lock_guard lock(mutex_);
  if (size_ == slots_.size()) return false;
  slots_[(head_ + size_) % slots_.size()] = std::move(frame);
  ++size_;
  return true;
}

void FrameQueue::pushDroppingOldest(FrameRef frame) {
  FrameRef dropped;  // released outside the lock: its release hook may take other locks
  {
    std::lock_guard lock(mutex_);
    if (size_ == slots_.size()) {
      dropped = popFrontLocked();
      ++dropped_;
    }
    slots_[(head_ + size_) % slots_.size()] = std::move(frame);
    ++size_;
  }
}

bool FrameQueue::waitForRoom(std::chrono::nanoseconds timeout) {
  std::unique_lock lock(mutex_);
  return room_.wait_for(lock, timeout, [this] { return closed_ || size_ < slots_.size(); }) && !closed_;
}

FrameRef FrameQueue::takeDue(Nanos now) {
  FrameRef newest;
  bool tookAny = false;
  for (;;) {
    FrameRef older;  // passed over: released outside the lock, where its release hook may lock
    {
      std::lock_guard lock(mutex_);
      if (size_ == 0 || slots_[head_]->pts > now) break;
      if (newest) {
        older = std::move(newest);
        ++dropped_;
      }
      newest = popFrontLocked();
      tookAny = true;
    }
  }
  if (tookAny) room_.notify_all();
  return newest;
}

bool FrameQueue::frontPts(Nanos& pts) const {
  std::lock_guard lock(mutex_);
  if (size_ == 0) return false;
  pts = slots_[head_]->pts;
  return true;
}

FrameRef FrameQueue::peekFront() const {
  std::lock_guard lock(mutex_);
  return size_ == 0 ? FrameRef{} : slots_[head_];
}

FrameRef FrameQueue::takeFront(bool passOver) {
  FrameRef f;
  {
    std::lock_guard lock(mutex_);
    if (size_ == 0) return f;
    f = popFrontLocked();
    if (passOver) ++dropped_;
  }
  room_.notify_all();
  return f;
}

void FrameQueue::clear() {
  std::vector<FrameRef> released;
  {
    std::lock_guard lock(mutex_);
    released.reserve(size_);
    while (size_ > 0) released.push_back(popFrontLocked());
  }
  room_.notify_all();
}

void FrameQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  room_.notify_all();
}

void FrameQueue::reopen() {
  std::lock_guard lock(mutex_);
  closed_ = false;
}

std::size_t FrameQueue::size() const {
  std::lock_guard lock(mutex_);
  return size_;
}

std::uint64_t FrameQueue::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace basalt
