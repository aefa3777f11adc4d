#pragma once

/// \file
/// \brief The queue device and media threads push into and the frame loop drains.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <utility>
#include <vector>

namespace basalt {

/// \brief A fixed-capacity FIFO: storage is allocated once, so pushing and popping never
/// allocate. A push into a full queue fails and is counted; nothing ever blocks.
///
/// Threading: any number of producers and consumers; `mutex_` guards the ring, `dropped_` is a
/// relaxed counter. The wake callback (usually EventLoop::wake) runs on the producer's thread,
/// outside the lock, when the queue goes from empty to non-empty.
template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity, std::function<void()> onNonEmpty = {})
      : slots_(capacity > 0 ? capacity : 1), onNonEmpty_(std::move(onNonEmpty)) {}

  BoundedQueue(const BoundedQueue&) = delete;
  BoundedQueue& operator=(const BoundedQueue&) = delete;

  /// \brief Adds an item; returns false (and counts a drop) when the queue is full.
  bool push(T item) {
    bool wasEmpty = false;
    {
      std::lock_guard lock(mutex_);
      if (size_ == slots_.size()) {
        dropped_.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
      wasEmpty = size_ == 0;
      slots_[(head_ + size_) % slots_.size()] = std::move(item);
      ++size_;
    }
    if (wasEmpty && onNonEmpty_) onNonEmpty_();
    return true;
  }

  /// \brief Removes the oldest item into `out`; false when empty.
  bool pop(T& out) {
    std::lock_guard lock(mutex_);
    if (size_ == 0) return false;
    out = std::move(slots_[head_]);
    slots_[head_] = T{};
    head_ = (head_ + 1) % slots_.size();
    --size_;
    return true;
  }

  /// \brief Pops items while `accept(front)` is true (e.g. events due by the frame's time).
  template <typename Accept, typename Sink>
  std::size_t drainWhile(Accept&& accept, Sink&& sink) {
    std::size_t n = 0;
    for (;;) {
      T item;
      {
        std::lock_guard lock(mutex_);
        if (size_ == 0 || !accept(std::as_const(slots_[head_]))) break;
        item = std::move(slots_[head_]);
        slots_[head_] = T{};
        head_ = (head_ + 1) % slots_.size();
        --size_;
      }
      sink(std::move(item));
      ++n;
    }
    return n;
  }

  [[nodiscard]] std::size_t size() const {
    std::lock_guard lock(mutex_);
    return size_;
  }
  [[nodiscard]] std::size_t capacity() const { return slots_.size(); }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  mutable std::mutex mutex_;
  std::vector<T> slots_;  // guarded by mutex_
  std::size_t head_ = 0;  // guarded by mutex_
  std::size_t size_ = 0;  // guarded by mutex_
  std::atomic<std::uint64_t> dropped_{0};
  std::function<void()> onNonEmpty_;  // set once at construction
};

}  // namespace basalt
